// Classical drift and kick for q'' = a(q) as operator flows: A = v d/dq (the drift q <- q + z v), B = a(q) d/dv
// (the kick v <- v + z a(q)). With them the operator layer (FlowIntegrator, any splitting or multi-product
// method of the catalog) runs on q'' = a(q) through the same loop as the classical engine
// (run_merged_splitting in engines/splitting.hpp); the classical engines add what only drift and kick allow
// (a force cache across kicks, compensated summation, multi-product products in lockstep) and stay the fast
// path for q'' = a(q).
#pragma once

#include <complex>
#include <stdexcept>
#include <utility>

#include "nystrom/core/scalar.hpp"
#include "nystrom/core/state.hpp"

namespace nystrom::operators {

/// Drift and kick over a state (q, v) of vector type V and a force functor force(q, a): a <- a(q). A real V
/// takes real coefficients only (a complex one is an error: it needs a complex state).
template <class V, class Force>
class DriftKickFlows {
 public:
  using state_type = State<V>;
  using scalar_type = typename V::value_type;
  using real_type = real_t<scalar_type>;
  using complex_type = std::complex<real_type>;

  explicit DriftKickFlows(Force force) : force_(std::move(force)) {}

  void apply_a(state_type& s, complex_type z) { nystrom::axpy(s.q, coefficient(z), s.v); }
  void apply_b(state_type& s, complex_type z) {
    resize_like(a_, s.q);
    force_(s.q, a_);
    ++evals_;
    nystrom::axpy(s.v, coefficient(z), a_);
  }
  void assign(state_type& d, const state_type& s) { d = s; }
  void scale(state_type& s, real_type r) {
    for (auto& x : s.q) x *= r;
    for (auto& x : s.v) x *= r;
  }
  void axpy(state_type& d, real_type r, const state_type& s) {
    resize_like(d.q, s.q);
    resize_like(d.v, s.v);
    nystrom::axpy(d.q, scalar_type(r), s.q);
    nystrom::axpy(d.v, scalar_type(r), s.v);
  }

  /// Force evaluations so far (one per kick: no cache).
  long force_evals() const { return evals_; }

 private:
  static scalar_type coefficient(complex_type z) {
    if constexpr (is_complex_v<scalar_type>) {
      return z;
    } else {
      if (z.imag() != 0) throw std::invalid_argument("a complex coefficient needs a complex state");
      return z.real();
    }
  }

  Force force_;
  V a_{};
  long evals_ = 0;
};

}  // namespace nystrom::operators
