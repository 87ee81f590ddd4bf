// The multi-product expansion over Gragg's modified midpoint rule, for velocity-dependent forces
// q'' = f(q, v) (the force callable as force(q, v, a)) and, through them, first-order systems; with fixed
// steps (MidpointMpeIntegrator, "mpe-midpoint:1,2,3") and adaptive steps (AdaptiveMidpointMpeIntegrator,
// "mpe-midpoint-adaptive:1,2,3,4").
//
// T_k(h) is Gragg's modified midpoint rule on z = (q, v), z' = (v, f(q, v)), with 2k substeps of h / (2k)
// (Hairer, Nørsett & Wanner I, sec. II.9, eqs (9.13)-(9.14), without the smoothing step): its error
// expands in even powers of h (Gragg 1965), as that of a symmetric second-order method does. The
// multi-product expansion of Chin (2010, eq 14) with the sequence k_1, ..., k_n,
//     z(h) = sum_i c_i T_{k_i}(h),   c_i = prod_{j != i} k_i^2 / (k_i^2 - k_j^2),
// then cancels the terms up to h^{2n}: order 2n (the same combination as n columns of the extrapolation
// table of GBS, here with a fixed order). One step costs 1 + sum_i (2 k_i - 1) force evaluations
// (f(z_0) is shared by the products; a step retried from the same state after a rejection reuses it). The
// increment sum_i c_i (T_i - z_0) is added with compensated summation when EngineOptions::compensated says so.
//
// The adaptive pair is free, as for the multi-product expansion over Verlet (engines/adaptive_mpe.hpp): the
// products without the one of largest k make a method of order 2n - 2 from the same forces, and the error
// estimate is sum_i d_i (T_i - z_0), d = c - chat (engines/adaptive_mpe_coefficients.hpp), controlled as an
// error of order 2n - 2 by the loop of every embedded pair (engines/embedded_pair.hpp); the solution of order
// 2n is propagated.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <utility>
#include <vector>

#include "nystrom/core/state.hpp"
#include "nystrom/engines/embedded_pair.hpp"
#include "nystrom/engines/options.hpp"

namespace nystrom {

template <class V, class F>
class MidpointMpeIntegrator {
 public:
  using scalar_type = typename V::value_type;
  using real_type = real_t<scalar_type>;

  /// k: the sequence (distinct positive integers); c: its coefficients in the working type; d: the
  /// coefficients of the error estimate (empty for fixed steps).
  MidpointMpeIntegrator(std::vector<long> k, std::vector<real_type> c, F force, EngineOptions opt = {},
                        std::vector<real_type> d = {})
      : k_(std::move(k)), c_(std::move(c)), d_(std::move(d)), force_(std::move(force)), opt_(opt) {
    if (k_.empty() || c_.size() != k_.size() || (!d_.empty() && d_.size() != k_.size()))
      throw std::invalid_argument("midpoint MPE: one coefficient per sequence member is needed");
  }

  long force_evals() const { return evals_; }
  std::size_t products() const { return k_.size(); }
  F& force() { return force_; }
  Compensator<V>& compensator() { return comp_; }

  /// n steps of size h, in place.
  void integrate(State<V>& s, real_type h, long n) {
    if (n <= 0) return;
    if (use_compensation<scalar_type>(opt_.compensated)) {
      comp_.begin(s);
      for (long i = 0; i < n; ++i) one_step(s, h, nullptr, &comp_);
      comp_.end(s);
    } else {
      for (long i = 0; i < n; ++i) one_step(s, h, nullptr, nullptr);
    }
  }

  /// One step that also returns the error estimate sum_i d_i (T_i - z_0) in err (q and v).
  void step_with_error(State<V>& s, real_type h, State<V>& err) { one_step(s, h, &err, nullptr); }
  /// The same, the increments added to s with compensated summation with the carries of comp.
  void step_with_error(State<V>& s, real_type h, State<V>& err, Compensator<V>& comp) { one_step(s, h, &err, &comp); }

 private:
  void one_step(State<V>& s, real_type h, State<V>* err, Compensator<V>* comp) {
    const std::size_t dim = s.q.size();
    resize_like(f0_, s.q);
    resize_like(dq_, s.q);
    resize_like(dv_, s.q);
    // The force at the start: kept from the last attempt if it started from this state (a rejected step).
    if (!(start_valid_ && same_values(sq_, s.q) && same_values(sv_, s.v))) {
      force_(static_cast<const V&>(s.q), static_cast<const V&>(s.v), f0_);
      ++evals_;
      resize_like(sq_, s.q);
      resize_like(sv_, s.v);
      assign(sq_, s.q);
      assign(sv_, s.v);
      start_valid_ = true;
    }
    for (std::size_t i = 0; i < dim; ++i) dq_[i] = dv_[i] = scalar_type(0);
    if (err) {
      resize_like(err->q, s.q);
      resize_like(err->v, s.q);
      for (std::size_t i = 0; i < dim; ++i) err->q[i] = err->v[i] = scalar_type(0);
    }
    for (std::size_t m = 0; m < k_.size(); ++m) {
      midpoint(s, h, 2 * k_[m]);
      for (std::size_t i = 0; i < dim; ++i) {
        const scalar_type eq = z_.q[i] - s.q[i], ev = z_.v[i] - s.v[i];
        dq_[i] += c_[m] * eq;
        dv_[i] += c_[m] * ev;
        if (err) {
          err->q[i] += d_[m] * eq;
          err->v[i] += d_[m] * ev;
        }
      }
    }
    if (comp) {
      comp->add_q(s.q, dq_);
      comp->add_v(s.v, dv_);
    } else {
      for (std::size_t i = 0; i < dim; ++i) {
        s.q[i] += dq_[i];
        s.v[i] += dv_[i];
      }
    }
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
      force_(static_cast<const V&>(z_.q), static_cast<const V&>(z_.v), f_);
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
  std::vector<real_type> c_, d_;
  F force_;
  EngineOptions opt_;
  Compensator<V> comp_;
  State<V> z_{}, zp_{};
  V f0_{}, f_{}, dq_{}, dv_{};
  V sq_{}, sv_{};  // the state whose force f0_ holds
  bool start_valid_ = false;
  long evals_ = 0;
};

/// The adaptive multi-product expansion over Gragg's modified midpoint rule (the API of
/// engines/embedded_pair.hpp): k the sequence (at least two members), c its coefficients (order 2n) and d
/// those of the error estimate, both in the working type.
template <class V, class F>
class AdaptiveMidpointMpeIntegrator : public EmbeddedPairIntegrator<V, MidpointMpeIntegrator<V, F>> {
  using Base = EmbeddedPairIntegrator<V, MidpointMpeIntegrator<V, F>>;

 public:
  using real_type = typename Base::real_type;

  AdaptiveMidpointMpeIntegrator(std::vector<long> k, std::vector<real_type> c, std::vector<real_type> d, F force,
                                AdaptiveOptions opt = {}, EngineOptions eopt = {})
      : Base(make_stepper(std::move(k), std::move(c), std::move(d), std::move(force), eopt), opt, eopt,
             "adaptive MPE (midpoint)") {
    const int n = static_cast<int>(this->stepper().products());
    this->set_orders(2 * n - 2, 2 * n, false);
  }

 private:
  static MidpointMpeIntegrator<V, F> make_stepper(std::vector<long> k, std::vector<real_type> c,
                                                  std::vector<real_type> d, F force, EngineOptions eopt) {
    if (k.size() < 2 || d.size() != k.size())
      throw std::invalid_argument(
          "an adaptive MPE needs at least two products and the coefficients of its error estimate");
    return MidpointMpeIntegrator<V, F>(std::move(k), std::move(c), std::move(force), eopt, std::move(d));
  }
};

}  // namespace nystrom
