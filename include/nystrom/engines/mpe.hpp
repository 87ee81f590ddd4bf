// The multi-product expansion engine (Chin, sec. II):
//
//   T_2n(h) = sum_i c_i T_2^{k_i}(h / k_i),   c_i = prod_{j != i} k_i^2 / (k_i^2 - k_j^2)   (eq 14)
//   error coefficient e_{2n+1} = (-1)^{n-1} prod_i 1 / k_i^2                                (eq 15)
//
// for any set of distinct positive integers {k_i} and any symmetric second-order splitting T_2
// (velocity Verlet, eq 25; position Verlet, eq 26; or another). The c_i are computed exactly as
// GMP rationals and converted to the working scalar type only at the end.
//
// The combination is formed as T_ref + sum_{i != ref} c_i (T_i - T_ref) with T_ref the product of
// largest k (sum c_i = 1 makes this exact algebra): the differences are O(h^3), so the large c_i
// multiply small numbers and less precision is lost than in sum c_i T_i.
// With compensated summation (EngineOptions::compensated, on by default in double) each product is
// run on a compensated carry and returns its increment T_i - s to full precision; the combined
// increment is added to the state with the carry of the whole run.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <exception>
#include <numeric>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <gmpxx.h>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "nystrom/core/eft.hpp"
#include "nystrom/core/state.hpp"
#include "nystrom/engines/splitting.hpp"
#include "nystrom/methods/mpe_coefficients.hpp"

namespace nystrom {

/// Executes an MPE integrator over any symmetric second-order base splitting.
template <class V, class Force>
class MpeStepper {
 public:
  using vector_type = V;
  using scalar_type = typename V::value_type;
  using real_type = real_t<scalar_type>;

  /// k: the sequence; c: its coefficients in the working type; base: T_2 as a splitting scheme.
  MpeStepper(std::vector<long> k, std::vector<scalar_type> c, SplittingScheme<scalar_type> base, Force force,
             EngineOptions opt = {})
      : k_(std::move(k)),
        c_(std::move(c)),
        base_(std::move(base), std::move(force), EngineOptions{true, Compensation::off}),
        opt_(opt) {
    validate_mpe_sequence(k_);
    if (c_.size() != k_.size()) throw std::invalid_argument("MPE: one coefficient per sequence member is needed");
    ref_ = static_cast<std::size_t>(std::max_element(k_.begin(), k_.end()) - k_.begin());
    starts_with_kick_ = base_.scheme().steps.front().flow == Flow::kick;
    products_.resize(k_.size());
    lockstep_ = base_.lockstep_capable() && (opt_.mpe_schedule == MpeSchedule::lockstep ||
                                             (opt_.mpe_schedule == MpeSchedule::automatic && is_std_array<V>::value));
    concurrent_ = opt_.mpe_schedule == MpeSchedule::concurrent;
    if (opt_.mpe_threads < 0) throw std::invalid_argument("MPE: the number of threads must be >= 0");
    if (lockstep_ || concurrent_) {
      pa_.resize(k_.size());
      pcq_.resize(k_.size());
      pcv_.resize(k_.size());
    }
    if (concurrent_) {
      // One copy of the base (and of its force functor) per product; the longest products first.
      // Copy-constructed, not assigned: a capturing lambda (a force a user writes) is not assignable.
      workers_.reserve(k_.size());
      for (std::size_t i = 0; i < k_.size(); ++i) workers_.push_back(base_);
      order_.resize(k_.size());
      std::iota(order_.begin(), order_.end(), std::size_t{0});
      std::stable_sort(order_.begin(), order_.end(), [&](std::size_t a, std::size_t b) { return k_[a] > k_[b]; });
    }
  }

  /// Whether a compensated run also takes the force's rounding error (a compensated force, force(q, cq, a, alo);
  /// SplittingStepper::carried_force): each product then starts from the state with the run's carries and runs the
  /// base's compensated drifts and kicks in double-word (SplittingStepper::advance_carried), one product after the
  /// other.
  static constexpr bool carried_force = SplittingStepper<V, Force>::carried_force;

  /// Whether the products of a step run in lockstep (EngineOptions::mpe_schedule).
  bool lockstep() const { return lockstep_; }

  /// The base's coefficient residuals (SplittingStepper::set_coefficient_residuals).
  void set_base_coefficient_residuals(std::vector<scalar_type> lo) { base_.set_coefficient_residuals(std::move(lo)); }

  long force_evals() const {
    long e = base_.force_evals() + extra_evals_;
    for (const auto& w : workers_) e += w.force_evals();
    return e;
  }
  Force& force() { return base_.force(); }
  /// The compensated-summation carries of the run (checkpoint/restart).
  Compensator<V>& compensator() { return comp_; }
  const std::vector<long>& sequence() const { return k_; }

  void step(State<V>& s, real_type h) { integrate(s, h, 1); }

  void integrate(State<V>& s, real_type h, long n) {
    if (n <= 0) return;
    if (opt_.mpe_naive_combination) {
      for (long i = 0; i < n; ++i) naive_step(s, h);
      comp_.invalidate();
      return;
    }
    if constexpr (carried_force) {
      if (use_compensation<scalar_type>(opt_.compensated)) {
        comp_.begin(s);
        carried_steps(s, h, n);
        comp_.end(s);
        return;
      }
    }
    // The base's coefficients times h / k_i, product after product (kept while h stays, in the built-in
    // floating-point types: a driver that takes one step per call pays for them once).
    const std::size_t m = base_.scheme().steps.size();
    if (!std::is_floating_point_v<real_type> || !scaled_for_h_ || !(scaled_h_ == h)) {
      scaled_.resize(k_.size() * m);
      for (std::size_t i = 0; i < k_.size(); ++i) {
        base_.scale_coefficients(h / static_cast<real_type>(k_[i]), hc_);
        std::copy(hc_.begin(), hc_.end(), scaled_.begin() + static_cast<std::ptrdiff_t>(i * m));
      }
      scaled_h_ = h;
      scaled_for_h_ = true;
    }
    // A fixed-size state and carry live in locals for the loop (see SplittingStepper::run).
    constexpr bool local = is_std_array<V>::value;
    std::conditional_t<local, State<V>, State<V>&> x = s;
    if (use_compensation<scalar_type>(opt_.compensated)) {
      comp_.begin(s);
      std::conditional_t<local, Compensator<V>, Compensator<V>&> c = comp_;
      if (!(lockstep_ && dispatch_fixed<true>(x, c, n)))
        for (long i = 0; i < n; ++i) one_step<true>(x, c);
      if constexpr (local) {
        s = x;
        comp_ = c;
      }
      comp_.end(s);
    } else {
      if (!(lockstep_ && dispatch_fixed<false>(x, comp_, n)))
        for (long i = 0; i < n; ++i) one_step<false>(x, comp_);
      if constexpr (local) s = x;
    }
  }

 private:
  void first_force(const State<V>& s) {
    resize_like(a0_, s.q);
    if (starts_with_kick_) {
      // All products start with a kick at q_0: evaluate that force once (n(n+1)/2 + 1 for VV).
      base_.force()(s.q, a0_);
      ++extra_evals_;
    }
  }

  // n compensated steps with a compensated force (carried_force). Each product starts from s with the run's
  // carries comp_.cq, comp_.cv (and the force there with its low part, evaluated once when the base starts with a
  // kick) and runs advance_carried with the base's coefficients times h / k_i as double-words; its increment
  // (T_i - s) + (carry_i - carry) is then of the size of h v, rounded at eps |h v| instead of eps |q|; the
  // combination T_ref + sum_{i != ref} c_i (T_i - T_ref) of the increments is added to s and its carry by an exact
  // two-sum.
  void carried_steps(State<V>& s, real_type h, long n) requires carried_force {
    using S = scalar_type;
    const std::size_t P = k_.size(), m = base_.scheme().steps.size();
    if (!carried_for_h_ || !(carried_h_ == h)) {
      base_.scale_products_carried(S(h), k_, carried_);
      carried_h_ = h;
      carried_for_h_ = true;
    }
    products_.resize(P);
    lows_.resize(P);
    V a0{}, a0lo{}, a{}, alo{};
    resize_like(a0, s.q);
    resize_like(a0lo, s.q);
    for (long step = 0; step < n; ++step) {
      if (starts_with_kick_) {
        base_.force()(s.q, comp_.cq, a0, a0lo);
        ++extra_evals_;
      }
      // Each product's increment as a double-word: products_[i] + lows_[i].
      for (std::size_t i = 0; i < P; ++i)
        base_.carried_product(s, comp_.cq, comp_.cv, a0, a0lo, carried_.data() + i * m, k_[i], products_[i], lows_[i],
                              a, alo);
      // T_ref + sum_{i != ref} c_i (T_i - T_ref): the differences of the increments (of the order of the base's
      // local error) rounded once, the reference increment added as a double-word by an exact two-sum.
      const State<V>& tref = products_[ref_];
      const State<V>& lref = lows_[ref_];
      for (std::size_t j = 0; j < s.q.size(); ++j) {
        S dq = 0, dv = 0;
        for (std::size_t i = 0; i < P; ++i) {
          if (i == ref_) continue;
          dq += c_[i] * ((products_[i].q[j] - tref.q[j]) + (lows_[i].q[j] - lref.q[j]));
          dv += c_[i] * ((products_[i].v[j] - tref.v[j]) + (lows_[i].v[j] - lref.v[j]));
        }
        eft::add_double_word(s.q[j], comp_.cq[j], tref.q[j], S(lref.q[j] + dq));
        eft::add_double_word(s.v[j], comp_.cv[j], tref.v[j], S(lref.v[j] + dv));
      }
    }
  }

  // Measurements only: sum c_i T_i, uncompensated.
  void naive_step(State<V>& s, real_type h) {
    first_force(s);
    resize_like(acc_.q, s.q);
    resize_like(acc_.v, s.v);
    for (auto& e : acc_.q) e = scalar_type(0);
    for (auto& e : acc_.v) e = scalar_type(0);
    for (std::size_t i = 0; i < k_.size(); ++i) {
      run_product(s, i, h, ti_);
      axpy(acc_.q, c_[i], ti_.q);
      axpy(acc_.v, c_[i], ti_.v);
    }
    assign(s.q, acc_.q);
    assign(s.v, acc_.v);
    if (is_complex_v<scalar_type> && !opt_.keep_complex) {
      project_real(s.q);
      project_real(s.v);
    }
  }

  // Uncompensated: T_i are end states. Compensated: T_i are the increments T_i - s, each product run
  // with its own compensated carry so that the increment is known to full precision; the combined
  // increment is then added to s with the carry `comp` of the whole run.
  template <bool Comp>
  NYSTROM_ALWAYS_INLINE void one_step(State<V>& s, Compensator<V>& comp) {
    // Fixed-size states, forces and carries live in locals (registers); see SplittingStepper::run.
    constexpr bool local = is_std_array<V>::value;
    std::conditional_t<local, V, V&> a0 = a0_, a = a_, pcq = pc_.cq, pcv = pc_.cv;
    resize_like(a0, s.q);
    resize_like(a, s.q);
    if (starts_with_kick_) {
      // All products start with a kick at q_0: evaluate that force once (n(n+1)/2 + 1 for VV).
      base_.force()(s.q, a0);
      ++extra_evals_;
    }
    const std::size_t m = base_.scheme().steps.size();
    auto product = [&](std::size_t i, State<V>& out) NYSTROM_ALWAYS_INLINE {
      start_product<Comp>(s, a0, out, a, pcq, pcv);
      bool valid = starts_with_kick_;
      base_.template advance_scaled<Comp>(out, a, valid, scaled_.data() + i * m, k_[i], pcq, pcv);
      if constexpr (Comp) to_increment(s, out, pcq, pcv);
    };
    if (lockstep_) {
      // All products in lockstep (SplittingStepper::advance_lockstep): bitwise the same end states.
      const std::size_t P = k_.size();
      for (std::size_t r = 0; r < P; ++r) start_product<Comp>(s, a0, products_[r], pa_[r], pcq_[r], pcv_[r]);
      base_.template advance_lockstep<Comp>(P, products_.data(), pa_.data(), starts_with_kick_, scaled_.data(),
                                            k_.data(), pcq_.data(), pcv_.data());
      if constexpr (Comp) to_increments(P, s, products_, pcq_, pcv_);
    } else if (concurrent_) {
      run_concurrent<Comp>(s, a0);
    } else {
      // The products are independent: the reference one (largest k, the longest chain of dependent
      // force evaluations) runs last, so that the processor overlaps the shorter ones with it.
      for (std::size_t i = 0; i < k_.size(); ++i) {
        if (i == ref_) continue;
        std::conditional_t<local, State<V>, State<V>&> ti = products_[i];
        product(i, ti);
        if constexpr (local) products_[i] = ti;
      }
      std::conditional_t<local, State<V>, State<V>&> tref0 = products_[ref_];
      product(ref_, tref0);
      if constexpr (local) products_[ref_] = tref0;
    }
    combine<Comp>(k_.size(), s, comp, products_);
  }

  // n steps with K products of a fixed-size state in lockstep, everything in local arrays and the loop
  // over the products unrolled (no store-to-load forwarding on the dependent chains). One function per
  // K, not inlined into integrate, so that the force and the vector operations inline here.
  template <bool Comp, std::size_t K>
  void fixed_steps(State<V>& s, Compensator<V>& comp, long n) {
    for (long i = 0; i < n; ++i) {
      V a0{};
      if (starts_with_kick_) {
        base_.force()(s.q, a0);
        ++extra_evals_;
      }
      fixed_step<Comp, K>(s, comp, a0);
    }
  }

  // The unrolled fixed-K loops pay off where a force is a short chain of hardware float operations
  // whose latency the processor can overlap across products: std::array states of float or double.
  // Other scalars (long double, complex, float128, dd, qd, MPFR) run the same lockstep order through
  // advance_lockstep with a run-time product count, bitwise the same (tests/engines/test_mpe_schedule.cpp),
  // without 16 more instantiations of the engine per state type and force (compile time).
  static constexpr bool fixed_lockstep = is_std_array<V>::value && word_scalar<scalar_type>;

  // Calls fixed_steps<Comp, K> for K = the number of products; false if there are more than 8.
  template <bool Comp>
  bool dispatch_fixed(State<V>& s, Compensator<V>& comp, long n) {
    if constexpr (fixed_lockstep) {
      switch (k_.size()) {
        case 1: fixed_steps<Comp, 1>(s, comp, n); return true;
        case 2: fixed_steps<Comp, 2>(s, comp, n); return true;
        case 3: fixed_steps<Comp, 3>(s, comp, n); return true;
        case 4: fixed_steps<Comp, 4>(s, comp, n); return true;
        case 5: fixed_steps<Comp, 5>(s, comp, n); return true;
        case 6: fixed_steps<Comp, 6>(s, comp, n); return true;
        case 7: fixed_steps<Comp, 7>(s, comp, n); return true;
        case 8: fixed_steps<Comp, 8>(s, comp, n); return true;
        default: return false;
      }
    } else {
      (void)s, (void)comp, (void)n;
      return false;
    }
  }

  // One step of K products of a fixed-size state in lockstep, in local arrays.
  template <bool Comp, std::size_t K>
  NYSTROM_ALWAYS_INLINE void fixed_step(State<V>& s, Compensator<V>& comp, const V& a0) {
    std::array<State<V>, K> x;
    std::array<V, K> a{}, cq, cv;
    for (std::size_t r = 0; r < K; ++r) {
      x[r] = s;
      if (starts_with_kick_) a[r] = a0;
      if constexpr (Comp) {
        cq[r].fill(scalar_type(0));
        cv[r].fill(scalar_type(0));
      }
    }
    base_.template advance_lockstep<Comp>(std::integral_constant<std::size_t, K>{}, x, a, starts_with_kick_,
                                          scaled_.data(), k_.data(), cq, cv);
    constexpr std::integral_constant<std::size_t, K> P{};
    if constexpr (Comp) to_increments(P, s, x, cq, cv);
    combine<Comp>(P, s, comp, x);
  }

  // A product's start: the state s, the force a0 at s.q when the base starts with a kick, zero carries.
  template <bool Comp>
  NYSTROM_ALWAYS_INLINE void start_product(const State<V>& s, const V& a0, State<V>& out, V& a, V& cq, V& cv) const {
    resize_like(out.q, s.q);
    resize_like(out.v, s.v);
    assign(out.q, s.q);
    assign(out.v, s.v);
    resize_like(a, s.q);
    if (starts_with_kick_) assign(a, a0);
    if constexpr (Comp) {
      resize_like(cq, s.q);
      resize_like(cv, s.q);
      for (auto& e : cq) e = scalar_type(0);
      for (auto& e : cv) e = scalar_type(0);
    }
  }

  // A compensated product: T - s to full precision from the end state T and its carries.
  NYSTROM_ALWAYS_INLINE static void to_increment(const State<V>& s, State<V>& T, const V& cq, const V& cv) {
    for (std::size_t j = 0; j < s.q.size(); ++j) {
      T.q[j] = (T.q[j] - s.q[j]) + cq[j];
      T.v[j] = (T.v[j] - s.v[j]) + cv[j];
    }
  }

  template <class Count, class TS, class CS>
  NYSTROM_ALWAYS_INLINE static void to_increments(Count P, const State<V>& s, TS& T, const CS& cq, const CS& cv) {
    SplittingStepper<V, Force>::for_each_run(
        P, [&](std::size_t r) NYSTROM_ALWAYS_INLINE { to_increment(s, T[r], cq[r], cv[r]); });
  }

  // s <- T_ref + sum_{i != ref} c_i (T_i - T_ref) (T: end states), or with Comp s += the same
  // combination of increments with the run's carry. P as in SplittingStepper::advance_lockstep: with an
  // integral_constant the products are never indexed at run time (local arrays stay in registers).
  template <bool Comp, class Count, class TS>
  NYSTROM_ALWAYS_INLINE void combine(Count P, State<V>& s, Compensator<V>& comp, const TS& T) {
    constexpr bool local = is_std_array<V>::value;
    std::conditional_t<local, State<V>, State<V>&> acc = acc_, tref = tref_;
    const std::size_t ref = ref_;
    SplittingStepper<V, Force>::for_each_run(P, [&](std::size_t r) NYSTROM_ALWAYS_INLINE {
      if (r == ref) {
        resize_like(tref.q, s.q);
        resize_like(tref.v, s.v);
        assign(tref.q, T[r].q);
        assign(tref.v, T[r].v);
      }
    });
    resize_like(acc.q, s.q);
    resize_like(acc.v, s.q);
    for (auto& e : acc.q) e = scalar_type(0);
    for (auto& e : acc.v) e = scalar_type(0);
    SplittingStepper<V, Force>::for_each_run(P, [&](std::size_t i) NYSTROM_ALWAYS_INLINE {
      if (i == ref) return;
      const State<V>& ti = T[i];
      const scalar_type ci = c_[i];
      for (std::size_t j = 0; j < s.q.size(); ++j) {
        acc.q[j] += ci * (ti.q[j] - tref.q[j]);
        acc.v[j] += ci * (ti.v[j] - tref.v[j]);
      }
    });
    if constexpr (Comp) {
      for (std::size_t j = 0; j < s.q.size(); ++j) {
        acc.q[j] += tref.q[j];
        acc.v[j] += tref.v[j];
      }
      comp.add_q(s.q, acc.q);
      comp.add_v(s.v, acc.v);
    } else {
      for (std::size_t j = 0; j < s.q.size(); ++j) {
        s.q[j] = tref.q[j] + acc.q[j];
        s.v[j] = tref.v[j] + acc.v[j];
      }
    }
    if (is_complex_v<scalar_type> && !opt_.keep_complex) {
      project_real(s.q);
      project_real(s.v);
      if constexpr (Comp) {
        project_real(comp.cq);
        project_real(comp.cv);
      }
    }
  }

  // The products on OpenMP threads, each on its own copy of the base (force functor, counter); the
  // same operations per product as the sequential schedule, so bitwise the same results.
  template <bool Comp>
  void run_concurrent(const State<V>& s, const V& a0) {
    const std::size_t m = base_.scheme().steps.size();
    const long P = static_cast<long>(k_.size());
    const int threads = opt_.mpe_threads > 0 ? opt_.mpe_threads : max_threads();
    std::exception_ptr error;
    (void)threads;
#ifdef _OPENMP
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) if (threads > 1)
#endif
    for (long idx = 0; idx < P; ++idx) {
      const std::size_t r = order_[static_cast<std::size_t>(idx)];
      try {
        start_product<Comp>(s, a0, products_[r], pa_[r], pcq_[r], pcv_[r]);
        bool valid = starts_with_kick_;
        workers_[r].template advance_scaled<Comp>(products_[r], pa_[r], valid, scaled_.data() + r * m, k_[r], pcq_[r],
                                                  pcv_[r]);
        if constexpr (Comp) to_increment(s, products_[r], pcq_[r], pcv_[r]);
      } catch (...) {
#ifdef _OPENMP
#pragma omp critical(nystrom_mpe_error)
#endif
        if (!error) error = std::current_exception();
      }
    }
    if (error) std::rethrow_exception(error);
  }

  static int max_threads() {
#ifdef _OPENMP
    return omp_get_max_threads();
#else
    return 1;
#endif
  }

  // Measurements only (naive_step): one product T_2^k_i(h / k_i) from s, uncompensated.
  void run_product(const State<V>& s, std::size_t i, real_type h, State<V>& out) {
    resize_like(out.q, s.q);
    resize_like(out.v, s.v);
    assign(out.q, s.q);
    assign(out.v, s.v);
    if (starts_with_kick_)
      base_.seed_force(s.q, a0_);
    else
      base_.reset_cache();
    base_.integrate(out, h / static_cast<real_type>(k_[i]), k_[i]);
  }

  std::vector<long> k_;
  std::vector<scalar_type> c_;
  SplittingStepper<V, Force> base_;
  EngineOptions opt_;
  std::size_t ref_ = 0;
  bool starts_with_kick_ = false;
  long extra_evals_ = 0;
  V a0_{}, a_{};
  State<V> ti_{}, acc_{}, tref_{};
  std::vector<State<V>> products_;  // T_2^k_i(h / k_i) of the current step (or its increment)
  bool lockstep_ = false, concurrent_ = false;
  std::vector<SplittingStepper<V, Force>> workers_;  // concurrent: a copy of the base per product
  std::vector<std::size_t> order_;                   // concurrent: products by decreasing k
  std::vector<V> pa_, pcq_, pcv_;                    // lockstep: each product's force cache and carries
  std::vector<scalar_type> scaled_, hc_;             // base coefficients times h / k_i, product after product
  real_type scaled_h_{};                             // the h of scaled_
  bool scaled_for_h_ = false;
  Compensator<V> comp_, pc_;
  // carried_steps: the base's coefficients times h / k_i as double-words, product after product, for carried_h_
  std::vector<typename SplittingStepper<V, Force>::Scaled> carried_;
  std::vector<State<V>> lows_;  // the low parts of the products' increments
  real_type carried_h_{};
  bool carried_for_h_ = false;
};

}  // namespace nystrom
