// Dense output of a second-order solution: the state at any t of the integrated span.
//
// sol(t) continues the solution from the step end before t by one step of the solution's own method
// with the step size t - t_n (a partial step, as REBOUND lands on output times). Its error is that of
// the step end t_n plus the local error of a step shorter than the method's, so it keeps the method's
// order and accuracy whatever the order; it costs one step of the method (its force evaluations) per
// call. Adaptive RKN pairs and adaptive multi-product methods continue with the fixed-step method they
// propagate (the high-order weights, or the full multi-product expansion); GBS with a fresh run of the
// extrapolation integrator over t - t_n at 1/1000 of the solution's tolerances (its accepted steps are
// usually far more accurate than the tolerance).
//
// hermite(t) is the cheap alternative: quintic Hermite interpolation between step ends from q, v and
// a = q'' at both ends (one force evaluation per step end, none per call). Its local error is O(h^6) in
// q and O(h^5) in v whatever the method, so it spoils the methods of order 8 and more and the long steps
// of the adaptive ones: on Kepler e = 0.5 (tests/solve/test_dense.cpp) sol(t) is within 1.2x of the step-end
// error for every catalog method, the Hermite interpolant 25x to 70x for the order-8 ones (M8, KL8)
// and 1e6 x between the steps of DP12-adaptive at rtol 1e-10. It is meant for plots.
#pragma once

#include <algorithm>
#include <cstddef>
#include <functional>
#include <vector>

#include "nystrom/core/error.hpp"
#include "nystrom/core/state.hpp"

namespace nystrom {

/// q and v at theta in [0, 1] of the step [t0, t0 + h] from (q, v, a) at both ends.
template <class V, class T>
void hermite_quintic(const V& q0, const V& v0, const V& a0, const V& q1, const V& v1, const V& a1, const T& h,
                     const T& th, V& q, V& v) {
  const T t2 = th * th, t3 = t2 * th, t4 = t3 * th, t5 = t4 * th;
  // Basis functions of y0 + h v0 H1 + h^2 a0 H2 + h^2 a1 H3 + h v1 H4 + (y1 - y0) H5 (H0 + H5 = 1).
  const T H1 = th - T(6) * t3 + T(8) * t4 - T(3) * t5;
  const T H2 = (t2 - T(3) * t3 + T(3) * t4 - t5) / T(2);
  const T H3 = (t3 - T(2) * t4 + t5) / T(2);
  const T H4 = T(-4) * t3 + T(7) * t4 - T(3) * t5;
  const T H5 = T(10) * t3 - T(15) * t4 + T(6) * t5;
  const T D1 = T(1) - T(18) * t2 + T(32) * t3 - T(15) * t4;
  const T D2 = (T(2) * th - T(9) * t2 + T(12) * t3 - T(5) * t4) / T(2);
  const T D3 = (T(3) * t2 - T(8) * t3 + T(5) * t4) / T(2);
  const T D4 = T(-12) * t2 + T(28) * t3 - T(15) * t4;
  const T D5 = T(30) * t2 - T(60) * t3 + T(30) * t4;
  resize_like(q, q0);
  resize_like(v, q0);
  const T h2 = h * h;
  for (std::size_t i = 0; i < q0.size(); ++i) {
    const T dy = q1[i] - q0[i];
    q[i] = q0[i] + h * (H1 * v0[i] + H4 * v1[i]) + h2 * (H2 * a0[i] + H3 * a1[i]) + H5 * dy;
    v[i] = D1 * v0[i] + D4 * v1[i] + h * (D2 * a0[i] + D3 * a1[i]) + D5 * dy / h;
  }
}

/// The step ends of a solution (times in the direction of integration) and sol(t) between them.
template <class V>
class DenseOutput {
 public:
  using real_type = real_t<typename V::value_type>;
  /// One step of the solution's method from the step end (t0, q0, v0) to t (t - t0 within the step
  /// after t0, in the direction of integration): the state at t in q and v; returns the force
  /// evaluations it took. It must be safe to call concurrently (solve() guards its engine with a mutex).
  using PartialStep =
      std::function<long(const real_type& t0, const V& q0, const V& v0, const real_type& t, V& q, V& v)>;

  void clear() {
    t_.clear();
    q_.clear();
    v_.clear();
    a_.clear();
  }
  void push(const real_type& t, const V& q, const V& v, const V& a) {
    t_.push_back(t);
    q_.push_back(q);
    v_.push_back(v);
    a_.push_back(a);
  }
  void set_partial_step(PartialStep p) { step_ = std::move(p); }
  bool has_partial_step() const { return static_cast<bool>(step_); }
  bool empty() const { return t_.empty(); }
  std::size_t size() const { return t_.size(); }
  const std::vector<real_type>& times() const { return t_; }

  /// The state at t (within the span of the stored steps; invalid_input otherwise): a partial step of
  /// the method from the step end before t, or hermite(t) where no method was kept.
  State<V> operator()(const real_type& t) const {
    State<V> s;
    std::size_t k = 0;
    if (find(t, k, s)) return s;
    if (!step_) {
      segment(k, t, s);
    } else {
      step_(t_[k], q_[k], v_[k], t, s.q, s.v);
    }
    return s;
  }

  /// The quintic Hermite interpolant at t (no force evaluation; order 6, see above).
  State<V> hermite(const real_type& t) const {
    State<V> s;
    std::size_t k = 0;
    if (!find(t, k, s)) segment(k, t, s);
    return s;
  }

  /// The Hermite interpolant at t inside step k (between step ends k and k + 1).
  void segment(std::size_t k, const real_type& t, State<V>& s) const {
    const real_type h = t_[k + 1] - t_[k];
    hermite_quintic(q_[k], v_[k], a_[k], q_[k + 1], v_[k + 1], a_[k + 1], h, real_type((t - t_[k]) / h), s.q, s.v);
  }

 private:
  // The step [t_k, t_k+1] containing t in k; true (and the stored state in s) when t is a step end.
  bool find(const real_type& t, std::size_t& k, State<V>& s) const {
    if (t_.empty()) throw invalid_input("no dense output was kept (SolveOptions::dense)");
    const bool fwd = t_.back() >= t_.front();
    const real_type lo = fwd ? t_.front() : t_.back(), hi = fwd ? t_.back() : t_.front();
    if (!(t >= lo && t <= hi)) throw invalid_input("sol(t): t lies outside the integrated span");
    if (t_.size() == 1) {
      s.q = q_[0];
      s.v = v_[0];
      return true;
    }
    // The first step end at or past t in the direction of integration.
    std::size_t j;
    if (fwd)
      j = static_cast<std::size_t>(std::lower_bound(t_.begin(), t_.end(), t) - t_.begin());
    else
      j = static_cast<std::size_t>(
          std::lower_bound(t_.begin(), t_.end(), t, [](const real_type& a, const real_type& b) { return a > b; }) -
          t_.begin());
    if (j == 0) j = 1;
    if (j >= t_.size()) j = t_.size() - 1;
    if (t == t_[j] || t == t_[j - 1]) {
      const std::size_t e = t == t_[j] ? j : j - 1;
      s.q = q_[e];
      s.v = v_[e];
      return true;
    }
    k = j - 1;
    return false;
  }

  std::vector<real_type> t_;
  std::vector<V> q_, v_, a_;
  PartialStep step_;
};

}  // namespace nystrom
