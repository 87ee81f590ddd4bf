// The problem solve() integrates: q'' = a(t, q) with q(t0) = q0, q'(t0) = v0 on [t0, t1] (t1 < t0
// integrates backward in time).
//
// The force is what a user writes, a functor or a lambda (capturing or not):
//   void(const V& q, V& a)                 time-independent (the engines call it directly: no overhead)
//   void(const T& t, const V& q, V& a)     time-dependent, T the real type of V's elements
// V is any container with size() and operator[] (std::array<T, N>, std::vector<T>) of a real T.
// Velocity-dependent forces a(t, q, v) are not supported (a clear compile-time error says so).
#pragma once

#include <cmath>
#include <concepts>
#include <string>
#include <type_traits>
#include <utility>

#include "nystrom/core/error.hpp"
#include "nystrom/core/scalar.hpp"
#include "nystrom/core/state.hpp"

namespace nystrom {

/// A time-independent force for state type V: force(q, a).
template <class F, class V>
concept AutonomousForce = std::invocable<F&, const V&, V&>;

/// A time-dependent force for state type V: force(t, q, a).
template <class F, class V>
concept TimeDependentForce = std::invocable < F&,
        const real_t<typename V::value_type>
&, const V&, V& > ;

/// Either form.
template <class F, class V>
concept ForceFor = AutonomousForce<F, V> || TimeDependentForce<F, V>;

template <class V, class F>
class SecondOrderProblem {
 public:
  using vector_type = V;
  using scalar_type = typename V::value_type;
  using real_type = real_t<scalar_type>;
  using force_type = F;
  static_assert(!is_complex_v<scalar_type>,
                "nystrom: a problem's state is real (complex-coefficient methods complexify it themselves)");
  static constexpr bool velocity_dependent =
      !ForceFor<F, V> &&
      (std::invocable<F&, const real_type&, const V&, const V&, V&> || std::invocable<F&, const V&, const V&, V&>);
  static_assert(!velocity_dependent,
                "nystrom: velocity-dependent forces a(t, q, v) are not supported by this interface: the force must "
                "be a(q) or a(t, q), callable as force(q, a) or force(t, q, a)");
  static_assert(ForceFor<F, V> || velocity_dependent,
                "nystrom: the force must be callable as force(q, a) or force(t, q, a), with const V& q, V& a of the "
                "problem's state type V and t of its real type");
  /// Whether the force takes the time (then the engines carry t as one more coordinate).
  static constexpr bool time_dependent = !AutonomousForce<F, V>;

  SecondOrderProblem(F f, V q_0, V v_0, real_type t_0, real_type t_1)
      : force(std::move(f)), q0(std::move(q_0)), v0(std::move(v_0)), t0(std::move(t_0)), t1(std::move(t_1)) {}

  F force;
  V q0, v0;
  real_type t0, t1;

  /// a = a(t, q), whichever form the force has.
  void acceleration(const real_type& t, const V& q, V& a) {
    if constexpr (time_dependent) {
      force(t, q, a);
    } else {
      (void)t;
      force(q, a);
    }
  }

  /// Throws invalid_input unless q0 and v0 are non-empty, of one size and finite and t0, t1 finite.
  void validate() const {
    if (q0.size() == 0) throw invalid_input("empty system: the initial state has no coordinates");
    if (q0.size() != v0.size())
      throw invalid_input("inconsistent initial state: " + std::to_string(q0.size()) + " positions but " +
                          std::to_string(v0.size()) + " velocities");
    if (!all_finite(q0) || !all_finite(v0)) throw invalid_input("the initial state contains NaN or infinite values");
    if (!is_finite_scalar(t0) || !is_finite_scalar(t1)) throw invalid_input("the time span must be finite");
  }
};

template <class F, class V, class T0, class T1>
SecondOrderProblem(F, V, V, T0, T1) -> SecondOrderProblem<V, F>;

}  // namespace nystrom
