// `nystrom run --problem kepler|harmonic` through solve(): one run of a method (run_orbit, runner_typed.hpp, in
// every precision), with output times, events, checkpoint and restart for Kepler in double (run_kepler_solve).
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "nystrom/methods/method.hpp"
#include "nystrom/solve/solution.hpp"
#include "runner.hpp"

namespace nystrom::cli {

/// What a run asks of solve() besides the final state (V: the problem's state vector). Nothing: only the
/// final state is kept.
template <class V>
struct RunOutputs {
  using R = real_t<typename V::value_type>;
  std::vector<double> t_eval;  // output times in [0, the end of the span]; empty: the final state only
  std::vector<Event<V>> events;
  double checkpoint_at = std::numeric_limits<double>::quiet_NaN();  // SolveOptions::checkpoint_at
  std::string checkpoint_problem;                                   // what a checkpoint must match
  std::function<void(const std::string&)> on_checkpoint;
  std::optional<Checkpoint<R>> restart;  // continue from this checkpoint (double: its time is exact)
};

/// The report of a run and its solution (the final state, and what RunOutputs asked for).
template <class T, std::size_t N>
struct OrbitRun {
  RunReport report;
  Solution<std::array<T, N>> sol;
};

/// A Kepler (N = 2, eccentricity req.ecc) or harmonic (N = 1) run of `def` through solve(), in scalar type T,
/// over req.periods whole periods: fixed steps (req.steps_per_period per period: the step is the span over
/// their number) or, for an adaptive method and GBS, the tolerance req.tol (a request that run_case's checks
/// accept). The report holds the steps, force evaluations, step (the mean accepted step when adaptive),
/// seconds, the final state and its errors against the exact solution at the exact end time (Kepler: the
/// precession too). Defined in runner_typed.hpp; for T = double, N = 2 compiled in runner_double.cpp.
template <class T, std::size_t N>
OrbitRun<T, N> run_orbit(const RunRequest& req, const MethodDef& def, const RunOutputs<std::array<T, N>>& outputs);

struct SolveRequest {
  std::string output_times;  // "A:B:N": N equally spaced output times from A to B (dense output)
  std::string events;        // comma-separated: pericentre, apocentre, y=0
  std::string checkpoint;    // file written at the first step boundary at or after checkpoint_at
  double checkpoint_at = std::numeric_limits<double>::quiet_NaN();
  std::string restart;  // checkpoint file to continue from
  bool any() const {
    return !output_times.empty() || !events.empty() || !checkpoint.empty() || !restart.empty() ||
           !std::isnan(checkpoint_at);
  }
};

struct SolveRunResult {
  RunReport report;
  nlohmann::json extra;  // t, q, v (the final state, exactly), output, events, ...
};

/// Kepler in double precision through solve() (run_orbit) with the output times, events, checkpoint and
/// restart of `sreq`; throws UsageError for bad input.
SolveRunResult run_kepler_solve(const RunRequest& req, const SolveRequest& sreq, const MethodDef& def);

/// The method specification a checkpoint file was taken with; throws UsageError for an unreadable file.
std::string checkpoint_method(const std::string& path);

}  // namespace nystrom::cli
