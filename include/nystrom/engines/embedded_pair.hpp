// The step loop of an adaptive integrator built on an embedded pair: a stepper that returns, with each step,
// the difference of its two solutions. Two engines share it: the embedded RKN pairs (engines/adaptive_rkn.hpp,
// "DP12-adaptive", "DOP853-adaptive") and the multi-product expansion over Gragg's modified midpoint rule
// (engines/mpe_midpoint.hpp, "mpe-midpoint-adaptive:1,2,3,4").
//
// The Stepper provides
//   step_with_error(State<V>& y, h, State<V>& err [, Compensator<V>& carries]): one step from y in place and the
//       error estimate (q, v) in err; with carries, the increments added with compensated summation;
//   force_evals(), force();
//   optionally low_error(): a second, lower-order estimate of the same step, which makes the norm Hairer's
//       stretched estimate err^2 / sqrt(err^2 + 0.01 low^2) (HNW I, sec. II.10; DOP853).
// The engine derived from EmbeddedPairIntegrator states the orders (set_orders): the error order p of the
// controller (h *= err^(-1/(p+1)); AdaptiveOptions::error_order overrides it) and the method's order, used by
// the starting-step estimate. The controller, the norm, the starting step, exact step ends, the resume point
// and exact force counting are those of engines/step_control.hpp.
#pragma once

#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include "nystrom/core/scalar.hpp"
#include "nystrom/core/state.hpp"
#include "nystrom/engines/options.hpp"
#include "nystrom/engines/step_control.hpp"

namespace nystrom {

template <class V, class Stepper>
class EmbeddedPairIntegrator {
 public:
  using vector_type = V;
  using scalar_type = typename V::value_type;
  using real_type = scalar_type;
  static_assert(!is_complex_v<scalar_type>, "adaptive step control needs a real scalar type");

  const AdaptiveOptions& options() const { return opt_; }
  int error_order() const { return opt_.error_order; }
  int method_order() const { return method_order_; }
  bool compensated() const { return compensated_; }
  const AdaptiveStats& total() const { return total_; }
  auto& force() { return stepper_.force(); }

  /// Integrates s from t0 to t1 (landing exactly on t1); obs(t, s) sees t0 and every accepted step, and stops
  /// the run after the step it has seen by returning true (resume_point() then holds where to go on).
  template <class Observer = adaptive_detail::NoObserver>
  AdaptiveStats integrate_to(State<V>& s, real_type t0, real_type t1, Observer&& obs = {}) {
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
    State<V> y = s, err{};
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
        adaptive_detail::throw_too_many_steps(name_, opt_.max_steps, as_double(t), as_double(t1));
      }
      // Steps whose end times are exactly representable (the time reached is the sum of the steps, see
      // StepSequence::next); compensated summation of the increments in double and float, as in the
      // fixed-step engines: both keep the round-off of 10^4 steps below the error of the state's last bit.
      bool last;
      if (!seq.template next<true>(t, h, last)) {
        store();
        adaptive_detail::throw_underflow(name_, as_double(t), as_double(h), error_finite);
      }
      assign_state(y, s);
      if (comp) {
        assign(trial.cq, comp_.cq);
        assign(trial.cv, comp_.cv);
        stepper_.step_with_error(y, h, err, trial);
      } else {
        stepper_.step_with_error(y, h, err);
      }
      // The controller works in double: 2 digits suffice.
      double e = adaptive_detail::error_norm(s, y, err, err_scale);
      if constexpr (requires { stepper_.low_error(); }) {
        if (stretched_ && e > 0) {
          const double e3 = adaptive_detail::error_norm(s, y, stepper_.low_error(), err_scale);
          e = e * e / std::sqrt(e * e + 0.01 * e3 * e3);
        }
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

 protected:
  /// name: the engine in messages ("adaptive RKN"); eopt.compensated: compensated summation of the accepted
  /// increments (automatic: in double and float).
  EmbeddedPairIntegrator(Stepper stepper, AdaptiveOptions opt, EngineOptions eopt, const char* name)
      : opt_(opt),
        stepper_(std::move(stepper)),
        compensated_(use_compensation<scalar_type>(eopt.compensated)),
        name_(name) {
    opt_.validate();
    bool compensated_force = false, could = false;
    if constexpr (requires { Stepper::carried_force; }) {
      compensated_force = Stepper::carried_force && compensated_;
      could = Stepper::precise_capable && compensated_ && !compensated_force;
    }
    adaptive_detail::check_tolerance<real_type>(opt_, compensated_force, could);
  }
  /// The pair's orders: error_order (taken unless the options give one), the method's order (0: the error
  /// order), and whether the stepper's second estimate stretches the norm.
  void set_orders(int error_order, int method_order, bool stretched) {
    if (opt_.error_order == 0) opt_.error_order = error_order;
    if (opt_.error_order < 1) throw std::invalid_argument("the embedded weights of the tableau have no order");
    stretched_ = stretched;
    method_order_ = method_order > 0 ? method_order : opt_.error_order;
  }
  const Stepper& stepper() const { return stepper_; }

 private:
  static void assign_state(State<V>& dst, const State<V>& src) {
    resize_like(dst.q, src.q);
    resize_like(dst.v, src.v);
    assign(dst.q, src.q);
    assign(dst.v, src.v);
  }

  AdaptiveOptions opt_;
  Stepper stepper_;
  int method_order_ = 0;
  bool compensated_ = false;
  bool stretched_ = false;
  const char* name_;
  real_type h_next_ = real_type(0);
  AdaptiveResumePoint<real_type> resume_;
  AdaptiveStats total_;
  Compensator<V> comp_;
};

}  // namespace nystrom
