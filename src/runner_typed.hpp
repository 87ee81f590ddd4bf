// The part of a run that depends on the scalar type, instantiated once per precision in its own
// translation unit (runner_<precision>.cpp), so that the precisions compile in parallel.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <optional>
#include <string>

#include "cli.hpp"
#include "experiments/kepler.hpp"
#include "nystrom/core/precision.hpp"
#include "nystrom/engines/integrator.hpp"
#include "nystrom/methods/catalog.hpp"
#include "nystrom/problems/kepler.hpp"
#include "nystrom/problems/reference.hpp"
#include "runner.hpp"

namespace nystrom::cli {

namespace detail {

// The force evaluations a fixed-step run of n steps makes (for the progress line; FSAL accounted).
inline long expected_evals(const MethodDef& def, long n) { return n * std::max(1, def.info.forces_per_step); }

// A fixed-step run of `def` on `prob` (KeplerProblem<T> or HarmonicProblem<T>, force Force) from its initial
// state: req.steps_per_period * req.periods steps of a period / req.steps_per_period, the force counted for the
// progress line. Fills the steps, force evaluations, step size and seconds of r; returns the final state.
template <class T, class Force, class Problem, class Result>
auto run_metered(const MethodDef& def, const RunRequest& req, const Problem& prob, Result& r) {
  const long n = req.steps_per_period * req.periods;
  const T h = Problem::period() / T(req.steps_per_period);
  auto s = prob.initial_state();
  using V = decltype(s.q);
  const auto t0 = std::chrono::steady_clock::now();
  std::optional<RunMeter> meter;
  if (req.progress) meter.emplace(expected_evals(def, n), precision_cost(req.precision));
  RealStateIntegrator<V, MeteredForce<Force>> integ(def, MeteredForce<Force>{Force{}, meter ? &*meter : nullptr},
                                                    EngineOptions{req.keep_complex});
  integ.integrate(s, h, n);
  if (meter) meter->finish();
  const long evals = integ.force_evals();
  const auto t1 = std::chrono::steady_clock::now();
  r.steps = n;
  r.force_evals = evals;
  r.h = as_double(h);
  r.seconds = std::chrono::duration<double>(t1 - t0).count();
  return s;
}

template <class T>
RunReport run_harmonic(const RunRequest& req, const MethodDef& def) {
  HarmonicProblem<T> prob;
  RunReport r;
  const auto s = run_metered<T, HarmonicForce>(def, req, prob, r);
  const T h = HarmonicProblem<T>::period() / T(req.steps_per_period);
  // against cos t, -sin t at the exact end time h n, in quad-double or better (problems/reference.hpp)
  const ReferenceErrors err = harmonic_reference_errors(prob.initial_state(), s, h, r.steps);
  r.position_error = err.position;
  r.energy_error = err.energy;
  r.t = as_double(h * T(r.steps));
  r.q = {as_double(s.q[0])};
  r.v = {as_double(s.v[0])};
  return r;
}

// run_kepler (experiments/kepler.hpp) with the force counted for the progress line: the same steps and
// results.
template <class T>
KeplerRunResult run_kepler_metered(const MethodDef& def, const RunRequest& req) {
  const KeplerProblem<T> prob(static_cast<T>(req.ecc));
  KeplerRunResult r;
  const auto s = run_metered<T, KeplerForce>(def, req, prob, r);
  const T h = KeplerProblem<T>::period() / T(req.steps_per_period);
  nystrom::detail::kepler_diagnostics(r, prob.initial_state(), s, h, r.steps, req.periods);
  return r;
}

}  // namespace detail

/// Kepler or harmonic run of `def` in scalar type T (validated request; GBS when `gbs`).
template <class T>
RunReport run_in_precision(const RunRequest& req, const MethodDef& def, bool gbs) {
  using detail::run_harmonic;
  if (req.problem == "kepler") {
    if (!std::isfinite(req.ecc) || req.ecc < 0 || req.ecc >= 1)
      throw UsageError("--ecc must satisfy 0 <= e < 1 for the Kepler problem");
    const auto k = gbs                 ? run_kepler_gbs<T>(req.ecc, req.tol, req.periods)
                   : def.info.adaptive ? run_kepler_adaptive<T>(def, req.ecc, req.tol, req.periods)
                                       : detail::run_kepler_metered<T>(def, req);
    RunReport out;
    out.ecc = req.ecc;
    out.steps = k.steps;
    out.force_evals = k.force_evals;
    out.h = k.h;
    out.precession_per_period = k.precession_per_period;
    out.energy_error = k.energy_error;
    out.position_error = k.position_error;
    out.seconds = k.seconds;
    out.t = k.t;
    out.q.assign(k.q.begin(), k.q.end());
    out.v.assign(k.v.begin(), k.v.end());
    return out;
  }
  if (req.problem == "harmonic") {
    if (def.info.adaptive) throw UsageError("adaptive methods run on the kepler problem only");
    return run_harmonic<T>(req, def);
  }
  std::string known;
  for (const auto& p : problem_names()) known += (known.empty() ? "" : ", ") + p;
  throw UsageError("unknown problem '" + req.problem + "' (known: " + known + ")");
}

#define NYSTROM_RUNNER_INSTANTIATE(T) template RunReport run_in_precision<T>(const RunRequest&, const MethodDef&, bool);

}  // namespace nystrom::cli
