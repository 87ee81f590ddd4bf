// Step-size control for an embedded RKN pair (e.g. the Dormand-El-Mikkawy-Prince RKN12(10),
// catalog entry "DP12-adaptive").
//
// API (what the CLI calls for `nystrom run --method DP12-adaptive --tol 1e-12`):
//
//   nystrom::AdaptiveOptions opt;            // all fields optional except tol
//   opt.tol = 1e-12;
//   auto ai = nystrom::make_adaptive_integrator<V>(def, force, opt);   // def: a MethodDef whose
//                                            // tableau carries bhat/Bhat (info.adaptive == true)
//   nystrom::AdaptiveStats st = ai.integrate_to(state, t0, t1);        // lands exactly on t1
//   nystrom::AdaptiveStats st = ai.integrate_to(state, t0, t1,
//       [](auto t, const nystrom::State<V>& s) { ... });               // observer: t0, then every accepted step
//   st.accepted, st.rejected, st.force_evals, st.last_h                 // this call; ai.total() sums all calls
//
// V is std::array<T, N> or std::vector<T> with a real T (double, long double, float128, ...).
// Errors: std::invalid_argument for bad input (tol or atol negative or not finite, both zero, tol
// below 10 eps of the scalar type, t1 < t0, t0/t1 not finite,
// NaN/inf or inconsistent state, a tableau without embedded weights, bad options);
// nystrom::StepSizeUnderflow (a std::runtime_error) when the step size falls below the rounding
// level of t, which happens when the tolerance cannot be met (too strict for the scalar type) or
// the solution is singular; nystrom::TooManySteps (std::runtime_error) after opt.max_steps steps.
// After such an exception the state holds the last accepted step (the observer has seen its time).
//
// The controller (Hairer, Norsett & Wanner I, sec. II.4; Brankin et al., ACM TOMS 15 (1989) 31):
//   * error estimate: the difference of the two solutions of the pair, in q (h^2 sum (b - bhat) f)
//     and v (h sum (B - Bhat) f); the higher-order solution is propagated (local extrapolation);
//   * norm: err = sqrt( (1/2n) sum_i (e_i / sc_i)^2 ) over all n positions and n velocities, with
//     sc_i = tol * (1 + max(|y_i(t)|, |y_i(t+h)|)): mixed absolute/relative with one tolerance
//     (opt.atol 0 or equal to tol), or sc_i = atol + tol * max(|y_i(t)|, |y_i(t+h)|) with a separate
//     absolute tolerance (tol 0: absolute only); adaptive_detail::ErrorScale;
//   * accept when err <= 1; new h = h * min(fac_max, max(fac_min, safety * err^(-1/(p+1)))), p the
//     lower order of the pair, or Gustafsson's predictive ratio when smaller (opt.predictive, on by
//     default; adaptive_detail::StepController); after a rejection the step may not grow in the next
//     attempt;
//   * first step: Hairer's starting-step algorithm (two force evaluations) unless opt.h0 > 0; later
//     calls continue with the step proposed at the end of the previous call;
//   * the last step is shortened to land exactly on t1 (and a step within 1% of the end is stretched); every
//     other step is rounded so that t + h is exact, and the accepted increments are added with compensated
//     summation (EngineOptions::compensated, on by default in double and float; the carries live in
//     compensator()). Both lower the round-off floor: Kepler, 100 periods, final position error at the four
//     tightest tolerances (1.8e-14 .. 3.2e-15), e = 0.5: 8.4e-12, 7.5e-12, 4.8e-13, 3.3e-12 without,
//     5.5e-13, 2.1e-12, 1.7e-12, 1.5e-12 with; e = 0.9: 1.8e-11, 7.2e-11, 6.7e-12, 4.8e-12 without, 5.3e-13,
//     3.9e-12, 1.7e-12, 1.2e-12 with. What remains is the rounding of the force and of the increments
//     themselves (the same tableau in long double with the force rounded to double: 1e-13 .. 6e-13).
// Force evaluations are counted exactly, rejected steps and the starting-step estimate included.
// The state and the steps live in the scalar type; the controller's own arithmetic (norms, step
// ratios) runs in double through as_double, so any type with scalar_traits, epsilon_of, as_double,
// abs and isfinite works (double, long double, float128, double_double, quad_double, mpfr_real).
// Defaults: safety 0.9 (Hairer's DOP853 value) and fac_max 4. With the standard ratio alone, 0.9
// rejects about one step in four on Kepler e = 0.5 and 0.9 (the exponent 1/11 of the 12(10) pair);
// with the predictive ratio it rejects 5-15% of the steps and costs fewer force evaluations than 0.7
// for the same final error, for both engines (Kepler, 100 periods, forces at error 1e-9 from a fit
// over 8 tolerances per decade, 0.7 against 0.9: DP12-adaptive e = 0.5 40 100 / 36 600, e = 0.9
// 76 800 / 73 900; M14-adaptive e = 0.9 138 800 / 117 600). A high order makes the difference larger:
// the controller aims at err = safety^(p+1), 0.005 for 0.7 and p = 14 (M16-adaptive), 0.2 for 0.9; at
// tol 1e-12 the former lies below the round-off of the MPE's error estimate (sum |d_i| ~ 175 times the
// increments' rounding), so M16-adaptive would shrink its steps for nothing (e = 0.5, error 1e-12:
// 1 457 000 forces at 0.7, 74 900 at 0.9).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>

#include "nystrom/core/bignum.hpp"
#include "nystrom/core/error.hpp"
#include "nystrom/core/state.hpp"
#include "nystrom/engines/options.hpp"
#include "nystrom/engines/rkn.hpp"
#include "nystrom/methods/method.hpp"
#include "nystrom/methods/method_data.hpp"
#include "nystrom/methods/rkn_order_conditions.hpp"

namespace nystrom {

struct AdaptiveStats {
  long accepted = 0;
  long rejected = 0;
  long force_evals = 0;
  double last_h = 0;  // the last accepted step
  AdaptiveStats& operator+=(const AdaptiveStats& o) {
    accepted += o.accepted;
    rejected += o.rejected;
    force_evals += o.force_evals;
    if (o.accepted > 0) last_h = o.last_h;
    return *this;
  }
};

/// The order of the main weights of a real tableau, from its order conditions evaluated in double (a
/// condition counts as satisfied below 1e-10; far above rounding, far below a failing condition of
/// a practical method). embedded_order: the same for the embedded weights.
template <class S>
int tableau_order(const RknTableau<S>& t, int max_order = 14) {
  auto d = convert_tableau<double>(t, [](const S& x) { return as_double(x); });
  return rkn_order(d, 1e-10, max_order);
}
template <class S>
int embedded_order(const RknTableau<S>& t, int max_order = 14) {
  return tableau_order(embedded_tableau(t), max_order);
}

namespace adaptive_detail {
inline std::string sci(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}
struct NoObserver {
  template <class T, class St>
  void operator()(const T&, const St&) const {}
};

/// The scale sc of the error of a component of size y (the larger of its sizes at both ends of the
/// step): tol (1 + y) with one tolerance (atol 0 or equal to tol), atol + tol y with two.
template <class R>
class ErrorScale {
 public:
  explicit ErrorScale(const AdaptiveOptions& opt)
      : tol_(opt.tol), atol_(opt.atol), mixed_(opt.atol == 0 || opt.atol == opt.tol) {}
  R operator()(const R& y) const { return mixed_ ? R(tol_ * (R(1) + y)) : R(atol_ + tol_ * y); }

 private:
  R tol_, atol_;
  bool mixed_;
};

/// Hairer's starting step (HNW I, II.4) for y' = F(y), y = (q, v), F = (v, a(q)): two force
/// evaluations; norms in double (they only set the order of magnitude).
template <class V, class F, class R>
R hairer_initial_step(F& force, const State<V>& s, const R& hmax, const ErrorScale<R>& scale, int order) {
  using std::abs;
  const std::size_t n = s.q.size();
  V a0 = s.q, a1 = s.q;
  force(s.q, a0);
  auto norm = [&](auto&& comp) {
    double sum = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const R sq = scale(abs(s.q[i]));
      const R sv = scale(abs(s.v[i]));
      const auto [x, y] = comp(i);
      const double rx = as_double(R(x / sq)), ry = as_double(R(y / sv));
      sum += rx * rx + ry * ry;
    }
    return std::sqrt(sum / static_cast<double>(2 * n));
  };
  const double d0 = norm([&](std::size_t i) { return std::pair<R, R>(s.q[i], s.v[i]); });
  const double d1 = norm([&](std::size_t i) { return std::pair<R, R>(s.v[i], a0[i]); });
  double h0d = (d0 < 1e-5 || d1 < 1e-5) ? 1e-6 : 0.01 * d0 / d1;
  h0d = std::min(h0d, as_double(hmax));
  const R h0(h0d);
  V q1 = s.q;
  for (std::size_t i = 0; i < n; ++i) q1[i] = s.q[i] + h0 * s.v[i];
  force(q1, a1);
  const double d2 = norm([&](std::size_t i) { return std::pair<R, R>(h0 * a0[i], a1[i] - a0[i]); }) / h0d;
  const double dm = std::max(d1, d2);
  const double h1 = dm <= 1e-15 ? std::max(1e-6, h0d * 1e-3) : std::pow(0.01 / dm, 1.0 / (order + 1));
  double h = std::min(100 * h0d, h1);
  if (!std::isfinite(h) || !(h > 0)) h = as_double(hmax) * 1e-3;
  return std::min(R(h), hmax);
}
/// The step ratio of both adaptive engines. q = err^(-1/(p+1)) of the attempted step (+inf for
/// err = 0, NaN for an error that is not finite), h its size. After an accepted step: safety * q, or
/// with opt.predictive (Gustafsson, ACM TOMS 20 (1994) 496; HNW II, IV.8, as in RADAU5) the smaller of
/// that and safety * q * (h_n / h_{n-1}) * (q_n / q_{n-1}) = safety * q * (h_n / h_{n-1}) *
/// (err_{n-1} / err_n)^(1/(p+1)), which follows the trend of the last two accepted steps: a step that
/// must shrink step after step (Kepler e = 0.9 falling towards pericentre) is shrunk ahead instead of
/// rejected. Then clamped to [fac_min, fac_max], and at most 1 right after a rejection. After a
/// rejected step: safety * q clamped to [fac_min, 1] (fac_min for an error that is not finite).
class StepController {
 public:
  explicit StepController(const AdaptiveOptions& opt) : opt_(opt) {}

  double accepted(double q, double h, bool after_rejection) {
    double fac = opt_.fac_max;
    if (std::isfinite(q)) {
      fac = opt_.safety * q;
      if (opt_.predictive && q_prev_ > 0) fac = std::min(fac, fac * (h / h_prev_) * (q / q_prev_));
      q_prev_ = q;
    } else {
      q_prev_ = 0;
    }
    h_prev_ = h;
    fac = std::min(opt_.fac_max, std::max(opt_.fac_min, fac));
    return after_rejection ? std::min(fac, 1.0) : fac;
  }

  double rejected(double q) const {
    if (!(q >= 0) || !std::isfinite(q)) return opt_.fac_min;
    return std::min(1.0, std::max(opt_.fac_min, opt_.safety * q));
  }

  /// The history of the last accepted step (checkpoint/restart).
  double q_prev() const { return q_prev_; }
  double h_prev() const { return h_prev_; }
  void restore(double q_prev, double h_prev) {
    q_prev_ = q_prev;
    h_prev_ = h_prev;
  }

 private:
  const AdaptiveOptions& opt_;
  double q_prev_ = 0, h_prev_ = 0;  // of the last accepted step
};

}  // namespace adaptive_detail

/// Where an adaptive run stopped between two accepted steps, with all that its controller needs to
/// go on exactly as if it had not stopped: the next step size, the step bound, whether the last
/// attempt was rejected and the predictive controller's history. An observer that returns true stops
/// integrate_to after the step it has seen; the engine keeps this point (resume_point()), and the
/// next integrate_to from that time continues from it (also after set_resume_point on a new engine,
/// for a restart from a checkpoint): the steps are bitwise those of the uninterrupted run.
template <class R>
struct AdaptiveResumePoint {
  R t{}, h_want{}, hmax{};
  bool last_rejected = false;
  double q_prev = 0, h_prev = 0;
  bool valid = false;
  /// A valid point must be one an engine can have stopped at: finite t, 0 < h_want <= hmax (finite), and
  /// a history q_prev, h_prev >= 0 (finite). Throws invalid_input otherwise (a checkpoint is refused).
  void check() const {
    if (!valid) return;
    if (!is_finite_scalar(t) || !is_finite_scalar(hmax) || !(h_want > R(0)) || !(h_want <= hmax) ||
        !std::isfinite(q_prev) || !std::isfinite(h_prev) || !(q_prev >= 0) || !(h_prev >= 0))
      throw invalid_input(
          "adaptive step control: the resume point needs a finite time, 0 < h_want <= hmax and a "
          "history >= 0");
  }
};

namespace adaptive_detail {

/// The step sizes of one integrate_to call of either adaptive engine, from t0 to t1: the first step
/// (from the resume point at t0, else opt.h0, else the step carried over from the previous call
/// h_carried, else the starting-step estimate starting_step(hmax)), the next step from t (shortened
/// to land on t1, stretched when within 1% of it), and the proposals after an accepted or rejected
/// step through StepController. The engine computes q = err^(-1/(p+1)) of each attempt.
template <class R>
class StepSequence {
 public:
  template <class Start>
  StepSequence(const AdaptiveOptions& opt, AdaptiveResumePoint<R>& resume, const R& h_carried, const R& t0, const R& t1,
               Start&& starting_step)
      : ctl_(opt), t1_(t1) {
    using std::abs;
    const R span = t1 - t0;
    hmax_ = opt.h_max > 0 ? std::min(span, R(opt.h_max)) : span;
    R h;
    const bool resumed = resume.valid && resume.t == t0;
    resume.valid = false;
    if (resumed) {
      h = resume.h_want;
      hmax_ = resume.hmax;
      last_rejected_ = resume.last_rejected;
      ctl_.restore(resume.q_prev, resume.h_prev);
    } else if (opt.h0 > 0) {
      h = R(opt.h0);
    } else if (h_carried > R(0)) {
      h = h_carried;
    } else {
      h = starting_step(static_cast<const R&>(hmax_));
    }
    h_want_ = std::min(h, hmax_);
    tiny_ = R(16) * epsilon_of<R>() * std::max(abs(t0), abs(t1));
  }

  /// The next step h from t; last: it lands on t1. ExactEnd: a step that does not land on t1 is
  /// rounded so that t + h is exactly representable. False when the step has fallen below the
  /// rounding level of t (step-size underflow).
  template <bool ExactEnd>
  bool next(const R& t, R& h, bool& last) const {
    h = h_want_;
    last = false;
    if (t + h * R(1.01) >= t1_) {
      h = t1_ - t;
      last = true;
    } else if constexpr (ExactEnd) {
      h = (t + h) - t;
    }
    return h > tiny_ && h > R(0);
  }

  /// After an accepted step h with ratio q: the next proposal, and into h_carried the step the next
  /// call starts with (a step shortened to land on t1 keeps the earlier proposal).
  void accepted(double q, const R& h, bool last, R& h_carried) {
    accepted_ratio(ctl_.accepted(q, as_double(h), last_rejected_), h, last, h_carried);
  }
  /// The same with a step ratio the engine chose itself (order control: the ratio of the next order).
  void accepted_ratio(double fac, const R& h, bool last, R& h_carried) {
    const R hn = std::min(h * R(fac), hmax_);
    h_carried = last && h < h_want_ ? h_want_ : hn;
    h_want_ = hn;
    last_rejected_ = false;
  }
  /// After a rejected step h with ratio q.
  void rejected(double q, const R& h) { rejected_ratio(ctl_.rejected(q), h); }
  void rejected_ratio(double fac, const R& h) {
    h_want_ = h * R(fac);
    last_rejected_ = true;
  }
  /// The last attempt was rejected (the next accepted step must not grow).
  bool after_rejection() const { return last_rejected_; }
  /// The point to go on from at t, after an accepted step.
  AdaptiveResumePoint<R> resume_point(const R& t) const {
    return {t, h_want_, hmax_, false, ctl_.q_prev(), ctl_.h_prev(), true};
  }

 private:
  StepController ctl_;
  R t1_, hmax_{}, h_want_{}, tiny_{};
  bool last_rejected_ = false;
};

[[noreturn]] inline void throw_too_many_steps(const char* engine, long max_steps, double t, double t1) {
  throw TooManySteps(std::string(engine) + ": more than " + std::to_string(max_steps) +
                     " steps before reaching t1 = " + sci(t1) + " (at t = " + sci(t) + ")");
}
[[noreturn]] inline void throw_underflow(const char* engine, double t, double h, bool error_finite) {
  throw StepSizeUnderflow(std::string(engine) + ": step size underflow at t = " + sci(t) + " (h = " + sci(h) + "): " +
                          (error_finite ? "the tolerance cannot be met or the solution is singular"
                                        : "the force returned NaN or infinity in this step"));
}

/// Calls the observer; true when it asks the run to stop (an observer that returns bool).
template <class Observer, class R, class St>
bool observe(Observer& obs, const R& t, const St& s) {
  if constexpr (std::is_same_v<std::invoke_result_t<Observer&, const R&, const St&>, bool>) {
    return obs(t, s);
  } else {
    obs(t, s);
    return false;
  }
}

}  // namespace adaptive_detail

template <class V, class Force>
class AdaptiveRknIntegrator {
  static std::string sci(double x) { return adaptive_detail::sci(x); }

 public:
  using vector_type = V;
  using scalar_type = typename V::value_type;
  using real_type = scalar_type;
  static_assert(!is_complex_v<scalar_type>, "adaptive step control needs a real scalar type");

  /// eopt.compensated: compensated summation of the accepted increments (automatic: in double and float).
  AdaptiveRknIntegrator(RknTableau<scalar_type> t, Force force, AdaptiveOptions opt = {}, EngineOptions eopt = {})
      : opt_(opt),
        stepper_(check(std::move(t)), std::move(force)),
        compensated_(use_compensation<scalar_type>(eopt.compensated)) {
    opt_.validate();
    const double min_tol = 10 * as_double(epsilon_of<real_type>());
    if (opt_.tol > 0 && opt_.tol < min_tol)
      throw std::invalid_argument("tolerance " + sci(opt_.tol) + " is below what " + scalar_traits<real_type>::name() +
                                  " resolves (10 eps = " + sci(min_tol) + "); use a wider precision");
    if (opt_.error_order == 0) opt_.error_order = embedded_order(stepper_.tableau());
    if (opt_.error_order < 1) throw std::invalid_argument("the embedded weights of the tableau have no order");
    const int high = tableau_order(stepper_.tableau());
    method_order_ = high > 0 ? high : opt_.error_order;
  }

  const AdaptiveOptions& options() const { return opt_; }
  int error_order() const { return opt_.error_order; }
  int method_order() const { return method_order_; }
  bool compensated() const { return compensated_; }
  const AdaptiveStats& total() const { return total_; }
  Force& force() { return stepper_.force(); }

  template <class Observer = adaptive_detail::NoObserver>
  AdaptiveStats integrate_to(State<V>& s, real_type t0, real_type t1, Observer&& obs = {}) {
    using std::abs;
    using std::isfinite;
    if (!isfinite(t0) || !isfinite(t1)) throw std::invalid_argument("integration times must be finite");
    if (t1 < t0) throw std::invalid_argument("end time t1 must not be before the start time t0");
    validate_state(s);
    AdaptiveStats st;
    const long evals_before = stepper_.force_evals();
    obs(static_cast<const real_type&>(t0), static_cast<const State<V>&>(s));
    if (t1 == t0) return st;

    const adaptive_detail::ErrorScale<real_type> err_scale(opt_);
    long extra_evals = 0;
    adaptive_detail::StepSequence<real_type> seq(opt_, resume_, h_next_, t0, t1, [&](const real_type& hmax) {
      extra_evals = 2;
      return adaptive_detail::hairer_initial_step(stepper_.force(), s, hmax, err_scale, method_order_);
    });
    const double expo = -1.0 / (opt_.error_order + 1);
    real_type t = t0, h;
    bool error_finite = true;  // the last error estimate was finite (else the force returned NaN or inf)
    State<V> y = s, err;
    const bool comp = compensated_;
    Compensator<V> trial;  // the carries of the attempted step; comp_ keeps those of the last accepted one
    if (comp) {
      comp_.begin(s);
      trial = comp_;
    }
    // Keeps the state and the carries of the last accepted step (also before an exception).
    auto store = [&] {
      if (comp) comp_.end(s);
    };
    while (t < t1) {
      if (st.accepted + st.rejected >= opt_.max_steps) {
        store();
        adaptive_detail::throw_too_many_steps("adaptive RKN", opt_.max_steps, as_double(t), as_double(t1));
      }
      // Steps whose end times are exactly representable (the time reached is the sum of the steps, see
      // StepSequence::next); compensated summation of the increments in double and float, as in the
      // fixed-step engine: both keep the round-off of 10^4 steps below the error of the state's last bit.
      bool last;
      if (!seq.template next<true>(t, h, last)) {
        store();
        adaptive_detail::throw_underflow("adaptive RKN", as_double(t), as_double(h), error_finite);
      }
      assign_state(y, s);
      if (comp) {
        assign(trial.cq, comp_.cq);
        assign(trial.cv, comp_.cv);
        stepper_.step_with_error(y, h, err, trial);
      } else {
        stepper_.step_with_error(y, h, err);
      }
      const double e = error_norm(s, y, err, err_scale);  // the controller works in double: 2 digits suffice
      error_finite = e < std::numeric_limits<double>::infinity();
      if (e <= 1.0) {
        assign_state(s, y);
        if (comp) {
          assign(comp_.cq, trial.cq);
          assign(comp_.cv, trial.cv);
        }
        t = last ? t1 : t + h;
        ++st.accepted;
        st.last_h = as_double(h);
        const bool stop =
            adaptive_detail::observe(obs, static_cast<const real_type&>(t), static_cast<const State<V>&>(s));
        seq.accepted(std::pow(e, expo), h, last, h_next_);
        if (stop && t < t1) {
          resume_ = seq.resume_point(t);
          break;
        }
      } else {
        ++st.rejected;
        seq.rejected(std::pow(e, expo), h);
      }
    }
    store();
    st.force_evals = stepper_.force_evals() - evals_before + extra_evals;
    total_ += st;
    return st;
  }

  /// Forget the step carried over between calls (the next call estimates a first step again).
  void reset() {
    h_next_ = real_type(0);
    comp_.invalidate();
    resume_.valid = false;
  }
  /// Where the last run stopped at its observer's request (valid == false: it did not stop).
  const AdaptiveResumePoint<real_type>& resume_point() const { return resume_; }
  void set_resume_point(const AdaptiveResumePoint<real_type>& p) {
    p.check();
    resume_ = p;
  }
  /// The compensated-summation carries of the run (checkpoint/restart).
  Compensator<V>& compensator() { return comp_; }

 private:
  static RknTableau<scalar_type> check(RknTableau<scalar_type> t) {
    t.validate();
    if (t.bhat.empty())
      throw std::invalid_argument("adaptive step control needs a tableau with embedded weights (bhat, Bhat)");
    return t;
  }

  static void assign_state(State<V>& dst, const State<V>& src) {
    resize_like(dst.q, src.q);
    resize_like(dst.v, src.v);
    assign(dst.q, src.q);
    assign(dst.v, src.v);
  }

  /// The mixed norm of the error estimate, in double (NaN or inf: +inf, i.e. reject).
  double error_norm(const State<V>& y0, const State<V>& y1, const State<V>& e,
                    const adaptive_detail::ErrorScale<real_type>& scale) const {
    using std::abs;
    double sum = 0;
    const std::size_t n = y0.q.size();
    for (std::size_t i = 0; i < n; ++i) {
      const real_type sq = scale(std::max(abs(y0.q[i]), abs(y1.q[i])));
      const real_type sv = scale(std::max(abs(y0.v[i]), abs(y1.v[i])));
      const double rq = as_double(real_type(e.q[i] / sq)), rv = as_double(real_type(e.v[i] / sv));
      sum += rq * rq + rv * rv;
    }
    const double r = std::sqrt(sum / static_cast<double>(2 * n));
    return std::isfinite(r) ? r : std::numeric_limits<double>::infinity();
  }

  AdaptiveOptions opt_;
  RknStepper<V, Force> stepper_;
  int method_order_ = 0;
  bool compensated_ = false;
  real_type h_next_ = real_type(0);
  AdaptiveResumePoint<real_type> resume_;
  AdaptiveStats total_;
  Compensator<V> comp_;
};

/// Builds an adaptive integrator for a catalog method with embedded weights, at a reference
/// precision matched to V's scalar type.
template <class V, class F>
AdaptiveRknIntegrator<V, F> make_adaptive_integrator(const MethodDef& def, F force, AdaptiveOptions opt = {},
                                                     EngineOptions eopt = {}) {
  using S = typename V::value_type;
  opt.validate();
  // Coefficients at the reference precision; the working values are created outside it (mpfr_real).
  const MethodData data = method_data_for(def, scalar_traits<S>::bits(), scalar_traits<S>::name());
  const auto* t = std::get_if<RknTableau<bigcomplex>>(&data);
  if (!t || t->bhat.empty())
    throw std::invalid_argument("method '" + def.info.name + "' has no embedded pair: it cannot run with a tolerance");
  auto conv = [](const bigcomplex& x) { return to_scalar<S>(x); };
  return AdaptiveRknIntegrator<V, F>(convert_tableau<S>(*t, conv), std::move(force), opt, eopt);
}

}  // namespace nystrom
