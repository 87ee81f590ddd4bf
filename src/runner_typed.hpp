// The part of a run that depends on the scalar type, instantiated once per precision in its own
// translation unit (runner_<precision>.cpp), so that the precisions compile in parallel. Every method
// (fixed step, adaptive, GBS) runs through solve(); the state is a std::array, which solve() integrates on
// the inline path (nystrom/solve_inline.hpp), the force inlined into the engines' loops.
#pragma once

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <optional>
#include <string>

#include "cli.hpp"
#include "nystrom/core/precision.hpp"
#include "nystrom/problems/kepler.hpp"
#include "nystrom/problems/reference.hpp"
#include "nystrom/solve_inline.hpp"
#include "runner.hpp"

namespace nystrom::cli {

namespace detail {

// The force evaluations a fixed-step run of n steps makes (for the progress line; FSAL accounted).
inline long expected_evals(const MethodDef& def, long n) { return n * std::max(1, def.info.forces_per_step); }

/// The final state of a run of `def` on the problem with initial state s0, force Force and period P (whole
/// periods: req.periods): fixed steps (req.steps_per_period per period; the step is the span over their
/// number) or, for an adaptive method and GBS, the tolerance req.tol. Fills the steps (accepted), force
/// evaluations, step size (the mean accepted step when adaptive) and seconds of r, and h_ref, n_ref: the
/// exact end time is h_ref n_ref (problems/reference.hpp).
template <class T, class Force, class S, class Report>
S run_solve(const MethodDef& def, const RunRequest& req, const S& s0, const T& period, Report& r, T& h_ref,
            long& n_ref) {
  const T t_end = period * T(req.periods);
  const bool adaptive = def.info.adaptive;
  const long n = req.steps_per_period * req.periods;
  std::optional<RunMeter> meter;  // fixed steps: a progress line over the expected force evaluations
  if (req.progress && !adaptive) meter.emplace(expected_evals(def, n), precision_cost(req.precision));
  const SecondOrderProblem prob(MeteredForce<Force>{Force{}, meter ? &*meter : nullptr}, s0.q, s0.v, T(0), t_end);
  SolveOptions opt;
  if (adaptive) {
    opt.rtol = req.tol;
  } else {
    opt.steps = n;
    opt.max_steps = std::max(opt.max_steps, n);  // the steps asked for (at most 1e9, checked before)
  }
  opt.keep_complex = req.keep_complex;
  opt.t_eval = {0.0};  // only the final state is kept (Solution::q_final)
  const auto w0 = std::chrono::steady_clock::now();
  Solution<decltype(s0.q)> sol;
  try {
    sol = solve(prob, def, opt);
  } catch (const invalid_input& e) {
    throw UsageError(e.what());
  }
  if (meter) meter->finish();
  const auto w1 = std::chrono::steady_clock::now();
  r.steps = sol.accepted;
  r.force_evals = sol.force_evals;
  r.seconds = std::chrono::duration<double>(w1 - w0).count();
  h_ref = adaptive ? t_end : T(t_end / T(n));  // the step solve() takes: the span over the number of steps
  n_ref = adaptive ? 1 : n;
  r.h = as_double(adaptive ? T(t_end / T(std::max(1L, sol.accepted))) : h_ref);
  return S{sol.q_final, sol.v_final};
}

}  // namespace detail

/// Kepler or harmonic run of `def` in scalar type T (validated request).
template <class T>
RunReport run_in_precision(const RunRequest& req, const MethodDef& def) {
  RunReport out;
  T h{};
  long n = 0;
  if (req.problem == "kepler") {
    if (!std::isfinite(req.ecc) || req.ecc < 0 || req.ecc >= 1)
      throw UsageError("--ecc must satisfy 0 <= e < 1 for the Kepler problem");
    const KeplerProblem<T> prob(static_cast<T>(req.ecc));
    const auto s0 = prob.initial_state();
    const auto s = detail::run_solve<T, KeplerForce>(def, req, s0, KeplerProblem<T>::period(), out, h, n);
    out.ecc = req.ecc;
    out.precession_per_period = as_double(signed_angle(lrl_vector(s0), lrl_vector(s)) / T(req.periods));
    // against the exact orbit of s0 at the exact end time h n, in quad-double or better
    const ReferenceErrors err = kepler_reference_errors(s0, s, h, n);
    out.energy_error = err.energy;
    out.position_error = err.position;
    out.t = as_double(h * T(n));
    out.q = {as_double(s.q[0]), as_double(s.q[1])};
    out.v = {as_double(s.v[0]), as_double(s.v[1])};
    return out;
  }
  if (req.problem == "harmonic") {
    const HarmonicProblem<T> prob;
    const auto s0 = prob.initial_state();
    const auto s = detail::run_solve<T, HarmonicForce>(def, req, s0, HarmonicProblem<T>::period(), out, h, n);
    // against cos t, -sin t at the exact end time h n, in quad-double or better
    const ReferenceErrors err = harmonic_reference_errors(s0, s, h, n);
    out.position_error = err.position;
    out.energy_error = err.energy;
    out.t = as_double(h * T(n));
    out.q = {as_double(s.q[0])};
    out.v = {as_double(s.v[0])};
    return out;
  }
  std::string known;
  for (const auto& p : problem_names()) known += (known.empty() ? "" : ", ") + p;
  throw UsageError("unknown problem '" + req.problem + "' (known: " + known + ")");
}

#define NYSTROM_RUNNER_INSTANTIATE(T) template RunReport run_in_precision<T>(const RunRequest&, const MethodDef&);

}  // namespace nystrom::cli
