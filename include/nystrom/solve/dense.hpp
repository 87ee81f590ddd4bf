// Dense output of a second-order solution: quintic Hermite interpolation between step ends from q,
// v = q' and a = q'' at both ends (the force at every step end: one evaluation per step). Local error
// O(h^6) in q and O(h^5) in v, whatever the method. Measured on Kepler e = 0.5 over one period at about
// 2000 forces per period (tests/test_solve.cpp): within 10x of the step-end error for every catalog
// method of order <= 6; for order 8 the interpolant's order limits sol(t) between step ends (M8: 2e-13
// at the step ends, 1.3e-10 inside; KL8 1e-11 and 3e-9; RKNa14 4e-11 and 1e-9), and for orders 10-16
// (M10-M16, SS10, DP10, DP12) 1e-15..4e-13 at the step ends, 1e-9..3e-7 inside. The step ends keep the
// method's accuracy; bound the step (AdaptiveOptions::h_max) where sol(t) or events need more.
#pragma once

#include <algorithm>
#include <cstddef>
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
  bool empty() const { return t_.empty(); }
  std::size_t size() const { return t_.size(); }
  const std::vector<real_type>& times() const { return t_; }

  /// The state at t (within the span of the stored steps; invalid_input otherwise).
  State<V> operator()(const real_type& t) const {
    if (t_.empty()) throw invalid_input("no dense output was kept (SolveOptions::dense)");
    const bool fwd = t_.back() >= t_.front();
    const real_type lo = fwd ? t_.front() : t_.back(), hi = fwd ? t_.back() : t_.front();
    if (!(t >= lo && t <= hi)) throw invalid_input("sol(t): t lies outside the integrated span");
    State<V> s;
    if (t_.size() == 1) {
      s.q = q_[0];
      s.v = v_[0];
      return s;
    }
    // The step containing t: the first step end at or past t in the direction of integration.
    std::size_t k;
    if (fwd)
      k = static_cast<std::size_t>(std::lower_bound(t_.begin(), t_.end(), t) - t_.begin());
    else
      k = static_cast<std::size_t>(
          std::lower_bound(t_.begin(), t_.end(), t, [](const real_type& a, const real_type& b) { return a > b; }) -
          t_.begin());
    if (k == 0) k = 1;
    if (k >= t_.size()) k = t_.size() - 1;
    if (t == t_[k]) {
      s.q = q_[k];
      s.v = v_[k];
      return s;
    }
    segment(k - 1, t, s);
    return s;
  }

  /// The state at t inside step k (between step ends k and k + 1).
  void segment(std::size_t k, const real_type& t, State<V>& s) const {
    const real_type h = t_[k + 1] - t_[k];
    hermite_quintic(q_[k], v_[k], a_[k], q_[k + 1], v_[k + 1], a_[k + 1], h, real_type((t - t_[k]) / h), s.q, s.v);
  }

 private:
  std::vector<real_type> t_;
  std::vector<V> q_, v_, a_;
};

}  // namespace nystrom
