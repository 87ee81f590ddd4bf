// The multi-product expansion over Gragg's modified midpoint rule, for velocity-dependent forces
// q'' = f(q, v) (the force callable as force(q, v, a)) and, through them, first-order systems.
//
// T_k(h) is Gragg's modified midpoint rule on z = (q, v), z' = (v, f(q, v)), with 2k substeps of h / (2k)
// (Hairer, Nørsett & Wanner I, sec. II.9, eqs (9.13)-(9.14), without the smoothing step): its error
// expands in even powers of h (Gragg 1965), as that of a symmetric second-order method does. The
// multi-product expansion of Chin (2010, eq 14) with the sequence k_1, ..., k_n,
//     z(h) = sum_i c_i T_{k_i}(h),   c_i = prod_{j != i} k_i^2 / (k_i^2 - k_j^2),
// then cancels the terms up to h^{2n}: order 2n (the same combination as n columns of the extrapolation
// table of GBS, here with fixed steps and order). One step costs 1 + sum_i (2 k_i - 1) force evaluations
// (f(z_0) is shared by the products). The increment sum_i c_i (T_i - z_0) is added with compensated
// summation when EngineOptions::compensated says so.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <utility>
#include <vector>

#include "nystrom/core/state.hpp"
#include "nystrom/engines/options.hpp"

namespace nystrom {

template <class V, class F>
class MidpointMpeIntegrator {
 public:
  using scalar_type = typename V::value_type;
  using real_type = real_t<scalar_type>;

  /// k: the sequence (distinct positive integers); c: its coefficients in the working type.
  MidpointMpeIntegrator(std::vector<long> k, std::vector<real_type> c, F force, EngineOptions opt = {})
      : k_(std::move(k)), c_(std::move(c)), force_(std::move(force)), opt_(opt) {
    if (k_.empty() || c_.size() != k_.size())
      throw std::invalid_argument("midpoint MPE: one coefficient per sequence member is needed");
  }

  long force_evals() const { return evals_; }
  F& force() { return force_; }
  Compensator<V>& compensator() { return comp_; }

  /// n steps of size h, in place.
  void integrate(State<V>& s, real_type h, long n) {
    for (long i = 0; i < n; ++i) step(s, h);
  }

 private:
  void step(State<V>& s, real_type h) {
    const std::size_t dim = s.q.size();
    resize_like(f0_, s.q);
    resize_like(dq_, s.q);
    resize_like(dv_, s.q);
    force_(s.q, s.v, f0_);
    ++evals_;
    for (std::size_t i = 0; i < dim; ++i) dq_[i] = dv_[i] = scalar_type(0);
    for (std::size_t m = 0; m < k_.size(); ++m) {
      midpoint(s, h, 2 * k_[m]);
      for (std::size_t i = 0; i < dim; ++i) {
        dq_[i] += c_[m] * (z_.q[i] - s.q[i]);
        dv_[i] += c_[m] * (z_.v[i] - s.v[i]);
      }
    }
    if (use_compensation<scalar_type>(opt_.compensated)) {
      comp_.begin(s);
      for (std::size_t i = 0; i < dim; ++i) {
        kahan_add(s.q[i], comp_.cq[i], dq_[i]);
        kahan_add(s.v[i], comp_.cv[i], dv_[i]);
      }
      comp_.end(s);
    } else {
      for (std::size_t i = 0; i < dim; ++i) {
        s.q[i] += dq_[i];
        s.v[i] += dv_[i];
      }
    }
  }

  static void kahan_add(scalar_type& x, scalar_type& carry, const scalar_type& d) {
    const scalar_type y = d - carry;
    const scalar_type t = x + y;
    carry = (t - x) - y;
    x = t;
  }

  // z_ = T(h) with n substeps from s (f0_ = f(s)).
  void midpoint(const State<V>& s, real_type H, long n) {
    const std::size_t dim = s.q.size();
    const real_type h = H / real_type(n);
    const real_type h2 = h + h;
    resize_like(z_.q, s.q);
    resize_like(z_.v, s.q);
    resize_like(zp_.q, s.q);
    resize_like(zp_.v, s.q);
    resize_like(f_, s.q);
    for (std::size_t i = 0; i < dim; ++i) {
      zp_.q[i] = s.q[i];
      zp_.v[i] = s.v[i];
      z_.q[i] = s.q[i] + h * s.v[i];
      z_.v[i] = s.v[i] + h * f0_[i];
    }
    for (long k = 1; k < n; ++k) {
      force_(z_.q, z_.v, f_);
      ++evals_;
      for (std::size_t i = 0; i < dim; ++i) {
        const scalar_type q = zp_.q[i] + h2 * z_.v[i];
        const scalar_type v = zp_.v[i] + h2 * f_[i];
        zp_.q[i] = z_.q[i];
        zp_.v[i] = z_.v[i];
        z_.q[i] = q;
        z_.v[i] = v;
      }
    }
  }

  std::vector<long> k_;
  std::vector<real_type> c_;
  F force_;
  EngineOptions opt_;
  Compensator<V> comp_;
  State<V> z_{}, zp_{};
  V f0_{}, f_{}, dq_{}, dv_{};
  long evals_ = 0;
};

}  // namespace nystrom
