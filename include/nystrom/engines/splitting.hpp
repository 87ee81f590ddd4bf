// The splitting engine: executes any product of exponentials e^{a_1 h A} e^{b_1 h B} ... .
//
// A splitting scheme is data: a sequence of sub-steps, each the flow of A ("drift",
// q += c h v) or of B ("kick", v += c h a(q)), listed IN THE ORDER THEY ARE APPLIED in time.
// (Operator products in the papers are often written right-to-left; the catalog converts.)
//
// The engine
//   * caches the last force together with the position it was evaluated at, so a kick that
//     follows a kick, or the first kick of a step that starts where the last one ended
//     (first-same-as-last), costs no new force evaluation; the count is exact;
//   * in integrate(), merges the last sub-step of a step with the first of the next when
//     they are of the same flow (drift ... drift, kick ... kick);
//   * works for real or complex coefficients: the state scalar is the coefficient type.
//     With complex coefficients the imaginary parts of q and v are dropped after each step
//     (Gürkan, sec. 5) unless keep_complex is set.
#pragma once

#include <array>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "nystrom/core/eft.hpp"
#include "nystrom/core/state.hpp"
#include "nystrom/methods/splitting_scheme.hpp"

namespace nystrom {

/// The loop of a splitting scheme over any pair of flows, shared by the classical engine (drift and kick with
/// a force cache, below) and the operator layer (operators/flows.hpp: any e^{h(A+B)}). hc holds the m
/// sub-steps' coefficients times h in the order of application; drift(c, j) and kick(c, j) apply sub-step j
/// (0 .. m - 1) with coefficient c; step_end() runs after each step.
///
/// Steps that merge (the first and last sub-steps are of the same flow, which after normalisation means that
/// the m sub-steps alternate, m odd and >= 3): n steps in which the last sub-step of a step and the first of
/// the next run as one sub-step of coefficient `joined`, with step_end() right after it (and after the final
/// sub-step). The n steps run as n (m - 1) / 2 pairs of sub-steps of known flows and then the last sub-step:
/// the same operations in the same order as sub-step by sub-step, but without a branch on the flow, so that
/// the compiler inlines drift and kick and keeps a fixed-size state in registers (bench_kepler: the library's
/// VV and FR against hand-written loops).
template <class C, class Drift, class Kick, class StepEnd>
NYSTROM_ALWAYS_INLINE inline void run_merged_splitting(bool kick_first, const C* hc, std::size_t m, long n,
                                                       const C& joined, Drift&& drift, Kick&& kick,
                                                       StepEnd&& step_end) {
  const long pairs = n * static_cast<long>((m - 1) / 2);
  std::size_t i = 0;  // position of the pair in the step
  for (long p = 0; p < pairs; ++p) {
    const C& c0 = i == 0 && p != 0 ? joined : hc[i];
    if (kick_first)
      kick(c0, i);
    else
      drift(c0, i);
    if (i == 0 && p != 0) step_end();
    if (kick_first)
      drift(hc[i + 1], i + 1);
    else
      kick(hc[i + 1], i + 1);
    i += 2;
    if (i + 1 >= m) i = 0;
  }
  if (kick_first)
    kick(hc[m - 1], m - 1);
  else
    drift(hc[m - 1], m - 1);
  step_end();
}

/// Steps that do not merge: n steps of the m sub-steps one after the other (flows[j]: the flow of sub-step j),
/// step_end() after each.
template <class C, class Drift, class Kick, class StepEnd>
NYSTROM_ALWAYS_INLINE inline void run_sequential_splitting(const Flow* flows, const C* hc, std::size_t m, long n,
                                                           Drift&& drift, Kick&& kick, StepEnd&& step_end) {
  for (long k = 0; k < n; ++k) {
    for (std::size_t j = 0; j < m; ++j) {
      if (flows[j] == Flow::drift)
        drift(hc[j], j);
      else
        kick(hc[j], j);
    }
    step_end();
  }
}

template <class V, class Force>
class SplittingStepper {
 public:
  using vector_type = V;
  using scalar_type = typename V::value_type;
  using real_type = real_t<scalar_type>;

  /// Whether a compensated run also takes the force's rounding error: with a compensated force, force(q, cq, a, alo)
  /// (takes_carry_v, core/state.hpp), evaluated at q + cq, the drifts and kicks add the exact products of the
  /// coefficients (with their residuals, set_coefficient_residuals) and v + cv or a + alo in double-word arithmetic.
  static constexpr bool carried_force = word_scalar<scalar_type> && takes_carry_v<Force, V>;

  SplittingStepper(SplittingScheme<scalar_type> scheme, Force force, EngineOptions opt = {})
      : scheme_(normalized(scheme)), force_(std::move(force)), opt_(opt) {
    if (scheme_.steps.empty()) throw std::invalid_argument("splitting scheme has no sub-steps");
    for (const auto& s : scheme_.steps)
      if (!is_finite_scalar(s.coef)) throw std::invalid_argument("splitting coefficient is not finite");
    const auto& st = scheme_.steps;
    merged_ = !project_ && st.size() > 1 && st.front().flow == st.back().flow;
    for (const auto& x : st) flows_.push_back(x.flow);
  }

  const SplittingScheme<scalar_type>& scheme() const { return scheme_; }
  /// The coefficients' rounding residuals (exact minus rounded), one per sub-step of scheme(), used by the
  /// compensated run with a compensated force (carried_force); without them that run takes the coefficients as
  /// rounded.
  void set_coefficient_residuals(std::vector<scalar_type> lo) {
    if (lo.size() != scheme_.steps.size())
      throw std::invalid_argument("splitting scheme: one coefficient residual per sub-step is needed");
    for (const auto& x : lo)
      if (!is_finite_scalar(x)) throw std::invalid_argument("splitting coefficient residual is not finite");
    lo_ = std::move(lo);
  }
  long force_evals() const { return evals_; }
  Force& force() { return force_; }
  /// The compensated-summation carries of the run (checkpoint/restart).
  Compensator<V>& compensator() { return comp_; }

  /// Forget the cached force (the next kick evaluates).
  void reset_cache() { cache_valid_ = false; }
  /// Provide a force already known at position q (used by the multi-product engine).
  void seed_force(const V& q, const V& a) {
    resize_like(a_, a);
    assign(a_, a);
    resize_like(aq_, q);
    assign(aq_, q);
    cache_valid_ = true;
    cache_carried_ = false;
  }

  void step(State<V>& s, real_type h) { integrate(s, h, 1); }

  /// n steps of size h.
  void integrate(State<V>& s, real_type h, long n) {
    if (n <= 0) return;
    if (use_compensation<scalar_type>(opt_.compensated)) {
      comp_.begin(s);
      if constexpr (carried_force)
        run_carried(s, h, n, comp_);
      else
        run<true>(s, h, n, comp_);
      comp_.end(s);
    } else {
      run<false>(s, h, n, comp_);
    }
  }

  /// n compensated steps of size h with the caller's carry c (c.begin() is the caller's business;
  /// used by the multi-product engine to obtain each product's increment to full precision).
  void integrate_compensated(State<V>& s, real_type h, long n, Compensator<V>& c) {
    if (n > 0) run<true>(s, h, n, c);
  }

  /// hc[i] = coefficient i times h, in the order of application (the input of advance_scaled).
  void scale_coefficients(real_type h, std::vector<scalar_type>& hc) const {
    const auto& st = scheme_.steps;
    hc.resize(st.size());
    for (std::size_t i = 0; i < st.size(); ++i) hc[i] = st[i].coef * scalar_type(h);
  }

  /// The loop of integrate() on a state x and force cache a held by the caller, with the coefficients
  /// already multiplied by the step size (scale_coefficients): n steps. `valid` says whether a is the
  /// force at x.q and is updated; the force evaluations are counted; the stepper's own cache is not
  /// touched. With Comp, the updates are compensated with the carries cq, cv (else those are unused).
  /// For engines built on this one (MpeStepper), which keep x, a and the carries in locals.
  template <bool Comp>
  NYSTROM_ALWAYS_INLINE void advance_scaled(State<V>& x, V& a, bool& valid, const scalar_type* hc, long n, V& cq,
                                            V& cv) {
    if (n <= 0) return;
    if (!merged_) {
      advance_sequential<Comp>(x, a, valid, hc, n, cq, cv);
      return;
    }
    auto drift = [&](const scalar_type& c) NYSTROM_ALWAYS_INLINE {
      if constexpr (Comp) {
        for (std::size_t j = 0; j < x.q.size(); ++j) compensated_add(x.q[j], cq[j], scalar_type(c * x.v[j]));
      } else {
        axpy(x.q, c, x.v);
      }
    };
    auto kick = [&](const scalar_type& c) NYSTROM_ALWAYS_INLINE {
      if constexpr (Comp) {
        for (std::size_t j = 0; j < x.v.size(); ++j) compensated_add(x.v[j], cv[j], scalar_type(c * a[j]));
      } else {
        axpy(x.v, c, a);
      }
    };
    long evals = 0;
    const auto& st = scheme_.steps;
    const std::size_t m = st.size();
    // Merged steps: every kick follows a drift and evaluates the force, except a first kick that finds a
    // valid cached force.
    const bool kick_first = st.front().flow == Flow::kick;
    bool cached = kick_first && valid;
    run_merged_splitting(
        kick_first, hc, m, n, scalar_type(hc[m - 1] + hc[0]),
        [&](const scalar_type& c, std::size_t) NYSTROM_ALWAYS_INLINE { drift(c); },
        [&](const scalar_type& c, std::size_t) NYSTROM_ALWAYS_INLINE {
          if (cached) {
            cached = false;
          } else {
            force_(x.q, a);
            ++evals;
          }
          kick(c);
        },
        []() NYSTROM_ALWAYS_INLINE {});
    valid = kick_first;
    evals_ += evals;
  }

  /// Whether advance_lockstep can run this scheme (the last sub-step of a step merges with the first
  /// of the next, which every symmetric base of the multi-product engine does).
  bool lockstep_capable() const { return merged_; }

  // f(r) for r = 0 .. P - 1: a run-time loop, or unrolled when P is an integral_constant.
  template <class Count, class Fn>
  NYSTROM_ALWAYS_INLINE static void for_each_run(Count P, Fn&& f) {
    if constexpr (std::is_integral_v<Count>) {
      for (std::size_t r = 0; r < P; ++r) f(r);
    } else {
      [&]<std::size_t... R>(std::index_sequence<R...>) NYSTROM_ALWAYS_INLINE { (f(R), ...); }
      (std::make_index_sequence<Count::value>{});
    }
  }

  // f(r) for r = P - 1 .. 0. The lockstep sub-steps issue the runs in this order: multi-product
  // sequences are ascending, so the run with the most sub-steps (the critical chain of forces) goes
  // first and the processor schedules its operations before the shorter runs' (bench_kepler, M8 step
  // over 10 sequential forces: 0.44-0.49 in this order, 0.51 in ascending order). The runs are independent: the order
  // changes no result.
  template <class Count, class Fn>
  NYSTROM_ALWAYS_INLINE static void for_each_run_reversed(Count P, Fn&& f) {
    if constexpr (std::is_integral_v<Count>) {
      for (std::size_t r = P; r-- > 0;) f(r);
    } else {
      [&]<std::size_t... R>(std::index_sequence<R...>) NYSTROM_ALWAYS_INLINE { (f(Count::value - 1 - R), ...); }
      (std::make_index_sequence<Count::value>{});
    }
  }

  /// P independent runs advanced in lockstep: run r starts from x[r] (force cache a[r], valid when
  /// kick_valid and the scheme starts with a kick), makes n[r] steps with the coefficients hc + r m
  /// (scale_coefficients, m sub-steps), and carries cq[r], cv[r] with Comp. Sub-step pair j of every
  /// run comes before pair j + 1 of any run, so that the processor overlaps the independent chains of
  /// dependent force evaluations (the critical path of the MPE {1,2,3,4} is 4 forces, not 10). Each run
  /// performs exactly the operations of advance_scaled in the same order: the results are bitwise
  /// those of running them one after the other. Requires lockstep_capable().
  /// x, a, cq, cv: pointers or arrays (local arrays of fixed-size states stay in registers); P: a
  /// run-time count or a std::integral_constant, which unrolls the loop over the runs.
  template <bool Comp, class Count, class XS, class AS, class CS>
  NYSTROM_ALWAYS_INLINE void advance_lockstep(Count P, XS&& x, AS&& a, bool kick_valid, const scalar_type* hc,
                                              const long* n, CS&& cq, CS&& cv) {
    const auto& st = scheme_.steps;
    const std::size_t m = st.size();
    const long half = static_cast<long>((m - 1) / 2);  // sub-step pairs per step
    const bool kick_first = st.front().flow == Flow::kick;
    long max_pairs = 0;
    for_each_run(P, [&](std::size_t r) { max_pairs = std::max(max_pairs, n[r] * half); });
    long evals = 0;
    std::size_t i = 0;  // position of the pair in the step: the same for every run
    for (long p = 0; p < max_pairs; ++p) {
      for_each_run_reversed(P, [&](std::size_t r) NYSTROM_ALWAYS_INLINE {
        if (p >= n[r] * half) return;
        const scalar_type* c = hc + r * m;
        State<V>& y = x[r];
        V& ar = a[r];
        // The first sub-step of a step after the first joins the previous step's last one.
        const scalar_type c0 = i == 0 ? (p == 0 ? c[0] : scalar_type(c[m - 1] + c[0])) : c[i];
        if (!kick_first) {
          if constexpr (Comp) {
            for (std::size_t j = 0; j < y.q.size(); ++j) compensated_add(y.q[j], cq[r][j], scalar_type(c0 * y.v[j]));
          } else {
            axpy(y.q, c0, y.v);
          }
        }
        if (!(kick_first && p == 0 && kick_valid)) {
          force_(y.q, ar);
          ++evals;
        }
        const scalar_type& ck = kick_first ? c0 : c[i + 1];
        if constexpr (Comp) {
          for (std::size_t j = 0; j < y.v.size(); ++j) compensated_add(y.v[j], cv[r][j], scalar_type(ck * ar[j]));
        } else {
          axpy(y.v, ck, ar);
        }
        if (kick_first) {
          if constexpr (Comp) {
            for (std::size_t j = 0; j < y.q.size(); ++j)
              compensated_add(y.q[j], cq[r][j], scalar_type(c[i + 1] * y.v[j]));
          } else {
            axpy(y.q, c[i + 1], y.v);
          }
        }
      });
      i += 2;
      if (i + 1 >= m) i = 0;
    }
    // The last sub-step of every run.
    for_each_run(P, [&](std::size_t r) NYSTROM_ALWAYS_INLINE {
      if (n[r] <= 0) return;
      const scalar_type* c = hc + r * m;
      State<V>& y = x[r];
      if (kick_first) {
        force_(y.q, a[r]);
        ++evals;
        if constexpr (Comp) {
          for (std::size_t j = 0; j < y.v.size(); ++j)
            compensated_add(y.v[j], cv[r][j], scalar_type(c[m - 1] * a[r][j]));
        } else {
          axpy(y.v, c[m - 1], a[r]);
        }
      } else {
        if constexpr (Comp) {
          for (std::size_t j = 0; j < y.q.size(); ++j)
            compensated_add(y.q[j], cq[r][j], scalar_type(c[m - 1] * y.v[j]));
        } else {
          axpy(y.q, c[m - 1], y.v);
        }
      }
    });
    evals_ += evals;
  }

  /// A coefficient times the step size as a double-word hi + lo (the compensated run with a compensated force).
  struct Scaled {
    scalar_type hi, lo;
  };

  /// The coefficient c (its rounding residual c_lo) times the step size h + h_lo, as a double-word.
  static Scaled scaled(const scalar_type& c, const scalar_type& c_lo, const scalar_type& h, const scalar_type& h_lo) {
    scalar_type e;
    const scalar_type hi = eft::two_prod(c, h, e);
    return {hi, scalar_type(e + (c * h_lo + c_lo * h))};
  }

  /// The coefficients of scheme() with their residuals times h + h_lo (m sub-steps, appended to out).
  void scale_coefficients_carried(const scalar_type& h, const scalar_type& h_lo, std::vector<Scaled>& out) const {
    const auto& st = scheme_.steps;
    for (std::size_t i = 0; i < st.size(); ++i)
      out.push_back(scaled(st[i].coef, lo_.empty() ? scalar_type(0) : lo_[i], h, h_lo));
  }

  /// The coefficients of the products of a multi-product expansion, product i running k[i] steps of h / k[i] (the
  /// rounded quotient and the exact remainder over k[i], a double-word), product after product (m sub-steps each;
  /// out is replaced).
  void scale_products_carried(const scalar_type& h, const std::vector<long>& k, std::vector<Scaled>& out) const {
    out.clear();
    for (long ki : k) {
      const scalar_type kk = static_cast<scalar_type>(ki), hk = h / kk;
      scalar_type e;
      const scalar_type p = eft::two_prod(hk, kk, e);
      scale_coefficients_carried(hk, scalar_type(((h - p) - e) / kk), out);
    }
  }

  /// One product of a multi-product expansion with a compensated force: n steps with the coefficients hcw
  /// (scale_products_carried) from s with the run's carries cq, cv (and the force there, a0 + a0lo, when the scheme
  /// starts with a kick), through advance_carried; then x + lo is the product's increment (T - s) + (carry_T - cq),
  /// the high part x from an exact two-sum. a, alo: the force cache's buffers. The force evaluations are counted.
  void carried_product(const State<V>& s, const V& cq, const V& cv, const V& a0, const V& a0lo, const Scaled* hcw,
                       long n, State<V>& x, State<V>& lo, V& a, V& alo) requires carried_force {
    x = s;
    lo.q = cq;
    lo.v = cv;
    a = a0;
    alo = a0lo;
    bool valid = scheme_.steps.front().flow == Flow::kick;
    advance_carried(x, a, alo, valid, hcw, n, lo.q, lo.v);
    for (std::size_t j = 0; j < s.q.size(); ++j) {
      scalar_type e;
      x.q[j] = eft::two_sum(x.q[j], scalar_type(-s.q[j]), e);
      lo.q[j] = e + (lo.q[j] - cq[j]);
      x.v[j] = eft::two_sum(x.v[j], scalar_type(-s.v[j]), e);
      lo.v[j] = e + (lo.v[j] - cv[j]);
    }
  }

  /// The compensated run with a compensated force (carried_force) on a state x, force cache a + alo (valid: it is
  /// the force at x.q + cq; updated) and carries cq, cv held by the caller: n steps with the scaled coefficients
  /// hcw (scale_coefficients_carried, m sub-steps). The position q + cq goes to the force, which returns a + alo; a
  /// drift adds c h (v + cv) and a kick c h (a + alo) to the double-word q + cq or v + cv, each product c h v and
  /// c h a exact. Only the force's own rounding (about eps^2 for a compensated force) and the double-word sums'
  /// (about eps^2) are left, so that a long run's error stays at the rounding of its double result where the plain
  /// force's rounding would set a floor about sqrt(force evaluations) times higher. The force evaluations are
  /// counted; the stepper's own cache is not touched. The results do not depend on how the steps are split into
  /// calls.
  void advance_carried(State<V>& x, V& a, V& alo, bool& valid, const Scaled* hcw, long n, V& cq,
                       V& cv) requires carried_force {
    using eft::add_double_word;
    using eft::two_prod;
    using S = scalar_type;
    if (n <= 0) return;
    const auto& st = scheme_.steps;
    const std::size_t m = st.size();
    long evals = 0;
    auto drift = [&](const Scaled& k, std::size_t) NYSTROM_ALWAYS_INLINE {
      for (std::size_t j = 0; j < x.q.size(); ++j) {
        S e;
        const S p = two_prod(k.hi, x.v[j], e);
        add_double_word(x.q[j], cq[j], p, S(e + (k.hi * cv[j] + k.lo * x.v[j])));
      }
      valid = false;
    };
    auto kick = [&](const Scaled& k, std::size_t) NYSTROM_ALWAYS_INLINE {
      if (!valid) {
        force_(x.q, cq, a, alo);
        ++evals;
        valid = true;
      }
      for (std::size_t j = 0; j < x.v.size(); ++j) {
        S e;
        const S p = two_prod(k.hi, a[j], e);
        add_double_word(x.v[j], cv[j], p, S(e + (k.hi * alo[j] + k.lo * a[j])));
      }
    };
    // Sub-step by sub-step, also where the last sub-step of a step and the first of the next are of the same flow:
    // joined into one, their double-word sum would round differently at the ends of a call, and a run split into
    // several calls would not be bitwise one call (the extra sub-step costs no force evaluation).
    run_sequential_splitting(flows_.data(), hcw, m, n, drift, kick, [] {});
    evals_ += evals;
  }

 private:
  /// Sub-steps one after the other: schemes whose steps do not merge, and complex schemes whose state is
  /// projected to real after every step (the arguments as for advance_scaled).
  template <bool Comp>
  void advance_sequential(State<V>& s, V& a_io, bool& valid_io, const scalar_type* hc, long n, V& cq_io, V& cv_io) {
    constexpr bool local = is_std_array<V>::value;  // see run()
    std::conditional_t<local, State<V>, State<V>&> x = s;
    std::conditional_t<local, V, V&> a = a_io, cq = cq_io, cv = cv_io;
    bool valid = valid_io;
    long evals = 0;
    run_sequential_splitting(
        flows_.data(), hc, flows_.size(), n,
        [&](const scalar_type& c, std::size_t) {
          if constexpr (Comp) {
            for (std::size_t j = 0; j < x.q.size(); ++j) compensated_add(x.q[j], cq[j], scalar_type(c * x.v[j]));
          } else {
            axpy(x.q, c, x.v);
          }
          valid = false;
        },
        [&](const scalar_type& c, std::size_t) {
          if (!valid) {
            force_(x.q, a);
            ++evals;
            valid = true;
          }
          if constexpr (Comp) {
            for (std::size_t j = 0; j < x.v.size(); ++j) compensated_add(x.v[j], cv[j], scalar_type(c * a[j]));
          } else {
            axpy(x.v, c, a);
          }
        },
        [&] {
          if (project_) {
            project_real(x.q);
            project_real(x.v);
            if constexpr (Comp) {
              project_real(cq);
              project_real(cv);
            }
            valid = false;
          }
        });
    if constexpr (local) {
      s = x;
      a_io = a;
      if constexpr (Comp) {
        cq_io = cq;
        cv_io = cv;
      }
    }
    valid_io = valid;
    evals_ += evals;
  }

  template <bool Comp>
  void run(State<V>& s, real_type h, long n, Compensator<V>& c) {
    resize_like(a_, s.q);
    check_cache(s.q);
    scale_coefficients(h, hc_);
    // A fixed-size state, force cache and carry are copied into locals for the loop: the caller's
    // state and this object's members could alias as far as the compiler knows, which would force a
    // store and a reload around every sub-step; locals (whose address never escapes) stay in registers.
    constexpr bool local = is_std_array<V>::value;
    std::conditional_t<local, State<V>, State<V>&> x = s;
    std::conditional_t<local, V, V&> a = a_, cq = c.cq, cv = c.cv;
    bool valid = cache_valid_;
    advance_scaled<Comp>(x, a, valid, hc_.data(), n, cq, cv);
    if constexpr (local) {
      s = x;
      a_ = a;
      if constexpr (Comp) {
        c.cq = cq;
        c.cv = cv;
      }
    }
    cache_valid_ = valid;
    cache_carried_ = false;
    remember(s.q);
  }

  // The compensated run with a compensated force (advance_carried) on the stepper's own cache.
  void run_carried(State<V>& s, real_type h, long n, Compensator<V>& c) {
    resize_like(a_, s.q);
    resize_like(alo_, s.q);
    check_cache(s.q);
    if (cache_valid_ && !(cache_carried_ && same_values(acq_, c.cq))) cache_valid_ = false;
    hcw_.clear();
    scale_coefficients_carried(scalar_type(h), scalar_type(0), hcw_);
    constexpr bool local = is_std_array<V>::value;  // see run()
    std::conditional_t<local, State<V>, State<V>&> x = s;
    std::conditional_t<local, V, V&> a = a_, alo = alo_, cq = c.cq, cv = c.cv;
    bool valid = cache_valid_;
    advance_carried(x, a, alo, valid, hcw_.data(), n, cq, cv);
    if constexpr (local) {
      s = x;
      a_ = a;
      alo_ = alo;
      c.cq = cq;
      c.cv = cv;
    }
    cache_valid_ = valid;
    cache_carried_ = valid;
    remember(s.q);
    if (valid) {
      resize_like(acq_, c.cq);
      assign(acq_, c.cq);
    }
  }

  // The cache survives between calls only if the caller did not move q.
  void check_cache(const V& q) {
    if (cache_valid_ && !same_values(aq_, q)) cache_valid_ = false;
  }
  void remember(const V& q) {
    if (cache_valid_) {
      resize_like(aq_, q);
      assign(aq_, q);
    }
  }

  SplittingScheme<scalar_type> scheme_;
  Force force_;
  EngineOptions opt_;
  bool project_ = is_complex_v<scalar_type> && !opt_.keep_complex;  // drop imaginary parts after each step
  bool merged_ = false;      // the last sub-step of a step merges with the first of the next
  std::vector<Flow> flows_;  // the flow of each sub-step
  Compensator<V> comp_;
  V a_{};
  V aq_{};
  bool cache_valid_ = false;
  long evals_ = 0;
  std::vector<scalar_type> hc_;
  // The compensated run with a compensated force: the coefficients' residuals, the scaled coefficients, the force's
  // low part and the carry of the position it was evaluated at (the cache holds a + alo at aq_ + acq_).
  std::vector<scalar_type> lo_;
  std::vector<Scaled> hcw_;
  V alo_{};
  V acq_{};
  bool cache_carried_ = false;
};

}  // namespace nystrom
