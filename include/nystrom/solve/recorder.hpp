// The recorder of a solve() run: every accepted step end goes through it; it keeps the saved states and the
// dense output, and locates the events (a first estimate on the Hermite interpolant, then the Illinois
// iteration on the method's partial step). Part of the inline path (nystrom/solve_inline.hpp).
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
#include "nystrom/solve/dense.hpp"
#include "nystrom/solve/options.hpp"
#include "nystrom/solve/solution.hpp"

namespace nystrom {
namespace solve_detail {

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
    if (need_a_) accel(t, q, v, ap_);
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
    if (need_a_) accel(t, q, v, a);
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
        sol_.dense.push(t_end, sol_.q_final, sol_.v_final, accel_copy(t_end, sol_.q_final, sol_.v_final));
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
  void accel(const R& t, const V& q, const V& v, V& a) {
    resize_like(a, q);
    prob_.acceleration(t, q, v, a);
    ++sol_.output_force_evals;
  }
  V accel_copy(const R& t, const V& q, const V& v) {
    V a = q;
    accel(t, q, v, a);
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

}  // namespace solve_detail
}  // namespace nystrom
