// The problem solve() integrates: q'' = a(t, q, v) with q(t0) = q0, q'(t0) = v0 on [t0, t1] (t1 < t0
// integrates backward in time).
//
// The force is what a user writes, a functor or a lambda (capturing or not):
//   void(const V& q, V& a)                              time-independent (the engines call it directly)
//   void(const T& t, const V& q, V& a)                  time-dependent, T the real type of V's elements
//   void(const V& q, const V& v, V& a)                  velocity-dependent
//   void(const T& t, const V& q, const V& v, V& a)      velocity- and time-dependent
// V is any container with size() and operator[] (std::array<T, N>, std::vector<T>) of a real T. A
// three-argument force is read as force(t, q, a) when it can be called so (a generic lambda can): write a
// velocity-dependent force with its types, or in the four-argument form.
//
// A velocity-dependent force runs only with the methods made for y'' = f(t, y, y') (MethodInfo::velocity:
// GBS on the first-order form, see `nystrom methods`); solve() refuses every other method with one line
// (velocity_refusal, methods/catalog.hpp).
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

/// A velocity-dependent force: force(q, v, a) or force(t, q, v, a) (and not one of the forms above).
template <class F, class V>
concept AutonomousVelocityForce = std::invocable<F&, const V&, const V&, V&>;
template <class F, class V>
concept TimeVelocityForce = std::invocable < F&,
        const real_t<typename V::value_type>
&, const V&, const V&, V& > ;
template <class F, class V>
concept VelocityForce = !ForceFor<F, V> && (AutonomousVelocityForce<F, V> || TimeVelocityForce<F, V>);

template <class V, class F>
class SecondOrderProblem {
 public:
  using vector_type = V;
  using scalar_type = typename V::value_type;
  using real_type = real_t<scalar_type>;
  using force_type = F;
  static_assert(!is_complex_v<scalar_type>,
                "nystrom: a problem's state is real (complex-coefficient methods complexify it themselves)");
  /// Whether the force takes the velocity (a(t, q, v)).
  static constexpr bool velocity_dependent = VelocityForce<F, V>;
  static_assert(ForceFor<F, V> || velocity_dependent,
                "nystrom: the force must be callable as force(q, a), force(t, q, a), force(q, v, a) or "
                "force(t, q, v, a), with const V& q, v, V& a of the problem's state type V and t of its real type");
  /// Whether the force takes the time (then the engines carry t as one more coordinate).
  static constexpr bool time_dependent = velocity_dependent ? !AutonomousVelocityForce<F, V> : !AutonomousForce<F, V>;

  SecondOrderProblem(F f, V q_0, V v_0, real_type t_0, real_type t_1)
      : force(std::move(f)), q0(std::move(q_0)), v0(std::move(v_0)), t0(std::move(t_0)), t1(std::move(t_1)) {}

  F force;
  V q0, v0;
  real_type t0, t1;

  /// a = a(t, q, v), whichever form the force has.
  void acceleration(const real_type& t, const V& q, const V& v, V& a) {
    if constexpr (velocity_dependent && time_dependent) {
      force(t, q, v, a);
    } else if constexpr (velocity_dependent) {
      (void)t;
      force(q, v, a);
    } else if constexpr (time_dependent) {
      (void)v;
      force(t, q, a);
    } else {
      (void)t, (void)v;
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
