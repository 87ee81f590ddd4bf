// A periodic grid [-L/2, L/2)^d with n points per axis (units hbar = m = 1), the potentials of the quantum
// layer and Gaussian initial states.
#pragma once

#include <cmath>
#include <complex>
#include <cstddef>
#include <functional>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "nystrom/quantum/fftw.hpp"

namespace nystrom::quantum {

template <class R>
struct Grid {
  int dims = 1;
  int n = 64;
  R box = 20;

  Grid() = default;
  Grid(int d, int points, R length) : dims(d), n(points), box(length) {
    if (d < 1 || d > 3) throw std::invalid_argument("dims must be 1, 2 or 3, got " + std::to_string(d));
    if (points < 2)
      throw std::invalid_argument("grid must have at least 2 points per axis, got " + std::to_string(points));
    if (!(length > 0) || !std::isfinite(static_cast<double>(length)))
      throw std::invalid_argument("box must be positive and finite");
    std::size_t total = 1;
    for (int i = 0; i < d; ++i) {
      if (total > (std::size_t{1} << 31) / static_cast<std::size_t>(points))
        throw std::invalid_argument("grid too large: " + std::to_string(points) + "^" + std::to_string(d) + " points");
      total *= static_cast<std::size_t>(points);
    }
  }

  std::size_t size() const {
    std::size_t s = 1;
    for (int i = 0; i < dims; ++i) s *= static_cast<std::size_t>(n);
    return s;
  }
  std::vector<int> shape() const { return std::vector<int>(static_cast<std::size_t>(dims), n); }
  R dx() const { return box / static_cast<R>(n); }
  /// Volume element dx^d.
  R cell() const { return std::pow(dx(), static_cast<R>(dims)); }
  R coordinate(int i) const { return -box / 2 + static_cast<R>(i) * dx(); }
  /// Wave number of FFT index i: 2 pi m / L with m in [-n/2, n/2).
  R wavenumber(int i) const {
    const int m = i < (n + 1) / 2 ? i : i - n;
    return 2 * std::numbers::pi_v<R> * static_cast<R>(m) / box;
  }
  /// Per-axis indices of flat index idx (last axis fastest).
  void indices(std::size_t idx, int* out) const {
    for (int a = dims - 1; a >= 0; --a) {
      out[a] = static_cast<int>(idx % static_cast<std::size_t>(n));
      idx /= static_cast<std::size_t>(n);
    }
  }
};

/// A potential as a function of the position (dims coordinates).
template <class R>
using PotentialFunction = std::function<R(const R* x, int dims)>;

/// Named potentials (docs/quantum.md):
///   harmonic      |x|^2 / 2 (ground state d/2)
///   anisotropic   sum_j w_j^2 x_j^2 / 2, w = 1, sqrt 2, sqrt 3 (ground state (1 + sqrt 2 + sqrt 3)/2 in 3D)
///   morse         sum_j D (1 - e^{-a x_j})^2, D = 8, a = 1/2 (levels per axis (v+1/2) w - ((v+1/2) w)^2/(4D),
///                 w = a sqrt(2D) = 2)
///   double-well   (x_0^2 - 1)^2 + sum_{j>0} x_j^2 / 2
///   soft-coulomb  -1 / sqrt(|x|^2 + 1)
///   free          0
inline std::vector<std::string> potential_names() {
  return {"harmonic", "anisotropic", "morse", "double-well", "soft-coulomb", "free"};
}

template <class R>
PotentialFunction<R> named_potential(const std::string& name) {
  if (name == "harmonic")
    return [](const R* x, int d) {
      R v = 0;
      for (int j = 0; j < d; ++j) v += x[j] * x[j] / 2;
      return v;
    };
  if (name == "anisotropic")
    return [](const R* x, int d) {
      R v = 0;
      for (int j = 0; j < d; ++j) v += static_cast<R>(j + 1) * x[j] * x[j] / 2;
      return v;
    };
  if (name == "morse")
    return [](const R* x, int d) {
      R v = 0;
      for (int j = 0; j < d; ++j) {
        const R e = 1 - std::exp(-x[j] / 2);
        v += 8 * e * e;
      }
      return v;
    };
  if (name == "double-well")
    return [](const R* x, int d) {
      R v = (x[0] * x[0] - 1) * (x[0] * x[0] - 1);
      for (int j = 1; j < d; ++j) v += x[j] * x[j] / 2;
      return v;
    };
  if (name == "soft-coulomb")
    return [](const R* x, int d) {
      R r2 = 1;
      for (int j = 0; j < d; ++j) r2 += x[j] * x[j];
      return -1 / std::sqrt(r2);
    };
  if (name == "free") return [](const R*, int) { return R(0); };
  std::string known;
  for (const auto& p : potential_names()) known += (known.empty() ? "" : ", ") + p;
  throw std::invalid_argument("unknown potential '" + name + "' (known: " + known + ")");
}

/// The potential's values on the grid.
template <class R>
std::vector<R> sample_potential(const Grid<R>& g, const PotentialFunction<R>& v) {
  std::vector<R> out(g.size());
  int idx[3];
  R x[3];
  for (std::size_t i = 0; i < out.size(); ++i) {
    g.indices(i, idx);
    for (int a = 0; a < g.dims; ++a) x[a] = g.coordinate(idx[a]);
    out[i] = v(x, g.dims);
    if (!std::isfinite(static_cast<double>(out[i])))
      throw std::invalid_argument("the potential is not finite on the grid");
  }
  return out;
}

/// A Gaussian wave packet prod_j (pi s^2)^{-1/4} exp(-(x_j - x0_j)^2 / (2 s^2) + i p0_j x_j) (missing
/// components of x0, p0 are 0). With s = 1 it is the coherent state of the harmonic oscillator.
template <class R>
Field<R> gaussian_packet(const Grid<R>& g, const std::vector<R>& x0, const std::vector<R>& p0, R s = 1) {
  if (!(s > 0)) throw std::invalid_argument("the width of the wave packet must be positive");
  Field<R> psi(g.size());
  int idx[3];
  const R norm1 = std::pow(std::numbers::pi_v<R> * s * s, R(-0.25));
  for (std::size_t i = 0; i < psi.size(); ++i) {
    g.indices(i, idx);
    std::complex<R> v(1);
    for (int a = 0; a < g.dims; ++a) {
      const R x = g.coordinate(idx[a]);
      const R c = a < static_cast<int>(x0.size()) ? x0[a] : R(0);
      const R p = a < static_cast<int>(p0.size()) ? p0[a] : R(0);
      v *= norm1 * std::exp(std::complex<R>(-(x - c) * (x - c) / (2 * s * s), p * x));
    }
    psi[i] = v;
  }
  return psi;
}

/// Exact solution of the isotropic harmonic oscillator (w = 1) from gaussian_packet(x0, p0, 1) at time t:
/// the coherent state keeps its shape and its centre follows the classical orbit q(t) = x0 cos t + p0 sin t,
/// p(t) = p0 cos t - x0 sin t: psi = prod_j pi^{-1/4} exp(-(x - q)^2/2 + i p x - i t/2 - i (q p - x0 p0)/2)
/// (substituting into i psi_t = (-d^2/dx^2 + x^2)/2 psi gives the phase; docs/quantum.md).
template <class R>
Field<R> harmonic_coherent_state(const Grid<R>& g, const std::vector<R>& x0, const std::vector<R>& p0, R t) {
  Field<R> psi(g.size());
  int idx[3];
  const R norm1 = std::pow(std::numbers::pi_v<R>, R(-0.25));
  for (std::size_t i = 0; i < psi.size(); ++i) {
    g.indices(i, idx);
    std::complex<R> v(1);
    for (int a = 0; a < g.dims; ++a) {
      const R x = g.coordinate(idx[a]);
      const R c0 = a < static_cast<int>(x0.size()) ? x0[a] : R(0);
      const R m0 = a < static_cast<int>(p0.size()) ? p0[a] : R(0);
      const R q = c0 * std::cos(t) + m0 * std::sin(t);
      const R p = m0 * std::cos(t) - c0 * std::sin(t);
      v *= norm1 * std::exp(std::complex<R>(-(x - q) * (x - q) / 2, p * x - t / 2 - (q * p - c0 * m0) / 2));
    }
    psi[i] = v;
  }
  return psi;
}

/// Exact free evolution of gaussian_packet(x0, p0, s) at time t (no periodic images: valid while the
/// packet stays far from the box edges).
template <class R>
Field<R> free_gaussian(const Grid<R>& g, const std::vector<R>& x0, const std::vector<R>& p0, R s, R t) {
  Field<R> psi(g.size());
  int idx[3];
  const std::complex<R> w = std::complex<R>(1, t / (s * s));  // 1 + i t / s^2
  const std::complex<R> norm1 = std::pow(std::numbers::pi_v<R> * s * s, R(-0.25)) / std::sqrt(w);
  for (std::size_t i = 0; i < psi.size(); ++i) {
    g.indices(i, idx);
    std::complex<R> v(1);
    for (int a = 0; a < g.dims; ++a) {
      const R x = g.coordinate(idx[a]);
      const R c = a < static_cast<int>(x0.size()) ? x0[a] : R(0);
      const R p = a < static_cast<int>(p0.size()) ? p0[a] : R(0);
      const R y = x - c - p * t;
      v *= norm1 * std::exp(-y * y / (2 * s * s * w) + std::complex<R>(0, p * x - p * p * t / 2));
    }
    psi[i] = v;
  }
  return psi;
}

}  // namespace nystrom::quantum
