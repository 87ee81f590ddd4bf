// The options of solve() (plain data; the public solve() header includes it).
#pragma once

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "nystrom/core/state.hpp"
#include "nystrom/engines/options.hpp"

namespace nystrom {

struct SolveOptions {
  /// Fixed step: the step size (the last step is shortened to end on t1), or the number of equal steps.
  double h = 0;
  long steps = 0;
  /// Adaptive methods and GBS: the relative and absolute tolerances, finite and >= 0, not both 0. The
  /// error of a component of size |y_i| is measured against sc_i = atol + rtol |y_i| (rtol 0: absolute
  /// only). atol 0 means atol = rtol; the adaptive RKN and MPE engines then (and for atol = rtol) use
  /// sc_i = rtol (1 + |y_i|), the same scale but for rounding.
  double rtol = 0;
  double atol = 0;
  /// Output times, monotone in the direction of integration, within the span (by partial steps of the
  /// method, as sol(t); their forces are counted in output_force_evals). Empty: the state at every step
  /// end (and at t0).
  std::vector<double> t_eval{};
  /// Keep every step end, and a copy of the method and force, for sol(t) (solve/dense.hpp): one force
  /// evaluation per step end for the Hermite interpolant, counted in output_force_evals. Off by default
  /// (it costs memory and force evaluations at every step); output times and events do not need it.
  bool dense = false;
  /// The largest number of steps (accepted and rejected).
  long max_steps = 10000000;
  /// Step control of the adaptive RKN and MPE methods and of GBS. The first step (0: automatic; Hairer's
  /// starting step for the adaptive methods, the whole span for GBS).
  double h0 = 0;
  /// Adaptive RKN and MPE methods only (solve() refuses them for GBS and fixed steps when not at these
  /// defaults): the largest step (0: the span); the safety factor on the optimal step, in (0, 1]; the
  /// smallest and largest step ratio per step; Gustafsson's predictive step ratio as well; the order p of
  /// the error estimate (0: from the method); the exponent and the anchor of the controller's tolerance (0: the
  /// method's calibration, MethodInfo::tolerance_exponent and tolerance_anchor; exponent 1: tol itself;
  /// AdaptiveOptions::tolerance_exponent).
  double h_max = 0;
  double safety = 0.9;
  double fac_min = 0.2;
  double fac_max = 4.0;
  bool predictive = true;
  int error_order = 0;
  double tolerance_exponent = 0;
  double tolerance_anchor = 0;
  /// Complex-coefficient methods: keep the complexified state instead of dropping the imaginary parts
  /// after every step (the default drops them, as in the Gurkan paper).
  bool keep_complex = false;
  /// Compensated summation of the updates q += dq, v += dv (automatic: on for float and double, off for
  /// wider types).
  Compensation compensated = Compensation::automatic;
  /// Multi-product methods: how the products of a step are scheduled (bitwise the same results; see
  /// EngineOptions in core/state.hpp), and the threads of the concurrent schedule (0: OpenMP's default).
  MpeSchedule mpe_schedule = MpeSchedule::automatic;
  int mpe_threads = 0;
  /// Take a checkpoint at the first step boundary at or after this time (NaN: none); the run goes on
  /// unchanged. Solution::checkpoint holds it; checkpoint_problem is stored in it.
  double checkpoint_at = std::numeric_limits<double>::quiet_NaN();
  std::string checkpoint_problem{};
  /// Called with the checkpoint as text (to_text; float, double and long double states) when it is
  /// taken, if set: e.g. to write it to a file (write_checkpoint_text) while the run goes on.
  std::function<void(const std::string& checkpoint_text)> on_checkpoint{};
  /// Called at every on_step_every-th accepted step end of the call (counted from its start) with its
  /// time, if set (a progress display, an interruption check); an exception it throws ends the run and
  /// leaves solve() unchanged. Fixed steps between two calls with nothing else to record (no events, no
  /// dense output, no output time, no checkpoint due) run as a loop of bare engine steps.
  std::function<void(double t)> on_step{};
  long on_step_every = 1;
  /// When a run fails (step_size_underflow, too_many_steps, a state no longer finite: a nystrom::error
  /// other than invalid_input), return what it reached instead of throwing: the saved states up to the
  /// failure (every step end, or the output times passed), status `failed`, the error's message, and the
  /// force evaluations and accepted steps up to the failure.
  bool partial_on_failure = false;
};

}  // namespace nystrom

namespace nystrom::detail {

/// The engines' options that SolveOptions carries.
inline EngineOptions engine_options(const SolveOptions& o) {
  EngineOptions e;
  e.keep_complex = o.keep_complex;
  e.compensated = o.compensated;
  e.mpe_schedule = o.mpe_schedule;
  e.mpe_threads = o.mpe_threads;
  return e;
}

/// The adaptive engines' options that SolveOptions carries.
inline AdaptiveOptions adaptive_options(const SolveOptions& opt) {
  AdaptiveOptions ao;
  ao.rtol = opt.rtol;
  ao.atol = opt.atol;
  ao.max_steps = opt.max_steps;
  ao.h0 = opt.h0;
  ao.h_max = opt.h_max;
  ao.safety = opt.safety;
  ao.fac_min = opt.fac_min;
  ao.fac_max = opt.fac_max;
  ao.predictive = opt.predictive;
  ao.error_order = opt.error_order;
  ao.tolerance_exponent = opt.tolerance_exponent;
  ao.tolerance_anchor = opt.tolerance_anchor;
  return ao;
}

}  // namespace nystrom::detail
