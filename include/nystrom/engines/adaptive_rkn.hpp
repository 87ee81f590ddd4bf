// Step-size control for an embedded RKN pair (e.g. the Dormand-El-Mikkawy-Prince RKN12(10),
// catalog entry "DP12-adaptive").
//
// API (what the CLI calls for `nystrom run --method DP12-adaptive --tol 1e-12`):
//
//   nystrom::AdaptiveOptions opt;            // all fields optional except rtol
//   opt.rtol = 1e-12;
//   auto ai = nystrom::make_adaptive_integrator<V>(def, force, opt);   // def: a MethodDef whose
//                                            // tableau carries bhat/Bhat (info.adaptive == true)
//   nystrom::AdaptiveStats st = ai.integrate_to(state, t0, t1);        // lands exactly on t1
//   nystrom::AdaptiveStats st = ai.integrate_to(state, t0, t1,
//       [](auto t, const nystrom::State<V>& s) { ... });               // observer: t0, then every accepted step
//   st.accepted, st.rejected, st.force_evals, st.last_h                 // this call; ai.total() sums all calls
//
// V is std::array<T, N> or std::vector<T> with a real T (double, long double, float128, ...).
// A general (RKNG) pair (RknTableau::general(), e.g. "Fine5-adaptive") also takes a velocity-dependent force
// force(q, v, a).
// Errors: std::invalid_argument for bad input (rtol or atol negative or not finite, both zero, rtol
// below 10 eps of the scalar type, t1 < t0, t0/t1 not finite,
// NaN/inf or inconsistent state, a tableau without embedded weights, bad options);
// nystrom::StepSizeUnderflow (a std::runtime_error) when the step size falls below the rounding
// level of t, which happens when the tolerance cannot be met (too strict for the scalar type) or
// the solution is singular; nystrom::TooManySteps (std::runtime_error) after opt.max_steps steps.
// After such an exception the state holds the last accepted step (the observer has seen its time).
//
// The controller is the one both adaptive engines share (engines/step_control.hpp): the error estimate is
// the difference of the two solutions of the pair, in q (h^2 sum (b - bhat) f) and v (h sum (B - Bhat) f),
// in the mixed norm; p is the lower order of the pair (the embedded weights' order unless opt.error_order).
// The accepted increments are added with compensated summation (EngineOptions::compensated, on by default in
// double and float; the carries live in compensator()). With the exact step ends of the controller it lowers
// the round-off floor: Kepler, 100 periods, final position error at the four tightest tolerances
// (1.8e-14 .. 3.2e-15), e = 0.5: 8.4e-12, 7.5e-12, 4.8e-13, 3.3e-12 without, 5.5e-13, 2.1e-12, 1.7e-12,
// 1.5e-12 with; e = 0.9: 1.8e-11, 7.2e-11, 6.7e-12, 4.8e-12 without, 5.3e-13, 3.9e-12, 1.7e-12, 1.2e-12
// with. What remains is the rounding of the force and of the increments themselves (the same tableau in
// long double with the force rounded to double: 1e-13 .. 6e-13).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
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
#include "nystrom/engines/step_control.hpp"
#include "nystrom/methods/method.hpp"
#include "nystrom/methods/method_data.hpp"
#include "nystrom/methods/rkn_order_conditions.hpp"

namespace nystrom {

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

template <class V, class Force>
class AdaptiveRknIntegrator {
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
    adaptive_detail::check_tolerance<real_type>(opt_);
    // A general (RKNG) tableau carries its orders for y'' = f(t, y, y'); the order conditions of
    // y'' = f(y) decide those of the others.
    const auto& tab = stepper_.tableau();
    // With a second, lower-order estimate (DOP853) the stretched error behaves like that of the main solution.
    if (opt_.error_order == 0)
      opt_.error_order = !tab.blow.empty() ? tab.general_order - 1
                         : tab.general()   ? tab.general_embedded_order
                                           : embedded_order(tab);
    if (opt_.error_order < 1) throw std::invalid_argument("the embedded weights of the tableau have no order");
    const int high = tab.general() ? tab.general_order : tableau_order(tab);
    stretched_ = !tab.blow.empty();
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
      // The controller works in double: 2 digits suffice. With a second estimate of lower order (DOP853's),
      // Hairer's stretched estimate err5^2 / sqrt(err5^2 + 0.01 err3^2) (HNW I, sec. II.10).
      double e = adaptive_detail::error_norm(s, y, err, err_scale);
      if (stretched_ && e > 0) {
        const double e3 = adaptive_detail::error_norm(s, y, stepper_.low_error(), err_scale);
        e = e * e / std::sqrt(e * e + 0.01 * e3 * e3);
      }
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

  AdaptiveOptions opt_;
  RknStepper<V, Force> stepper_;
  int method_order_ = 0;
  bool compensated_ = false;
  bool stretched_ = false;  // the tableau has a second estimate (blow, Blow)
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
