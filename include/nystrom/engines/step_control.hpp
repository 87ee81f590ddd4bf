// Step-size control shared by both adaptive engines: the embedded RKN pairs (engines/adaptive_rkn.hpp,
// e.g. "DP12-adaptive") and the multi-product expansion with and without order control
// (engines/adaptive_mpe.hpp, "M14-adaptive", "MPE-adaptive"): the statistics of a run, the error norm, the
// step ratio, the starting step, the sequence of steps of one call and the resume point.
//
// The controller (Hairer, Norsett & Wanner I, sec. II.4; Brankin et al., ACM TOMS 15 (1989) 31):
//   * error estimate: the difference of the two solutions of the engine's pair (for an RKN pair, in q
//     (h^2 sum (b - bhat) f) and v (h sum (B - Bhat) f)); the higher-order solution is propagated (local
//     extrapolation);
//   * norm: err = sqrt( (1/2n) sum_i (e_i / sc_i)^2 ) over all n positions and n velocities, with
//     sc_i = rtol * (1 + max(|y_i(t)|, |y_i(t+h)|)): mixed absolute/relative with one tolerance
//     (opt.atol 0 or equal to opt.rtol), or sc_i = atol + rtol * max(|y_i(t)|, |y_i(t+h)|) with a separate
//     absolute tolerance (rtol 0: absolute only); ErrorScale, error_norm (error_norm2: its square with a
//     floor on the scale, for the multi-product expansion);
//   * accept when err <= 1; new h = h * min(fac_max, max(fac_min, safety * err^(-1/(p+1)))), p the
//     lower order of the pair, or Gustafsson's predictive ratio when smaller (opt.predictive, on by
//     default; StepController); after a rejection the step may not grow in the next attempt;
//   * first step: Hairer's starting-step algorithm (two force evaluations; hairer_initial_step) unless
//     opt.h0 > 0; later calls continue with the step proposed at the end of the previous call;
//   * the last step is shortened to land exactly on t1 (and a step within 1% of the end is stretched); every
//     other step is rounded so that t + h is exact (StepSequence).
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

#include "nystrom/core/error.hpp"
#include "nystrom/core/state.hpp"
#include "nystrom/engines/options.hpp"

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

/// The anchor of controlled_tolerance when neither the options nor the method give one.
inline constexpr double kToleranceAnchor = 1e-15;

/// The tolerance the controller works to for the user's tolerance tol: anchor (tol / anchor)^gamma above
/// the anchor (0: kToleranceAnchor), tol itself at and below it (and for gamma 0 or 1).
/// Why: an error-per-step controller for a pair of orders p (e) makes steps h ~ tol^(1/(e+1)), so a global
/// error ~ h^p would grow as tol^(p/(e+1)); the pairs with e = p - 2 (DP12(10), the multi-product
/// expansion) were measured to grow faster still, as h^(p+1), i.e. tol^((p+1)/(e+1)) (M4 tol^1.59,
/// M8 tol^1.26, DP12 tol^1.18, M16 tol^1.12; Kepler e = 0.5 and 0.9 over 100 periods, outer solar system over 100
/// Jupiter periods, long double so that truncation alone counts), so that error / tol climbed 1.5 to 6 decades between
/// tolerances 1e-15 and 1e-6. With gamma = (e+1)/(p+1) (MethodInfo::tolerance_exponent) the error follows tol; the
/// anchor (MethodInfo::tolerance_anchor) is where the calibrated and the plain controller agree: the tightest tolerance
/// in double for the high orders, so that the floor stays where it was and no tolerance is loosened.
/// docs/performance.md, "Tolerance proportionality".
inline double controlled_tolerance(double tol, double gamma, double anchor = 0) {
  if (!(anchor > 0)) anchor = kToleranceAnchor;
  if (!(gamma > 0) || !(gamma < 1) || !(tol > anchor)) return tol;
  return anchor * std::pow(tol / anchor, gamma);
}

/// The scale sc of the error of a component of size y (the larger of its sizes at both ends of the
/// step): rtol (1 + y) with one tolerance (atol 0 or equal to rtol), atol + rtol y with two; rtol and atol
/// are the controlled tolerances (controlled_tolerance with opt.tolerance_exponent and opt.tolerance_anchor).
template <class R>
class ErrorScale {
 public:
  explicit ErrorScale(const AdaptiveOptions& opt)
      : rtol_(controlled_tolerance(opt.rtol, opt.tolerance_exponent, opt.tolerance_anchor)),
        atol_(controlled_tolerance(opt.atol, opt.tolerance_exponent, opt.tolerance_anchor)),
        mixed_(opt.atol == 0 || opt.atol == opt.rtol) {}
  R operator()(const R& y) const { return mixed_ ? R(rtol_ * (R(1) + y)) : R(atol_ + rtol_ * y); }

 private:
  R rtol_, atol_;
  bool mixed_;
};

/// Refuses a tolerance below what the scalar type R resolves: 10 eps, or eps / 2 for a run whose increments and
/// force are compensated (a compensated force, takes_carry_v, in the adaptive RKN pairs' precise update);
/// could_compensate: the message names that way down.
template <class R>
void check_tolerance(const AdaptiveOptions& opt, bool compensated_force = false, bool could_compensate = false) {
  const double eps = as_double(epsilon_of<R>());
  const double min_tol = compensated_force ? eps / 2 : 10 * eps;
  if (opt.rtol > 0 && opt.rtol < min_tol)
    throw std::invalid_argument("tolerance " + sci(opt.rtol) + " is below what " + scalar_traits<R>::name() +
                                " resolves (" + (compensated_force ? "eps / 2 = " : "10 eps = ") + sci(min_tol) +
                                (could_compensate ? "; eps / 2 with a compensated force" : "") +
                                "); use a wider precision");
}

/// Hairer's starting step (HNW I, II.4) for y' = F(y), y = (q, v), F = (v, a(q)): two force
/// evaluations; norms in double (they only set the order of magnitude).
template <class V, class F, class R>
R hairer_initial_step(F& force, const State<V>& s, const R& hmax, const ErrorScale<R>& scale, int order) {
  using std::abs;
  const std::size_t n = s.q.size();
  V a0 = s.q, a1 = s.q;
  // A velocity-dependent force (force(q, v, a)) is evaluated at (q0, v0) and at the Euler step (q1, v1).
  constexpr bool vd = takes_velocity_v<F, V>;
  if constexpr (vd)
    force(s.q, s.v, a0);
  else
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
  if constexpr (vd) {
    V v1 = s.v;
    for (std::size_t i = 0; i < n; ++i) v1[i] = s.v[i] + h0 * a0[i];
    force(static_cast<const V&>(q1), static_cast<const V&>(v1), a1);
  } else {
    force(q1, a1);
  }
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

/// The mixed norm of the error estimate e of a step from y0 to y1, in double (NaN or inf: +inf, i.e. reject).
template <class V, class R>
inline double error_norm(const State<V>& y0, const State<V>& y1, const State<V>& e, const ErrorScale<R>& scale) {
  using std::abs;
  double sum = 0;
  const std::size_t n = y0.q.size();
  for (std::size_t i = 0; i < n; ++i) {
    const R sq = scale(std::max(abs(y0.q[i]), abs(y1.q[i])));
    const R sv = scale(std::max(abs(y0.v[i]), abs(y1.v[i])));
    const double rq = as_double(R(e.q[i] / sq)), rv = as_double(R(e.v[i] / sv));
    sum += rq * rq + rv * rv;
  }
  const double r = std::sqrt(sum / static_cast<double>(2 * n));
  return std::isfinite(r) ? r : std::numeric_limits<double>::infinity();
}

/// The same norm squared, of a step from y0 by the increment inc (NaN or inf: +inf, i.e. reject). The scale
/// of a component is at least noise |increment|: an estimate at its own round-off level is not an error the
/// step size can reduce (the multi-product expansion's floor; engines/adaptive_mpe.hpp).
template <class V, class R>
inline double error_norm2(const State<V>& y0, const State<V>& inc, const State<V>& e, const ErrorScale<R>& sc,
                          const R& noise) {
  using std::abs;
  double sum = 0;
  const std::size_t n = y0.q.size();
  for (std::size_t i = 0; i < n; ++i) {
    const R q1 = y0.q[i] + inc.q[i], v1 = y0.v[i] + inc.v[i];
    const R sq = std::max(sc(std::max(abs(y0.q[i]), abs(q1))), R(noise * abs(inc.q[i])));
    const R sv = std::max(sc(std::max(abs(y0.v[i]), abs(v1))), R(noise * abs(inc.v[i])));
    const double rq = as_double(R(e.q[i] / sq)), rv = as_double(R(e.v[i] / sv));
    sum += rq * rq + rv * rv;
  }
  const double r = sum * (1.0 / static_cast<double>(2 * n));  // the reciprocal off the chain of the step
  return std::isfinite(r) ? r : std::numeric_limits<double>::infinity();
}

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

}  // namespace nystrom
