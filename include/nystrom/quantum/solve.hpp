// One problem, one solve(): a wave function on a periodic grid propagated in real or imaginary time by any
// splitting or multi-product method of the catalog (operators/flow_methods.hpp), with its observables,
// FFT count and, where one exists, the error against the exact solution.
#pragma once

#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "nystrom/core/scalar.hpp"
#include "nystrom/operators/flow_methods.hpp"
#include "nystrom/quantum/diagnostics.hpp"
#include "nystrom/quantum/grid.hpp"
#include "nystrom/quantum/schrodinger.hpp"

namespace nystrom::quantum {

template <class R>
struct QuantumProblem {
  int dims = 1;
  int grid = 256;
  R box = 20;
  std::string potential = "harmonic";  // a name of named_potential(), ignored when `user` is set
  PotentialFunction<R> user;           // a user potential
  R g = 0;                             // Gross-Pitaevskii coupling
  TimeKind time = TimeKind::real;
  std::vector<R> x0, p0;  // initial Gaussian centre and momentum (missing components 0)
  R width = 1;            // initial Gaussian width (1: the harmonic coherent state)
  FftOptions fft;
};

/// Observables at one time.
struct QuantumSample {
  double time, norm, energy;
  std::vector<double> mean_x;
};

struct QuantumResult {
  std::string method;
  int order = 0;
  double dt = 0, time = 0;
  long steps = 0;
  double norm = 0, norm_drift = 0, energy = 0, chemical_potential = 0;
  std::vector<double> mean_x, mean_p;
  double exact_error = std::numeric_limits<double>::quiet_NaN();  // L2 distance to the exact solution, if known
  std::string exact_solution;                                     // "harmonic coherent state", "free Gaussian", ""
  long fft_count = 0;
  double seconds = 0;
  std::vector<QuantumSample> samples;
};

namespace detail {

inline void check_positive_finite(double x, const std::string& what) {
  if (!std::isfinite(x) || !(x > 0)) throw std::invalid_argument(what + " must be positive and finite");
}

}  // namespace detail

/// Propagates the problem's initial Gaussian by `steps` steps of size dt with `method`; records
/// `samples` evenly spaced observations (0: none). Throws std::invalid_argument for bad input or a method
/// that does not apply, std::runtime_error when the wave function blows up.
template <class R>
QuantumResult solve(const QuantumProblem<R>& p, const std::string& method, R dt, long steps, long samples = 0) {
  detail::check_positive_finite(static_cast<double>(dt), "dt");
  if (steps < 0) throw std::invalid_argument("steps must not be negative");
  detail::check_positive_finite(static_cast<double>(p.width), "the initial width");
  for (const auto& v : {p.x0, p.p0})
    for (R x : v)
      if (!std::isfinite(static_cast<double>(x))) throw std::invalid_argument("x0 and p0 must be finite");
  const Grid<R> grid(p.dims, p.grid, p.box);
  const operators::FlowMethod fm = operators::resolve_flow_method(method, operators::OperatorStructure::rkn,
                                                                  scalar_traits<R>::bits(), scalar_traits<R>::name());
  const PotentialFunction<R> vf = p.user ? p.user : named_potential<R>(p.potential);
  SchrodingerFlows<R> flows(grid, sample_potential(grid, vf), p.time, p.g, p.fft);
  operators::FlowIntegrator<SchrodingerFlows<R>> integ(fm);
  Field<R> psi = gaussian_packet(grid, p.x0, p.p0, p.width);
  if (p.time == TimeKind::imaginary) flows.renormalize(psi);
  flows.set_step_size(dt);

  QuantumResult r;
  r.method = fm.info.name;
  r.order = fm.info.order;
  r.dt = static_cast<double>(dt);
  r.steps = steps;
  r.time = static_cast<double>(dt) * static_cast<double>(steps);
  const double norm0 = static_cast<double>(observe(flows, psi).norm);
  auto record = [&](long done) {
    const auto o = observe(flows, psi);
    QuantumSample s{static_cast<double>(dt) * static_cast<double>(done),
                    static_cast<double>(o.norm),
                    static_cast<double>(o.energy),
                    {}};
    for (R x : o.mean_x) s.mean_x.push_back(static_cast<double>(x));
    r.samples.push_back(std::move(s));
  };
  const auto t0 = std::chrono::steady_clock::now();
  if (samples > 0) {
    record(0);
    long done = 0;
    for (long i = 1; i <= samples; ++i) {
      const long target = steps * i / samples;
      integ.integrate(flows, psi, dt, target - done);
      done = target;
      record(done);
    }
  } else {
    integ.integrate(flows, psi, dt, steps);
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.fft_count = flows.fft_count();

  const auto o = observe(flows, psi);
  r.norm = static_cast<double>(o.norm);
  r.norm_drift = r.norm - norm0;
  r.energy = static_cast<double>(o.energy);
  r.chemical_potential = static_cast<double>(o.chemical_potential);
  for (R x : o.mean_x) r.mean_x.push_back(static_cast<double>(x));
  for (R x : o.mean_p) r.mean_p.push_back(static_cast<double>(x));
  if (!std::isfinite(r.norm) || !std::isfinite(r.energy))
    throw std::runtime_error("the wave function blew up (norm or energy not finite): '" + r.method +
                             "' is unstable for this problem and step");
  if (p.time == TimeKind::real && p.g == 0 && !p.user) {
    const R t = dt * static_cast<R>(steps);
    if (p.potential == "harmonic" && p.width == 1) {
      r.exact_error = static_cast<double>(l2_distance(grid, psi, harmonic_coherent_state(grid, p.x0, p.p0, t)));
      r.exact_solution = "harmonic coherent state";
    } else if (p.potential == "free") {
      r.exact_error = static_cast<double>(l2_distance(grid, psi, free_gaussian(grid, p.x0, p.p0, p.width, t)));
      r.exact_solution = "free Gaussian";
    }
  }
  return r;
}

}  // namespace nystrom::quantum
