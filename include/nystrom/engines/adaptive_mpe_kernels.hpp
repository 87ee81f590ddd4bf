// The trial steps of the adaptive multi-product expansion (engines/adaptive_mpe.hpp): the products of one
// step and their combination into the increment T_2n - s and the error estimate T_2n - T_{2n-2}
// (engines/adaptive_mpe_coefficients.hpp), for the fixed-order controller (trial, trial_verlet) and for order
// control (oc_products, oc_combine).
//
// Cost per step: sum k_i force evaluations (+1 for a base that starts with a kick: the force at q_0,
// shared by all products and kept across a rejected step). The products of a step run in lockstep so
// that the processor overlaps their independent force chains; for std::array states of float, double
// or long double the whole controller loop is compiled per product count (2..8), and for the three-step
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
// (Bases whose steps do not merge run on the state itself, with compensated sub-steps when on.)
// Precise products (Precise = true; AdaptiveMpeIntegrator::precise_products: a compensated run at a tolerance
// near the rounding floor): every addition to a product's increments carries its rounding error (Knuth's
// two-sum) into a carry of the product, the combination takes the carries' differences, and the increment
// comes back as a double-word (inc + low). In double the increments' own additions, not the forces, set the
// floor of the multi-product expansion: the combination multiplies each product's rounding by |c_i| (sum 26 for
// M12). Kepler e = 0.5, 100 periods, M12-adaptive, rms final position error over 12 tolerances 1e-13..3.2e-15:
// 1.0e-11 plain, 2.9e-12 precise (1.3e-12 in long double: the truncation at these steps), at 1.5x the
// instructions per step (1.2-1.6x the time); at larger tolerances truncation dominates and the products stay plain.
#pragma once

#include <algorithm>
#include <cstddef>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "nystrom/core/eft.hpp"
#include "nystrom/core/state.hpp"
#include "nystrom/engines/splitting.hpp"

namespace nystrom {
namespace adaptive_detail {

/// The products of an adaptive MPE and their combination: the sequence k, the coefficients c (order 2n) and
/// d = c - chat (the error combination) in the working type, the base T_2 (a SplittingStepper, whose force
/// count holds the products' forces on the state itself) and the buffers of a step. AdaptiveMpeIntegrator
/// checks the data and runs the controllers on these kernels.
template <class V, class Force>
class MpeKernels {
 public:
  using scalar_type = typename V::value_type;
  using real_type = scalar_type;

 protected:
  // The unrolled loops are compiled for std::array states of float, double and long double (on the x87 stack the
  // run-time loop passes every long double operand through memory, the unrolled one keeps a step in locals).
  // Other scalars (complex, float128, double-double, quad-double, MPFR) and std::vector states run the run-time
  // product count, bitwise the same.
  static constexpr bool fixed_lockstep =
      is_std_array<V>::value && (std::is_same_v<scalar_type, double> || std::is_same_v<scalar_type, float> ||
                                 std::is_same_v<scalar_type, long double>);
  // Precise products need an exact two-sum: the built-in floating types.
  static constexpr bool can_be_precise = std::is_floating_point_v<scalar_type>;

  // f(std::true_type) for precise products (when Allowed and the type can), else f(std::false_type).
  template <bool Allowed, class F>
  NYSTROM_ALWAYS_INLINE static decltype(auto) with_precision(bool precise, F&& f) {
    if constexpr (Allowed && can_be_precise) {
      if (precise) return f(std::true_type{});
    }
    return f(std::false_type{});
  }

  // x += y, the rounding error of the addition into the carry c (Knuth's two-sum; precise products only).
  NYSTROM_ALWAYS_INLINE static void add_with_carry(scalar_type& x, scalar_type& c, const scalar_type& y) {
    scalar_type e;
    x = eft::two_sum(x, y, e);
    c += e;
  }

  MpeKernels(std::vector<long> k, std::vector<scalar_type> c, std::vector<scalar_type> d,
             SplittingScheme<scalar_type> base, Force force)
      : k_(std::move(k)),
        c_(std::move(c)),
        d_(std::move(d)),
        base_(std::move(base), std::move(force), EngineOptions{true, Compensation::off}) {}

  // The layout of the products (once the sequence is checked): the reference product (largest k), the base's
  // steps, the increment form, the schedule, and the products by decreasing k.
  void setup(MpeSchedule schedule) {
    ref_ = static_cast<std::size_t>(std::max_element(k_.begin(), k_.end()) - k_.begin());
    kick_first_ = base_.scheme().steps.front().flow == Flow::kick;
    m_ = base_.scheme().steps.size();
    merged_ = base_.lockstep_capable();
    lockstep_ = merged_ && schedule != MpeSchedule::sequential;
    scaled_.resize(k_.size() * m_);
    by_k_.resize(k_.size());
    for (std::size_t r = 0; r < k_.size(); ++r) by_k_[r] = r;
    std::sort(by_k_.begin(), by_k_.end(), [this](std::size_t x, std::size_t y) { return k_[x] > k_[y]; });
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
  // and in sequence (advance_lockstep is bitwise advance_scaled product after product). Precise (merged
  // bases only): the increments' carries in cq, cv, and inc + low the increment.
  template <bool Comp, bool Precise, class Count, class XS, class AS, class CS>
  NYSTROM_ALWAYS_INLINE void trial(Count P, const State<V>& s, const V& a0, XS& x, AS& a, CS& cq, CS& cv, State<V>& inc,
                                   State<V>& err, State<V>& low) {
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
      advance_increments<Precise>(P, s, x, a, cq, cv);
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
    constexpr bool precise = Precise && can_be_precise;
    SS::for_each_run(P, [&](std::size_t i) NYSTROM_ALWAYS_INLINE {
      if (i == ref) return;
      const scalar_type ci = c_[i], di = d_[i];
      for (std::size_t j = 0; j < n; ++j) {
        scalar_type dq = x[i].q[j] - dref.q[j], dv = x[i].v[j] - dref.v[j];
        if constexpr (precise) {
          dq += cq[i][j] - cq[ref][j];
          dv += cv[i][j] - cv[ref][j];
        }
        inc.q[j] += ci * dq;
        inc.v[j] += ci * dv;
        err.q[j] += di * dq;
        err.v[j] += di * dv;
      }
    });
    for (std::size_t j = 0; j < n; ++j) {
      if constexpr (precise) {
        inc.q[j] = eft::two_sum(dref.q[j], inc.q[j] + cq[ref][j], low.q[j]);
        inc.v[j] = eft::two_sum(dref.v[j], inc.v[j] + cv[ref][j], low.v[j]);
      } else {
        inc.q[j] += dref.q[j];
        inc.v[j] += dref.v[j];
      }
    }
  }

  // The products in increment form: x[r] = (dq, dv) = T_r - s from zero, positions s.q + dq for the
  // forces and velocities s.v + dv for the drifts. The increments are small (O(h)), so their rounding
  // is eps |dq| instead of eps |q|: the combination gets them nearly to full precision at one addition
  // per sub-step (a compensated sum costs four, on the chain of dependent operations). The sub-steps
  // as in SplittingStepper::advance_lockstep (merged steps, pair by pair); every product performs the
  // same operations in the same order in lockstep and in sequence: bitwise the same results.
  template <bool Precise, class Count, class XS, class AS, class CS>
  NYSTROM_ALWAYS_INLINE void advance_increments(Count P, const State<V>& s, XS& x, AS& a, CS& cx, CS& cy) {
    constexpr bool precise = Precise && can_be_precise;
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
        if constexpr (precise) {
          cx[r][j] = scalar_type(0);
          cy[r][j] = scalar_type(0);
        }
      }
    });
    auto drift = [&](std::size_t r, const scalar_type& c) NYSTROM_ALWAYS_INLINE {
      State<V>& y = x[r];
      if constexpr (precise) {
        for (std::size_t j = 0; j < n; ++j) add_with_carry(y.q[j], cx[r][j], c * (s.v[j] + y.v[j]));
      } else {
        for (std::size_t j = 0; j < n; ++j) y.q[j] += c * (s.v[j] + y.v[j]);
      }
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
    auto kick = [&](std::size_t r, const scalar_type& c, const V& ar) NYSTROM_ALWAYS_INLINE {
      State<V>& y = x[r];
      if constexpr (precise) {
        for (std::size_t j = 0; j < n; ++j) add_with_carry(y.v[j], cy[r][j], c * ar[j]);
      } else {
        for (std::size_t j = 0; j < n; ++j) y.v[j] += c * ar[j];
      }
    };
    // Pair p (position i in the step) of product r.
    auto pair = [&](std::size_t r, long p, std::size_t i) NYSTROM_ALWAYS_INLINE {
      const scalar_type* c = hc + r * m;
      const scalar_type c0 = i == 0 ? (p == 0 ? c[0] : scalar_type(c[m - 1] + c[0])) : c[i];
      if (!kick_first) drift(r, c0);
      if (!(kick_first && p == 0)) force(x[r], a[r]);  // a kick-first product starts with a[r] = a0
      kick(r, kick_first ? c0 : c[i + 1], a[r]);
      if (kick_first) drift(r, c[i + 1]);
    };
    auto last = [&](std::size_t r) NYSTROM_ALWAYS_INLINE {
      const scalar_type* c = hc + r * m;
      if (kick_first) {
        force(x[r], a[r]);
        kick(r, c[m - 1], a[r]);
      } else {
        drift(r, c[m - 1]);
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
  // Precise: the increments' carries in local arrays, inc + low the increment (as trial).
  template <std::size_t K, bool Precise>
  NYSTROM_ALWAYS_INLINE long trial_verlet(const State<V>& s, const V& a0, const real_type& h, State<V>& inc,
                                          State<V>& err, State<V>& low) {
    constexpr bool precise = Precise && can_be_precise;
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
    scalar_type cq[precise ? K : 1][precise ? D : 1], cv[precise ? K : 1][precise ? D : 1];
    long evals = 0;
    auto force = [&](std::size_t r) NYSTROM_ALWAYS_INLINE {
      V q, ar;
      for (std::size_t j = 0; j < D; ++j) q[j] = s.q[j] + dq[r][j];
      base_.force()(q, ar);
      for (std::size_t j = 0; j < D; ++j) a[r][j] = ar[j];
      ++evals;
    };
    auto drift = [&](std::size_t r, const scalar_type& c) NYSTROM_ALWAYS_INLINE {
      if constexpr (precise) {
        for (std::size_t j = 0; j < D; ++j) add_with_carry(dq[r][j], cq[r][j], c * (s.v[j] + dv[r][j]));
      } else {
        for (std::size_t j = 0; j < D; ++j) dq[r][j] += c * (s.v[j] + dv[r][j]);
      }
    };
    auto kick = [&](std::size_t r, const scalar_type& c) NYSTROM_ALWAYS_INLINE {
      if constexpr (precise) {
        for (std::size_t j = 0; j < D; ++j) add_with_carry(dv[r][j], cv[r][j], c * a[r][j]);
      } else {
        for (std::size_t j = 0; j < D; ++j) dv[r][j] += c * a[r][j];
      }
    };
    for (std::size_t r = 0; r < K; ++r)
      for (std::size_t j = 0; j < D; ++j) {
        dq[r][j] = scalar_type(0);
        dv[r][j] = scalar_type(0);
        a[r][j] = kick_first ? a0[j] : scalar_type(0);
        if constexpr (precise) {
          cq[r][j] = scalar_type(0);
          cv[r][j] = scalar_type(0);
        }
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
        scalar_type eq = dq[i][j] - dq[ref][j], ev = dv[i][j] - dv[ref][j];
        if constexpr (precise) {
          eq += cq[i][j] - cq[ref][j];
          ev += cv[i][j] - cv[ref][j];
        }
        inc.q[j] += ci * eq;
        inc.v[j] += ci * ev;
        err.q[j] += di * eq;
        err.v[j] += di * ev;
      }
    }
    for (std::size_t j = 0; j < D; ++j) {
      if constexpr (precise) {
        inc.q[j] = eft::two_sum(dq[ref][j], inc.q[j] + cq[ref][j], low.q[j]);
        inc.v[j] = eft::two_sum(dv[ref][j], inc.v[j] + cv[ref][j], low.v[j]);
      } else {
        inc.q[j] += dq[ref][j];
        inc.v[j] += dv[ref][j];
      }
    }
    return evals;
  }

  // ---- order control (AdaptiveMpeIntegrator::run_oc) -------------------------------------------------------

  // The increments and forces of the products of one step: local arrays for fixed-size states (nothing of the
  // step in memory that the force functor could alias, as in trial_verlet: the unrolled step keeps them in
  // registers; measured on Kepler e = 0.9, the products in std::array<State<V>, 8> made a step twice as slow)
  // or the member buffers.
  // Cq, Cv: the carries of the increments (precise products).
  template <bool Precise>
  struct LocalProducts {
    static constexpr std::size_t D = fixed_lockstep ? std::tuple_size<V>::value : 1;
    static constexpr std::size_t DC = Precise ? D : 1;
    static constexpr bool precise = Precise, local = true;
    scalar_type dq[8][D], dv[8][D], a[8][D], cdq[8][DC], cdv[8][DC];
    scalar_type& q(std::size_t r, std::size_t j) { return dq[r][j]; }
    scalar_type& v(std::size_t r, std::size_t j) { return dv[r][j]; }
    scalar_type& acc(std::size_t r, std::size_t j) { return a[r][j]; }
    scalar_type& cq(std::size_t r, std::size_t j) { return cdq[r][j]; }
    scalar_type& cv(std::size_t r, std::size_t j) { return cdv[r][j]; }
    const scalar_type& q(std::size_t r, std::size_t j) const { return dq[r][j]; }
    const scalar_type& v(std::size_t r, std::size_t j) const { return dv[r][j]; }
    const scalar_type& cq(std::size_t r, std::size_t j) const { return cdq[r][j]; }
    const scalar_type& cv(std::size_t r, std::size_t j) const { return cdv[r][j]; }
  };
  template <bool Precise>
  struct MemberProducts {
    static constexpr bool precise = Precise, local = false;
    std::vector<State<V>>& x;
    std::vector<V>& as;
    std::vector<V>& cqs;
    std::vector<V>& cvs;
    scalar_type& q(std::size_t r, std::size_t j) { return x[r].q[j]; }
    scalar_type& v(std::size_t r, std::size_t j) { return x[r].v[j]; }
    scalar_type& acc(std::size_t r, std::size_t j) { return as[r][j]; }
    scalar_type& cq(std::size_t r, std::size_t j) { return cqs[r][j]; }
    scalar_type& cv(std::size_t r, std::size_t j) { return cvs[r][j]; }
    const scalar_type& q(std::size_t r, std::size_t j) const { return x[r].q[j]; }
    const scalar_type& v(std::size_t r, std::size_t j) const { return x[r].v[j]; }
    const scalar_type& cq(std::size_t r, std::size_t j) const { return cqs[r][j]; }
    const scalar_type& cv(std::size_t r, std::size_t j) const { return cvs[r][j]; }
  };

  // The products k = 1..N of a step from s in increment form (product r: k = r + 1), products 1..N-1 complete
  // before the last pair of product N; then check(x) (true: go on), and after product N done(x). The same
  // operations per product as trial_verlet (bitwise the same increments). Returns the forces evaluated.
  template <bool Precise, class Count, class XS, class Check, class Done>
  NYSTROM_ALWAYS_INLINE long oc_products(Count N, const State<V>& s, const V& a0, const real_type& h, XS& x,
                                         Check&& check, Done&& done) {
    constexpr bool precise = Precise && can_be_precise;
    const std::size_t n = s.q.size();
    const auto& st = base_.scheme().steps;
    const scalar_type b0 = st[0].coef, b1 = st[1].coef, b2 = st[2].coef;
    const bool kick_first = kick_first_;
    constexpr bool local = XS::local;
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
        if constexpr (precise) {
          x.cq(r, j) = scalar_type(0);
          x.cv(r, j) = scalar_type(0);
        }
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
      if constexpr (precise) {
        for (std::size_t j = 0; j < n; ++j) add_with_carry(x.q(r, j), x.cq(r, j), c * (s.v[j] + x.v(r, j)));
      } else {
        for (std::size_t j = 0; j < n; ++j) x.q(r, j) += c * (s.v[j] + x.v(r, j));
      }
    };
    auto kick = [&](std::size_t r, const scalar_type& c) NYSTROM_ALWAYS_INLINE {
      if constexpr (precise) {
        for (std::size_t j = 0; j < n; ++j) add_with_carry(x.v(r, j), x.cv(r, j), c * x.acc(r, j));
      } else {
        for (std::size_t j = 0; j < n; ++j) x.v(r, j) += c * x.acc(r, j);
      }
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

  // inc = T_2n - s and err = T_2n - T_{2n-2} from the increments of products 1..n, as in trial_verlet
  // (precise: with the carries, and inc + low the increment).
  template <bool Precise, class XS>
  NYSTROM_ALWAYS_INLINE void oc_combine(std::size_t nprod, const XS& x, State<V>& inc, State<V>& err,
                                        State<V>& low) const {
    constexpr bool precise = Precise && can_be_precise;
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
        scalar_type eq = x.q(i, j) - x.q(ref, j), ev = x.v(i, j) - x.v(ref, j);
        if constexpr (precise) {
          eq += x.cq(i, j) - x.cq(ref, j);
          ev += x.cv(i, j) - x.cv(ref, j);
        }
        inc.q[j] += ci * eq;
        inc.v[j] += ci * ev;
        err.q[j] += di * eq;
        err.v[j] += di * ev;
      }
    }
    for (std::size_t j = 0; j < n; ++j) {
      if constexpr (precise) {
        inc.q[j] = eft::two_sum(x.q(ref, j), inc.q[j] + x.cq(ref, j), low.q[j]);
        inc.v[j] = eft::two_sum(x.v(ref, j), inc.v[j] + x.cv(ref, j), low.v[j]);
      } else {
        inc.q[j] += x.q(ref, j);
        inc.v[j] += x.v(ref, j);
      }
    }
  }

  // The products of one step, unrolled for fixed-size states (see LocalProducts).
  template <bool Precise, class Check, class Done>
  NYSTROM_ALWAYS_INLINE long oc_dispatch(int nprod, const State<V>& s, const V& a0, const real_type& h, Check&& check,
                                         Done&& done) {
    if constexpr (fixed_lockstep) {
      LocalProducts<Precise> x;
      switch (nprod) {
        case 2: return oc_products<Precise>(std::integral_constant<std::size_t, 2>{}, s, a0, h, x, check, done);
        case 3: return oc_products<Precise>(std::integral_constant<std::size_t, 3>{}, s, a0, h, x, check, done);
        case 4: return oc_products<Precise>(std::integral_constant<std::size_t, 4>{}, s, a0, h, x, check, done);
        case 5: return oc_products<Precise>(std::integral_constant<std::size_t, 5>{}, s, a0, h, x, check, done);
        case 6: return oc_products<Precise>(std::integral_constant<std::size_t, 6>{}, s, a0, h, x, check, done);
        case 7: return oc_products<Precise>(std::integral_constant<std::size_t, 7>{}, s, a0, h, x, check, done);
        default: return oc_products<Precise>(std::integral_constant<std::size_t, 8>{}, s, a0, h, x, check, done);
      }
    } else {
      MemberProducts<Precise> x{xs_, as_, cqs_, cvs_};
      return oc_products<Precise>(static_cast<std::size_t>(nprod), s, a0, h, x, check, done);
    }
  }

  // The products with a compensated force, force(q, cq, a, alo) (SplittingStepper::carried_force), as the
  // fixed-step engine's carried steps (engines/mpe.hpp): each product starts from s with the run's carries ccq, ccv
  // and runs the base's double-word drifts and kicks (SplittingStepper::carried_product; the base's coefficients
  // times h / k_i as double-words, the force at q + cq with its low part), its increment a double-word. Then
  // inc + low = T_2n - s (the reference increment and, as its low part, the combination of the products'
  // differences) and err = T_2n - T_{2n-2}. The products' forces count in the base; returns the forces at s
  // (kick-first bases), which the caller counts.
  static constexpr bool carried_force = SplittingStepper<V, Force>::carried_force;
  long trial_carried(const State<V>& s, const V& ccq, const V& ccv, const real_type& h, State<V>& inc, State<V>& err,
                     State<V>& low) requires carried_force {
    using S = scalar_type;
    const std::size_t P = k_.size(), n = s.q.size();
    base_.scale_products_carried(S(h), k_, carried_);
    cx_.resize(P);
    clo_.resize(P);
    resize_like(ca0_, s.q);
    resize_like(ca0lo_, s.q);
    long at_s = 0;
    if (kick_first_) {
      base_.force()(s.q, ccq, ca0_, ca0lo_);
      ++at_s;
    }
    for (std::size_t i = 0; i < P; ++i)
      base_.carried_product(s, ccq, ccv, ca0_, ca0lo_, carried_.data() + i * m_, k_[i], cx_[i], clo_[i], ca_, calo_);
    const State<V>& xr = cx_[ref_];
    const State<V>& lr = clo_[ref_];
    for (std::size_t j = 0; j < n; ++j) {
      S dq = 0, dv = 0, eq = 0, ev = 0;
      for (std::size_t i = 0; i < P; ++i) {
        if (i == ref_) continue;
        const S xq = (cx_[i].q[j] - xr.q[j]) + (clo_[i].q[j] - lr.q[j]);
        const S xv = (cx_[i].v[j] - xr.v[j]) + (clo_[i].v[j] - lr.v[j]);
        dq += c_[i] * xq;
        dv += c_[i] * xv;
        eq += d_[i] * xq;
        ev += d_[i] * xv;
      }
      inc.q[j] = xr.q[j];
      inc.v[j] = xr.v[j];
      low.q[j] = lr.q[j] + dq;
      low.v[j] = lr.v[j] + dv;
      err.q[j] = eq;
      err.v[j] = ev;
    }
    return at_s;
  }

  std::vector<long> k_;
  std::vector<scalar_type> c_, d_;
  SplittingStepper<V, Force> base_;
  std::size_t ref_ = 0, m_ = 0;
  bool kick_first_ = false, lockstep_ = false;
  bool merged_ = false;  // the base's steps merge (every symmetric base): the increment form applies
  long own_evals_ = 0;   // forces of the products in increment form
  V qbuf_{};
  std::vector<State<V>> xs_;
  std::vector<V> as_, cqs_, cvs_;
  std::vector<scalar_type> scaled_;
  std::vector<std::size_t> by_k_;              // product indices by decreasing k (trial_verlet's issue order)
  std::vector<std::vector<scalar_type>> occ_;  // order control: the coefficients of T_2n over k = 1..n
  std::vector<std::vector<scalar_type>> ocd_;  // order control: T_2n - T_{2n-2} over k = 1..n
  // trial_carried: the double-word coefficients of the products, their states and their carries, the force at the
  // step's start (high and low parts) and the products' force buffers
  std::vector<typename SplittingStepper<V, Force>::Scaled> carried_;
  std::vector<State<V>> cx_, clo_;
  V ca0_{}, ca0lo_{}, ca_{}, calo_{};
};

}  // namespace adaptive_detail
}  // namespace nystrom
