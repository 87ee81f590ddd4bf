// The recorder of a solve() run: every accepted step end goes through it; it keeps the saved states and the
// dense output, and locates the events (a first estimate on the Hermite interpolant of the step, then one
// partial step of the method there, rarely more). Part of the inline path (nystrom/solve_inline.hpp).
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

// The zero of g in the bracket (lo, hi) with g(lo) = ga and g(hi) = gb of opposite signs, by the
// Illinois variant of regula falsi from a first point `first` (used when strictly inside), to a few
// units of rounding of t (or 100 evaluations of g).
template <class R, class G>
R illinois(G&& gfun, R lo, R hi, R ga, R gb, const R& first) {
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

/// Receives every accepted step end (user time and state), keeps the dense output, the saved states
/// and the events, and says when a terminal event stops the run. Output times and events inside a
/// step come from the partial step of the method (DenseOutput::PartialStep). An event is bracketed by
/// the signs of g at the step ends; its time is first estimated on the step's quintic Hermite
/// interpolant (the forces at the two step ends: two evaluations, made only for a step that brackets
/// an event unless the dense output keeps them anyway), then the method's partial step to that time
/// gives the state there exactly (as sol(t) would) and the interpolant between it and the step end on
/// the other side of the zero, whose error near that knot falls as the cube of the distance, gives the
/// time to rounding. A second partial step is taken only when the estimate moved too far for that
/// (rarely), the Illinois iteration on partial steps after three. Cost per event: two or three forces
/// plus one partial step (one step of the method) in almost every case.
template <class V, class P>
class Recorder {
 public:
  using R = real_t<typename V::value_type>;
  using PartialStep = typename DenseOutput<V>::PartialStep;

  Recorder(P& prob, const SolveOptions& opt, const std::vector<Event<V>>& events, Solution<V>& sol, int dir,
           PartialStep partial)
      : prob_(prob), opt_(opt), events_(events), sol_(sol), dir_(dir), partial_(std::move(partial)) {
    need_a_ = opt.dense;
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
    ap_valid_ = false;
    if (need_a_) accel(t, q, v, ap_), ap_valid_ = true;
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
    a_valid_ = false;
    if (need_a_) accel(t, q, v, a), a_valid_ = true;
    // Events in this step, the earliest first.
    struct Hit {
      R t;
      std::size_t i;
      State<V> s;
    };
    std::vector<Hit> hits;
    std::vector<R> g(events_.size());
    for (std::size_t i = 0; i < events_.size(); ++i) {
      g[i] = events_[i].g(t, q, v);
      const R g0 = gp_[i], g1 = g[i];
      const bool rising = g0 < R(0) && g1 >= R(0);
      const bool falling = g0 > R(0) && g1 <= R(0);
      const int d = events_[i].direction * dir_;  // in the direction of integration
      if ((rising && d >= 0) || (falling && d <= 0)) {
        Hit hit{t, i, {}};
        hit.t = locate(i, t, q, v, g0, g1, hit.s);
        hits.push_back(std::move(hit));
      }
    }
    std::stable_sort(hits.begin(), hits.end(), [&](const Hit& x, const Hit& y) { return dir_ * x.t < dir_ * y.t; });
    bool terminal = false;
    R t_end = t;
    for (const auto& [te, i, s] : hits) {
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
    ap_valid_ = a_valid_;
    if (a_valid_) assign_v(ap_, a);
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
    if (need_a_ || !events_.empty() || opt_.t_eval.empty() || last <= done) return 0;
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
    ap_valid_ = false;
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
  // The zero of event i in (tp, t) that ended at (t, q, v), with g(tp) = ga and g(t) = gb of opposite
  // signs, and the state there (in s).
  R locate(std::size_t i, const R& t, const V& q, const V& v, const R& ga, const R& gb, State<V>& s) {
    using std::abs;
    if (gb == R(0)) {
      s.q = q;
      s.v = v;
      return t;
    }
    if (!ap_valid_) accel(tp_, qp_, vp_, ap_), ap_valid_ = true;
    if (!a_valid_) accel(t, q, v, a_), a_valid_ = true;
    const auto& g = events_[i].g;
    // The zero of g on the quintic Hermite interpolant between the knots (ta, qa, va, aa) and
    // (tb, qb, vb, ab), inside the bracket (lo, hi) where g has the signs glo, ghi, from `first`.
    auto on_interpolant = [&](const R& ta, const V& qa, const V& va, const V& aa, const R& tb, const V& qb, const V& vb,
                              const V& ab, const R& lo, const R& hi, const R& glo, const R& ghi, const R& first) {
      const R hab = tb - ta;
      return illinois(
          [&](const R& m) {
            State<V> x;
            hermite_quintic(qa, va, aa, qb, vb, ab, hab, R((m - ta) / hab), x.q, x.v);
            return g(m, x.q, x.v);
          },
          lo, hi, glo, ghi, first);
    };
    const R h = t - tp_;
    R te = on_interpolant(tp_, qp_, vp_, ap_, t, q, v, a_, tp_, t, ga, gb, tp_);
    const R eps = epsilon_of<R>();
    State<V> x;
    V ax;
    for (int round = 0; round < 3; ++round) {
      if (!((te - tp_) * (t - te) > R(0))) break;  // on a step end: the partial steps decide
      sol_.output_force_evals += partial_(tp_, qp_, vp_, te, x.q, x.v);
      const R gx = g(te, x.q, x.v);
      if (gx == R(0)) {
        s = std::move(x);
        return te;
      }
      resize_like(ax, x.q);
      accel(te, x.q, x.v, ax);
      // The knot te and the step end on the other side of the zero.
      const bool below = (gx < R(0)) == (ga < R(0));  // the zero lies between te and t
      const R next = below ? on_interpolant(te, x.q, x.v, ax, t, q, v, a_, te, t, gx, gb, te)
                           : on_interpolant(tp_, qp_, vp_, ap_, te, x.q, x.v, ax, tp_, te, ga, gx, te);
      // The interpolant's error at a distance d from the knot is about 64 (d/h)^3 times that of the
      // step's interpolant at the midpoint, which moved the zero by about d: accepted once the move it
      // predicts is below the rounding of the time.
      const R d = abs(next - te), rel = d / abs(h);
      const R scale = std::max(abs(next), abs(h));
      if (R(64) * rel * rel * rel * d <= eps * scale) {
        State<V> y;
        if (below)
          hermite_quintic(x.q, x.v, ax, q, v, a_, R(t - te), R((next - te) / (t - te)), y.q, y.v);
        else
          hermite_quintic(qp_, vp_, ap_, x.q, x.v, ax, R(te - tp_), R((next - tp_) / (te - tp_)), y.q, y.v);
        s = std::move(y);
        return next;
      }
      te = next;
    }
    // The Illinois iteration on the partial steps.
    const R tz = illinois(
        [&](const R& m) {
          const State<V> y = interpolate(t, q, v, m);
          return g(m, y.q, y.v);
        },
        tp_, t, ga, gb, te);
    s = interpolate(t, q, v, tz);
    return tz;
  }

  P& prob_;
  const SolveOptions& opt_;
  const std::vector<Event<V>>& events_;
  Solution<V>& sol_;
  int dir_;
  PartialStep partial_;
  bool need_a_ = true;     // the force at every step end (the dense output keeps it)
  bool ap_valid_ = false;  // ap_ holds the force at tp_
  bool a_valid_ = false;   // a_ holds the force at the last step end
  std::size_t next_ = 0;
  long steps_ = 0;
  R tp_{};
  V qp_{}, vp_{}, ap_{}, a_{};
  std::vector<R> gp_;
};

}  // namespace solve_detail
}  // namespace nystrom
