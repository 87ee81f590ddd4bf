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
    // The stage position and the increments: locals if fixed-size (see integrate).
    constexpr bool local = is_std_array<V>::value;
    std::conditional_t<local, V, V&> y = y_, dq = dq_, dv = dv_;
    const bool project = is_complex_v<scalar_type> && !opt_.keep_complex;
    std::size_t k = 0;  // index into nz_, ordered by stage
    for (std::size_t i = 0; i < s; ++i) {
      if (i == 0 && fsal_ && cache_valid_ && same(aq_, st.q)) {
        while (k < nz_.size() && nz_[k].i == 0) ++k;
        continue;  // f_[0] already holds the force at q_n
      }
      assign(y, st.q);
      if (!(t_.c[i] == scalar_type(0))) axpy(y, t_.c[i] * h, st.v);
      for (; k < nz_.size() && nz_[k].i == i; ++k) axpy(y, nz_[k].a * h2, f_[nz_[k].j]);
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
    if (comp) {
      // One increment per step for q and for v, added with compensation.
      resize_like(dq, st.q);
      resize_like(dv, st.q);
      for (std::size_t j = 0; j < st.q.size(); ++j) {
        dq[j] = scalar_type(0);
        dv[j] = scalar_type(0);
      }
      for (std::size_t i = 0; i < s; ++i)
        if (!(t_.b[i] == scalar_type(0))) axpy(dq, t_.b[i] * h2, f_[i]);
      axpy(dq, h, st.v);
      for (std::size_t i = 0; i < s; ++i)
        if (!(t_.B[i] == scalar_type(0))) axpy(dv, t_.B[i] * h, f_[i]);
      comp->add_q(st.q, dq);
      comp->add_v(st.v, dv);
    } else {
      axpy(st.q, h, st.v);
      for (std::size_t i = 0; i < s; ++i)
        if (!(t_.b[i] == scalar_type(0))) axpy(st.q, t_.b[i] * h2, f_[i]);
      for (std::size_t i = 0; i < s; ++i)
        if (!(t_.B[i] == scalar_type(0))) axpy(st.v, t_.B[i] * h, f_[i]);
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
  std::vector<Nz> nz_;
  std::vector<V> f_;
  V y_{};
  V aq_{};
  V dq_{}, dv_{};
  Compensator<V> comp_;
  bool cache_valid_ = false;
  long evals_ = 0;
};

}  // namespace nystrom
