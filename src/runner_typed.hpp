// The part of a run that depends on the scalar type, instantiated once per precision in its own
// translation unit (runner_<precision>.cpp), so that the precisions compile in parallel. Every method
// (fixed step, adaptive, GBS) runs through solve(); the state is a std::array, which solve() integrates on
// the inline path (nystrom/solve_inline.hpp), the force inlined into the engines' loops.
#pragma once

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <optional>
#include <string>
#include <type_traits>

#include "cli.hpp"
#include "nystrom/core/precision.hpp"
#include "nystrom/problems/kepler.hpp"
#include "nystrom/problems/reference.hpp"
#include "nystrom/solve_inline.hpp"
#include "runner.hpp"
#include "runner_solve.hpp"

namespace nystrom::cli {

namespace detail {

// The force evaluations a fixed-step run of n steps makes (for the progress line; FSAL accounted).
inline long expected_evals(const MethodDef& def, long n) { return n * std::max(1, def.info.forces_per_step); }

}  // namespace detail

/// The run with the force Force (KeplerForce, CompensatedKeplerForce or HarmonicForce).
template <class T, std::size_t N, class Force>
OrbitRun<T, N> run_orbit_with(const RunRequest& req, const MethodDef& def,
                              const RunOutputs<std::array<T, N>>& outputs) {
  static_assert(N == 1 || N == 2, "Kepler (N = 2) or the harmonic oscillator (N = 1)");
  constexpr bool kepler = N == 2;
  using Problem = std::conditional_t<kepler, KeplerProblem<T>, HarmonicProblem<T>>;
  if (kepler && (!std::isfinite(req.ecc) || req.ecc < 0 || req.ecc >= 1))
    throw UsageError("--ecc must satisfy 0 <= e < 1 for the Kepler problem");
  const Problem problem = [&] {
    if constexpr (kepler)
      return Problem(static_cast<T>(req.ecc));
    else
      return Problem();
  }();
  const auto s0 = problem.initial_state();
  const T t_end = Problem::period() * T(req.periods);
  const bool adaptive = def.info.adaptive;
  const long n = req.steps_per_period * req.periods;
  std::optional<RunMeter> meter;  // fixed steps: a progress line over the expected force evaluations
  if (req.progress && !adaptive) meter.emplace(detail::expected_evals(def, n), precision_cost(req.precision));
  const SecondOrderProblem prob(MeteredForce<Force>{Force{}, meter ? &*meter : nullptr}, s0.q, s0.v, T(0), t_end);
  SolveOptions opt;
  if (adaptive) {
    opt.rtol = req.tol;
  } else {
    opt.steps = n;
    opt.max_steps = std::max(opt.max_steps, n);  // the steps asked for (at most 1e9, checked before)
  }
  opt.keep_complex = req.keep_complex;
  for (double t : outputs.t_eval)
    if (t < 0 || T(t) > t_end)
      throw UsageError("--output-times: every time must lie in the integrated span [0, " +
                       std::to_string(as_double(t_end)) + "]");
  // Without output times only the final state is kept (Solution::q_final): the one time saved is the start.
  opt.t_eval = outputs.t_eval;
  if (opt.t_eval.empty()) opt.t_eval = {outputs.restart ? as_double(outputs.restart->t) : 0.0};
  opt.checkpoint_at = outputs.checkpoint_at;
  opt.checkpoint_problem = outputs.checkpoint_problem;
  opt.on_checkpoint = outputs.on_checkpoint;
  OrbitRun<T, N> out;
  auto& sol = out.sol;
  const auto w0 = std::chrono::steady_clock::now();
  try {
    if (outputs.restart) {
      if (outputs.restart->t > t_end) throw UsageError("the checkpoint lies after the end of the span");
      sol = resume(prob, def, *outputs.restart, opt, outputs.events);
    } else {
      sol = solve(prob, def, opt, outputs.events);
    }
  } catch (const invalid_input& e) {
    throw UsageError(e.what());
  }
  if (meter) meter->finish();
  const auto w1 = std::chrono::steady_clock::now();
  RunReport& r = out.report;
  label_report(r, req, def);
  r.steps = sol.accepted;
  r.force_evals = sol.force_evals;
  r.rejected = sol.rejected;
  r.precise_products = sol.precise_products;
  r.seconds = std::chrono::duration<double>(w1 - w0).count();
  // The exact end time is h n (problems/reference.hpp): n steps of the span over n, or one adaptive run.
  const T h = adaptive ? t_end : T(t_end / T(n));
  const long steps = adaptive ? 1 : n;
  r.h = as_double(adaptive ? T(t_end / T(std::max(1L, sol.accepted))) : h);
  const State<std::array<T, N>> s{sol.q_final, sol.v_final};
  // against the exact solution from s0 at the exact end time h n, in quad-double or better
  ReferenceErrors err;
  if constexpr (kepler) {
    r.ecc = req.ecc;
    r.precession_per_period = as_double(signed_angle(lrl_vector(s0), lrl_vector(s)) / T(req.periods));
    err = kepler_reference_errors(s0, s, h, steps);
  } else {
    err = harmonic_reference_errors(s0, s, h, steps);
  }
  r.energy_error = err.energy;
  r.position_error = err.position;
  r.t = as_double(h * T(steps));
  for (std::size_t i = 0; i < N; ++i) {
    r.q.push_back(as_double(s.q[i]));
    r.v.push_back(as_double(s.v[i]));
  }
  return out;
}

template <class T, std::size_t N>
OrbitRun<T, N> run_orbit(const RunRequest& req, const MethodDef& def, const RunOutputs<std::array<T, N>>& outputs) {
  // check_run_request (every caller's first step) admits --force compensated only for kepler in double.
  if constexpr (N == 2 && std::is_same_v<T, double>) {
    if (req.force == "compensated") return run_orbit_with<T, N, CompensatedKeplerForce>(req, def, outputs);
  }
  return run_orbit_with<T, N, std::conditional_t<N == 2, KeplerForce, HarmonicForce>>(req, def, outputs);
}

/// Kepler or harmonic run of `def` in scalar type T (validated request).
template <class T>
RunReport run_in_precision(const RunRequest& req, const MethodDef& def) {
  if (req.problem == "kepler") return run_orbit<T, 2>(req, def, {}).report;
  if (req.problem == "harmonic") return run_orbit<T, 1>(req, def, {}).report;
  std::string known;
  for (const auto& p : problem_names()) known += (known.empty() ? "" : ", ") + p;
  throw UsageError("unknown problem '" + req.problem + "' (known: " + known + ")");
}

#define NYSTROM_RUNNER_INSTANTIATE(T) template RunReport run_in_precision<T>(const RunRequest&, const MethodDef&);

}  // namespace nystrom::cli
