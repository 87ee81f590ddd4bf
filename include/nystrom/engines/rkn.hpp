// The explicit Runge-Kutta-Nyström engine, form (2.1) of the Gürkan paper:
//
//   y_i     = q_n + c_i h v_n + h^2 sum_{j<i} a_ij f(y_j)
//   q_{n+1} = q_n + h v_n + h^2 sum_i b_i f(y_i)
//   v_{n+1} = v_n + h sum_i B_i f(y_i)
//
// Any explicit RKN tableau runs here, including the force-consolidated methods of the Chin
// paper (Nyström 4, M4, the 5-force M6, Albrecht A6, A'), which are tableaux too.
// First-same-as-last is detected from the tableau (stage 1 at q_n, last stage at q_{n+1}): the last
// stage is evaluated at the step's result itself, and the reused force is checked against the state it
// was evaluated at.
// An optional embedded solution (bhat, Bhat) gives an error estimate for step control. The compensated steps of
// step control (step_with_error with carries) keep their rounding below the force's in double and float
// (precise_update). A compensated force, force(q, cq, a, alo) (takes_carry_v; CompensatedKeplerForce), takes them
// below that: the stage positions in double-word with the residuals of the rounded c_i, the weights' residuals, the
// force's rounding error in the sums, and the velocity's sum as a compensated dot product.
//
// A general (RKNG) tableau (RknTableau::general()) also integrates a velocity-dependent force,
// force(q, v, a): the stages are evaluated at (y_i, w_i) with w_i = v_n + h sum_{j<i} av_ij f_j
// (Hairer, Norsett & Wanner I, sec. II.14). A tableau without velocity coefficients refuses such a force.
#pragma once

#include <cmath>
#include <cstddef>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "nystrom/core/eft.hpp"
#include "nystrom/core/state.hpp"
#include "nystrom/methods/rkn_tableau.hpp"

namespace nystrom {

template <class V, class Force>
class RknStepper {
 public:
  using vector_type = V;
  using scalar_type = typename V::value_type;
  using real_type = real_t<scalar_type>;

  /// Whether the force takes the velocity (force(q, v, a)).
  static constexpr bool velocity_dependent = takes_velocity_v<Force, V>;
  /// Whether a compensated step with an error estimate is made in double-word arithmetic (precise_update).
  static constexpr bool precise_capable = word_scalar<scalar_type> && !velocity_dependent;
  /// Whether the precise update also takes the force's rounding error: a compensated force, force(q, cq, a, alo)
  /// (takes_carry_v), evaluated at the stage positions with their low parts.
  static constexpr bool carried_force = precise_capable && takes_carry_v<Force, V>;

  RknStepper(RknTableau<scalar_type> t, Force force, EngineOptions opt = {})
      : t_(std::move(t)), force_(std::move(force)), opt_(opt) {
    t_.validate();
    if (velocity_dependent && !t_.general())
      throw std::invalid_argument(
          "this RKN tableau has no velocity coefficients: it cannot integrate a velocity-dependent force");
    fsal_ = t_.fsal();
    const std::size_t s = t_.stages();
    // For a velocity-dependent force the last stage is at (q_{n+1}, v_{n+1}) only if its velocity weight is 0.
    if (velocity_dependent && fsal_ && !(t_.B[s - 1] == scalar_type(0))) fsal_ = false;
    for (std::size_t i = 0; i < s; ++i)
      for (std::size_t j = 0; j < i; ++j) {
        if (!(t_.a[i][j] == scalar_type(0))) nz_.push_back({i, j, t_.a[i][j]});
        if (velocity_dependent && !(t_.av[i][j] == scalar_type(0))) nzv_.push_back({i, j, t_.av[i][j]});
      }
    f_.resize(s);
    if constexpr (carried_force) fl_.resize(s);
    if constexpr (precise_capable) {
      // The update in difference form needs sum b = 1/2 and sum B = 1 (every method of order 2 or more).
      precise_ = weight_sum_is(t_.b, scalar_type(0.5)) && weight_sum_is(t_.B, scalar_type(1));
    }
  }

  const RknTableau<scalar_type>& tableau() const { return t_; }
  long force_evals() const { return evals_; }
  Force& force() { return force_; }
  /// The compensated-summation carries of the run (checkpoint/restart).
  Compensator<V>& compensator() { return comp_; }
  void reset_cache() { cache_valid_ = false; }

  void step(State<V>& s, real_type h) { integrate(s, h, 1); }

  void integrate(State<V>& s, real_type h, long n) {
    if (n <= 0) return;
    // A fixed-size state (and carry) is copied into a local for the loop (one_step is inlined here):
    // the caller's state could alias this object's members as far as the compiler knows, which would
    // force stores and reloads around every stage; a local stays in registers.
    constexpr bool local = is_std_array<V>::value;
    std::conditional_t<local, State<V>, State<V>&> x = s;
    if (use_compensation<scalar_type>(opt_.compensated)) {
      comp_.begin(s);
      std::conditional_t<local, Compensator<V>, Compensator<V>&> c = comp_;
      for (long k = 0; k < n; ++k) one_step(x, h, nullptr, &c);
      if constexpr (local) {
        s = x;
        comp_ = c;
      }
      comp_.end(s);
    } else {
      for (long k = 0; k < n; ++k) one_step(x, h, nullptr, nullptr);
      if constexpr (local) s = x;
    }
  }

  /// One step that also returns the embedded error estimate (q, v) in err (if the tableau has one).
  /// (Not compensated.)
  void step_with_error(State<V>& s, real_type h, State<V>& err) { one_step(s, h, &err, nullptr); }
  /// The same, the increments added to s with compensated summation with the carries of comp (the caller
  /// keeps the carries of the last accepted step).
  void step_with_error(State<V>& s, real_type h, State<V>& err, Compensator<V>& comp) { one_step(s, h, &err, &comp); }
  /// The second (lower-order) error estimate of the last step_with_error, for a tableau with blow, Blow.
  const State<V>& low_error() const { return err_low_; }

 private:
  struct Nz {
    std::size_t i, j;
    scalar_type a;
  };

  NYSTROM_ALWAYS_INLINE void one_step(State<V>& st, real_type hr, State<V>* err, Compensator<V>* comp) {
    const std::size_t s = t_.stages();
    const scalar_type h(hr), h2 = h * h;
    for (auto& f : f_) resize_like(f, st.q);
    resize_like(y_, st.q);
    if constexpr (carried_force) {
      for (auto& f : fl_) resize_like(f, st.q);
      resize_like(ylo_, st.q);
    }
    // The stage position and the increments: locals if fixed-size (see integrate).
    constexpr bool local = is_std_array<V>::value;
    std::conditional_t<local, V, V&> y = y_, dq = dq_, dv = dv_;
    const bool project = is_complex_v<scalar_type> && !opt_.keep_complex;
    const bool precise = precise_capable && precise_ && comp && err;
    std::size_t k = 0, kv = 0;  // indices into nz_ and nzv_, ordered by stage
    if constexpr (velocity_dependent) resize_like(w_, st.v);
    // First same as last: the last stage is the step's result (q_{n+1}, and v_{n+1} for a velocity-dependent
    // force), so it is evaluated there, after the update: the force reused by the next step is then that of the
    // state itself, and a run restarted from a checkpoint (which holds the state, not the force) recomputes it
    // bitwise.
    const bool at_end = fsal_ && !project;
    const std::size_t ns = at_end ? s - 1 : s;
    for (std::size_t i = 0; i < ns; ++i) {
      if (i == 0 && fsal_ && cache_valid_) {
        // f_[0] holds the force at the end of the last step, f_[s-1] the one at its start (a step that the
        // controller rejected starts there again).
        bool reuse = same_values(aq_, st.q) && (!velocity_dependent || same_values(av_, st.v));
        if (!reuse && same_values(sq_, st.q) && (!velocity_dependent || same_values(sv_, st.v))) {
          std::swap(f_[0], f_[s - 1]);
          if constexpr (carried_force) std::swap(fl_[0], fl_[s - 1]);
          reuse = true;
        }
        if (reuse) {
          while (k < nz_.size() && nz_[k].i == 0) ++k;
          while (kv < nzv_.size() && nzv_[kv].i == 0) ++kv;
          continue;  // f_[0] already holds the force at (q_n, v_n)
        }
      }
      // The stage position; in a precise step its increment first, with the position's carry, then q (not the
      // first stage: its force is the one first-same-as-last evaluates at q itself, also after a restart). A
      // compensated force takes the stage position in double-word: q + c_i h v with c_i's residual and exact
      // products, plus the carry and the small terms h^2 sum_j a_ij f_j; the first stage's is q + cq, as at the
      // end of a step (carried_force_at).
      if constexpr (carried_force) {
        if (precise) {
          assign(y, comp->cq);
          for (; k < nz_.size() && nz_[k].i == i; ++k) axpy(y, nz_[k].a * h2, f_[nz_[k].j]);
          scalar_type che;
          const scalar_type ch = eft::two_prod(t_.c[i], h, che);
          if (!t_.c_lo.empty()) che += t_.c_lo[i] * h;
          for (std::size_t j = 0; j < y.size(); ++j) {
            scalar_type pe, se;
            const scalar_type p = eft::two_prod(ch, st.v[j], pe);
            const scalar_type hi = eft::two_sum(st.q[j], p, se);
            y[j] = eft::fast_two_sum(hi, se + (pe + che * st.v[j]) + y[j], ylo_[j]);
          }
          force_(static_cast<const V&>(y), static_cast<const V&>(ylo_), f_[i], fl_[i]);
          ++evals_;
          continue;
        }
      }
      const bool carried = precise && i > 0;
      assign(y, carried ? comp->cq : st.q);
      if (!(t_.c[i] == scalar_type(0))) axpy(y, t_.c[i] * h, st.v);
      for (; k < nz_.size() && nz_[k].i == i; ++k) axpy(y, nz_[k].a * h2, f_[nz_[k].j]);
      if (carried)
        for (std::size_t j = 0; j < y.size(); ++j) y[j] += st.q[j];
      if constexpr (velocity_dependent) {
        assign(w_, st.v);
        for (; kv < nzv_.size() && nzv_[kv].i == i; ++kv) axpy(w_, nzv_[kv].a * h, f_[nzv_[kv].j]);
        force_(static_cast<const V&>(y), static_cast<const V&>(w_), f_[i]);
      } else {
        force_(y, f_[i]);
        if constexpr (carried_force) zero_like(fl_[i], st.q);
      }
      ++evals_;
    }
    if (at_end) {  // the start of the step, whose force f_[0] is kept (see the stage loop)
      resize_like(sq_, st.q);
      assign(sq_, st.q);
      if constexpr (velocity_dependent) {
        resize_like(sv_, st.v);
        assign(sv_, st.v);
      }
    }
    // The increments: q's first (b_s = 0 for a first-same-as-last tableau), then, for a force of the position
    // only, the last stage at q_{n+1} and v's with it; for a velocity-dependent force v's first (B_s = 0 is
    // required, see the constructor) and the last stage at (q_{n+1}, v_{n+1}).
    auto last_stage = [&] {
      if constexpr (carried_force) {
        if (precise) {
          assign(y, comp->cq);
          carried_force_at(st.q, y, s - 1);
          return;
        }
      }
      if constexpr (velocity_dependent)
        force_(static_cast<const V&>(st.q), static_cast<const V&>(st.v), f_[s - 1]);
      else
        force_(static_cast<const V&>(st.q), f_[s - 1]);
      if constexpr (carried_force) zero_like(fl_[s - 1], st.q);
      ++evals_;
    };
    const bool v_first = at_end && velocity_dependent;
    bool updated = false;
    if constexpr (precise_capable) {
      if (precise) {
        precise_update(st, *comp, h, h2, ns, at_end, last_stage);
        updated = true;
      }
    }
    if (updated) {
      // done
    } else if (comp) {
      // One increment per step for q and for v, added with compensation.
      resize_like(dq, st.q);
      resize_like(dv, st.q);
      for (std::size_t j = 0; j < st.q.size(); ++j) {
        dq[j] = scalar_type(0);
        dv[j] = scalar_type(0);
      }
      for (std::size_t i = 0; i < ns; ++i)
        if (!(t_.b[i] == scalar_type(0))) axpy(dq, t_.b[i] * h2, f_[i]);
      axpy(dq, h, st.v);
      if (v_first) {
        for (std::size_t i = 0; i < ns; ++i)
          if (!(t_.B[i] == scalar_type(0))) axpy(dv, t_.B[i] * h, f_[i]);
        comp->add_q(st.q, dq);
        comp->add_v(st.v, dv);
        last_stage();
      } else {
        comp->add_q(st.q, dq);
        if (at_end) last_stage();
        for (std::size_t i = 0; i < s; ++i)
          if (!(t_.B[i] == scalar_type(0))) axpy(dv, t_.B[i] * h, f_[i]);
        comp->add_v(st.v, dv);
      }
    } else {
      axpy(st.q, h, st.v);
      for (std::size_t i = 0; i < ns; ++i)
        if (!(t_.b[i] == scalar_type(0))) axpy(st.q, t_.b[i] * h2, f_[i]);
      if (at_end && !v_first) last_stage();
      for (std::size_t i = 0; i < (v_first ? ns : s); ++i)
        if (!(t_.B[i] == scalar_type(0))) axpy(st.v, t_.B[i] * h, f_[i]);
      if (v_first) last_stage();
    }
    if (err) {
      // The difference of the main solution and an embedded one (weights wq, wv; none: zero).
      auto difference = [&](State<V>& e, const std::vector<scalar_type>& wq, const std::vector<scalar_type>& wv) {
        resize_like(e.q, st.q);
        resize_like(e.v, st.q);
        for (auto& x : e.q) x = scalar_type(0);
        for (auto& x : e.v) x = scalar_type(0);
        if (!wq.empty())
          for (std::size_t i = 0; i < s; ++i) {
            axpy(e.q, (t_.b[i] - wq[i]) * h2, f_[i]);
            axpy(e.v, (t_.B[i] - wv[i]) * h, f_[i]);
          }
      };
      difference(*err, t_.bhat, t_.Bhat);
      if (!t_.blow.empty()) difference(err_low_, t_.blow, t_.Blow);
    }
    if (project) {
      project_real(st.q);
      project_real(st.v);
      if (comp) {
        project_real(comp->cq);
        project_real(comp->cv);
      }
    }
    if (at_end) {
      // The last stage was evaluated at the step's result: the next step's first force.
      std::swap(f_[0], f_[s - 1]);
      if constexpr (carried_force) std::swap(fl_[0], fl_[s - 1]);
      resize_like(aq_, st.q);
      assign(aq_, st.q);
      if constexpr (velocity_dependent) {
        resize_like(av_, st.v);
        assign(av_, st.v);
      }
      cache_valid_ = true;
    } else {
      cache_valid_ = false;
    }
  }

  // The update of a compensated step with an error estimate, its rounding kept below the force's (Kepler over 100
  // periods in double, DP12-adaptive at tolerances 1.8e-14..2.5e-15: the position error's rms falls from 2.5e-12
  // to 4.3e-13 at e = 0.5 and from 3.0e-12 to 9.6e-13 at e = 0.9, where the same steps in long double score
  // 3.5e-13 and 6.8e-13: what remains is truncation). The weighted sums in difference form,
  //   sum_i B_i f_i = f_1 + sum_{i>1} B_i (f_i - f_1),   sum_i b_i f_i = f_1 / 2 + sum_{i>1} b_i (f_i - f_1),
  // so that the weights' rounding touches only the small differences and sum b = 1/2, sum B = 1 hold exactly
  // (rounded weights bias every step the same way); the large terms h v, h^2 f_1 / 2 and h f_1 as exact
  // products; q and v with their carries as double-word sums (two-sums, then the low parts), the velocity's
  // carry entering the position's increment. The stage positions carry the position's carry (stage loop).
  template <class LastStage>
  NYSTROM_ALWAYS_INLINE void precise_update(State<V>& st, Compensator<V>& c, scalar_type h, scalar_type h2,
                                            std::size_t ns, bool at_end, LastStage& last_stage) {
    using eft::two_prod;
    using eft::two_sum;
    const std::size_t s = t_.stages(), n = st.q.size();
    const bool residuals = carried_force && !t_.b_lo.empty() && !t_.B_lo.empty();
    scalar_type h2e;
    two_prod(h, h, h2e);
    const scalar_type hh = scalar_type(0.5) * h2, hhe = scalar_type(0.5) * h2e;
    for (std::size_t j = 0; j < n; ++j) {
      const scalar_type f1 = f_[0][j];
      scalar_type sb = 0, sbl = 0, f1l = 0;  // sbl: sum of the weights' residuals times the differences
      if constexpr (carried_force) f1l = fl_[0][j];
      for (std::size_t i = 1; i < ns; ++i) {
        scalar_type d = f_[i][j] - f1;
        if constexpr (carried_force) {
          d += fl_[i][j] - f1l;
          if (residuals) sbl += t_.b_lo[i] * d;
        }
        sb += t_.b[i] * d;
      }
      scalar_type e1, e2, e3, e4;
      const scalar_type p1 = two_prod(h, st.v[j], e1);
      const scalar_type p2 = two_prod(hh, f1, e2);
      const scalar_type s1 = two_sum(st.q[j], p1, e3);
      const scalar_type s2 = two_sum(s1, p2, e4);
      scalar_type low = (e3 + e4) + (c.cq[j] + (e1 + e2));
      if constexpr (carried_force)
        low += hhe * f1 + hh * f1l + h * c.cv[j] + h2 * sb + h2 * sbl;
      else
        low += hhe * f1 + h * c.cv[j] + h2 * sb;
      st.q[j] = two_sum(s2, low, c.cq[j]);
    }
    if (at_end) last_stage();
    for (std::size_t j = 0; j < n; ++j) {
      const scalar_type f1 = f_[0][j];
      scalar_type e1, e2;
      const scalar_type p = two_prod(h, f1, e1);
      const scalar_type s1 = two_sum(st.v[j], p, e2);
      scalar_type low = e2 + (c.cv[j] + e1);
      if constexpr (carried_force) {
        // With a compensated force, sum_{i>1} B_i (f_i - f_1) as a compensated dot product (Ogita, Rump and
        // Oishi's Dot2) and h times it as an exact product: the velocity's increment is then rounded at the
        // working precision squared, its rounding no longer a random walk of the energy.
        const scalar_type f1l = fl_[0][j];
        scalar_type sB = 0, sBl = 0;
        for (std::size_t i = 1; i < s; ++i) {
          scalar_type de, pe, se;
          const scalar_type d = two_sum(f_[i][j], -f1, de);
          const scalar_type dl = de + (fl_[i][j] - f1l);
          const scalar_type pr = two_prod(t_.B[i], d, pe);
          sB = two_sum(sB, pr, se);
          sBl += se + pe + t_.B[i] * dl;
          if (residuals) sBl += t_.B_lo[i] * d;
        }
        scalar_type hse, e3;
        const scalar_type hs = two_prod(h, sB, hse);
        const scalar_type s2 = two_sum(s1, hs, e3);
        low += e3 + (h * f1l + hse + h * sBl);
        st.v[j] = two_sum(s2, low, c.cv[j]);
      } else {
        scalar_type sB = 0;
        for (std::size_t i = 1; i < s; ++i) sB += t_.B[i] * (f_[i][j] - f1);
        low += h * sB;
        st.v[j] = two_sum(s1, low, c.cv[j]);
      }
    }
  }

  // The compensated force at the stage position q + y (y its increment with the position's carry), split by a
  // two-sum into the high part (in y) and the low part, into stage i's force and its rounding error.
  NYSTROM_ALWAYS_INLINE void carried_force_at(const V& q, V& y, std::size_t i) {
    for (std::size_t j = 0; j < y.size(); ++j) y[j] = eft::two_sum(q[j], y[j], ylo_[j]);
    force_(static_cast<const V&>(y), static_cast<const V&>(ylo_), f_[i], fl_[i]);
    ++evals_;
  }
  static void zero_like(V& x, const V& like) {
    resize_like(x, like);
    for (auto& e : x) e = scalar_type(0);
  }

  // Whether the weights sum to target up to their rounding (an error-free sum).
  static bool weight_sum_is(const std::vector<scalar_type>& w, scalar_type target) {
    scalar_type hi = 0, lo = 0;
    for (const auto& x : w) {
      scalar_type e;
      hi = eft::two_sum(hi, x, e);
      lo += e;
    }
    using std::abs;
    return abs((target - hi) - lo) <= scalar_type(64) * std::numeric_limits<scalar_type>::epsilon();
  }

  RknTableau<scalar_type> t_;
  Force force_;
  EngineOptions opt_;
  bool fsal_ = false;
  std::vector<Nz> nz_, nzv_;
  std::vector<V> f_;
  std::vector<V> fl_;  // a compensated force's rounding errors (carried_force)
  V y_{}, w_{}, ylo_{};
  V aq_{}, av_{};  // the end of the last step (its force is f_[0])
  V sq_{}, sv_{};  // its start (its force is f_[s-1])
  V dq_{}, dv_{};
  Compensator<V> comp_;
  State<V> err_low_{};
  bool cache_valid_ = false;
  bool precise_ = false;  // the weights allow precise_update
  long evals_ = 0;
};

}  // namespace nystrom
