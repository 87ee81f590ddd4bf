// One driver for every method: solve(problem, method, options) integrates a SecondOrderProblem with any
// catalog method or specification and returns a Solution.
//
//   auto prob = nystrom::SecondOrderProblem(force, q0, v0, 0.0, 20.0);       // force(q, a) or force(t, q, a)
//   auto sol  = nystrom::solve(prob, "M8", {.steps = 2000});                  // fixed step (or .h = 0.01)
//   auto sol  = nystrom::solve(prob, "DP12-adaptive", {.rtol = 1e-12});       // adaptive (also M10-adaptive, ...)
//   auto sol  = nystrom::solve(prob, "GBS", {.rtol = 1e-12});                 // Gragg-Bulirsch-Stoer
//   sol.t, sol.q, sol.v         saved times and states (options.t_eval, or every step end)
//   sol(t)                      the state at any t of the span (dense output, solve/dense.hpp)
//   sol.events                  located events (Event: g(t, q, v) = 0, direction, terminal)
//   sol.force_evals, sol.accepted, sol.rejected, sol.status, sol.message
//
// solve() chooses the engine from the method once: splitting, RKN and multi-product methods with fixed
// steps; adaptive RKN pairs and adaptive multi-product methods with a tolerance; GBS. Complex-coefficient
// methods run on the complexified state and drop the imaginary parts after every step (the force must
// then accept complex states: a generic lambda or a template operator()). Backward integration (t1 < t0)
// integrates the time-reversed problem (v -> -v, t -> -t), so that every engine steps forward. A
// time-dependent force a(t, q) runs as an autonomous one with t as one more coordinate (velocity 1,
// acceleration 0): every method integrates it exactly (drifts move it by c h, RKN stages by c_i h), and a
// time-independent force costs nothing more.
//
// Fixed steps: one engine call per step (Integrator::integrate(s, h, n) with n > 1 joins the last
// sub-step of a step with the first of the next, which changes the rounding), so that the steps are the
// same with or without outputs, events and checkpoints, and a restarted run is bitwise the
// uninterrupted one.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <cstddef>
#include <exception>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "nystrom/core/error.hpp"
#include "nystrom/core/state.hpp"
#include "nystrom/engines/adaptive_mpe.hpp"
#include "nystrom/engines/adaptive_rkn.hpp"
#include "nystrom/engines/gbs.hpp"
#include "nystrom/engines/integrator.hpp"
#include "nystrom/methods/catalog.hpp"
#include "nystrom/problems/counting_force.hpp"
#include "nystrom/solve/checkpoint.hpp"
#include "nystrom/solve/dense.hpp"
#include "nystrom/solve/problem.hpp"

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
  /// evaluation per step end for the Hermite interpolant, counted in output_force_evals. Output times
  /// and events do not need it.
  bool dense = true;
  /// The largest number of steps (accepted and rejected).
  long max_steps = 10000000;
  /// Engine options (compensated summation, MPE schedule, keep_complex).
  EngineOptions engine{};
  /// Adaptive RKN and MPE controller (tol and max_steps are taken from above).
  AdaptiveOptions adaptive{};
  /// GBS (rtol, atol and max_steps are taken from above).
  GbsOptions gbs{};
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

/// An event function g(t, q, v): its zeros are located (direction: +1 rising only, -1 falling only,
/// 0 both); a terminal event ends the integration there.
template <class V>
struct Event {
  using real_type = real_t<typename V::value_type>;
  std::string name;
  std::function<real_type(const real_type& t, const V& q, const V& v)> g;
  int direction = 0;
  bool terminal = false;
};

template <class V>
struct EventHit {
  using real_type = real_t<typename V::value_type>;
  std::string name;
  std::size_t index = 0;  // which event
  real_type t{};
  V q, v;
};

enum class SolveStatus { success, terminated_by_event, failed };

template <class V>
struct Solution {
  using real_type = real_t<typename V::value_type>;
  std::vector<real_type> t;
  std::vector<V> q, v;
  /// The state where the integration ended (t1, a terminal event, or the last saved state of a failed run).
  real_type t_final{};
  V q_final, v_final;
  long force_evals = 0;         // by the method: every stage, rejected steps and starting-step estimates
                                // (a failed run: those up to the failure)
  long output_force_evals = 0;  // at step ends for the dense output and events
  long accepted = 0, rejected = 0;
  SolveStatus status = SolveStatus::success;
  std::string message;
  std::vector<EventHit<V>> events;
  DenseOutput<V> dense;
  std::optional<Checkpoint<real_type>> checkpoint;

  /// The state at any t within the integrated span.
  State<V> operator()(const real_type& tt) const { return dense(tt); }
};

namespace solve_detail {

/// The vector the engines integrate: V (or its complex counterpart) with one more coordinate for t
/// when the force is time-dependent.
template <class V, bool Extend>
struct extended;
template <class V>
struct extended<V, false> {
  using type = V;
};
template <class S, std::size_t N>
struct extended<std::array<S, N>, true> {
  using type = std::array<S, N + 1>;
};
template <class S, class A>
struct extended<std::vector<S, A>, true> {
  using type = std::vector<S>;
};

/// The force on the engine's vector: the user's force, time-reversed for backward integration
/// (dir = -1: t = -tau) and with t read from the extra coordinate when it is time-dependent.
template <class V, class VE, class F, bool TD>
struct EngineForce {
  F f;
  int dir = 1;
  std::size_t n = 0;
  V qb{}, ab{};
  void operator()(const VE& q, VE& a) {
    if constexpr (!TD) {
      f(q, a);
    } else {
      using R = real_t<typename V::value_type>;
      resize_like_n(qb, n);
      resize_like_n(ab, n);
      for (std::size_t i = 0; i < n; ++i) qb[i] = q[i];
      const R t = dir > 0 ? R(q[n]) : R(-q[n]);
      f(t, static_cast<const V&>(qb), ab);
      for (std::size_t i = 0; i < n; ++i) a[i] = ab[i];
      a[n] = typename VE::value_type(0);
    }
  }
  static void resize_like_n(V& x, std::size_t m) {
    if constexpr (!is_std_array<V>::value) {
      if (x.size() != m) x.resize(m);
    } else {
      (void)x, (void)m;
    }
  }
};

template <class VE>
VE make_vector(std::size_t m) {
  VE x{};
  if constexpr (!is_std_array<VE>::value) x.resize(m);
  return x;
}

template <class T>
T sgn_mul(int dir, const T& x) {
  return dir > 0 ? x : T(-x);
}

/// Flattens an engine vector of real or complex scalars into reals.
template <class T, class VE>
void flatten(const VE& x, std::vector<T>& out) {
  for (const auto& e : x) {
    if constexpr (is_complex_v<std::decay_t<decltype(e)>>) {
      out.push_back(e.real());
      out.push_back(e.imag());
    } else {
      out.push_back(e);
    }
  }
}
template <class T, class VE>
std::size_t unflatten(const std::vector<T>& in, std::size_t pos, VE& x) {
  for (auto& e : x) {
    if (pos >= in.size()) throw invalid_input("checkpoint: the state has the wrong size for this problem");
    if constexpr (is_complex_v<std::decay_t<decltype(e)>>) {
      if (pos + 1 >= in.size()) throw invalid_input("checkpoint: the state has the wrong size for this problem");
      e = typename VE::value_type(in[pos], in[pos + 1]);
      pos += 2;
    } else {
      e = in[pos++];
    }
  }
  return pos;
}

/// Receives every accepted step end (user time and state), keeps the dense output, the saved states
/// and the events, and says when a terminal event stops the run. Output times and events inside a
/// step come from the partial step of the method (DenseOutput::PartialStep); an event is bracketed
/// by the signs of g at the step ends, started at the zero of g on the Hermite interpolant and then
/// located on the partial step.
template <class V, class P>
class Recorder {
 public:
  using R = real_t<typename V::value_type>;
  using PartialStep = typename DenseOutput<V>::PartialStep;

  Recorder(P& prob, const SolveOptions& opt, const std::vector<Event<V>>& events, Solution<V>& sol, int dir,
           PartialStep partial)
      : prob_(prob), opt_(opt), events_(events), sol_(sol), dir_(dir), partial_(std::move(partial)) {
    need_a_ = opt.dense || !events.empty();
    if (opt.on_step_every <= 0) throw invalid_input("on_step_every must be positive");
    for (const auto& e : events_)
      if (!e.g) throw invalid_input("event '" + e.name + "' has no function");
    if (opt.dense) sol_.dense.set_partial_step(partial_);
  }

  void start(const R& t, const V& q, const V& v) {
    tp_ = t;
    qp_ = q;
    vp_ = v;
    ap_ = q;
    if (need_a_) accel(t, q, ap_);
    if (opt_.dense) sol_.dense.push(t, q, v, ap_);
    gp_.clear();
    for (const auto& e : events_) gp_.push_back(e.g(t, q, v));
    if (opt_.t_eval.empty()) {
      save(t, q, v);
    } else {
      while (next_ < opt_.t_eval.size() && R(opt_.t_eval[next_]) == t) save(t, q, v), ++next_;
    }
  }

  /// A step ended at (t, q, v); true when a terminal event ends the run inside it (the solution's
  /// final state is then set to the event's).
  bool step(const R& t, const V& q, const V& v) {
    ++steps_;
    if (opt_.on_step && steps_ % opt_.on_step_every == 0) opt_.on_step(as_double(t));
    V& a = a_;
    if (need_a_) accel(t, q, a);
    // Events in this step, the earliest first.
    std::vector<std::pair<R, std::size_t>> hits;
    std::vector<R> g(events_.size());
    for (std::size_t i = 0; i < events_.size(); ++i) {
      g[i] = events_[i].g(t, q, v);
      const R g0 = gp_[i], g1 = g[i];
      const bool rising = g0 < R(0) && g1 >= R(0);
      const bool falling = g0 > R(0) && g1 <= R(0);
      const int d = events_[i].direction * dir_;  // in the direction of integration
      if ((rising && d >= 0) || (falling && d <= 0)) hits.push_back({locate(i, t, q, v, a, g0, g1), i});
    }
    std::sort(hits.begin(), hits.end(), [&](const auto& x, const auto& y) { return dir_ * x.first < dir_ * y.first; });
    bool terminal = false;
    R t_end = t;
    for (const auto& [te, i] : hits) {
      State<V> s = interpolate(t, q, v, te);
      sol_.events.push_back({events_[i].name, i, te, s.q, s.v});
      if (events_[i].terminal) {
        terminal = true;
        t_end = te;
        sol_.t_final = te;
        sol_.q_final = s.q;
        sol_.v_final = s.v;
        sol_.status = SolveStatus::terminated_by_event;
        sol_.message = "terminated by event '" + events_[i].name + "'";
        break;
      }
    }
    // Output times in (tp, t_end].
    if (opt_.t_eval.empty()) {
      if (!terminal) save(t, q, v);
    } else {
      while (next_ < opt_.t_eval.size() && dir_ * R(opt_.t_eval[next_]) <= dir_ * t_end) {
        const R te = R(opt_.t_eval[next_++]);
        State<V> s = interpolate(t, q, v, te);
        save(te, s.q, s.v);
      }
    }
    if (opt_.dense) {
      if (terminal)
        sol_.dense.push(t_end, sol_.q_final, sol_.v_final, accel_copy(t_end, sol_.q_final));
      else
        sol_.dense.push(t, q, v, a);
    }
    tp_ = t;
    assign_v(qp_, q);
    assign_v(vp_, v);
    if (need_a_) assign_v(ap_, a);
    gp_ = g;
    return terminal;
  }

  /// The number of steps from the last step end that need nothing of the recorder but the state where
  /// they end (quiet(), with step_end(j): the time at the end of the j-th step of the run, monotone in
  /// j): none with events or dense output (every step end is needed) or without output times (every
  /// step end is saved); else up to the step before the one that reaches the next output time or ends
  /// on a call of on_step. `done`: steps of the run so far; `last`: the last step of the run that may
  /// be quiet; `mean_step`: the step size, for a first guess.
  template <class StepEnd>
  long quiet_steps(long done, long last, StepEnd&& step_end, double mean_step) const {
    if (need_a_ || opt_.t_eval.empty() || last <= done) return 0;
    long end = last;  // the first step end that must be recorded lies after `end`
    if (opt_.on_step) end = std::min(end, done + (opt_.on_step_every - steps_ % opt_.on_step_every) - 1);
    if (next_ < opt_.t_eval.size()) {
      // The first step end j in (done, last] at or past the next output time: from the step end nearest
      // to it by the step size (mean_step: the span of a step, > 0), on to its neighbours while they
      // decide (the step ends are monotone, the estimate is off by a step or two at most).
      const R te = R(opt_.t_eval[next_]);
      auto reached = [&](long j) { return dir_ * te <= dir_ * step_end(j); };
      const double ahead = as_double(R(dir_ * (te - tp_))) / mean_step;
      long j =
          done + 1 + static_cast<long>(std::clamp(std::ceil(ahead) - 1, 0.0, static_cast<double>(last - done - 1)));
      if (reached(j)) {
        while (j - 1 > done && reached(j - 1)) --j;
        end = std::min(end, j - 1);
      } else {
        while (j < last && !reached(j)) ++j;
        if (reached(j)) end = std::min(end, j - 1);
      }
    }
    return std::max(0L, end - done);
  }

  /// `count` steps ended with nothing to record (quiet_steps), the last of them at (t, q, v).
  void quiet(long count, const R& t, const V& q, const V& v) {
    steps_ += count;
    tp_ = t;
    assign_v(qp_, q);
    assign_v(vp_, v);
  }

  /// Accepted step ends seen by this recorder (step() and quiet()).
  long steps() const { return steps_; }

 private:
  static void assign_v(V& x, const V& y) {
    resize_like(x, y);
    assign(x, y);
  }
  void accel(const R& t, const V& q, V& a) {
    resize_like(a, q);
    prob_.acceleration(t, q, a);
    ++sol_.output_force_evals;
  }
  V accel_copy(const R& t, const V& q) {
    V a = q;
    accel(t, q, a);
    return a;
  }
  void save(const R& t, const V& q, const V& v) {
    sol_.t.push_back(t);
    sol_.q.push_back(q);
    sol_.v.push_back(v);
  }
  // The state at te in the step (tp, t] that ended at (t, q, v): the step end itself, or a partial step.
  State<V> interpolate(const R& t, const V& q, const V& v, const R& te) {
    State<V> s;
    if (te == t) {
      s.q = q;
      s.v = v;
    } else if (te == tp_) {
      s.q = qp_;
      s.v = vp_;
    } else {
      sol_.output_force_evals += partial_(tp_, qp_, vp_, te, s.q, s.v);
    }
    return s;
  }
  // The zero of event i in (tp, t): a first estimate on the Hermite interpolant (no force evaluations),
  // then on the partial step.
  R locate(std::size_t i, const R& t, const V& q, const V& v, const V& a, const R& ga, const R& gb) {
    if (gb == R(0)) return t;
    const R h = t - tp_;
    const R guess = illinois(
        [&](const R& m) {
          State<V> s;
          hermite_quintic(qp_, vp_, ap_, q, v, a, h, R((m - tp_) / h), s.q, s.v);
          return events_[i].g(m, s.q, s.v);
        },
        tp_, t, ga, gb, tp_);
    return illinois(
        [&](const R& m) {
          const State<V> s = interpolate(t, q, v, m);
          return events_[i].g(m, s.q, s.v);
        },
        tp_, t, ga, gb, guess);
  }
  // The zero of g in the bracket (lo, hi) with g(lo) = ga and g(hi) = gb of opposite signs, by the
  // Illinois variant of regula falsi from a first point `first` (used when strictly inside), to a few
  // units of rounding of t (or 100 evaluations of g).
  template <class G>
  static R illinois(G&& gfun, R lo, R hi, R ga, R gb, const R& first) {
    using std::abs;
    int side = 0;
    const R eps = epsilon_of<R>();
    for (int it = 0; it < 100; ++it) {
      if (abs(hi - lo) <= R(4) * eps * std::max(abs(lo), abs(hi))) break;
      R m = (it == 0 && (first - lo) * (hi - first) > R(0)) ? first : R((lo * gb - hi * ga) / (gb - ga));
      if (!((m - lo) * (hi - m) > R(0))) m = (lo + hi) / R(2);  // strictly inside the bracket
      const R gm = gfun(m);
      if (gm == R(0)) return m;
      if ((gm < R(0)) == (ga < R(0))) {
        lo = m;
        ga = gm;
        if (side == -1) gb /= R(2);
        side = -1;
      } else {
        hi = m;
        gb = gm;
        if (side == 1) ga /= R(2);
        side = 1;
      }
    }
    return abs(ga) < abs(gb) ? lo : hi;
  }

  P& prob_;
  const SolveOptions& opt_;
  const std::vector<Event<V>>& events_;
  Solution<V>& sol_;
  int dir_;
  PartialStep partial_;
  bool need_a_ = true;
  std::size_t next_ = 0;
  long steps_ = 0;
  R tp_{};
  V qp_{}, vp_{}, ap_{}, a_{};
  std::vector<R> gp_;
};

/// Conversions between the user's state (time t, q, v) and the engine's (time-reversed for backward
/// integration, complexified for complex-coefficient methods, with t as one more coordinate when the
/// force depends on time).
template <class V, class VE, bool TD>
struct Conversion {
  using R = real_t<typename V::value_type>;
  using S = typename VE::value_type;
  int dir = 1;
  std::size_t n = 0;

  State<VE> to_engine(const R& t, const V& q, const V& v) const {
    State<VE> s{make_vector<VE>(n + (TD ? 1 : 0)), make_vector<VE>(n + (TD ? 1 : 0))};
    for (std::size_t i = 0; i < n; ++i) {
      s.q[i] = S(q[i]);
      s.v[i] = S(sgn_mul(dir, v[i]));
    }
    if constexpr (TD) {
      s.q[n] = S(sgn_mul(dir, t));
      s.v[n] = S(1);
    } else {
      (void)t;
    }
    return s;
  }
  void from_engine(const State<VE>& s, V& q, V& v) const {
    if constexpr (!is_std_array<V>::value) {
      q.resize(n);
      v.resize(n);
    }
    for (std::size_t i = 0; i < n; ++i) {
      if constexpr (is_complex_v<S>) {
        q[i] = s.q[i].real();
        v[i] = sgn_mul(dir, R(s.v[i].real()));
      } else {
        q[i] = s.q[i];
        v[i] = sgn_mul(dir, s.v[i]);
      }
    }
  }
};

template <class E>
struct is_gbs : std::false_type {};
template <class VE, class F>
struct is_gbs<GbsIntegrator<VE, F>> : std::true_type {};

/// The partial step of a solution's dense output (DenseOutput::PartialStep): one step of the method
/// from a step end, on a copy of the engine that the solution keeps (with its copy of the force) after
/// solve() returns. A fixed-step Integrator takes one step with its compensation restarted; GBS runs a
/// fresh copy of the extrapolation integrator over the interval. A mutex makes concurrent calls safe.
template <class V, class VE, bool TD, class Engine>
class PartialStepper {
 public:
  using R = real_t<typename V::value_type>;

  PartialStepper(Conversion<V, VE, TD> conv, Engine engine) : p_(std::make_shared<Shared>(conv, std::move(engine))) {}

  long operator()(const R& t0, const V& q0, const V& v0, const R& t, V& q, V& v) const {
    Shared& p = *p_;
    std::lock_guard<std::mutex> lock(p.m);
    State<VE> s = p.conv.to_engine(t0, q0, v0);
    const R h = sgn_mul(p.conv.dir, R(t - t0));
    long evals = 0;
    if (h > R(0)) {
      if constexpr (is_gbs<Engine>::value) {
        Engine g = p.engine;
        g.integrate_to(s, h);
        evals = g.force_evals() - p.engine.force_evals();
      } else {
        const long e0 = p.engine.force_evals();
        p.engine.compensator().valid = false;  // no carry from an earlier call
        p.engine.integrate(s, h, 1);
        evals = p.engine.force_evals() - e0;
      }
    }
    p.conv.from_engine(s, q, v);
    return evals;
  }

 private:
  struct Shared {
    Shared(Conversion<V, VE, TD> c, Engine e) : conv(c), engine(std::move(e)) {}
    std::mutex m;
    Conversion<V, VE, TD> conv;
    Engine engine;
  };
  std::shared_ptr<Shared> p_;
};

/// Common state of a run: problem, options, direction, conversions between the user's state and the
/// engine's.
template <class V, class F, class VE>
struct Run {
  using R = real_t<typename V::value_type>;
  static constexpr bool td = SecondOrderProblem<V, F>::time_dependent;
  using Force = EngineForce<V, VE, F, td>;

  SecondOrderProblem<V, F>& prob;
  const SolveOptions& opt;
  int dir;
  std::size_t n;
  std::string method;

  /// Completes a checkpoint just taken and hands it to the solution and the options' callback.
  void take(Checkpoint<R>& c, Solution<V>& sol) const {
    c.method = method;
    c.problem = opt.checkpoint_problem;
    if constexpr (checkpoint_detail::exact_text<R>) {
      if (opt.on_checkpoint) opt.on_checkpoint(to_text(c));
    }
    sol.checkpoint = c;
  }

  Conversion<V, VE, td> conversion() const { return {dir, n}; }
  State<VE> to_engine(const R& t, const V& q, const V& v) const { return conversion().to_engine(t, q, v); }
  void from_engine(const State<VE>& s, V& q, V& v) const { conversion().from_engine(s, q, v); }
  Force force() const { return {prob.force, dir, n, {}, {}}; }
  /// The dense output's partial step with `engine` (a copy the solution keeps).
  template <class Engine>
  typename DenseOutput<V>::PartialStep partial_step(Engine engine) const {
    return PartialStepper<V, VE, td, Engine>(conversion(), std::move(engine));
  }
  /// The fixed-step method that the adaptive engines propagate (the high-order weights of an RKN pair,
  /// the whole multi-product expansion of an adaptive one), for the partial steps.
  typename DenseOutput<V>::PartialStep propagated_method(const MethodDef& def) const {
    using T = real_t<typename VE::value_type>;
    const MethodData data = method_data_for(def, scalar_traits<T>::bits(), scalar_traits<T>::name());
    return partial_step(Integrator<VE, Force>(data, force(), opt.engine));
  }
  void check_finite(const V& q, const V& v, const R& ta, const R& tb) const {
    if (!all_finite(q) || !all_finite(v)) throw not_finite(ta, tb);
  }
  /// Whether the user's coordinates of engine state s (the real parts) are finite: check_finite without
  /// the conversion.
  bool finite_in_engine(const State<VE>& s) const {
    for (std::size_t i = 0; i < n; ++i) {
      if constexpr (is_complex_v<typename VE::value_type>) {
        if (!is_finite_scalar(s.q[i].real()) || !is_finite_scalar(s.v[i].real())) return false;
      } else {
        if (!is_finite_scalar(s.q[i]) || !is_finite_scalar(s.v[i])) return false;
      }
    }
    return true;
  }
  static error not_finite(const R& ta, const R& tb) {
    return error("the state became NaN or infinite in the step from t = " + adaptive_detail::sci(as_double(ta)) +
                 " to t = " + adaptive_detail::sci(as_double(tb)) + " (the force returned NaN or infinity)");
  }
  /// Restores the state of a checkpoint into s.
  void restore(const Checkpoint<R>& c, State<VE>& s) const {
    std::size_t pos = unflatten(c.state, 0, s.q);
    pos = unflatten(c.state, pos, s.v);
    if (pos != c.state.size()) throw invalid_input("checkpoint: the state has the wrong size for this problem");
  }
  /// And its compensation carries into the engine's compensator.
  void restore(const Checkpoint<R>& c, State<VE>& s, Compensator<VE>& comp) const {
    restore(c, s);
    if (!c.carry.empty()) {
      VE cq = s.q, cv = s.v;
      std::size_t p2 = unflatten(c.carry, 0, cq);
      p2 = unflatten(c.carry, p2, cv);
      if (p2 != c.carry.size()) throw invalid_input("checkpoint: the carries have the wrong size");
      comp.restore(cq, cv, s);
    }
  }
};

/// The observer of the adaptive and GBS engines: records every accepted step end and stops the engine
/// for a terminal event or where the checkpoint is due.
template <class V, class F, class VE>
struct StepEnds {
  using R = real_t<typename V::value_type>;
  const Run<V, F, VE>& run;
  Recorder<V, SecondOrderProblem<V, F>>& rec;
  V q{}, v{};
  R tprev{};
  bool taken = false, terminal = false, want_checkpoint = false;

  StepEnds(const Run<V, F, VE>& r, Recorder<V, SecondOrderProblem<V, F>>& rc, const R& t_start, const State<VE>& s)
      : run(r), rec(rc), tprev(t_start), taken(!std::isfinite(r.opt.checkpoint_at)) {
    run.from_engine(s, q, v);
    rec.start(t_start, q, v);
  }
  /// A step ended at user time t with engine state st: true to stop the engine there.
  bool operator()(const R& t, const State<VE>& st) {
    run.from_engine(st, q, v);
    run.check_finite(q, v, tprev, t);
    tprev = t;
    if (rec.step(t, q, v)) {
      terminal = true;
      return true;
    }
    if (!taken && run.dir * as_double(t) >= run.dir * run.opt.checkpoint_at) {
      taken = true;
      want_checkpoint = true;
      return true;
    }
    return false;
  }
  void finish(Solution<V>& sol) const {
    if (sol.status == SolveStatus::success) {
      sol.t_final = run.prob.t1;
      sol.q_final = q;
      sol.v_final = v;
    }
  }
};

/// Runs an adaptive or GBS engine from engine state s (user time t_start) to the end or a terminal
/// event, recording every accepted step end. advance(obs) runs the engine from where it stands to the
/// end under the observer obs(te, st) (te: engine time), which user_time(te) maps to the user's time
/// (std::nullopt: a time not to record, the start that the engine reports again). Where the run stopped
/// for the checkpoint, fill(c) completes the checkpoint c (and sets where the engine goes on), and
/// the engine goes on from its resume point: the same steps as without the stop.
template <class V, class F, class VE, class UserTime, class Advance, class Fill>
void drive_engine(const Run<V, F, VE>& run, Recorder<V, SecondOrderProblem<V, F>>& rec, Solution<V>& sol,
                  const real_t<typename V::value_type>& t_start, const State<VE>& s, UserTime&& user_time,
                  Advance&& advance, Fill&& fill) {
  using R = real_t<typename V::value_type>;
  StepEnds<V, F, VE> ends(run, rec, t_start, s);
  auto obs = [&](const R& te, const State<VE>& st) -> bool {
    const std::optional<R> t = user_time(te);
    return t ? ends(*t, st) : false;
  };
  for (;;) {
    ends.want_checkpoint = false;
    advance(obs);
    if (ends.terminal || !ends.want_checkpoint) break;
    Checkpoint<R> c;
    fill(c);
    c.output_force_evals = sol.output_force_evals;
    run.take(c, sol);
  }
  ends.finish(sol);
}

template <class VE, class V, class F>
void run_fixed(SecondOrderProblem<V, F>& prob, const MethodDef& def, const SolveOptions& opt,
               const std::vector<Event<V>>& events, Solution<V>& sol, int dir,
               const Checkpoint<real_t<typename V::value_type>>* resume) {
  using R = real_t<typename V::value_type>;
  Run<V, F, VE> run{prob, opt, dir, prob.q0.size(), def.info.name};
  const R span = prob.t1 - prob.t0;
  const R aspan = dir > 0 ? span : R(-span);
  long n;
  R h;
  if (opt.steps > 0) {
    n = opt.steps;
    h = aspan / R(n);
  } else {
    if (!(opt.h > 0) || !std::isfinite(opt.h))
      throw invalid_input("a fixed-step method needs a positive step size h or a number of steps");
    h = R(opt.h);
    const double nd = std::ceil(as_double(aspan) / opt.h * (1 - 1e-12));
    if (nd > 1e15) throw invalid_input("the step size is too small for the span");
    n = std::max(1L, static_cast<long>(nd));
  }
  if (n > opt.max_steps) throw too_many_steps("the span needs " + std::to_string(n) + " steps, more than max_steps");
  auto integ = make_integrator<VE>(def, run.force(), opt.engine);
  const R tau0 = sgn_mul(dir, prob.t0), tau1 = sgn_mul(dir, prob.t1);
  State<VE> s = run.to_engine(prob.t0, prob.q0, prob.v0);
  long k0 = 0;
  long evals0 = 0;
  Recorder<V, SecondOrderProblem<V, F>> rec(prob, opt, events, sol, dir, run.partial_step(integ));
  if (resume) {
    if (resume->engine != "fixed") throw invalid_input("checkpoint of another engine (" + resume->engine + ")");
    k0 = resume->step_index;
    if (k0 < 0 || k0 > n) throw invalid_input("checkpoint step index outside the run");
    run.restore(*resume, s, integ.compensator());
    evals0 = resume->force_evals;
    sol.output_force_evals = resume->output_force_evals;
  }
  V q, v;
  run.from_engine(s, q, v);
  const R tstart = resume ? resume->t : prob.t0;
  rec.start(tstart, q, v);
  bool taken = !std::isfinite(opt.checkpoint_at);
  R tprev = tstart;
  // The user's time at the end of the j-th step (the last one ends on t1).
  auto step_end = [&](long j) -> R { return j == n ? prob.t1 : sgn_mul(dir, R(tau0 + h * R(j))); };
  if (resume && resume->t != step_end(k0)) throw invalid_input("checkpoint: its time is not that of its step index");
  // A failed run reports the forces evaluated up to the failure.
  struct CountOnExit {
    Solution<V>& sol;
    const Integrator<VE, typename Run<V, F, VE>::Force>& engine;
    long evals0;
    ~CountOnExit() { sol.force_evals = evals0 + engine.force_evals(); }
  } count_on_exit{sol, integ, evals0};
  for (long k = k0; k < n; ++k) {
    // Steps with nothing to record (Recorder::quiet_steps; none while a checkpoint is due) run as bare
    // engine steps, the same engine calls as below: the loop costs what a hand-written loop of them costs.
    if (const long m = taken ? rec.quiet_steps(k, n - 1, step_end, as_double(h)) : 0; m > 0) {
      for (const long stop = k + m; k < stop; ++k) {
        integ.integrate(s, h, 1);
        if (!run.finite_in_engine(s)) {
          sol.accepted = k;
          throw run.not_finite(step_end(k), step_end(k + 1));
        }
      }
      tprev = step_end(k);
      run.from_engine(s, q, v);
      sol.accepted = k;
      rec.quiet(m, tprev, q, v);
    }
    // The last step of a given h ends on t1.
    const R hk = (opt.steps <= 0 && k == n - 1) ? R((tau1 - tau0) - h * R(n - 1)) : h;
    integ.integrate(s, hk, 1);
    const R t = step_end(k + 1);
    run.from_engine(s, q, v);
    run.check_finite(q, v, tprev, t);
    sol.accepted = k + 1;
    if (rec.step(t, q, v)) break;
    tprev = t;
    if (!taken && dir * as_double(t) >= dir * opt.checkpoint_at && k + 1 < n) {
      taken = true;
      Checkpoint<R> c;
      c.engine = "fixed";
      c.t = t;
      c.step_index = k + 1;
      flatten(s.q, c.state);
      flatten(s.v, c.state);
      if (use_compensation<typename VE::value_type>(opt.engine.compensated)) {
        flatten(integ.compensator().cq, c.carry);
        flatten(integ.compensator().cv, c.carry);
      }
      c.force_evals = evals0 + integ.force_evals();
      c.output_force_evals = sol.output_force_evals;
      c.accepted = k + 1;
      run.take(c, sol);
    }
  }
  if (sol.status == SolveStatus::success) {
    sol.t_final = prob.t1;
    sol.q_final = q;
    sol.v_final = v;
  }
}

/// Adaptive RKN or MPE (Engine: AdaptiveRknIntegrator or AdaptiveMpeIntegrator on VE, its force counting
/// its calls in `calls`: the engines add up their own counts when a call returns, a failed run reports these).
template <class VE, class V, class F, class Engine>
void run_adaptive(Run<V, F, VE>& run, Engine& engine, const long& calls, const char* name, const MethodDef& def,
                  Solution<V>& sol, const std::vector<Event<V>>& events,
                  const Checkpoint<real_t<typename V::value_type>>* resume) {
  using R = real_t<typename V::value_type>;
  auto& prob = run.prob;
  const int dir = run.dir;
  const R tau0 = sgn_mul(dir, prob.t0), tau1 = sgn_mul(dir, prob.t1);
  State<VE> s = run.to_engine(prob.t0, prob.q0, prob.v0);
  long evals0 = 0, acc0 = 0, rej0 = 0;
  R tau = tau0;
  if (resume) {
    if (resume->engine != name)
      throw invalid_input(std::string("checkpoint of another engine (") + resume->engine + ")");
    if constexpr (requires { engine.compensator(); })
      run.restore(*resume, s, engine.compensator());
    else
      run.restore(*resume, s);
    tau = sgn_mul(dir, resume->t);
    engine.set_resume_point(
        {tau, resume->h_want, resume->hmax, resume->last_rejected, resume->q_prev, resume->h_prev, true});
    evals0 = resume->force_evals;
    acc0 = resume->accepted;
    rej0 = resume->rejected;
    sol.output_force_evals = resume->output_force_evals;
  }
  Recorder<V, SecondOrderProblem<V, F>> rec(prob, run.opt, events, sol, dir, run.propagated_method(def));
  struct CountOnFailure {
    Solution<V>& sol;
    const Recorder<V, SecondOrderProblem<V, F>>& rec;
    const long& calls;
    long evals0, acc0;
    ~CountOnFailure() {
      if (std::uncaught_exceptions() == 0) return;
      sol.force_evals = evals0 + calls;
      sol.accepted = acc0 + rec.steps();
    }
  } count_on_failure{sol, rec, calls, evals0, acc0};
  drive_engine(
      run, rec, sol, sgn_mul(dir, tau), s,
      [&](const R& tt) -> std::optional<R> {
        if (tt == tau) return std::nullopt;  // the start
        return tt == tau1 ? prob.t1 : sgn_mul(dir, tt);
      },
      [&](auto& obs) { engine.integrate_to(s, tau, tau1, obs); },
      [&](Checkpoint<R>& c) {
        const auto& rp = engine.resume_point();
        c.engine = name;
        c.t = sgn_mul(dir, rp.t);
        flatten(s.q, c.state);
        flatten(s.v, c.state);
        if constexpr (requires { engine.compensator(); }) {
          if (use_compensation<typename VE::value_type>(run.opt.engine.compensated)) {
            flatten(engine.compensator().cq, c.carry);
            flatten(engine.compensator().cv, c.carry);
          }
        }
        c.h_want = rp.h_want;
        c.hmax = rp.hmax;
        c.last_rejected = rp.last_rejected;
        c.q_prev = rp.q_prev;
        c.h_prev = rp.h_prev;
        c.force_evals = evals0 + engine.total().force_evals;
        c.accepted = acc0 + engine.total().accepted;
        c.rejected = rej0 + engine.total().rejected;
        tau = rp.t;  // go on from the resume point
      });
  sol.force_evals = evals0 + engine.total().force_evals;
  sol.accepted = acc0 + engine.total().accepted;
  sol.rejected = rej0 + engine.total().rejected;
}

template <class VE, class V, class F>
void run_gbs(Run<V, F, VE>& run, Solution<V>& sol, const std::vector<Event<V>>& events,
             const Checkpoint<real_t<typename V::value_type>>* resume) {
  using R = real_t<typename V::value_type>;
  auto& prob = run.prob;
  const int dir = run.dir;
  GbsOptions go = run.opt.gbs;
  go.rtol = run.opt.rtol;
  go.atol = run.opt.atol > 0 ? run.opt.atol : run.opt.rtol;
  go.max_steps = run.opt.max_steps;
  GbsIntegrator<VE, typename Run<V, F, VE>::Force> g(run.force(), go);
  const R tau0 = sgn_mul(dir, prob.t0);
  const R span = sgn_mul(dir, R(prob.t1 - prob.t0));
  State<VE> s = run.to_engine(prob.t0, prob.q0, prob.v0);
  R t_start = prob.t0;
  // The partial steps run a fresh copy of the integrator (its controller in the initial state) at a
  // tolerance 1000 times smaller (bounded by rounding): GBS's accepted steps are usually far more
  // accurate than its tolerance (the estimate is that of the column before the accepted one), and a
  // partial step must not be less accurate than the steps it lies between.
  GbsOptions gp = go;
  gp.rtol = std::max(go.rtol * 1e-3, 100 * as_double(epsilon_of<R>()));
  gp.atol = std::max(go.atol * 1e-3, 100 * as_double(epsilon_of<R>()));
  Recorder<V, SecondOrderProblem<V, F>> rec(
      prob, run.opt, events, sol, dir,
      run.partial_step(GbsIntegrator<VE, typename Run<V, F, VE>::Force>(run.force(), gp)));
  if (resume) {
    if (resume->engine != "gbs") throw invalid_input("checkpoint of another engine (" + resume->engine + ")");
    run.restore(*resume, s);
    g.set_resume_point({resume->span, span, resume->h_want, resume->columns, resume->last_rejected, true});
    g.set_counters(resume->force_evals, resume->accepted, resume->rejected);
    t_start = resume->t;
    sol.output_force_evals = resume->output_force_evals;
  }
  struct CountOnExit {  // also a failed run: the counts up to the failure
    Solution<V>& sol;
    const GbsIntegrator<VE, typename Run<V, F, VE>::Force>& g;
    ~CountOnExit() {
      sol.force_evals = g.force_evals();
      sol.accepted = g.steps();
      sol.rejected = g.rejected();
    }
  } count_on_exit{sol, g};
  drive_engine(
      run, rec, sol, t_start, s,
      [&](const R& trel) -> std::optional<R> { return trel == span ? prob.t1 : sgn_mul(dir, R(tau0 + trel)); },
      [&](auto& obs) { g.integrate_to(s, span, obs); },
      [&](Checkpoint<R>& c) {
        const auto& rp = g.resume_point();
        c.engine = "gbs";
        c.t = sgn_mul(dir, R(tau0 + rp.t));
        c.span = rp.t;
        flatten(s.q, c.state);
        flatten(s.v, c.state);
        c.h_want = rp.H;
        c.columns = rp.k;
        c.last_rejected = rp.last_rejected;
        c.force_evals = g.force_evals();
        c.accepted = g.steps();
        c.rejected = g.rejected();
      });
}

/// The run of solve_impl with the method's engine, into sol.
template <class V, class F, class VE>
void run_method(SecondOrderProblem<V, F>& prob, const MethodDef& def, const SolveOptions& opt,
                const std::vector<Event<V>>& events, Solution<V>& sol, int dir,
                const Checkpoint<real_t<typename V::value_type>>* resume, bool gbs) {
  using R = real_t<typename V::value_type>;
  constexpr bool td = SecondOrderProblem<V, F>::time_dependent;
  if (gbs || def.info.adaptive) {
    if (!(opt.rtol >= 0) || !std::isfinite(opt.rtol)) throw invalid_input("rtol must be finite and >= 0");
    if (!(opt.atol >= 0) || !std::isfinite(opt.atol)) throw invalid_input("atol must be finite and >= 0");
    if (opt.rtol == 0 && opt.atol == 0)
      throw invalid_input("method '" + def.info.name + "' needs a tolerance (rtol > 0 or atol > 0)");
    Run<V, F, VE> run{prob, opt, dir, prob.q0.size(), def.info.name};
    if (gbs) {
      run_gbs<VE>(run, sol, events, resume);
    } else {
      AdaptiveOptions ao = opt.adaptive;
      ao.tol = opt.rtol;
      ao.atol = opt.atol;
      ao.max_steps = opt.max_steps;
      long calls = 0;
      using Counted = CountingForce<typename Run<V, F, VE>::Force>;
      if (std::holds_alternative<MpeDef>(def.build())) {
        auto engine = make_adaptive_mpe_integrator<VE>(def, Counted{&calls, run.force()}, ao, opt.engine);
        run_adaptive<VE>(run, engine, calls, "adaptive-mpe", def, sol, events, resume);
      } else {
        auto engine = make_adaptive_integrator<VE>(def, Counted{&calls, run.force()}, ao, opt.engine);
        run_adaptive<VE>(run, engine, calls, "adaptive-rkn", def, sol, events, resume);
      }
    }
  } else if (def.info.complex) {
    using C = std::complex<R>;
    using VC = rebind_vector_t<V, C>;
    if constexpr (!td && std::is_invocable_v<F&, const VC&, VC&>) {
      run_fixed<VC>(prob, def, opt, events, sol, dir, resume);
    } else {
      throw invalid_input("method '" + def.info.name +
                          "' has complex coefficients: its force must accept complex states (a generic lambda or a "
                          "template operator()) and not depend on time");
    }
  } else {
    run_fixed<VE>(prob, def, opt, events, sol, dir, resume);
  }
}

template <class V, class F>
Solution<V> solve_impl(const SecondOrderProblem<V, F>& problem, const MethodDef& def, const SolveOptions& opt,
                       const std::vector<Event<V>>& events, const Checkpoint<real_t<typename V::value_type>>* resume) {
  using R = real_t<typename V::value_type>;
  using P = SecondOrderProblem<V, F>;
  constexpr bool td = P::time_dependent;
  problem.validate();
  if (opt.max_steps <= 0) throw invalid_input("max_steps must be positive");
  P prob = problem;
  const int dir = prob.t1 >= prob.t0 ? 1 : -1;
  // Output times: within the span and monotone in the direction of integration.
  for (std::size_t i = 0; i < opt.t_eval.size(); ++i) {
    const double te = opt.t_eval[i];
    if (!std::isfinite(te)) throw invalid_input("output times must be finite");
    if (sgn_mul(dir, R(te)) < sgn_mul(dir, prob.t0))
      throw invalid_input("output time " + adaptive_detail::sci(te) + " lies before t0");
    if (sgn_mul(dir, R(te)) > sgn_mul(dir, prob.t1))
      throw invalid_input("output time " + adaptive_detail::sci(te) + " lies after t1");
    if (i > 0 && dir * te < dir * opt.t_eval[i - 1])
      throw invalid_input("output times must be ordered in the direction of integration");
  }
  if (!std::isnan(opt.checkpoint_at) && !std::isfinite(opt.checkpoint_at))
    throw invalid_input("the checkpoint time must be finite");
  Solution<V> sol;
  if (resume && resume->problem != opt.checkpoint_problem)
    throw invalid_input("the checkpoint was taken for another problem ('" + resume->problem + "', not '" +
                        opt.checkpoint_problem + "')");
  if (resume && resume->method != def.info.name)
    throw invalid_input("the checkpoint was taken with method '" + resume->method + "', not '" + def.info.name + "'");
  if (prob.t1 == prob.t0) {
    Recorder<V, P> rec(prob, opt, events, sol, dir, {});
    rec.start(prob.t0, prob.q0, prob.v0);
    sol.t_final = prob.t0;
    sol.q_final = prob.q0;
    sol.v_final = prob.v0;
    return sol;
  }
  using VE = typename extended<V, td>::type;
  const bool gbs = def.info.name == "GBS" || def.info.family == "extrapolation";
  try {
    run_method<V, F, VE>(prob, def, opt, events, sol, dir, resume, gbs);
  } catch (const invalid_input&) {
    throw;
  } catch (const error& e) {
    if (!opt.partial_on_failure) throw;
    sol.status = SolveStatus::failed;
    sol.message = e.what();
    if (!sol.t.empty()) {
      sol.t_final = sol.t.back();
      sol.q_final = sol.q.back();
      sol.v_final = sol.v.back();
    }
  }
  return sol;
}

}  // namespace solve_detail

/// Integrates `problem` with `method` (a catalog entry or specification, see resolve_method) and returns
/// the solution. Throws invalid_input for a problem or options that cannot be integrated,
/// step_size_underflow / too_many_steps when an adaptive run cannot go on, nystrom::error when the
/// state becomes NaN or infinite.
template <class V, class F>
Solution<V> solve(const SecondOrderProblem<V, F>& problem, const MethodDef& method, const SolveOptions& options = {},
                  const std::vector<Event<V>>& events = {}) {
  return solve_detail::solve_impl(problem, method, options, events, nullptr);
}
/// The Gragg-Bulirsch-Stoer extrapolation integrator (engines/gbs.hpp) as a method for solve(): adaptive
/// step and order, tolerances rtol and atol.
inline MethodDef gbs_method_def() {
  MethodDef d;
  d.info.name = "GBS";
  d.info.family = "extrapolation";
  d.info.adaptive = true;
  d.info.source = "Gragg (1965); Bulirsch & Stoer (1966); Hairer, Norsett & Wanner I, sec. II.9/II.14 (ODEX2)";
  d.info.description = "Gragg-Bulirsch-Stoer extrapolation, adaptive step and order";
  d.build = []() -> MethodData { throw invalid_input("GBS has no coefficient table"); };
  return d;
}

/// resolve_method(spec), and "GBS" (or "gbs") for the extrapolation integrator.
inline MethodDef resolve_solve_method(const std::string& spec) {
  if (spec == "GBS" || spec == "gbs") return gbs_method_def();
  return resolve_method(spec);
}

template <class V, class F>
Solution<V> solve(const SecondOrderProblem<V, F>& problem, const std::string& method, const SolveOptions& options = {},
                  const std::vector<Event<V>>& events = {}) {
  return solve_detail::solve_impl(problem, resolve_solve_method(method), options, events, nullptr);
}

/// Continues a run from a checkpoint (Solution::checkpoint) to problem.t1: the same problem, method and
/// options as the run that took it (the method and options.checkpoint_problem are checked); the result
/// is bitwise that of the run that was never interrupted. The problem's q0, v0 are not used.
template <class V, class F>
Solution<V> resume(const SecondOrderProblem<V, F>& problem, const MethodDef& method,
                   const Checkpoint<real_t<typename V::value_type>>& from, const SolveOptions& options = {},
                   const std::vector<Event<V>>& events = {}) {
  return solve_detail::solve_impl(problem, method, options, events, &from);
}

}  // namespace nystrom
