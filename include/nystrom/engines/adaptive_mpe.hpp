// Step-size control for the multi-product expansion (catalog specs "M10-adaptive",
// "mpe-adaptive:1,2,3,4,5", "mpe-vv-adaptive:1,2,3"), and order and step control over the natural sequence
// ("MPE-adaptive", orders 4..16; "MPE-adaptive-max:P", orders 4..P: see "order control" below, run_oc).
//
// The MPE T_2n(h) = sum_i c_i T_2^{k_i}(h / k_i) (Chin eq 14; engines/mpe.hpp) is Richardson
// extrapolation in h^2 of a symmetric second-order base. Dropping the product of largest k leaves
// n - 1 products whose own exact coefficients chat_i (the same formula on the shorter sequence) make
// a method of order 2n - 2 from the same force evaluations: the embedded pair is free. The error
// estimate is
//
//   err = T_2n - T_{2n-2} = sum_i (c_i - chat_i) T_i = sum_{i != ref} d_i (T_i - T_ref),  d = c - chat,
//
// (sum d_i = 0; ref the product of largest k), of order h^{2n-1}; the higher-order solution is
// propagated (local extrapolation), as in the adaptive RKN engine.
//
// API (the same as engines/adaptive_rkn.hpp, whose AdaptiveOptions/AdaptiveStats/exceptions it uses):
//
//   nystrom::AdaptiveOptions opt;  opt.tol = 1e-12;
//   auto ai = nystrom::make_adaptive_mpe_integrator<V>(def, force, opt);  // def: an MPE method (MpeDef)
//   nystrom::AdaptiveStats st = ai.integrate_to(state, t0, t1 [, observer]);
//
// The controller is that of AdaptiveRknIntegrator: mixed norm sqrt((1/2n) sum (e_i / sc_i)^2) with
// sc_i = tol (1 + max(|y_i(t)|, |y_i(t+h)|)) (or atol + tol max(...) with opt.atol); accept when <= 1; h *=
// min(fac_max, max(fac_min, safety err^(-1/(p+1)))), p = 2n - 2, or Gustafsson's predictive ratio when smaller (the
// default, adaptive_detail::StepController); no growth right after a rejection; Hairer's starting step unless opt.h0 >
// 0; the last step lands exactly on t1; exact force counting (rejected steps and the starting-step estimate included).
// There is no PI term: on Kepler e = 0.9 with M12, a PI controller with the usual beta drives the error far below the
// tolerance, which only rescales tol. The predictive ratio matters on Kepler e = 0.9, where the optimal step falls by
// ~30% per step towards pericentre, faster than the standard ratio follows: with the standard ratio M14-adaptive
// rejects 500-700 steps per 3000 accepted, with the predictive one 0-100, and the same final error costs 25-35% less
// time.
//
// Cost per step: sum k_i force evaluations (+1 for a base that starts with a kick: the force at q_0,
// shared by all products and kept across a rejected step). The products of a step run in lockstep so
// that the processor overlaps their independent force chains; for std::array states of double or
// float the whole controller loop is compiled per product count (2..8), and for the three-step
// (Verlet) bases of the catalog a step is trial_verlet: the products' increments, forces and
// coefficients in local arrays, the product of largest k issued first in every sub-step (it is the
// critical chain). An adaptive M12 step on Kepler e = 0.9 (21 forces, a chain of 6) costs 277 ns as a
// generic loop over the products, 231 ns as trial_verlet, 219 ns with the issue order too (one run; a
// fixed-step M12 step: about 145 ns, no error estimate and no step-size control on its chain). The
// sequential schedule (EngineOptions::mpe_schedule) runs the products one after the other with the
// same operations: bitwise the same results.
// The products run in increment form for every base whose steps merge (all symmetric ones): dq, dv
// from zero, forces at s.q + dq, so their rounding is that of the small increments instead of the
// state's; the combination then gets them nearly to full precision at one addition per sub-step.
// Compensated summation (EngineOptions::compensated, on by default in double) adds the accepted
// increments to the state with the carry of the whole run (kept between calls that continue a run);
// off, they are added plainly. (Bases whose steps do not merge run on the state itself, with
// compensated sub-steps when on.)
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

#include <gmpxx.h>

#include "nystrom/core/state.hpp"
#include "nystrom/engines/adaptive_rkn.hpp"
#include "nystrom/engines/integrator.hpp"  // mpe_coefficients_as, method_data_for
#include "nystrom/engines/mpe.hpp"
#include "nystrom/engines/splitting.hpp"
#include "nystrom/methods/method.hpp"

namespace nystrom {

/// The exact coefficients of an adaptive MPE: `high` (all products, order 2n), `low` (all but the
/// product of largest k, order 2n - 2) and diff_i = c_i - chat_i (chat = 0 for the dropped product).
struct AdaptiveMpeCoefficients {
  MpeCoefficients high, low;
  std::vector<mpq_class> diff;
  std::size_t dropped = 0;
};

inline AdaptiveMpeCoefficients adaptive_mpe_coefficients(const std::vector<long>& k) {
  validate_mpe_sequence(k);
  if (k.size() < 2)
    throw std::invalid_argument("an adaptive MPE needs at least two products (the error estimate drops one)");
  AdaptiveMpeCoefficients r;
  r.high = mpe_coefficients(k);
  r.dropped = static_cast<std::size_t>(std::max_element(k.begin(), k.end()) - k.begin());
  std::vector<long> kl;
  for (std::size_t i = 0; i < k.size(); ++i)
    if (i != r.dropped) kl.push_back(k[i]);
  r.low = mpe_coefficients(kl);
  r.diff.resize(k.size());
  for (std::size_t i = 0, j = 0; i < k.size(); ++i) {
    r.diff[i] = r.high.c[i];
    if (i != r.dropped) r.diff[i] -= r.low.c[j++];
    r.diff[i].canonicalize();
  }
  return r;
}

/// The coefficients of order control (AdaptiveMpeIntegrator): for each number of products n = 2..N of the
/// natural sequence k = 1..N, c[n] those of T_2n over k = 1..n and d[n] those of T_2n - T_{2n-2}; entries 0
/// and 1 empty.
template <class S>
struct MpeOrderTables {
  std::vector<std::vector<S>> c, d;
};

template <class V, class Force>
class AdaptiveMpeIntegrator {
  static std::string sci(double x) { return adaptive_detail::sci(x); }

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
      : opt_(opt),
        eopt_(eopt),
        k_(std::move(k)),
        c_(std::move(c)),
        d_(std::move(d)),
        base_(std::move(base), std::move(force), EngineOptions{true, Compensation::off}) {
    opt_.validate();
    validate_mpe_sequence(k_);
    if (k_.size() < 2)
      throw std::invalid_argument("an adaptive MPE needs at least two products (the error estimate drops one)");
    if (c_.size() != k_.size() || d_.size() != k_.size())
      throw std::invalid_argument("adaptive MPE: one coefficient and one error weight per sequence member are needed");
    for (std::size_t i = 0; i < k_.size(); ++i)
      if (!is_finite_scalar(c_[i]) || !is_finite_scalar(d_[i]))
        throw std::invalid_argument("adaptive MPE: coefficient is not finite");
    const double min_tol = 10 * as_double(epsilon_of<real_type>());
    if (opt_.tol > 0 && opt_.tol < min_tol)
      throw std::invalid_argument("tolerance " + sci(opt_.tol) + " is below what " + scalar_traits<real_type>::name() +
                                  " resolves (10 eps = " + sci(min_tol) + "); use a wider precision");
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
    noise_floor_ = real_type(10 * dsum * as_double(epsilon_of<real_type>()));
    method_order_ = 2 * static_cast<int>(k_.size());
    if (opt_.error_order == 0) opt_.error_order = method_order_ - 2;
    ref_ = static_cast<std::size_t>(std::max_element(k_.begin(), k_.end()) - k_.begin());
    kick_first_ = base_.scheme().steps.front().flow == Flow::kick;
    m_ = base_.scheme().steps.size();
    merged_ = base_.lockstep_capable();
    lockstep_ = merged_ && eopt_.mpe_schedule != MpeSchedule::sequential;
    compensated_ = use_compensation<scalar_type>(eopt_.compensated);
    scaled_.resize(k_.size() * m_);
    by_k_.resize(k_.size());
    for (std::size_t r = 0; r < k_.size(); ++r) by_k_[r] = r;
    std::sort(by_k_.begin(), by_k_.end(), [this](std::size_t x, std::size_t y) { return k_[x] > k_[y]; });
    if (!orders.c.empty()) setup_order_control(std::move(orders));
  }

  const AdaptiveOptions& options() const { return opt_; }
  int error_order() const { return opt_.error_order; }
  int method_order() const { return method_order_; }
  bool lockstep() const { return lockstep_; }
  bool compensated() const { return compensated_; }
  const std::vector<long>& sequence() const { return k_; }
  const AdaptiveStats& total() const { return total_; }
  /// Order control: the largest number of products per step (0: one order per run).
  int max_products() const { return nmax_; }
  /// Order control: the accepted steps of all calls so far by the order of the solution they propagated
  /// (index: the order 2n; size 2N + 1). Empty for one order per run.
  const std::vector<long>& order_histogram() const { return hist_; }
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
    if (compensated_)
      trial<true>(k_.size(), s, a0_, xs_, as_, cqs_, cvs_, inc, err);
    else
      trial<false>(k_.size(), s, a0_, xs_, as_, cqs_, cvs_, inc, err);
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
  // The unrolled loops are compiled for std::array states of float and double only (as in MpeStepper).
  static constexpr bool fixed_lockstep =
      is_std_array<V>::value && (std::is_same_v<scalar_type, double> || std::is_same_v<scalar_type, float>);

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

  void resize_buffers(const State<V>& s) {
    const std::size_t P = k_.size();
    xs_.resize(P);
    as_.resize(P);
    cqs_.resize(P);
    cvs_.resize(P);
    for (std::size_t r = 0; r < P; ++r) {
      resize_like(xs_[r].q, s.q);
      resize_like(xs_[r].v, s.v);
      resize_like(as_[r], s.q);
      resize_like(cqs_[r], s.q);
      resize_like(cvs_[r], s.q);
    }
  }

  // The base's coefficients times h / k_i, product after product.
  void scale(const real_type& h) {
    const auto& st = base_.scheme().steps;
    for (std::size_t i = 0; i < k_.size(); ++i) {
      const real_type hk = h / static_cast<real_type>(k_[i]);
      for (std::size_t j = 0; j < m_; ++j) scaled_[i * m_ + j] = st[j].coef * hk;
    }
  }

  // The products of one trial step from s (force a0 at s.q if the base starts with a kick), then
  // inc = the combined increment and err = the error estimate. P: a run-time count (x, a, cq, cv
  // vectors) or a std::integral_constant (local arrays, unrolled). The same operations in lockstep
  // and in sequence (advance_lockstep is bitwise advance_scaled product after product).
  template <bool Comp, class Count, class XS, class AS, class CS>
  NYSTROM_ALWAYS_INLINE void trial(Count P, const State<V>& s, const V& a0, XS& x, AS& a, CS& cq, CS& cv, State<V>& inc,
                                   State<V>& err) {
    using SS = SplittingStepper<V, Force>;
    const std::size_t n = s.q.size();
    SS::for_each_run(P, [&](std::size_t r) NYSTROM_ALWAYS_INLINE {
      if (kick_first_) assign(a[r], a0);
      if (merged_) return;  // increment form: advance_increments starts x from zero, no carries
      assign(x[r].q, s.q);
      assign(x[r].v, s.v);
      if constexpr (Comp) {
        for (auto& e : cq[r]) e = scalar_type(0);
        for (auto& e : cv[r]) e = scalar_type(0);
      }
    });
    if (merged_) {
      // The products run in increment form (x holds T_r - s, see advance_increments).
      advance_increments(P, s, x, a);
    } else if (lockstep_) {
      base_.template advance_lockstep<Comp>(P, x, a, kick_first_, scaled_.data(), k_.data(), cq, cv);
    } else {
      // One product after the other, the reference (largest k) last, as MpeStepper's sequential schedule.
      auto one = [&](std::size_t r) {
        bool valid = kick_first_;
        base_.template advance_scaled<Comp>(x[r], a[r], valid, scaled_.data() + r * m_, k_[r], cq[r], cv[r]);
      };
      for (std::size_t r = 0; r < k_.size(); ++r)
        if (r != ref_) one(r);
      one(ref_);
    }
    // Increments D_r = T_r - s (with the product's carry: to full precision).
    if (!merged_) {
      SS::for_each_run(P, [&](std::size_t r) NYSTROM_ALWAYS_INLINE {
        for (std::size_t j = 0; j < n; ++j) {
          if constexpr (Comp) {
            x[r].q[j] = (x[r].q[j] - s.q[j]) + cq[r][j];
            x[r].v[j] = (x[r].v[j] - s.v[j]) + cv[r][j];
          } else {
            x[r].q[j] = x[r].q[j] - s.q[j];
            x[r].v[j] = x[r].v[j] - s.v[j];
          }
        }
      });
    }
    for (std::size_t j = 0; j < n; ++j) {
      inc.q[j] = scalar_type(0);
      inc.v[j] = scalar_type(0);
      err.q[j] = scalar_type(0);
      err.v[j] = scalar_type(0);
    }
    const std::size_t ref = ref_;
    const State<V>& dref = x[ref];
    SS::for_each_run(P, [&](std::size_t i) NYSTROM_ALWAYS_INLINE {
      if (i == ref) return;
      const scalar_type ci = c_[i], di = d_[i];
      for (std::size_t j = 0; j < n; ++j) {
        const scalar_type dq = x[i].q[j] - dref.q[j], dv = x[i].v[j] - dref.v[j];
        inc.q[j] += ci * dq;
        inc.v[j] += ci * dv;
        err.q[j] += di * dq;
        err.v[j] += di * dv;
      }
    });
    for (std::size_t j = 0; j < n; ++j) {
      inc.q[j] += dref.q[j];
      inc.v[j] += dref.v[j];
    }
  }

  // The products in increment form: x[r] = (dq, dv) = T_r - s from zero, positions s.q + dq for the
  // forces and velocities s.v + dv for the drifts. The increments are small (O(h)), so their rounding
  // is eps |dq| instead of eps |q|: the combination gets them nearly to full precision at one addition
  // per sub-step (a compensated sum costs four, on the chain of dependent operations). The sub-steps
  // as in SplittingStepper::advance_lockstep (merged steps, pair by pair); every product performs the
  // same operations in the same order in lockstep and in sequence: bitwise the same results.
  template <class Count, class XS, class AS>
  NYSTROM_ALWAYS_INLINE void advance_increments(Count P, const State<V>& s, XS& x, AS& a) {
    using SS = SplittingStepper<V, Force>;
    const std::size_t n = s.q.size();
    const std::size_t m = m_;
    const long half = static_cast<long>((m - 1) / 2);
    const bool kick_first = kick_first_;
    const scalar_type* hc = scaled_.data();
    const long* ks = k_.data();
    constexpr bool local = is_std_array<V>::value;
    std::conditional_t<local, V, V&> qt = qbuf_;
    resize_like(qt, s.q);
    long evals = 0;
    SS::for_each_run(P, [&](std::size_t r) NYSTROM_ALWAYS_INLINE {
      for (std::size_t j = 0; j < n; ++j) {
        x[r].q[j] = scalar_type(0);
        x[r].v[j] = scalar_type(0);
      }
    });
    auto drift = [&](State<V>& y, const scalar_type& c) NYSTROM_ALWAYS_INLINE {
      for (std::size_t j = 0; j < n; ++j) y.q[j] += c * (s.v[j] + y.v[j]);
    };
    auto force = [&](const State<V>& y, V& ar) NYSTROM_ALWAYS_INLINE {
      if constexpr (local) {
        V q;  // a fresh local per call: no false dependence between the products' chains
        for (std::size_t j = 0; j < q.size(); ++j) q[j] = s.q[j] + y.q[j];  // std::array: q.size() == n
        base_.force()(q, ar);
      } else {
        for (std::size_t j = 0; j < n; ++j) qt[j] = s.q[j] + y.q[j];
        base_.force()(qt, ar);
      }
      ++evals;
    };
    auto kick = [&](State<V>& y, const scalar_type& c, const V& ar) NYSTROM_ALWAYS_INLINE {
      for (std::size_t j = 0; j < n; ++j) y.v[j] += c * ar[j];
    };
    // Pair p (position i in the step) of product r.
    auto pair = [&](std::size_t r, long p, std::size_t i) NYSTROM_ALWAYS_INLINE {
      const scalar_type* c = hc + r * m;
      const scalar_type c0 = i == 0 ? (p == 0 ? c[0] : scalar_type(c[m - 1] + c[0])) : c[i];
      if (!kick_first) drift(x[r], c0);
      if (!(kick_first && p == 0)) force(x[r], a[r]);  // a kick-first product starts with a[r] = a0
      kick(x[r], kick_first ? c0 : c[i + 1], a[r]);
      if (kick_first) drift(x[r], c[i + 1]);
    };
    auto last = [&](std::size_t r) NYSTROM_ALWAYS_INLINE {
      const scalar_type* c = hc + r * m;
      if (kick_first) {
        force(x[r], a[r]);
        kick(x[r], c[m - 1], a[r]);
      } else {
        drift(x[r], c[m - 1]);
      }
    };
    if (lockstep_) {
      long max_pairs = 0;
      SS::for_each_run(P, [&](std::size_t r) { max_pairs = std::max(max_pairs, ks[r] * half); });
      std::size_t i = 0;
      for (long p = 0; p < max_pairs; ++p) {
        SS::for_each_run(P, [&](std::size_t r) NYSTROM_ALWAYS_INLINE {
          if (p < ks[r] * half) pair(r, p, i);
        });
        i += 2;
        if (i + 1 >= m) i = 0;
      }
      SS::for_each_run(P, [&](std::size_t r) NYSTROM_ALWAYS_INLINE { last(r); });
    } else {
      auto one = [&](std::size_t r) {
        std::size_t i = 0;
        for (long p = 0; p < ks[r] * half; ++p) {
          pair(r, p, i);
          i += 2;
          if (i + 1 >= m) i = 0;
        }
        last(r);
      };
      for (std::size_t r = 0; r < k_.size(); ++r)
        if (r != ref_) one(r);
      one(ref_);
    }
    own_evals_ += evals;
  }

  // The hot path of the unrolled lockstep: K products of a three-step (Verlet) base in increment form,
  // the products' increments, forces and coefficients in local arrays indexed [product][component]
  // (nothing of the step in member memory, which the force functor could alias), then inc and err.
  // The same operations in the same order per product as advance_increments and trial (bitwise the
  // same results as the sequential schedule and the run-time lockstep): per product r, hk = h / k_r,
  // c = base coefficients * hk; drift-first base (position Verlet): drift c0, then k_r times
  // {force, kick c1, drift (c2 + c0 or, last, c2)}; kick-first base (velocity Verlet): a = a0, then
  // k_r times {kick (c0, later c2 + c0), drift c1}, then force, kick c2. Returns the forces evaluated.
  template <std::size_t K>
  NYSTROM_ALWAYS_INLINE long trial_verlet(const State<V>& s, const V& a0, const real_type& h, State<V>& inc,
                                          State<V>& err) {
    constexpr std::size_t D = std::tuple_size<V>::value;
    const auto& st = base_.scheme().steps;
    const scalar_type b0 = st[0].coef, b1 = st[1].coef, b2 = st[2].coef;
    const bool kick_first = kick_first_;
    long kr[K];
    std::size_t ord[K];  // the products by decreasing k: the longest chain of forces is issued first
    scalar_type c0[K], c1[K], c2[K], cm[K];
    long max_k = 0;
    for (std::size_t r = 0; r < K; ++r) {
      ord[r] = by_k_[r];
      kr[r] = k_[r];
      max_k = std::max(max_k, kr[r]);
      const scalar_type hk = h / static_cast<scalar_type>(kr[r]);
      c0[r] = b0 * hk;
      c1[r] = b1 * hk;
      c2[r] = b2 * hk;
      cm[r] = c2[r] + c0[r];
    }
    scalar_type dq[K][D], dv[K][D], a[K][D];
    long evals = 0;
    auto force = [&](std::size_t r) NYSTROM_ALWAYS_INLINE {
      V q, ar;
      for (std::size_t j = 0; j < D; ++j) q[j] = s.q[j] + dq[r][j];
      base_.force()(q, ar);
      for (std::size_t j = 0; j < D; ++j) a[r][j] = ar[j];
      ++evals;
    };
    auto drift = [&](std::size_t r, const scalar_type& c) NYSTROM_ALWAYS_INLINE {
      for (std::size_t j = 0; j < D; ++j) dq[r][j] += c * (s.v[j] + dv[r][j]);
    };
    auto kick = [&](std::size_t r, const scalar_type& c) NYSTROM_ALWAYS_INLINE {
      for (std::size_t j = 0; j < D; ++j) dv[r][j] += c * a[r][j];
    };
    for (std::size_t r = 0; r < K; ++r)
      for (std::size_t j = 0; j < D; ++j) {
        dq[r][j] = scalar_type(0);
        dv[r][j] = scalar_type(0);
        a[r][j] = kick_first ? a0[j] : scalar_type(0);
      }
    if (kick_first) {
      for (long p = 0; p < max_k; ++p)
        for (std::size_t o = 0; o < K; ++o) {
          const std::size_t r = ord[o];
          if (p >= kr[r]) break;  // ord is by decreasing k: the later products have ended too
          if (p > 0) force(r);
          kick(r, p == 0 ? c0[r] : cm[r]);
          drift(r, c1[r]);
        }
      for (std::size_t r = 0; r < K; ++r) {
        force(r);
        kick(r, c2[r]);
      }
    } else {
      for (long p = 0; p < max_k; ++p)
        for (std::size_t o = 0; o < K; ++o) {
          const std::size_t r = ord[o];
          if (p >= kr[r]) break;  // ord is by decreasing k: the later products have ended too
          drift(r, p == 0 ? c0[r] : cm[r]);
          force(r);
          kick(r, c1[r]);
        }
      for (std::size_t r = 0; r < K; ++r) drift(r, c2[r]);
    }
    // inc = D_ref + sum_{i != ref} c_i (D_i - D_ref), err = sum_{i != ref} d_i (D_i - D_ref), as in trial.
    const std::size_t ref = ref_;
    for (std::size_t j = 0; j < D; ++j) {
      inc.q[j] = scalar_type(0);
      inc.v[j] = scalar_type(0);
      err.q[j] = scalar_type(0);
      err.v[j] = scalar_type(0);
    }
    for (std::size_t i = 0; i < K; ++i) {
      if (i == ref) continue;
      const scalar_type ci = c_[i], di = d_[i];
      for (std::size_t j = 0; j < D; ++j) {
        const scalar_type eq = dq[i][j] - dq[ref][j], ev = dv[i][j] - dv[ref][j];
        inc.q[j] += ci * eq;
        inc.v[j] += ci * ev;
        err.q[j] += di * eq;
        err.v[j] += di * ev;
      }
    }
    for (std::size_t j = 0; j < D; ++j) {
      inc.q[j] += dq[ref][j];
      inc.v[j] += dv[ref][j];
    }
    return evals;
  }

  /// The mixed norm of the error estimate, squared, in double (NaN or inf: +inf, i.e. reject). The scale
  /// of a component is at least noise |increment| (noise_floor_): an estimate at its own round-off level
  /// is not an error the step size can reduce.
  static double error_norm2(const State<V>& y0, const State<V>& inc, const State<V>& e,
                            const adaptive_detail::ErrorScale<real_type>& sc, const real_type& noise) {
    using std::abs;
    double sum = 0;
    const std::size_t n = y0.q.size();
    for (std::size_t i = 0; i < n; ++i) {
      const real_type q1 = y0.q[i] + inc.q[i], v1 = y0.v[i] + inc.v[i];
      const real_type sq = std::max(sc(std::max(abs(y0.q[i]), abs(q1))), real_type(noise * abs(inc.q[i])));
      const real_type sv = std::max(sc(std::max(abs(y0.v[i]), abs(v1))), real_type(noise * abs(inc.v[i])));
      const double rq = as_double(real_type(e.q[i] / sq)), rv = as_double(real_type(e.v[i] / sv));
      sum += rq * rq + rv * rv;
    }
    const double r = sum * (1.0 / static_cast<double>(2 * n));  // the reciprocal off the chain of the step
    return std::isfinite(r) ? r : std::numeric_limits<double>::infinity();
  }

  // The controller loop; K > 0: K products in local arrays (fixed-size states in lockstep), K = 0:
  // the member buffers and a run-time product count.
  template <bool Comp, std::size_t K, class Observer>
  AdaptiveStats run(State<V>& s_io, real_type t0, real_type t1, Observer& obs) {
    using std::abs;
    AdaptiveStats st;
    const long evals_before = force_evals();
    obs(static_cast<const real_type&>(t0), static_cast<const State<V>&>(s_io));
    if (t1 == t0) return st;

    const adaptive_detail::ErrorScale<real_type> err_scale(opt_);
    adaptive_detail::StepSequence<real_type> seq(opt_, resume_, h_next_, t0, t1, [&](const real_type& hmax) {
      long calls = 0;
      auto counted = [&](const V& q, V& a) {
        ++calls;
        base_.force()(q, a);
      };
      const real_type h = adaptive_detail::hairer_initial_step<V>(counted, s_io, hmax, err_scale, method_order_);
      extra_evals_ += calls;
      return h;
    });

    // Exponents on the squared norm: err^(-1/(p+1)) = (err^2)^(-1/(2(p+1))).
    const double p1 = opt_.error_order + 1;
    const double expo = -0.5 / p1;
    real_type t = t0, h;
    bool error_finite = true;  // the last error estimate was finite (else the force returned NaN or inf)

    constexpr bool local = K > 0;
    std::conditional_t<local, State<V>, State<V>&> s = s_io;
    State<V> inc = s_io, err = s_io;
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
    auto store = [&] {
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
    };

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
      if (!(local && verlet)) scale(h);
      if (kick_first_ && !a0_valid) {
        base_.force()(s.q, a0);
        ++a0_evals;
        a0_valid = true;
      }
      if constexpr (local) {
        if (verlet)
          own_evals_ += trial_verlet<K>(s, a0, h, inc, err);
        else
          trial<Comp>(std::integral_constant<std::size_t, K>{}, s, a0, lx, la, lcq, lcv, inc, err);
      } else
        trial<Comp>(k_.size(), s, a0, xs_, as_, cqs_, cvs_, inc, err);
      const double e2 = error_norm2(s, inc, err, err_scale, noise_floor_);
      error_finite = e2 < std::numeric_limits<double>::infinity();
      if (e2 <= 1.0) {
        for (std::size_t j = 0; j < s.q.size(); ++j) {
          if constexpr (Comp) {
            compensated_add(s.q[j], ccq[j], inc.q[j]);
            compensated_add(s.v[j], ccv[j], inc.v[j]);
          } else {
            s.q[j] += inc.q[j];
            s.v[j] += inc.v[j];
          }
        }
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
  //   * err_{n-1}, the estimate of T_{2n-2} - T_{2n-4} (products 1..n-1, free), <= 1: the step is accepted with
  //     T_{2n-2}, without the last force(s) of product n;
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

  // The increments and forces of the products of one step: local arrays for fixed-size states (nothing of the
  // step in memory that the force functor could alias, as in trial_verlet: the unrolled step keeps them in
  // registers; measured on Kepler e = 0.9, the products in std::array<State<V>, 8> made a step twice as slow)
  // or the member buffers.
  struct LocalProducts {
    static constexpr std::size_t D = fixed_lockstep ? std::tuple_size<V>::value : 1;
    scalar_type dq[8][D], dv[8][D], a[8][D];
    scalar_type& q(std::size_t r, std::size_t j) { return dq[r][j]; }
    scalar_type& v(std::size_t r, std::size_t j) { return dv[r][j]; }
    scalar_type& acc(std::size_t r, std::size_t j) { return a[r][j]; }
    const scalar_type& q(std::size_t r, std::size_t j) const { return dq[r][j]; }
    const scalar_type& v(std::size_t r, std::size_t j) const { return dv[r][j]; }
  };
  struct MemberProducts {
    std::vector<State<V>>& x;
    std::vector<V>& as;
    scalar_type& q(std::size_t r, std::size_t j) { return x[r].q[j]; }
    scalar_type& v(std::size_t r, std::size_t j) { return x[r].v[j]; }
    scalar_type& acc(std::size_t r, std::size_t j) { return as[r][j]; }
    const scalar_type& q(std::size_t r, std::size_t j) const { return x[r].q[j]; }
    const scalar_type& v(std::size_t r, std::size_t j) const { return x[r].v[j]; }
  };

  // The products k = 1..N of a step from s in increment form (product r: k = r + 1), products 1..N-1 complete
  // before the last pair of product N; then check(x) (true: go on), and after product N done(x). The same
  // operations per product as trial_verlet (bitwise the same increments). Returns the forces evaluated.
  template <class Count, class XS, class Check, class Done>
  NYSTROM_ALWAYS_INLINE long oc_products(Count N, const State<V>& s, const V& a0, const real_type& h, XS& x,
                                         Check&& check, Done&& done) {
    const std::size_t n = s.q.size();
    const auto& st = base_.scheme().steps;
    const scalar_type b0 = st[0].coef, b1 = st[1].coef, b2 = st[2].coef;
    const bool kick_first = kick_first_;
    constexpr bool local = std::is_same_v<XS, LocalProducts>;
    std::conditional_t<local, V, V&> qt = qbuf_;
    resize_like(qt, s.q);
    scalar_type c0[8], c1[8], c2[8], cm[8];
    for (std::size_t r = 0; r < N; ++r) {
      const scalar_type hk = h / static_cast<scalar_type>(static_cast<long>(r) + 1);
      c0[r] = b0 * hk;
      c1[r] = b1 * hk;
      c2[r] = b2 * hk;
      cm[r] = c2[r] + c0[r];
      for (std::size_t j = 0; j < n; ++j) {
        x.q(r, j) = scalar_type(0);
        x.v(r, j) = scalar_type(0);
        x.acc(r, j) = kick_first ? a0[j] : scalar_type(0);
      }
    }
    long evals = 0;
    auto force = [&](std::size_t r) NYSTROM_ALWAYS_INLINE {
      if constexpr (local) {
        V q, ar;  // fresh locals per call: no false dependence between the products' chains
        for (std::size_t j = 0; j < n; ++j) q[j] = s.q[j] + x.q(r, j);
        base_.force()(q, ar);
        for (std::size_t j = 0; j < n; ++j) x.acc(r, j) = ar[j];
      } else {
        for (std::size_t j = 0; j < n; ++j) qt[j] = s.q[j] + x.q(r, j);
        base_.force()(qt, x.as[r]);
      }
      ++evals;
    };
    auto drift = [&](std::size_t r, const scalar_type& c) NYSTROM_ALWAYS_INLINE {
      for (std::size_t j = 0; j < n; ++j) x.q(r, j) += c * (s.v[j] + x.v(r, j));
    };
    auto kick = [&](std::size_t r, const scalar_type& c) NYSTROM_ALWAYS_INLINE {
      for (std::size_t j = 0; j < n; ++j) x.v(r, j) += c * x.acc(r, j);
    };
    auto pair = [&](std::size_t r, std::size_t p) NYSTROM_ALWAYS_INLINE {
      if (kick_first) {
        if (p > 0) force(r);
        kick(r, p == 0 ? c0[r] : cm[r]);
        drift(r, c1[r]);
      } else {
        drift(r, p == 0 ? c0[r] : cm[r]);
        force(r);
        kick(r, c1[r]);
      }
    };
    auto finish = [&](std::size_t r) NYSTROM_ALWAYS_INLINE {
      if (kick_first) {
        force(r);
        kick(r, c2[r]);
      } else {
        drift(r, c2[r]);
      }
    };
    const std::size_t top = N - 1;
    for (std::size_t p = 0; p < top; ++p) {
      for (std::size_t r = top + 1; r-- > p;) pair(r, p);  // the products with k > p, the longest first
      finish(p);                                           // product k = p + 1 has made its k pairs
    }
    if (check(static_cast<const XS&>(x))) {
      pair(top, top);
      finish(top);
    }
    done(static_cast<const XS&>(x));
    return evals;
  }

  // inc = T_2n - s and err = T_2n - T_{2n-2} from the increments of products 1..n, as in trial_verlet.
  template <class XS>
  NYSTROM_ALWAYS_INLINE void oc_combine(std::size_t nprod, const XS& x, State<V>& inc, State<V>& err) const {
    const std::size_t n = inc.q.size();
    const std::size_t ref = nprod - 1;
    const scalar_type* c = occ_[nprod].data();
    const scalar_type* d = ocd_[nprod].data();
    for (std::size_t j = 0; j < n; ++j) {
      inc.q[j] = scalar_type(0);
      inc.v[j] = scalar_type(0);
      err.q[j] = scalar_type(0);
      err.v[j] = scalar_type(0);
    }
    for (std::size_t i = 0; i < ref; ++i) {
      const scalar_type ci = c[i], di = d[i];
      for (std::size_t j = 0; j < n; ++j) {
        const scalar_type eq = x.q(i, j) - x.q(ref, j), ev = x.v(i, j) - x.v(ref, j);
        inc.q[j] += ci * eq;
        inc.v[j] += ci * ev;
        err.q[j] += di * eq;
        err.v[j] += di * ev;
      }
    }
    for (std::size_t j = 0; j < n; ++j) {
      inc.q[j] += x.q(ref, j);
      inc.v[j] += x.v(ref, j);
    }
  }

  // The first target: ODEX's rule (HNW I, sec. II.9) for the orders of the products.
  // The smallest target: three products (the step can still stop at two), so that every full step has the
  // estimates of two orders to choose from; two when that is the largest.
  int nmin_target() const { return std::min(3, nmax_); }

  int oc_initial_products() const {
    const double tol = opt_.tol > 0 ? opt_.tol : opt_.atol;
    const int n = static_cast<int>(-0.6 * std::log10(tol) + 1.5);
    return std::max(nmin_target(), std::min(nmax_, n));
  }

  // The products of one step, unrolled for fixed-size states (see LocalProducts).
  template <class Check, class Done>
  NYSTROM_ALWAYS_INLINE long oc_dispatch(int nprod, const State<V>& s, const V& a0, const real_type& h, Check&& check,
                                         Done&& done) {
    if constexpr (fixed_lockstep) {
      LocalProducts x;
      switch (nprod) {
        case 2: return oc_products(std::integral_constant<std::size_t, 2>{}, s, a0, h, x, check, done);
        case 3: return oc_products(std::integral_constant<std::size_t, 3>{}, s, a0, h, x, check, done);
        case 4: return oc_products(std::integral_constant<std::size_t, 4>{}, s, a0, h, x, check, done);
        case 5: return oc_products(std::integral_constant<std::size_t, 5>{}, s, a0, h, x, check, done);
        case 6: return oc_products(std::integral_constant<std::size_t, 6>{}, s, a0, h, x, check, done);
        case 7: return oc_products(std::integral_constant<std::size_t, 7>{}, s, a0, h, x, check, done);
        default: return oc_products(std::integral_constant<std::size_t, 8>{}, s, a0, h, x, check, done);
      }
    } else {
      MemberProducts x{xs_, as_};
      return oc_products(static_cast<std::size_t>(nprod), s, a0, h, x, check, done);
    }
  }

  template <bool Comp, class Observer>
  AdaptiveStats run_oc(State<V>& s_io, real_type t0, real_type t1, Observer& obs) {
    AdaptiveStats st;
    const long evals_before = force_evals();
    obs(static_cast<const real_type&>(t0), static_cast<const State<V>&>(s_io));
    if (t1 == t0) return st;

    const adaptive_detail::ErrorScale<real_type> err_scale(opt_);
    int nt = n_next_ > 0 ? n_next_ : oc_initial_products();  // the target number of products
    adaptive_detail::StepSequence<real_type> seq(opt_, resume_, h_next_, t0, t1, [&](const real_type& hmax) {
      long calls = 0;
      auto counted = [&](const V& q, V& a) {
        ++calls;
        base_.force()(q, a);
      };
      const real_type h = adaptive_detail::hairer_initial_step<V>(counted, s_io, hmax, err_scale, 2 * nt);
      extra_evals_ += calls;
      return h;
    });
    std::vector<adaptive_detail::StepController> ctl(static_cast<std::size_t>(nmax_) + 1,
                                                     adaptive_detail::StepController(opt_));
    // err_n / err_{n-1} of the last full step of n products, and its step (the early rejection's prediction).

    real_type t = t0, h;
    bool error_finite = true;
    constexpr bool local = fixed_lockstep;
    std::conditional_t<local, State<V>, State<V>&> s = s_io;
    State<V> inc = s_io, err = s_io, inc_lo = s_io, err_lo = s_io;
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
        oc_combine(static_cast<std::size_t>(n - 1), x, inc_lo, err_lo);
        e2_lo = error_norm2(s, inc_lo, err_lo, err_scale, ocnoise_[static_cast<std::size_t>(n - 1)]);
        if (e2_lo <= 1.0) {
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
          oc_combine(static_cast<std::size_t>(n), x, inc, err);
          e2 = error_norm2(s, inc, err, err_scale, ocnoise_[static_cast<std::size_t>(n)]);
          if (e2 <= 1.0) taken = n;
          if (n - 1 >= 2) elo = e2_lo;
        } else if (n - 2 >= 2) {  // stopped after products 1..n-1: the estimate of order 2n - 4 as well
          oc_combine(static_cast<std::size_t>(n - 2), x, inc, err);
          elo = error_norm2(s, inc, err, err_scale, ocnoise_[static_cast<std::size_t>(n - 2)]);
        }
      };
      own_evals_ += oc_dispatch(n, s, a0, h, check, done);
      // j: the highest order estimated (the one taken, or the last one computed); elo that of j - 1.
      const int j = (taken == n - 1 || early_reject) ? n - 1 : n;
      const double ej = j == n ? e2 : e2_lo;
      error_finite = std::isfinite(ej);
      const State<V>& inc_taken = taken == n ? inc : inc_lo;
      if (taken) {
        for (std::size_t i = 0; i < s.q.size(); ++i) {
          if constexpr (Comp) {
            compensated_add(s.q[i], ccq[i], inc_taken.q[i]);
            compensated_add(s.v[i], ccv[i], inc_taken.v[i]);
          } else {
            s.q[i] += inc_taken.q[i];
            s.v[i] += inc_taken.v[i];
          }
        }
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
        double fac = fj;
        int next = j;
        if (j - 1 >= 2) {
          const double fl = ctl[static_cast<std::size_t>(j - 1)].accepted(qof(elo, j - 1), hd, after_rej);
          const double wj = work_[static_cast<std::size_t>(j)] / fj, wl = work_[static_cast<std::size_t>(j - 1)] / fl;
          if (wl < 0.7 * wj) {
            next = j - 1;
            fac = fl;
          } else if (j < nmax_ && !after_rej && wj < 1.0 * wl) {
            next = j + 1;
            fac = std::min(opt_.fac_max,
                           fj * work_[static_cast<std::size_t>(j + 1)] / work_[static_cast<std::size_t>(j)]);
          }
        } else if (j < nmax_ && !after_rej && fj >= opt_.fac_max) {
          next = j + 1;
        }
        nt = std::max(nmin_target(), next);
        seq.accepted_ratio(fac, h, last, h_next_);
        if (stop && t < t1) {
          resume_ = seq.resume_point(t);
          break;
        }
      } else {
        ++rejected;
        if (early_reject) ++early_rejected_;
        const double fj = ctl[static_cast<std::size_t>(j)].rejected(qof(ej, j));
        double fac = fj;
        int next = j;
        if (j - 1 >= 2 && std::isfinite(elo)) {
          const double fl = ctl[static_cast<std::size_t>(j - 1)].rejected(qof(elo, j - 1));
          if (work_[static_cast<std::size_t>(j - 1)] / fl < 0.7 * work_[static_cast<std::size_t>(j)] / fj) {
            next = j - 1;
            fac = fl;
          }
        }
        nt = std::max(nmin_target(), next);
        seq.rejected_ratio(fac, h);
      }
    }
    store();
    total_ += st;
    return st;
  }

  AdaptiveOptions opt_;
  EngineOptions eopt_;
  std::vector<long> k_;
  std::vector<scalar_type> c_, d_;
  SplittingStepper<V, Force> base_;
  std::size_t ref_ = 0, m_ = 0;
  bool kick_first_ = false, lockstep_ = false, compensated_ = false;
  int method_order_ = 0;
  real_type noise_floor_{};  // the error scale's floor, relative to the increment (see the constructor)
  long extra_evals_ = 0;     // forces outside the base's count: starting steps, forces at q_0
  long own_evals_ = 0;       // forces of the products in increment form
  bool merged_ = false;      // the base's steps merge (every symmetric base): the increment form applies
  V qbuf_{};
  real_type h_next_ = real_type(0);
  AdaptiveResumePoint<real_type> resume_;
  AdaptiveStats total_;
  Compensator<V> comp_;
  V a0_{};
  std::vector<State<V>> xs_;
  std::vector<V> as_, cqs_, cvs_;
  std::vector<scalar_type> scaled_;
  std::vector<std::size_t> by_k_;  // product indices by decreasing k (trial_verlet's issue order)
  // Order control (setup_order_control); indexed by the number of products n (0 and 1 unused).
  int nmax_ = 0;                               // 0: one order per run
  int n_next_ = 0;                             // the products of the next step (carried between calls)
  std::vector<std::vector<scalar_type>> occ_;  // the coefficients of T_2n over k = 1..n
  std::vector<std::vector<scalar_type>> ocd_;  // T_2n - T_{2n-2} over k = 1..n
  std::vector<real_type> ocnoise_;             // the error scale's floor of each n (see the constructor)
  std::vector<double> work_;                   // A_n: the cost of a step of n products (in forces)
  std::vector<long> hist_;                     // accepted steps by order 2n
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
  const MethodData data = method_data_for(def, scalar_traits<S>::bits(), scalar_traits<S>::name());
  const auto* m = std::get_if<MpeDef>(&data);
  if (!m) throw std::invalid_argument("method '" + def.info.name + "' is not a multi-product method");
  const AdaptiveMpeCoefficients ac = adaptive_mpe_coefficients(m->k);
  MpeCoefficients dm = ac.high;
  dm.c = ac.diff;
  auto conv = [](const bigcomplex& x) { return to_scalar<S>(x); };
  MpeOrderTables<S> orders;
  if (m->order_control) {
    for (std::size_t n = 0; n < m->k.size(); ++n)
      if (m->k[n] != static_cast<long>(n) + 1)
        throw std::invalid_argument("adaptive MPE order control runs the natural sequence 1, 2, ..., N only");
    orders.c.resize(m->k.size() + 1);
    orders.d.resize(m->k.size() + 1);
    for (std::size_t n = 2; n <= m->k.size(); ++n) {
      const AdaptiveMpeCoefficients an =
          adaptive_mpe_coefficients(std::vector<long>(m->k.begin(), m->k.begin() + static_cast<long>(n)));
      MpeCoefficients dn = an.high;
      dn.c = an.diff;
      orders.c[n] = mpe_coefficients_as<S>(an.high);
      orders.d[n] = mpe_coefficients_as<S>(dn);
    }
  }
  return AdaptiveMpeIntegrator<V, F>(m->k, mpe_coefficients_as<S>(ac.high), mpe_coefficients_as<S>(dm),
                                     convert_scheme<S>(m->base, conv), std::move(force), opt, eopt, std::move(orders));
}

}  // namespace nystrom
