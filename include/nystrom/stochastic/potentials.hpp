// The built-in one-dimensional Langevin problems of the tool and the Python module (unit mass):
//   harmonic     U(q) = omega^2 q^2 / 2,   a(q) = -omega^2 q
//   double-well  U(q) = (q^2 - 1)^2,       a(q) = -4 q (q^2 - 1)
// with the observables q, q2 = q^2, q4 = q^4, v2 = v^2 and the energy U(q) + v^2 / 2.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "nystrom/core/error.hpp"
#include "nystrom/stochastic/langevin.hpp"

namespace nystrom::stochastic {

enum class Potential1D : unsigned char { harmonic, double_well };

inline Potential1D parse_potential_1d(const std::string& name) {
  if (name == "harmonic") return Potential1D::harmonic;
  if (name == "double-well") return Potential1D::double_well;
  throw invalid_input("unknown Langevin potential '" + name.substr(0, 40) + "' (harmonic or double-well)");
}

struct Acceleration1D {
  Potential1D potential = Potential1D::harmonic;
  double omega2 = 1;
  void operator()(std::span<const double> q, std::span<double> a) const {
    a[0] = potential == Potential1D::harmonic ? -omega2 * q[0] : -4 * q[0] * (q[0] * q[0] - 1);
  }
  double energy(double q) const {
    return potential == Potential1D::harmonic ? 0.5 * omega2 * q * q : (q * q - 1) * (q * q - 1);
  }
};

struct Moments1D {
  Acceleration1D force;
  void operator()(std::span<const double> q, std::span<const double> v, std::span<double> out) const {
    const double x = q[0], x2 = x * x;
    out[0] = x;
    out[1] = x2;
    out[2] = x2 * x2;
    out[3] = v[0] * v[0];
    out[4] = force.energy(x) + 0.5 * v[0] * v[0];
  }
};

using Problem1D = LangevinProblem<Acceleration1D, Moments1D>;

/// A built-in problem: `potential` harmonic (with omega) or double-well, from (q0, v0).
inline Problem1D builtin_problem_1d(const std::string& potential, double gamma, double kT, double t_end, double q0 = 1,
                                    double v0 = 0, double omega = 1) {
  if (!(omega > 0) || !std::isfinite(omega)) throw invalid_input("omega must be positive and finite");
  const Acceleration1D a{parse_potential_1d(potential), omega * omega};
  Problem1D p{a, Moments1D{a}, {"q", "q2", "q4", "v2", "energy"}, {q0}, {v0}, gamma, kT, 1.0, t_end};
  return p;
}

}  // namespace nystrom::stochastic
