// The explicit Runge-Kutta-Nyström engine, form (2.1) of the Gürkan paper:
//
//   y_i     = q_n + c_i h v_n + h^2 sum_{j<i} a_ij f(y_j)
//   q_{n+1} = q_n + h v_n + h^2 sum_i b_i f(y_i)
//   v_{n+1} = v_n + h sum_i B_i f(y_i)
//
// Any explicit RKN tableau runs here, including the force-consolidated methods of the Chin
// paper (Nyström 4, M4, the 5-force M6, Albrecht A6, A'), which are tableaux too.
// First-same-as-last is detected from the tableau (stage 1 at q_n, last stage at q_{n+1})
// and the reused force is checked against the position it was evaluated at.
// An optional embedded solution (bhat, Bhat) gives an error estimate for step control.
//
// Rounding. Every consistent tableau has sum b_i = 1/2 and sum B_i = 1, but the weights rounded to the
// working type do not: their exact sums miss by an ulp or so, the same way every step, which drifts the
// energy and makes the phase error grow as T^2. The weighted sums are therefore formed in difference form,
//   sum_i B_i f_i = f_1 + sum_{i>1} B_i (f_i - f_1),   sum_i b_i f_i = f_1 / 2 + sum_{i>1} b_i (f_i - f_1),
// which holds the conditions exactly whatever the rounding of the weights (used when the rounded sums
// agree with 1/2 and 1 to rounding, as they do for every tableau of the catalog). With compensated
// summation (double and float by default), the carries of q and v enter the stage positions and the
// increments (y_i = q_n + (c_q + c_i h (v_n + c_v) + h^2 sum a_ij f_j), dq = h (v_n + c_v) + ...), the
// increments' own rounding (the sum of h v and the force terms, of f_1 and the differences) is kept, and
// they are added by exact two-sums (compensated_add_folded, core/state.hpp).
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "nystrom/core/state.hpp"
#include "nystrom/methods/rkn_tableau.hpp"

namespace nystrom {

template <class V, class Force>
class RknStepper {
 public:
  using vector_type = V;
  using scalar_type = typename V::value_type;
  using real_type = real_t<scalar_type>;

  RknStepper(RknTableau<scalar_type> t, Force force, EngineOptions opt = {})
      : t_(std::move(t)), force_(std::move(force)), opt_(opt) {
    t_.validate();
    fsal_ = t_.fsal();
    const std::size_t s = t_.stages();
    for (std::size_t i = 0; i < s; ++i)
      for (std::size_t j = 0; j < i; ++j)
        if (!(t_.a[i][j] == scalar_type(0))) nz_.push_back({i, j, t_.a[i][j]});
    f_.resize(s);
    // Difference form when the rounded weights sum to 1/2 and 1 up to rounding (see the top).
    using std::abs;
    scalar_type sb(0), sB(0);
    real_type mb(0), mB(0);
    for (std::size_t i = 0; i < s; ++i) {
      sb += t_.b[i];
      sB += t_.B[i];
      mb += abs(t_.b[i]);
      mB += abs(t_.B[i]);
    }
    const real_type tol = real_type(8 * static_cast<long>(s)) * epsilon_of<real_type>();
    diff_ = s > 1 && abs(sb - scalar_type(real_type(1) / real_type(2))) <= tol * (mb + real_type(1)) &&
            abs(sB - scalar_type(1)) <= tol * (mB + real_type(1));
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
      for (long k = 0; k < n; ++k) one_step<false>(x, h, nullptr, &c);
      if constexpr (local) {
        s = x;
        comp_ = c;
      }
      comp_.end(s);
    } else {
      for (long k = 0; k < n; ++k) one_step<false>(x, h, nullptr, nullptr);
      if constexpr (local) s = x;
    }
  }

  /// One step that also returns the embedded error estimate (q, v) in err (if the tableau has one).
  /// (Not compensated.)
  void step_with_error(State<V>& s, real_type h, State<V>& err) { one_step(s, h, &err, nullptr); }
  /// The same, the increments added to s with compensated summation with the carries of comp (the caller
  /// keeps the carries of the last accepted step).
  void step_with_error(State<V>& s, real_type h, State<V>& err, Compensator<V>& comp) { one_step(s, h, &err, &comp); }

 private:
  struct Nz {
    std::size_t i, j;
    scalar_type a;
  };

  // Full: the carries also enter the stage positions and the increments are added by exact two-sums (the
  // adaptive engine); otherwise (the fixed-step loop, where these cost 10-25% per step of a cheap force) the
  // velocity's carry enters the position increment and compensated_add adds it.
  template <bool Full = true>
  NYSTROM_ALWAYS_INLINE void one_step(State<V>& st, real_type hr, State<V>* err, Compensator<V>* comp) {
    const std::size_t s = t_.stages();
    const std::size_t n = st.q.size();
    const scalar_type h(hr), h2 = h * h;
    for (auto& f : f_) resize_like(f, st.q);
    resize_like(y_, st.q);
    // The stage position, the weighted sums and h c_v: locals if fixed-size (see integrate).
    constexpr bool local = is_std_array<V>::value;
    std::conditional_t<local, V, V&> y = y_, dq = dq_, sv = sv_, dv = dv_;
    resize_like(dq, st.q);
    resize_like(sv, st.q);
    resize_like(dv, st.q);
    const bool project = is_complex_v<scalar_type> && !opt_.keep_complex;
    if (comp)
      for (std::size_t j = 0; j < n; ++j) dv[j] = h * comp->cv[j];  // h c_v: the velocity's carry
    std::size_t k = 0;                                              // index into nz_, ordered by stage
    for (std::size_t i = 0; i < s; ++i) {
      if (i == 0 && fsal_ && cache_valid_ && same(aq_, st.q)) {
        while (k < nz_.size() && nz_[k].i == 0) ++k;
        continue;  // f_[0] already holds the force at q_n
      }
      const bool moved = !(t_.c[i] == scalar_type(0)) || (k < nz_.size() && nz_[k].i == i);
      if (Full && comp && moved) {
        // the increment first, with the carries, then one rounding at the size of q (at q_n itself, q + c_q
        // rounds back to q: the compensated update leaves |c_q| below half an ulp of q)
        for (std::size_t j = 0; j < n; ++j) y[j] = comp->cq[j];
        if (!(t_.c[i] == scalar_type(0))) {
          const scalar_type ch = t_.c[i] * h;
          for (std::size_t j = 0; j < n; ++j) y[j] += t_.c[i] * dv[j] + ch * st.v[j];
        }
        for (; k < nz_.size() && nz_[k].i == i; ++k) axpy(y, nz_[k].a * h2, f_[nz_[k].j]);
        for (std::size_t j = 0; j < n; ++j) y[j] = st.q[j] + y[j];
      } else {
        assign(y, st.q);
        if (!(t_.c[i] == scalar_type(0))) axpy(y, t_.c[i] * h, st.v);
        for (; k < nz_.size() && nz_[k].i == i; ++k) axpy(y, nz_[k].a * h2, f_[nz_[k].j]);
      }
      force_(y, f_[i]);
      ++evals_;
    }
    if (err) {
      resize_like(err->q, st.q);
      resize_like(err->v, st.q);
      for (auto& e : err->q) e = scalar_type(0);
      for (auto& e : err->v) e = scalar_type(0);
      if (!t_.bhat.empty())
        for (std::size_t i = 0; i < s; ++i) {
          axpy(err->q, (t_.b[i] - t_.bhat[i]) * h2, f_[i]);
          axpy(err->v, (t_.B[i] - t_.Bhat[i]) * h, f_[i]);
        }
    }
    // dq = h^2 sum b_i f_i (+ h c_v) and sv = h sum B_i f_i; in difference form (diff_) the f_1 terms are split
    // off: dq = h^2 f_1 / 2 + sum_{i>1} b_i h^2 (f_i - f_1), sv = sum_{i>1} B_i h (f_i - f_1), h f_1 added by the
    // update. The sums start from the terms known first, so that the last force is one product and one addition
    // away from the update.
    if (diff_) {
      const scalar_type hh2 = h2 * scalar_type(real_type(1) / real_type(2));
      for (std::size_t j = 0; j < n; ++j) {
        dq[j] = comp ? scalar_type(hh2 * f_[0][j] + dv[j]) : scalar_type(hh2 * f_[0][j]);
        sv[j] = scalar_type(0);
      }
      for (std::size_t i = 1; i < s; ++i) {
        const bool nb = !(t_.b[i] == scalar_type(0)), nB = !(t_.B[i] == scalar_type(0));
        if (!nb && !nB) continue;
        const scalar_type bh2 = t_.b[i] * h2, Bh = t_.B[i] * h;
        for (std::size_t j = 0; j < n; ++j) {
          const scalar_type d = f_[i][j] - f_[0][j];
          if (nb) dq[j] += bh2 * d;
          if (nB) sv[j] += Bh * d;
        }
      }
    } else {
      for (std::size_t j = 0; j < n; ++j) {
        dq[j] = comp ? dv[j] : scalar_type(0);
        sv[j] = scalar_type(0);
      }
      for (std::size_t i = 0; i < s; ++i) {
        if (!(t_.b[i] == scalar_type(0))) axpy(dq, t_.b[i] * h2, f_[i]);
        if (!(t_.B[i] == scalar_type(0))) axpy(sv, t_.B[i] * h, f_[i]);
      }
    }
    if (comp) {
      for (std::size_t j = 0; j < n; ++j) {
        // q + c_q += h v_n + dq (h c_v included), v + c_v += h f_1 + sv (difference form; else sv alone)
        const scalar_type hf = diff_ ? scalar_type(h * f_[0][j]) : scalar_type(0);
        if constexpr (Full) {
          compensated_add_folded(st.q[j], comp->cq[j], scalar_type(h * st.v[j]), scalar_type(dq[j] + comp->cq[j]));
          compensated_add_folded(st.v[j], comp->cv[j], hf, scalar_type(sv[j] + comp->cv[j]));
        } else {
          compensated_add(st.q[j], comp->cq[j], scalar_type(h * st.v[j] + dq[j]));
          compensated_add(st.v[j], comp->cv[j], scalar_type(hf + sv[j]));
        }
      }
    } else {
      for (std::size_t j = 0; j < n; ++j) {
        st.q[j] += h * st.v[j] + dq[j];
        st.v[j] += diff_ ? scalar_type(h * f_[0][j] + sv[j]) : sv[j];
      }
    }
    if (project) {
      project_real(st.q);
      project_real(st.v);
      if (comp) {
        project_real(comp->cq);
        project_real(comp->cv);
      }
    }
    if (fsal_ && !project) {
      // The last stage was evaluated at q_{n+1} up to rounding; reuse it exactly as the
      // method prescribes (the tableau says y_s = q_{n+1}).
      std::swap(f_[0], f_[s - 1]);
      resize_like(aq_, st.q);
      assign(aq_, st.q);
      cache_valid_ = true;
    } else {
      cache_valid_ = false;
    }
  }

  static bool same(const V& x, const V& y) {
    if (x.size() != y.size()) return false;
    for (std::size_t i = 0; i < x.size(); ++i)
      if (!(x[i] == y[i])) return false;
    return true;
  }

  RknTableau<scalar_type> t_;
  Force force_;
  EngineOptions opt_;
  bool fsal_ = false;
  bool diff_ = false;  // weighted sums in difference form
  std::vector<Nz> nz_;
  std::vector<V> f_;
  V y_{};
  V aq_{};
  V dq_{}, sv_{}, dv_{};
  Compensator<V> comp_;
  bool cache_valid_ = false;
  long evals_ = 0;
};

}  // namespace nystrom
