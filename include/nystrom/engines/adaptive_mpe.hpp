// Step-size control for the multi-product expansion (catalog specs "M10-adaptive",
// "mpe-adaptive:1,2,3,4,5", "mpe-vv-adaptive:1,2,3"), and order and step control over the natural sequence
// ("MPE-adaptive", orders 4..16; "MPE-adaptive-max:P", orders 4..P: see "order control" below, run_oc).
//
// The embedded pair is free: the products without the one of largest k make a method of order 2n - 2 from the
// same force evaluations, and the error estimate is T_2n - T_{2n-2} = sum_{i != ref} d_i (T_i - T_ref), d = c - chat
// (engines/adaptive_mpe_coefficients.hpp). The products of a step run in lockstep, in increment form, unrolled for
// fixed-size states (engines/adaptive_mpe_kernels.hpp).
//
// API (the same as engines/adaptive_rkn.hpp; AdaptiveOptions, AdaptiveStats and the exceptions of
// engines/step_control.hpp):
//
//   nystrom::AdaptiveOptions opt;  opt.rtol = 1e-12;
//   auto ai = nystrom::make_adaptive_mpe_integrator<V>(def, force, opt);  // def: an MPE method (MpeDef)
//   nystrom::AdaptiveStats st = ai.integrate_to(state, t0, t1 [, observer]);
//
// The controller is the one both adaptive engines share (engines/step_control.hpp): mixed norm
// sqrt((1/2n) sum (e_i / sc_i)^2) with sc_i = rtol (1 + max(|y_i(t)|, |y_i(t+h)|)) (or atol + rtol max(...) with
// opt.atol); accept when <= 1; h *= min(fac_max, max(fac_min, safety err^(-1/(p+1)))), p = 2n - 2, or Gustafsson's
// predictive ratio when smaller (the default, adaptive_detail::StepController); no growth right after a rejection;
// Hairer's starting step unless opt.h0 > 0; the last step lands exactly on t1; exact force counting (rejected steps
// and the starting-step estimate included).
// There is no PI term: on Kepler e = 0.9 with M12, a PI controller with the usual beta drives the error far below the
// tolerance, which only rescales tol. The predictive ratio matters on Kepler e = 0.9, where the optimal step falls by
// ~30% per step towards pericentre, faster than the standard ratio follows: with the standard ratio M14-adaptive
// rejects 500-700 steps per 3000 accepted, with the predictive one 0-100, and the same final error costs 25-35% less
// time.
//
// Compensated summation (EngineOptions::compensated, on by default in double) adds the accepted
// increments to the state with the carry of the whole run (kept between calls that continue a run);
// off, they are added plainly.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "nystrom/core/eft.hpp"
#include "nystrom/core/state.hpp"
#include "nystrom/engines/adaptive_mpe_coefficients.hpp"
#include "nystrom/engines/adaptive_mpe_kernels.hpp"
#include "nystrom/engines/integrator.hpp"  // mpe_coefficients_as, shared_method_data_for
#include "nystrom/engines/splitting.hpp"
#include "nystrom/engines/step_control.hpp"
#include "nystrom/methods/method.hpp"

namespace nystrom {

namespace adaptive_detail {

/// The next number of products of order control and its step ratio (HNW I, eqs (9.25)-(9.28), with the orders
/// of the products in place of the columns): after a step whose solution took j products, with the step ratios
/// fj of order 2j and fl of order 2j - 2 (NaN when there is no estimate of the lower order) and the work per step
/// work[n] = A_n, the work per unit step is W = A / ratio; the choice is j - 1 (ratio fl) when W_{j-1} < 0.7 W_j,
/// else, after an accepted step that did not follow a rejection and below the largest number nmax, j + 1 with the
/// ratio fj A_{j+1} / A_j (at most fac_max) when W_j < W_{j-1}, or when there is no lower estimate and fj is at
/// fac_max; else j (ratio fj).
struct ProductsChoice {
  int next;
  double fac;
};
inline ProductsChoice choose_products(int j, double fj, double fl, const std::vector<double>& work, int nmax,
                                      bool accepted, bool after_rejection, double fac_max) {
  const bool may_grow = accepted && !after_rejection && j < nmax;
  if (!std::isnan(fl)) {
    const double wj = work[static_cast<std::size_t>(j)] / fj, wl = work[static_cast<std::size_t>(j - 1)] / fl;
    if (wl < 0.7 * wj) return {j - 1, fl};
    if (may_grow && wj < wl)
      return {j + 1, std::min(fac_max, fj * work[static_cast<std::size_t>(j + 1)] / work[static_cast<std::size_t>(j)])};
    return {j, fj};
  }
  if (may_grow && fj >= fac_max) return {j + 1, fj};
  return {j, fj};
}

}  // namespace adaptive_detail

template <class V, class Force>
class AdaptiveMpeIntegrator : private adaptive_detail::MpeKernels<V, Force> {
 public:
  using vector_type = V;
  using scalar_type = typename V::value_type;
  using real_type = scalar_type;
  static_assert(!is_complex_v<scalar_type>, "adaptive step control needs a real scalar type");

  /// k: the sequence (>= 2 members); c: its coefficients (order 2n) and d = c - chat (the error
  /// combination), in the working type; base: the symmetric second-order T_2.
  /// orders: empty for one order per run; else order control over the prefixes of the natural sequence k =
  /// 1..N (see MpeOrderTables).
  AdaptiveMpeIntegrator(std::vector<long> k, std::vector<scalar_type> c, std::vector<scalar_type> d,
                        SplittingScheme<scalar_type> base, Force force, AdaptiveOptions opt = {},
                        EngineOptions eopt = {}, MpeOrderTables<scalar_type> orders = {})
      : adaptive_detail::MpeKernels<V, Force>(std::move(k), std::move(c), std::move(d), std::move(base),
                                              std::move(force)),
        opt_(opt),
        eopt_(eopt) {
    opt_.validate();
    validate_mpe_sequence(k_);
    if (k_.size() < 2)
      throw std::invalid_argument("an adaptive MPE needs at least two products (the error estimate drops one)");
    if (c_.size() != k_.size() || d_.size() != k_.size())
      throw std::invalid_argument("adaptive MPE: one coefficient and one error weight per sequence member are needed");
    for (std::size_t i = 0; i < k_.size(); ++i)
      if (!is_finite_scalar(c_[i]) || !is_finite_scalar(d_[i]))
        throw std::invalid_argument("adaptive MPE: coefficient is not finite");
    compensated_ = use_compensation<scalar_type>(eopt_.compensated);
    carried_ = Kernels::carried_force && compensated_;
    // With a compensated force the tolerance may go down to eps / 2, as for the adaptive RKN pairs (the refusal
    // says so where such a force would be taken: one order per run, double or float, compensated).
    const bool could = word_scalar<scalar_type> && compensated_ && !carried_ && orders.c.empty();
    adaptive_detail::check_tolerance<real_type>(opt_, carried_, could);
    if (eopt_.mpe_schedule == MpeSchedule::concurrent)
      throw std::invalid_argument(
          "adaptive MPE: the concurrent schedule is not available (use lockstep or sequential)");
    // The round-off of the error estimate sum d_i (D_i - D_ref) is at most about eps sum |d_i| times the
    // increment; the controller aims at err = safety^(p+1) (0.2 for M16), so a floor 10 times that level keeps
    // the estimate's noise below the aim: at tolerances near eps the step then stops shrinking where the
    // estimate reaches its round-off. Kepler e = 0.5, 100 periods, M16-adaptive at tol 3.2e-15: 5742 steps and
    // a final position error of 6e-11 without the floor, 2031 steps and 9e-11 with it (e = 0.9: 9314 and 1.3e-10,
    // 4512 and 5e-11).
    double dsum = 0;
    for (const auto& di : d_) dsum += std::abs(as_double(di));
    // With a compensated force (trial_carried) the products are double-words and the estimate's round-off is about
    // eps times smaller.
    noise_floor_ = real_type(10 * dsum * as_double(epsilon_of<real_type>()));
    if (carried_) noise_floor_ = real_type(noise_floor_ * epsilon_of<real_type>());
    method_order_ = 2 * static_cast<int>(k_.size());
    if (opt_.error_order == 0) opt_.error_order = method_order_ - 2;
    this->setup(eopt_.mpe_schedule);
    if (!orders.c.empty()) {
      if (carried_)
        throw std::invalid_argument(
            "adaptive MPE: order control calls force(q, a); run it with a plain force (or one order per run)");
      setup_order_control(std::move(orders));
    }
  }

  const AdaptiveOptions& options() const { return opt_; }
  int error_order() const { return opt_.error_order; }
  int method_order() const { return method_order_; }
  bool lockstep() const { return lockstep_; }
  bool compensated() const { return compensated_; }
  /// Whether the products take the force's rounding: a compensated run in double or float with a compensated force,
  /// force(q, cq, a, alo) (trial_carried, engines/adaptive_mpe_kernels.hpp), at every tolerance.
  bool carried() const { return carried_; }
  /// Whether the products carry their own rounding (precise products, engines/adaptive_mpe_kernels.hpp): every run
  /// with a compensated force (carried()); else a compensated run of a built-in floating type on a symmetric base
  /// whose controlled tolerance (tol, or atol when tol is 0, through the method's calibration) is at most
  /// kPreciseProducts eps, where the increments' rounding, not truncation, sets the error.
  bool precise_products() const {
    if (carried_) return true;
    if (!Kernels::can_be_precise || !compensated_ || !merged_) return false;
    const double tol = opt_.rtol > 0 ? opt_.rtol : opt_.atol;
    const double tc = adaptive_detail::controlled_tolerance(tol, opt_.tolerance_exponent, opt_.tolerance_anchor);
    return tc <= kPreciseProducts * as_double(epsilon_of<real_type>());
  }
  /// The largest controlled tolerance, in units of eps, at which the products are precise (1e4: 2.2e-12 in double,
  /// a user tolerance of 9e-12 and below for M12-adaptive, whose calibration exponent is 11/13).
  static constexpr double kPreciseProducts = 1e4;
  const std::vector<long>& sequence() const { return k_; }
  const AdaptiveStats& total() const { return total_; }
  /// Order control: the largest number of products per step (0: one order per run).
  int max_products() const { return nmax_; }
  /// Order control: the accepted steps of all calls so far by the order of the solution they propagated
  /// (index: the order 2n; size 2N + 1). Empty for one order per run.
  const std::vector<long>& order_histogram() const { return hist_; }
  /// Order control: the products of the first step of a run, from the tolerance by ODEX's rule for the first
  /// order (HNW I, sec. II.9): floor(-0.6 log10(tol) + 1.5), at least min(3, N) and at most N (tol: rtol, or
  /// atol when rtol is 0). 0 for one order per run.
  int initial_products() const {
    if (nmax_ == 0) return 0;
    const double tol = opt_.rtol > 0 ? opt_.rtol : opt_.atol;
    const int n = static_cast<int>(-0.6 * std::log10(tol) + 1.5);
    return std::max(nmin_target(), std::min(nmax_, n));
  }
  /// Order control: steps rejected after the products of order 2n - 2 alone, before the last pair of the
  /// longest product (their estimate was not finite: the force returned NaN or inf).
  long early_rejections() const { return early_rejected_; }
  Force& force() { return base_.force(); }
  /// Force evaluations of all calls so far (the starting-step estimates included).
  long force_evals() const { return base_.force_evals() + extra_evals_ + own_evals_; }

  /// One trial step of size h from s, s unchanged: inc = T_2n(h) s - s and the error estimate err
  /// (T_2n - T_{2n-2}). For tests of the estimate's order; counts its force evaluations.
  void trial_step(const State<V>& s, real_type h, State<V>& inc, State<V>& err) {
    validate_state(s);
    scale(h);
    resize_buffers(s);
    resize_like(a0_, s.q);
    if (kick_first_) {
      base_.force()(s.q, a0_);
      ++extra_evals_;
    }
    State<V> low = s;  // the increment's low part: unused, the products of a trial step are plain
    if (compensated_)
      this->template trial<true, false>(k_.size(), s, a0_, xs_, as_, cqs_, cvs_, inc, err, low);
    else
      this->template trial<false, false>(k_.size(), s, a0_, xs_, as_, cqs_, cvs_, inc, err, low);
  }

  template <class Observer = adaptive_detail::NoObserver>
  AdaptiveStats integrate_to(State<V>& s, real_type t0, real_type t1, Observer&& obs = {}) {
    using std::isfinite;
    if (!isfinite(t0) || !isfinite(t1)) throw std::invalid_argument("integration times must be finite");
    if (t1 < t0) throw std::invalid_argument("end time t1 must not be before the start time t0");
    validate_state(s);
    if (compensated_) return dispatch<true>(s, t0, t1, obs);
    return dispatch<false>(s, t0, t1, obs);
  }

  /// Forget the step carried over between calls (the next call estimates a first step again).
  void reset() {
    h_next_ = real_type(0);
    n_next_ = 0;
    comp_.invalidate();
    resume_.valid = false;
  }
  /// Where the last run stopped at its observer's request (AdaptiveResumePoint, adaptive_rkn.hpp).
  const AdaptiveResumePoint<real_type>& resume_point() const { return resume_; }
  void set_resume_point(const AdaptiveResumePoint<real_type>& p) {
    p.check();
    resume_ = p;
  }
  /// The compensated-summation carries of the run (checkpoint/restart).
  Compensator<V>& compensator() { return comp_; }

 private:
  using Kernels = adaptive_detail::MpeKernels<V, Force>;
  using Kernels::as_;
  using Kernels::base_;
  using Kernels::c_;
  using Kernels::can_be_precise;
  using Kernels::cqs_;
  using Kernels::cvs_;
  using Kernels::d_;
  using Kernels::fixed_lockstep;
  using Kernels::k_;
  using Kernels::kick_first_;
  using Kernels::lockstep_;
  using Kernels::m_;
  using Kernels::merged_;
  using Kernels::oc_combine;
  using Kernels::oc_dispatch;
  using Kernels::occ_;
  using Kernels::ocd_;
  using Kernels::own_evals_;
  using Kernels::resize_buffers;
  using Kernels::scale;
  using Kernels::xs_;

  // s += inc: with Comp, through the run's carries (ccq, ccv); with precise products the increment is the
  // double-word inc + low, added by an exact two-sum (eft::add_double_word; the built-in floating types only,
  // other types never run precise products).
  template <bool Comp>
  NYSTROM_ALWAYS_INLINE static void apply_increment(State<V>& s, V& ccq, V& ccv, const State<V>& inc,
                                                    [[maybe_unused]] const State<V>& low,
                                                    [[maybe_unused]] bool precise) {
    for (std::size_t j = 0; j < s.q.size(); ++j) {
      if constexpr (Comp) {
        if constexpr (can_be_precise) {
          if (precise) {
            eft::add_double_word(s.q[j], ccq[j], inc.q[j], low.q[j]);
            eft::add_double_word(s.v[j], ccv[j], inc.v[j], low.v[j]);
            continue;
          }
        }
        compensated_add(s.q[j], ccq[j], inc.q[j]);
        compensated_add(s.v[j], ccv[j], inc.v[j]);
      } else {
        s.q[j] += inc.q[j];
        s.v[j] += inc.v[j];
      }
    }
  }

  template <bool Comp, class Observer>
  AdaptiveStats dispatch(State<V>& s, real_type t0, real_type t1, Observer& obs) {
    if (nmax_ > 0) return run_oc<Comp>(s, t0, t1, obs);
    if constexpr (fixed_lockstep) {
      if (lockstep_) {
        switch (k_.size()) {
          case 2: return run<Comp, 2>(s, t0, t1, obs);
          case 3: return run<Comp, 3>(s, t0, t1, obs);
          case 4: return run<Comp, 4>(s, t0, t1, obs);
          case 5: return run<Comp, 5>(s, t0, t1, obs);
          case 6: return run<Comp, 6>(s, t0, t1, obs);
          case 7: return run<Comp, 7>(s, t0, t1, obs);
          case 8: return run<Comp, 8>(s, t0, t1, obs);
          default: break;
        }
      }
    }
    return run<Comp, 0>(s, t0, t1, obs);
  }

  // Writes the state and carries a controller keeps in locals back (also before an exception: the last accepted
  // step), the forces at q_0 it counted (a0_evals) into extra_evals_, and the counts of the call into st.
  template <bool Comp, class St, class Carry>
  void store_call(State<V>& s_io, const St& s, const Carry& ccq, const Carry& ccv, long& a0_evals, long accepted,
                  long rejected, double last_h, long evals_before, AdaptiveStats& st) {
    if (&s != &s_io) s_io = s;
    if (&ccq != &comp_.cq) {
      comp_.cq = ccq;
      comp_.cv = ccv;
    }
    if (Comp) comp_.end(s_io);
    extra_evals_ += a0_evals;
    a0_evals = 0;
    st.accepted = accepted;
    st.rejected = rejected;
    st.last_h = last_h;
    st.force_evals = force_evals() - evals_before;
  }

  // Hairer's starting step from s for a controller of the given order (StepSequence), its forces counted.
  auto starting_step(const State<V>& s, const adaptive_detail::ErrorScale<real_type>& err_scale, int order) {
    return [this, &s, &err_scale, order](const real_type& hmax) {
      long calls = 0;
      auto counted = [&](const V& q, V& a) {
        ++calls;
        base_.force()(q, a);
      };
      const real_type h = adaptive_detail::hairer_initial_step<V>(counted, s, hmax, err_scale, order);
      extra_evals_ += calls;
      return h;
    };
  }

  // The controller loop; K > 0: K products in local arrays (fixed-size states in lockstep), K = 0:
  // the member buffers and a run-time product count.
  template <bool Comp, std::size_t K, class Observer>
  AdaptiveStats run(State<V>& s_io, real_type t0, real_type t1, Observer& obs) {
    AdaptiveStats st;
    const long evals_before = force_evals();
    obs(static_cast<const real_type&>(t0), static_cast<const State<V>&>(s_io));
    if (t1 == t0) return st;

    const adaptive_detail::ErrorScale<real_type> err_scale(opt_);
    adaptive_detail::StepSequence<real_type> seq(opt_, resume_, h_next_, t0, t1,
                                                 starting_step(s_io, err_scale, method_order_));

    // Exponents on the squared norm: err^(-1/(p+1)) = (err^2)^(-1/(2(p+1))).
    const double p1 = opt_.error_order + 1;
    const double expo = -0.5 / p1;
    real_type t = t0, h;
    bool error_finite = true;  // the last error estimate was finite (else the force returned NaN or inf)

    constexpr bool local = K > 0;
    std::conditional_t<local, State<V>, State<V>&> s = s_io;
    State<V> inc = s_io, err = s_io, low = s_io;  // low: the low part of inc (precise products)
    const bool precise = Comp && precise_products();
    const bool carried = Comp && carried_;  // the products with a compensated force (trial_carried)
    if (!local) resize_buffers(s_io);
    if (Comp) comp_.begin(s_io);
    std::conditional_t<local, V, V&> ccq = comp_.cq, ccv = comp_.cv;
    std::conditional_t<local, V, V&> a0 = a0_;
    resize_like(a0, s_io.q);
    bool a0_valid = false;  // the force at s.q is in a0 (kick-first bases; kept across a rejection)
    long a0_evals = 0;
    // Local arrays of the products (K > 0); unused otherwise.
    std::array<State<V>, K> lx;
    std::array<V, K> la{}, lcq, lcv;
    long accepted = 0, rejected = 0;
    double last_h = 0;
    const bool verlet = merged_ && m_ == 3;  // trial_verlet applies (local arrays, K products)
    // Writes the local state and carries back (also before an exception: the last accepted step).
    auto store = [&] { store_call<Comp>(s_io, s, ccq, ccv, a0_evals, accepted, rejected, last_h, evals_before, st); };

    while (t < t1) {
      if (accepted + rejected >= opt_.max_steps) {
        store();
        adaptive_detail::throw_too_many_steps("adaptive MPE", opt_.max_steps, as_double(t), as_double(t1));
      }
      // A step whose end time is exactly representable: the time reached is then the sum of the
      // steps taken, not its rounding (over 10^4 steps to t = 600 that rounding, ~1e-11 in time,
      // would be the round-off floor of the position error on Kepler).
      bool last;
      if (!seq.template next<true>(t, h, last)) {
        store();
        adaptive_detail::throw_underflow("adaptive MPE", as_double(t), as_double(h), error_finite);
      }
      if constexpr (Comp && Kernels::carried_force)
        if (carried) a0_evals += this->trial_carried(s, ccq, ccv, h, inc, err, low);
      if (!carried && !(local && verlet)) scale(h);
      if (!carried && kick_first_ && !a0_valid) {
        base_.force()(s.q, a0);
        ++a0_evals;
        a0_valid = true;
      }
      if (!carried)
        Kernels::template with_precision<Comp>(precise, [&](auto pr) NYSTROM_ALWAYS_INLINE {
          constexpr bool P = decltype(pr)::value;
          if constexpr (local) {
            if (verlet)
              own_evals_ += this->template trial_verlet<K, P>(s, a0, h, inc, err, low);
            else
              this->template trial<Comp, P>(std::integral_constant<std::size_t, K>{}, s, a0, lx, la, lcq, lcv, inc, err,
                                            low);
          } else {
            this->template trial<Comp, P>(k_.size(), s, a0, xs_, as_, cqs_, cvs_, inc, err, low);
          }
        });
      const double e2 = adaptive_detail::error_norm2(s, inc, err, err_scale, noise_floor_);
      error_finite = e2 < std::numeric_limits<double>::infinity();
      if (e2 <= 1.0) {
        apply_increment<Comp>(s, ccq, ccv, inc, low, precise);
        a0_valid = false;
        t = last ? t1 : t + h;
        ++accepted;
        last_h = as_double(h);
        const bool stop =
            adaptive_detail::observe(obs, static_cast<const real_type&>(t), static_cast<const State<V>&>(s));
        seq.accepted(std::pow(e2, expo), h, last, h_next_);
        if (stop && t < t1) {
          resume_ = seq.resume_point(t);
          break;
        }
      } else {
        ++rejected;
        seq.rejected(std::pow(e2, expo), h);
      }
    }
    store();
    total_ += st;
    return st;
  }

  // ---- order control ------------------------------------------------------------------------------------
  //
  // The natural sequence k = 1..N on a Verlet base (HNW I, sec. II.9, ODEX, carried over from the GBS columns to
  // the products): a step of target n runs the products k = 1..n in lockstep, the longest first in every
  // sub-step, so that products 1..n-1 are complete one pair before product n. Then the convergence monitor:
  //   * err_{n-1}, the estimate of T_{2n-2} - T_{2n-4} (products 1..n-1, free), <= 1 and n - 1 >= 3: the step is
  //     accepted with T_{2n-2}, without the last force(s) of product n (with n - 1 = 2 product n completes, and
  //     T_4 is taken only when T_6 fails);
  //   * err_{n-1} not finite (the force returned NaN or inf): the step is rejected at once;
  //   * else product n completes, and the step is accepted with T_2n when err_n <= 1.
  // Then order and step: H_j = h * ratio_j (the step ratio of order j by the controller of the fixed-order
  // engine, adaptive_detail::StepController, one per order, Gustafsson's predictive ratio included) for the
  // order j of the solution taken and j - 1, the work per unit step W_j = A_j / H_j, and the next target is
  // j - 1 when W_{j-1} < 0.7 W_j, else j + 1 with step H_j A_{j+1} / A_j when W_j < W_{j-1} and the step was
  // accepted (HNW I, eqs (9.25)-(9.28) with the orders of the products in place of the columns), else j.
  // A_n = n + 3: the time of a lockstep step of n products is set by its chain of n forces, not by its
  // n(n+1)/2 forces (measured on Kepler e = 0.9, fixed-order steps of 4..8 products: about (n + 2.7) x 26 ns);
  // with A_n = n(n+1)/2, as ODEX counts, the controller chose orders 8-12 where M14/M16 are faster. The factors
  // 0.7 and 1.0 instead of ODEX's 0.8 and 0.9: fewer order changes (tol 1e-9, e = 0.9: 0.99 ms with 0.8 and 0.9,
  // 0.82 ms with 0.7 and 1.0, at a final error of 7e-6 and 1.2e-5).
  // ODEX's early rejection of a hopeless step (err_n predicted from err_{n-1} and the last ratio err_n /
  // err_{n-1}) rejected steps that would have passed: at tol 1e-12, e = 0.9, rejections 201 -> 529 and 18%
  // more time; it saves one pair of one product, so it is left out. A target of two products has no lower
  // estimate; it moves up when its step ratio is at fac_max. The error scale, its noise floor (per n), the exact ends,
  // the compensated increments and the force counts are those of the fixed-order engine.

  void setup_order_control(MpeOrderTables<scalar_type> orders) {
    const std::size_t N = k_.size();
    if (N > 8) throw std::invalid_argument("adaptive MPE order control: at most 8 products (order 16)");
    for (std::size_t i = 0; i < N; ++i)
      if (k_[i] != static_cast<long>(i) + 1)
        throw std::invalid_argument("adaptive MPE order control runs the natural sequence 1, 2, ..., N only");
    if (!merged_ || m_ != 3)
      throw std::invalid_argument("adaptive MPE order control needs a Verlet base (three merged sub-steps)");
    if (orders.c.size() != N + 1 || orders.d.size() != N + 1)
      throw std::invalid_argument("adaptive MPE order control: one coefficient table per product count is needed");
    for (std::size_t n = 2; n <= N; ++n) {
      if (orders.c[n].size() != n || orders.d[n].size() != n)
        throw std::invalid_argument("adaptive MPE order control: a table has the wrong length");
      for (std::size_t i = 0; i < n; ++i)
        if (!is_finite_scalar(orders.c[n][i]) || !is_finite_scalar(orders.d[n][i]))
          throw std::invalid_argument("adaptive MPE: coefficient is not finite");
    }
    nmax_ = static_cast<int>(N);
    occ_ = std::move(orders.c);
    ocd_ = std::move(orders.d);
    ocnoise_.assign(N + 1, real_type(0));
    work_.assign(N + 2, 0.0);
    hist_.assign(2 * N + 1, 0);
    for (std::size_t n = 2; n <= N; ++n) {
      double dsum = 0;
      for (const auto& di : ocd_[n]) dsum += std::abs(as_double(di));
      ocnoise_[static_cast<std::size_t>(n)] = real_type(10 * dsum * as_double(epsilon_of<real_type>()));
    }
    for (std::size_t n = 1; n <= N + 1; ++n) work_[n] = static_cast<double>(n) + 3;
  }

  // The smallest target: three products (which always complete: a step taken with two products, whose order 4
  // has no lower estimate to weigh against, could not raise the order again), so that every step has the
  // estimates of two orders to choose from; two when that is the largest.
  int nmin_target() const { return std::min(3, nmax_); }

  template <bool Comp, class Observer>
  AdaptiveStats run_oc(State<V>& s_io, real_type t0, real_type t1, Observer& obs) {
    AdaptiveStats st;
    const long evals_before = force_evals();
    obs(static_cast<const real_type&>(t0), static_cast<const State<V>&>(s_io));
    if (t1 == t0) return st;

    const adaptive_detail::ErrorScale<real_type> err_scale(opt_);
    int nt = n_next_ > 0 ? n_next_ : initial_products();  // the target number of products
    adaptive_detail::StepSequence<real_type> seq(opt_, resume_, h_next_, t0, t1,
                                                 starting_step(s_io, err_scale, 2 * nt));
    std::vector<adaptive_detail::StepController> ctl(static_cast<std::size_t>(nmax_) + 1,
                                                     adaptive_detail::StepController(opt_));

    real_type t = t0, h;
    bool error_finite = true;
    constexpr bool local = fixed_lockstep;
    std::conditional_t<local, State<V>, State<V>&> s = s_io;
    State<V> inc = s_io, err = s_io, inc_lo = s_io, err_lo = s_io, low = s_io, low_lo = s_io;
    const bool precise = Comp && precise_products();
    if (!local) resize_buffers(s_io);
    if (Comp) comp_.begin(s_io);
    std::conditional_t<local, V, V&> ccq = comp_.cq, ccv = comp_.cv;
    std::conditional_t<local, V, V&> a0 = a0_;
    resize_like(a0, s_io.q);
    bool a0_valid = false;
    long a0_evals = 0;
    long accepted = 0, rejected = 0;
    double last_h = 0;
    auto store = [&] {
      store_call<Comp>(s_io, s, ccq, ccv, a0_evals, accepted, rejected, last_h, evals_before, st);
      n_next_ = nt;
    };
    // q_j = err_j^(-1/(2j - 1)) from the squared norm (the estimate of order 2j is O(h^(2j-1))).
    auto qof = [](double e2, int j) { return std::pow(e2, -0.5 / (2 * j - 1)); };

    while (t < t1) {
      if (accepted + rejected >= opt_.max_steps) {
        store();
        adaptive_detail::throw_too_many_steps("adaptive MPE", opt_.max_steps, as_double(t), as_double(t1));
      }
      bool last;
      if (!seq.template next<true>(t, h, last)) {
        store();
        adaptive_detail::throw_underflow("adaptive MPE", as_double(t), as_double(h), error_finite);
      }
      if (kick_first_ && !a0_valid) {
        base_.force()(s.q, a0);
        ++a0_evals;
        a0_valid = true;
      }
      const int n = nt;
      const double hd = as_double(h);
      double e2_lo = std::numeric_limits<double>::infinity(), e2 = e2_lo;
      double elo = std::numeric_limits<double>::quiet_NaN();  // the estimate of order j - 1 (below)
      int taken = 0;                                          // the products of the solution taken (0: rejected)
      bool early_reject = false;
      auto check = [&](const auto& x) -> bool {
        if (n - 1 < 2) return true;
        this->template oc_combine<std::remove_cvref_t<decltype(x)>::precise>(static_cast<std::size_t>(n - 1), x, inc_lo,
                                                                             err_lo, low_lo);
        e2_lo = adaptive_detail::error_norm2(s, inc_lo, err_lo, err_scale, ocnoise_[static_cast<std::size_t>(n - 1)]);
        // Two products (order 4) have no lower estimate to weigh against: a step taken there could never raise the
        // order again (its step ratio is about 1 in a steady run, never fac_max), so the step completes product n.
        if (e2_lo <= 1.0 && n - 1 >= 3) {
          taken = n - 1;
          return false;
        }
        if (!std::isfinite(e2_lo)) {  // the force returned NaN or inf: product n cannot help
          early_reject = true;
          return false;
        }
        return true;
      };
      auto done = [&](const auto& x) {
        if (taken == 0 && !early_reject) {
          this->template oc_combine<std::remove_cvref_t<decltype(x)>::precise>(static_cast<std::size_t>(n), x, inc, err,
                                                                               low);
          e2 = adaptive_detail::error_norm2(s, inc, err, err_scale, ocnoise_[static_cast<std::size_t>(n)]);
          if (e2 <= 1.0) taken = n;
          if (n - 1 >= 2) elo = e2_lo;
          if (!taken && n - 1 == 2 && e2_lo <= 1.0) taken = n - 1;  // order 6 failed where order 4 passed
        } else if (n - 2 >= 2) {  // stopped after products 1..n-1: the estimate of order 2n - 4 as well
          this->template oc_combine<std::remove_cvref_t<decltype(x)>::precise>(static_cast<std::size_t>(n - 2), x, inc,
                                                                               err, low);
          elo = adaptive_detail::error_norm2(s, inc, err, err_scale, ocnoise_[static_cast<std::size_t>(n - 2)]);
        }
      };
      own_evals_ += Kernels::template with_precision<Comp>(precise, [&](auto pr) NYSTROM_ALWAYS_INLINE {
        return this->template oc_dispatch<decltype(pr)::value>(n, s, a0, h, check, done);
      });
      // j: the highest order estimated (the one taken, or the last one computed); elo that of j - 1.
      const int j = (taken == n - 1 || early_reject) ? n - 1 : n;
      const double ej = j == n ? e2 : e2_lo;
      error_finite = std::isfinite(ej);
      const State<V>& inc_taken = taken == n ? inc : inc_lo;
      const State<V>& low_taken = taken == n ? low : low_lo;
      if (taken) {
        apply_increment<Comp>(s, ccq, ccv, inc_taken, low_taken, precise);
        a0_valid = false;
        t = last ? t1 : t + h;
        ++accepted;
        ++hist_[static_cast<std::size_t>(2 * taken)];
        last_h = hd;
        const bool stop =
            adaptive_detail::observe(obs, static_cast<const real_type&>(t), static_cast<const State<V>&>(s));
        const bool after_rej = seq.after_rejection();
        for (int i = 2; i <= nmax_; ++i)
          if (i != j && i != j - 1) ctl[static_cast<std::size_t>(i)].restore(0, 0);
        const double fj = ctl[static_cast<std::size_t>(j)].accepted(qof(ej, j), hd, after_rej);
        const double fl = j - 1 >= 2 ? ctl[static_cast<std::size_t>(j - 1)].accepted(qof(elo, j - 1), hd, after_rej)
                                     : std::numeric_limits<double>::quiet_NaN();
        const auto choice = adaptive_detail::choose_products(j, fj, fl, work_, nmax_, true, after_rej, opt_.fac_max);
        nt = std::max(nmin_target(), choice.next);
        seq.accepted_ratio(choice.fac, h, last, h_next_);
        if (stop && t < t1) {
          resume_ = seq.resume_point(t);
          break;
        }
      } else {
        ++rejected;
        if (early_reject) ++early_rejected_;
        const double fj = ctl[static_cast<std::size_t>(j)].rejected(qof(ej, j));
        const double fl = j - 1 >= 2 && std::isfinite(elo)
                              ? ctl[static_cast<std::size_t>(j - 1)].rejected(qof(elo, j - 1))
                              : std::numeric_limits<double>::quiet_NaN();
        const auto choice = adaptive_detail::choose_products(j, fj, fl, work_, nmax_, false, true, opt_.fac_max);
        nt = std::max(nmin_target(), choice.next);
        seq.rejected_ratio(choice.fac, h);
      }
    }
    store();
    total_ += st;
    return st;
  }

  AdaptiveOptions opt_;
  EngineOptions eopt_;
  bool compensated_ = false;
  int method_order_ = 0;
  bool carried_ = false;     // the products take the force's rounding (carried())
  real_type noise_floor_{};  // the error scale's floor, relative to the increment (see the constructor)
  long extra_evals_ = 0;     // forces outside the base's count: starting steps, forces at q_0
  real_type h_next_ = real_type(0);
  AdaptiveResumePoint<real_type> resume_;
  AdaptiveStats total_;
  Compensator<V> comp_;
  V a0_{};
  // Order control (setup_order_control); indexed by the number of products n (0 and 1 unused). The coefficients
  // of each n are the kernels' (occ_, ocd_).
  int nmax_ = 0;                    // 0: one order per run
  int n_next_ = 0;                  // the products of the next step (carried between calls)
  std::vector<real_type> ocnoise_;  // the error scale's floor of each n (see the constructor)
  std::vector<double> work_;        // A_n: the cost of a step of n products (in forces)
  std::vector<long> hist_;          // accepted steps by order 2n
  long early_rejected_ = 0;
};

/// Builds an adaptive MPE for a multi-product method (MpeDef: "M10", "M10-adaptive", "mpe:1,2,3",
/// "mpe-adaptive:1,2,3,4", "mpe-vv-adaptive:1,2,3") for state type V. Coefficients: exact rationals
/// converted to the working type once.
template <class V, class F>
AdaptiveMpeIntegrator<V, F> make_adaptive_mpe_integrator(const MethodDef& def, F force, AdaptiveOptions opt = {},
                                                         EngineOptions eopt = {}) {
  using S = typename V::value_type;
  opt.validate();
  if (opt.tolerance_exponent == 0) opt.tolerance_exponent = def.info.tolerance_exponent;
  if (opt.tolerance_anchor == 0) opt.tolerance_anchor = def.info.tolerance_anchor;
  const auto data = shared_method_data_for(def, scalar_traits<S>::bits(), scalar_traits<S>::name());
  const auto* m = std::get_if<MpeDef>(data.get());
  if (!m) throw std::invalid_argument("method '" + def.info.name + "' is not a multi-product method");
  const AdaptiveMpeCoefficients ac = adaptive_mpe_coefficients(m->k);
  auto conv = [](const bigcomplex& x) { return to_scalar<S>(x); };
  MpeOrderTables<S> orders;
  if (m->order_control) orders = mpe_order_tables<S>(m->k);
  return AdaptiveMpeIntegrator<V, F>(m->k, mpe_coefficients_as<S>(ac.high), mpe_coefficients_as<S>(ac.error()),
                                     convert_scheme<S>(m->base, conv), std::move(force), opt, eopt, std::move(orders));
}

}  // namespace nystrom