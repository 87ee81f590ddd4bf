// One problem, one solve(): a wave function on a periodic grid propagated in real or imaginary time by any
// splitting or multi-product method of the catalog (operators/flow_methods.hpp), with its observables,
// FFT count and, where one exists, the error against the exact solution.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <variant>
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
  /// The potential's values on the whole grid (row-major, last axis fastest, at x_i = -L/2 + i L/n); when not
  /// empty they replace `potential` and `user`.
  std::vector<R> values;
  R g = 0;  // Gross-Pitaevskii coupling
  TimeKind time = TimeKind::real;
  std::vector<R> x0, p0;  // initial Gaussian centre and momentum (missing components 0)
  R width = 1;            // initial Gaussian width (1: the harmonic coherent state)
  FftOptions fft;
  /// Imaginary time, g = 0: the `states` lowest eigenstates, the first from the initial Gaussian, each further
  /// one from that Gaussian with a fixed pseudo-random modulation, orthogonalised (Gram-Schmidt) against the
  /// lower ones after every step; QuantumResult::energies.
  int states = 1;
  /// Record the autocorrelation C(t) = <psi(0)|psi(t)> at every sample and at the end (keeps a copy of psi(0)).
  bool autocorrelation = false;
  /// The transforms of the grid; empty: FftPair over the whole grid. distributed_transforms() of
  /// quantum/fftw_mpi.hpp spreads the grid over MPI ranks (then solve() is collective and every rank gets the
  /// result of the whole grid).
  std::function<std::unique_ptr<FftTransforms<R>>(const Grid<R>&, const FftOptions&)> transforms;
  /// Keep the final wave function in QuantumResult::psi (the points this process holds).
  bool keep_state = false;
  /// When set, called as heartbeat(done, total) after every `heartbeat_steps` steps (total: steps times
  /// states), e.g. to report progress or to stop the run by throwing. A heartbeat ends a call of the
  /// integrator, so a splitting's last sub-step is not merged with the next step's first there: the result
  /// differs from a run without heartbeat in the last bits.
  std::function<void(long done, long total)> heartbeat;
  long heartbeat_steps = 0;
};

/// Observables at one time.
struct QuantumSample {
  double time, norm, energy;
  std::vector<double> mean_x;
  std::complex<double> autocorrelation{};  // <psi(0)|psi(t)> when QuantumProblem::autocorrelation is set
};

struct QuantumResult {
  std::string method;
  int order = 0;
  double dt = 0, time = 0;
  long steps = 0;
  double norm = 0, norm_drift = 0, energy = 0, chemical_potential = 0;
  std::vector<double> mean_x, mean_p;
  std::complex<double> autocorrelation{};                         // <psi(0)|psi(t)> at the end, when requested
  std::vector<double> energies;                                   // of the lowest QuantumProblem::states states
  double exact_error = std::numeric_limits<double>::quiet_NaN();  // L2 distance to the exact solution, if known
  std::string exact_solution;                                     // "harmonic coherent state", "free Gaussian", ""
  long fft_count = 0;
  double seconds = 0;
  std::vector<QuantumSample> samples;
  std::vector<std::complex<double>> psi;  // the final wave function, when QuantumProblem::keep_state is set
};

namespace detail {

inline void check_positive_finite(double x, const std::string& what) {
  if (!std::isfinite(x) || !(x > 0)) throw std::invalid_argument(what + " must be positive and finite");
}

/// A number in [-1, 1) fixed by (i, k) (splitmix64), the same on every process of a distributed grid.
inline double unit_noise(std::uint64_t i, std::uint64_t k) {
  std::uint64_t z = i * 0x9e3779b97f4a7c15ULL + k * 0xbf58476d1ce4e5b9ULL + 0x94d049bb133111ebULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  z ^= z >> 31;
  return static_cast<double>(z >> 11) * 0x1.0p-52 - 1;
}

}  // namespace detail

/// Propagates the problem's initial Gaussian by `steps` steps of size dt with `method`; records
/// `samples` evenly spaced observations (0: none). Throws std::invalid_argument for bad input or a method
/// that does not apply, std::runtime_error when the wave function blows up.
template <class R>
QuantumResult solve(const QuantumProblem<R>& p, const std::string& method, R dt, long steps, long samples = 0) {
  detail::check_positive_finite(static_cast<double>(dt), "dt");
  if (steps < 0) throw std::invalid_argument("steps must not be negative");
  if (p.states < 1 || p.states > 1000) throw std::invalid_argument("states must be between 1 and 1000");
  if (p.states > 1 && (p.time != TimeKind::imaginary || p.g != 0))
    throw std::invalid_argument("excited states need imaginary time and g = 0");
  detail::check_positive_finite(static_cast<double>(p.width), "the initial width");
  if (!std::isfinite(static_cast<double>(p.g))) throw std::invalid_argument("g must be finite");
  if (p.heartbeat && p.heartbeat_steps < 1) throw std::invalid_argument("heartbeat_steps must be positive");
  for (const auto& v : {p.x0, p.p0})
    for (R x : v)
      if (!std::isfinite(static_cast<double>(x))) throw std::invalid_argument("x0 and p0 must be finite");
  for (const auto* v : {&p.x0, &p.p0})
    if (static_cast<int>(v->size()) > p.dims)
      throw std::invalid_argument(std::string(v == &p.x0 ? "x0" : "p0") + " has " + std::to_string(v->size()) +
                                  " components for " + std::to_string(p.dims) + " dimension(s)");
  const Grid<R> grid(p.dims, p.grid, p.box);
  const operators::FlowMethod fm = operators::resolve_flow_method(method, operators::OperatorStructure::rkn,
                                                                  scalar_traits<R>::bits(), scalar_traits<R>::name());
  const PotentialFunction<R> vf = p.user ? p.user : p.values.empty() ? named_potential<R>(p.potential) : nullptr;
  auto transforms = p.transforms ? p.transforms(grid, p.fft) : std::make_unique<FftPair<R>>(grid.shape(), p.fft);
  const PointRange range{transforms->first(), transforms->local_size()};
  std::vector<R> v;
  if (p.values.empty()) {
    v = sample_potential(grid, vf, range);
  } else {
    if (p.values.size() != grid.size())
      throw std::invalid_argument("the potential has " + std::to_string(p.values.size()) + " values for " +
                                  std::to_string(grid.size()) + " grid points");
    for (R x : p.values)
      if (!std::isfinite(static_cast<double>(x))) throw std::invalid_argument("the potential is not finite");
    const auto first = p.values.begin() + static_cast<std::ptrdiff_t>(range.first);
    v.assign(first, first + static_cast<std::ptrdiff_t>(range.count));
  }
  SchrodingerFlows<R> flows(grid, std::move(v), p.time, p.g, std::move(transforms));
  if (std::holds_alternative<operators::GradientSplitting>(fm.data)) {
    if (!vf) throw std::invalid_argument("'" + method + "' needs the potential as a function (for its gradient)");
    if (p.g != 0) throw std::invalid_argument("'" + method + "' needs g = 0: its gradient term is that of V alone");
    flows.set_gradient_term(sample_gradient_squared(grid, vf, range));
  }
  operators::FlowIntegrator<SchrodingerFlows<R>> integ(fm);
  Field<R> psi = gaussian_packet(grid, p.x0, p.p0, p.width, range);
  if (p.time == TimeKind::imaginary) flows.renormalize(psi);
  flows.set_step_size(dt);

  QuantumResult r;
  r.method = fm.info.name;
  r.order = fm.info.order;
  r.dt = static_cast<double>(dt);
  r.steps = steps;
  r.time = static_cast<double>(dt) * static_cast<double>(steps);
  const double norm0 = static_cast<double>(observe(flows, psi).norm);
  Field<R> psi0;
  if (p.autocorrelation) psi0 = psi;
  auto autocorrelation = [&] {
    if (!p.autocorrelation) return std::complex<double>();
    const std::complex<R> c = overlap(flows, psi0, psi);
    return std::complex<double>(static_cast<double>(c.real()), static_cast<double>(c.imag()));
  };
  auto record = [&](long done) {
    const auto o = observe(flows, psi);
    QuantumSample s{static_cast<double>(dt) * static_cast<double>(done),
                    static_cast<double>(o.norm),
                    static_cast<double>(o.energy),
                    {}};
    for (R x : o.mean_x) s.mean_x.push_back(static_cast<double>(x));
    s.autocorrelation = autocorrelation();
    r.samples.push_back(std::move(s));
  };
  const long total = steps * p.states;
  long beaten = 0;  // steps done over all states, for the heartbeat
  // n steps of phi, in calls of at most heartbeat_steps steps with a heartbeat after each
  auto advance = [&](Field<R>& phi, long n) {
    if (!p.heartbeat) {
      integ.integrate(flows, phi, dt, n);
      return;
    }
    while (n > 0) {
      const long k = std::min(n, p.heartbeat_steps);
      integ.integrate(flows, phi, dt, k);
      n -= k;
      beaten += k;
      p.heartbeat(beaten, total);
    }
  };
  const auto t0 = std::chrono::steady_clock::now();
  if (samples > 0) {
    record(0);
    long done = 0;
    for (long i = 1; i <= samples; ++i) {
      const long target = steps * i / samples;
      advance(psi, target - done);
      done = target;
      record(done);
    }
  } else {
    advance(psi, steps);
  }
  r.autocorrelation = autocorrelation();
  const auto o = observe(flows, psi);
  r.energies.push_back(static_cast<double>(o.energy));
  std::vector<Field<R>> lower;  // the states found so far
  if (p.states > 1) lower.push_back(psi);
  for (int k = 1; k < p.states; ++k) {
    // the initial Gaussian modulated by a fixed pseudo-random factor per point: a product of one-axis
    // functions meets each degenerate level along one direction only, which the lower states may already fill
    Field<R> phi = gaussian_packet(grid, p.x0, p.p0, p.width, range);
    for (std::size_t i = 0; i < phi.size(); ++i)
      phi[i] *= static_cast<R>(1 + detail::unit_noise(range.first + i, static_cast<std::uint64_t>(k)) / 2);
    auto orthogonalise = [&] {
      for (const auto& l : lower) {
        const std::complex<R> c = overlap(flows, l, phi);
        for (std::size_t i = 0; i < phi.size(); ++i) phi[i] -= c * l[i];
      }
      flows.renormalize(phi);
    };
    orthogonalise();
    for (long i = 0; i < steps; ++i) {
      integ.integrate(flows, phi, dt, 1);
      orthogonalise();
      if (p.heartbeat && (++beaten % p.heartbeat_steps == 0 || i + 1 == steps)) p.heartbeat(beaten, total);
    }
    r.energies.push_back(static_cast<double>(observe(flows, phi).energy));
    lower.push_back(std::move(phi));
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.fft_count = flows.fft_count();

  r.norm = static_cast<double>(o.norm);
  r.norm_drift = r.norm - norm0;
  r.energy = static_cast<double>(o.energy);
  r.chemical_potential = static_cast<double>(o.chemical_potential);
  for (R x : o.mean_x) r.mean_x.push_back(static_cast<double>(x));
  for (R x : o.mean_p) r.mean_p.push_back(static_cast<double>(x));
  if (p.keep_state)
    for (const auto& z : psi) r.psi.emplace_back(static_cast<double>(z.real()), static_cast<double>(z.imag()));
  if (!std::isfinite(r.norm) || !std::isfinite(r.energy))
    throw std::runtime_error("the wave function blew up (norm or energy not finite): '" + r.method +
                             "' is unstable for this problem and step");
  if (p.time == TimeKind::real && p.g == 0 && !p.user && p.values.empty()) {
    const R t = dt * static_cast<R>(steps);
    if (p.potential == "harmonic" && p.width == 1) {
      r.exact_error = static_cast<double>(l2_distance(flows, psi, harmonic_coherent_state(grid, p.x0, p.p0, t, range)));
      r.exact_solution = "harmonic coherent state";
    } else if (p.potential == "free") {
      r.exact_error = static_cast<double>(l2_distance(flows, psi, free_gaussian(grid, p.x0, p.p0, p.width, t, range)));
      r.exact_solution = "free Gaussian";
    }
  }
  return r;
}

}  // namespace nystrom::quantum
