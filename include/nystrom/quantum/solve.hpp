// One problem, one solve(): a wave function on a periodic grid propagated in real or imaginary time by any
// splitting or multi-product method of the catalog (operators/flow_methods.hpp), with its observables,
// FFT count and, where one exists, the error against the exact solution.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "nystrom/core/error.hpp"
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
  /// The initial wave function on the whole grid (row-major, last axis fastest, as `values`); when not empty it
  /// replaces the Gaussian (x0, p0 and width must then keep their defaults). It is normalised on input
  /// (sum |psi|^2 dx^d = 1); every value must be finite and not all zero.
  std::vector<std::complex<R>> initial;
  /// Imaginary time: stop once the energy changes by less than `converge` per unit imaginary time over one step,
  /// |E_n - E_{n-1}| / dt < converge (the energy is evaluated after every step); `steps` is then the most steps.
  /// QuantumResult::converged and steps_taken say what happened. 0: off (all `steps` steps).
  double converge = 0;
  /// Imaginary time: run a method with a backward sub-step (a coefficient whose real part is not positive),
  /// which solve() otherwise refuses (see solve()).
  bool allow_negative_coefficients = false;
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
  double dt = 0, time = 0;  // time: of the steps taken
  long steps = 0;           // the steps asked for (with a convergence criterion: the most)
  long steps_taken = 0;     // the steps run (fewer than `steps` when the convergence criterion stopped the run)
  bool converged = false;   // the convergence criterion was met (false when there was none)
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

/// "-1.18" or "0.25+0.14i", for messages.
inline std::string coefficient_text(std::complex<double> z) {
  char buf[64];
  if (z.imag() == 0)
    std::snprintf(buf, sizeof buf, "%.4g", z.real());
  else
    std::snprintf(buf, sizeof buf, "%.4g%+.4gi", z.real(), z.imag());
  return buf;
}

}  // namespace detail

/// The method solve() runs when none is named: in real time KL8 (Kahan-Li, order 8), a splitting with real
/// coefficients and therefore unitary (it keeps the norm and cannot blow up); in imaginary time M8 (the
/// multi-product expansion of order 8), whose flows all run forward.
inline std::string default_method(TimeKind time) { return time == TimeKind::real ? "KL8" : "M8"; }

/// The one-line refusal of a method with a backward sub-step in imaginary time; `gradient`: Chin's 4A runs
/// on this problem (the potential is a function and g = 0).
inline std::string backward_method_message(const std::string& method, const operators::BackwardSubStep& b,
                                           bool gradient) {
  const std::string where = b.gradient ? "gradient term" : b.flow == Flow::drift ? "kinetic flow" : "potential flow";
  return "'" + method + "' has a coefficient with a real part that is not positive (" +
         detail::coefficient_text(b.coefficient) + " in the " + where +
         "): in imaginary time it amplifies the highest wave numbers and gives a wrong ground state; use a forward "
         "method: " +
         operators::forward_alternatives(operators::OperatorStructure::rkn, gradient) +
         "; allow_negative_coefficients (CLI --allow-negative-coefficients) runs it anyway";
}

/// Propagates the problem's initial state (the Gaussian or QuantumProblem::initial) by `steps` steps of size dt
/// with `method` (empty: default_method()); records `samples` evenly spaced observations (0: none). Throws
/// std::invalid_argument or nystrom::invalid_input for bad input or a method that does not apply (in
/// imaginary time: a method with a backward sub-step, unless allow_negative_coefficients), std::runtime_error
/// when the wave function blows up.
template <class R>
QuantumResult solve(const QuantumProblem<R>& p, const std::string& method_name, R dt, long steps, long samples = 0) {
  const std::string method = method_name.empty() ? default_method(p.time) : method_name;
  detail::check_positive_finite(static_cast<double>(dt), "dt");
  if (steps < 0) throw std::invalid_argument("steps must not be negative");
  if (p.states < 1 || p.states > 1000) throw std::invalid_argument("states must be between 1 and 1000");
  if (p.states > 1 && (p.time != TimeKind::imaginary || p.g != 0))
    throw std::invalid_argument("excited states need imaginary time and g = 0");
  detail::check_positive_finite(static_cast<double>(p.width), "the initial width");
  if (!std::isfinite(static_cast<double>(p.g))) throw std::invalid_argument("g must be finite");
  if (p.heartbeat && p.heartbeat_steps < 1) throw std::invalid_argument("heartbeat_steps must be positive");
  if (!(p.converge >= 0) || !std::isfinite(p.converge))
    throw std::invalid_argument("the convergence tolerance must be positive and finite");
  if (p.converge > 0 && p.time != TimeKind::imaginary)
    throw std::invalid_argument("a convergence tolerance needs imaginary time");
  if (p.converge > 0 && p.states > 1)
    throw std::invalid_argument("a convergence tolerance works on the ground state alone (states = 1)");
  if (!p.initial.empty() && (!p.x0.empty() || !p.p0.empty() || p.width != 1))
    throw std::invalid_argument("an initial wave function replaces the Gaussian: give no x0, p0 or width with it");
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
  // |psi|^2 is not analytic in psi: sub-steps at complex times do not compose as a complex method's order
  // conditions assume (BC1 and AC1 in imaginary time on g = 2 converge at first order, measured)
  if (p.g != 0 && fm.info.complex)
    throw invalid_input("'" + fm.info.name +
                        "' has complex coefficients: on the Gross-Pitaevskii equation (g != 0) it loses its order "
                        "(the nonlinearity |psi|^2 is not analytic in complex sub-steps); use a real method such as "
                        "M4..M16 or PV");
  if (p.time == TimeKind::imaginary && !p.allow_negative_coefficients)
    if (const auto b = operators::backward_sub_step(fm))
      throw invalid_input(backward_method_message(fm.info.name, *b, vf && p.g == 0));
  if (!p.initial.empty()) {
    if (p.initial.size() != grid.size())
      throw std::invalid_argument("the initial wave function has " + std::to_string(p.initial.size()) + " values for " +
                                  std::to_string(grid.size()) + " grid points");
    for (const auto& z : p.initial)
      if (!std::isfinite(static_cast<double>(z.real())) || !std::isfinite(static_cast<double>(z.imag())))
        throw std::invalid_argument("the initial wave function is not finite");
  }
  SchrodingerFlows<R> flows(grid, std::move(v), p.time, p.g, std::move(transforms));
  if (std::holds_alternative<operators::GradientSplitting>(fm.data)) {
    if (!vf) throw std::invalid_argument("'" + method + "' needs the potential as a function (for its gradient)");
    if (p.g != 0) throw std::invalid_argument("'" + method + "' needs g = 0: its gradient term is that of V alone");
    flows.set_gradient_term(sample_gradient_squared(grid, vf, range));
  }
  operators::FlowIntegrator<SchrodingerFlows<R>> integ(fm);
  // the initial state: the user's (normalised here) or the Gaussian
  auto initial_state = [&] {
    if (p.initial.empty()) return gaussian_packet(grid, p.x0, p.p0, p.width, range);
    const auto first = p.initial.begin() + static_cast<std::ptrdiff_t>(range.first);
    Field<R> f(first, first + static_cast<std::ptrdiff_t>(range.count));
    const R n2 = flows.norm2(f);
    if (!(n2 > 0) || !std::isfinite(static_cast<double>(n2)))
      throw std::invalid_argument("the initial wave function is zero or too large to normalise");
    flows.scale(f, 1 / std::sqrt(n2));
    return f;
  };
  Field<R> psi = initial_state();
  if (p.time == TimeKind::imaginary) flows.renormalize(psi);
  flows.set_step_size(dt);

  QuantumResult r;
  r.method = fm.info.name;
  r.order = fm.info.order;
  r.dt = static_cast<double>(dt);
  r.steps = steps;
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
  long done = 0;
  if (p.converge > 0) {
    // one step at a time, the energy after each; the heartbeat every heartbeat_steps steps and at the stop
    if (samples > 0) record(0);
    long next_sample = 1;
    double e_prev = static_cast<double>(observe(flows, psi).energy);
    while (done < steps) {
      integ.integrate(flows, psi, dt, 1);
      ++done;
      const double e = static_cast<double>(observe(flows, psi).energy);
      r.converged = std::abs(e - e_prev) / static_cast<double>(dt) < p.converge;
      const bool stop = r.converged || !std::isfinite(e);
      e_prev = e;
      if (samples > 0 && next_sample <= samples && (done == steps * next_sample / samples || stop)) {
        record(done);
        while (next_sample <= samples && steps * next_sample / samples <= done) ++next_sample;
      }
      if (p.heartbeat && (done % p.heartbeat_steps == 0 || done == steps || stop)) p.heartbeat(done, total);
      if (stop) break;
    }
  } else if (samples > 0) {
    record(0);
    for (long i = 1; i <= samples; ++i) {
      const long target = steps * i / samples;
      advance(psi, target - done);
      done = target;
      record(done);
    }
  } else {
    advance(psi, steps);
    done = steps;
  }
  r.steps_taken = done;
  r.time = static_cast<double>(dt) * static_cast<double>(done);
  r.autocorrelation = autocorrelation();
  const auto o = observe(flows, psi);
  r.energies.push_back(static_cast<double>(o.energy));
  std::vector<Field<R>> lower;  // the states found so far
  if (p.states > 1) lower.push_back(psi);
  for (int k = 1; k < p.states; ++k) {
    // the initial Gaussian modulated by a fixed pseudo-random factor per point: a product of one-axis
    // functions meets each degenerate level along one direction only, which the lower states may already fill
    Field<R> phi = initial_state();
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
  const std::string remedy =
      "; use a smaller step or " +
      std::string(p.time == TimeKind::real
                      ? "a unitary method (a splitting with real coefficients, e.g. KL8, the real-time default; a "
                        "multi-product or complex-coefficient method is not unitary in real time)"
                      : "a forward method (e.g. M8, the imaginary-time default)");
  if (!std::isfinite(r.norm) || !std::isfinite(r.energy))
    throw std::runtime_error("the wave function blew up (norm or energy not finite): '" + r.method +
                             "' is unstable for this problem and step" + remedy);
  // real time: a unitary method keeps the norm to rounding; a drift of 1% means the result is not the solution
  if (p.time == TimeKind::real && std::abs(r.norm_drift) > 0.01 * norm0) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "the norm drifted from %.6g to %.6g in real time: '", norm0, r.norm);
    throw std::runtime_error(buf + r.method + "' is not unitary and unstable for this problem and step" + remedy);
  }
  if (p.time == TimeKind::real && p.g == 0 && !p.user && p.values.empty() && p.initial.empty()) {
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
