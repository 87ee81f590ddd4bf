// A stepper that models Boost.Odeint's Stepper concept for second-order systems, so that odeint's
// integrate functions run any nystrom method:
//
//   nystrom::OdeintStepper<std::array<double, 2>> st("M8");
//   auto x = std::make_pair(q, p);                                   // or std::make_pair(std::ref(q), std::ref(p))
//   boost::numeric::odeint::integrate_const(st, force, x, t0, t1, dt, observer);   // observer(x, t)
//
// The system is the force in the form of odeint's symplectic steppers' momentum function (unit mass:
// p = v): force(q, dpdt) for a(q), or force(t, q, dpdt) for a time-dependent a(t, q), which gets the
// time of each of its evaluations (t as one more coordinate of the state, velocity 1, as solve() does;
// t + c_i dt at the stages). Velocity-dependent forces are not supported. The state is a pair (q, p) of
// V, or of references to V (std::reference_wrapper or boost::reference_wrapper). Each do_step is one
// step of the method (compensated summation and FSAL forces carry over between steps while the caller
// does not move the state). This header includes no Boost header: it only names odeint's stepper_tag.
#pragma once

#include <array>
#include <cstddef>
#include <memory>
#include <string>
#include <type_traits>
#include <typeinfo>
#include <utility>
#include <vector>

#include "nystrom/engines/integrator.hpp"
#include "nystrom/methods/catalog.hpp"

namespace boost::numeric::odeint {
struct stepper_tag;
}  // namespace boost::numeric::odeint

namespace nystrom {

namespace odeint_detail {
/// V with one more coordinate (the time of a time-dependent force).
template <class V>
struct with_clock;
template <class S, std::size_t N>
struct with_clock<std::array<S, N>> {
  using type = std::array<S, N + 1>;
};
template <class S, class A>
struct with_clock<std::vector<S, A>> {
  using type = std::vector<S, A>;
};
}  // namespace odeint_detail

template <class V>
class OdeintStepper {
 public:
  using state_type = std::pair<V, V>;
  using deriv_type = std::pair<V, V>;
  using value_type = real_t<typename V::value_type>;
  using time_type = value_type;
  using order_type = unsigned short;
  using stepper_category = boost::numeric::odeint::stepper_tag;

  explicit OdeintStepper(const std::string& method, EngineOptions opt = {})
      : OdeintStepper(resolve_method(method), opt) {}
  explicit OdeintStepper(MethodDef def, EngineOptions opt = {}) : def_(std::move(def)), opt_(opt) {
    if (def_.info.adaptive)
      throw invalid_input("method '" + def_.info.name + "' chooses its steps from a tolerance: use solve()");
    if (def_.info.complex) throw invalid_input("complex-coefficient methods run through solve(), not odeint");
  }

  order_type order() const { return static_cast<order_type>(def_.info.order); }
  long force_evals() const { return *cache_ ? (*cache_)->force_evals() : 0; }

  /// One step of size dt from the state (q, p) at time t, in place; a time-dependent force
  /// system(t, q, dpdt) is called at the times of its evaluations within the step.
  template <class System, class StateInOut>
  void do_step(System system, StateInOut& x, time_type t, time_type dt) {
    step(system, unwrap(x.first), unwrap(x.second), t, dt);
  }
  /// A pair of references (std::make_pair(std::ref(q), std::ref(p))), or a temporary pair that
  /// integrate_const holds (odeint passes it on as const; its members are the state to advance).
  template <class System, class StateInOut>
  void do_step(System system, const StateInOut& x, time_type t, time_type dt) {
    do_step(system, const_cast<StateInOut&>(x), t, dt);
  }

 private:
  template <class T>
  static V& unwrap(T& x) {
    if constexpr (std::is_same_v<std::remove_const_t<T>, V>) {
      return const_cast<V&>(x);
    } else {
      return x.get();  // std::reference_wrapper<V> or boost::reference_wrapper<V>
    }
  }

  /// Which form the force has: system(q, dpdt), or (if not) system(t, q, dpdt).
  template <class System>
  static constexpr bool time_dependent =
      !std::is_invocable_v<System&, const V&, V&> && std::is_invocable_v<System&, const time_type&, const V&, V&>;
  using VT = typename odeint_detail::with_clock<V>::type;  // (q, t) of a time-dependent force

  // The force seen by the engine: the current system, reached through a pointer that every do_step
  // sets, so that the integrator (coefficients converted once) lives across steps.
  template <class System>
  struct SystemRef {
    System* sys = nullptr;
    void operator()(const V& q, V& a) const { (*sys)(q, a); }
  };
  // A time-dependent one on (q, t): t is the last coordinate, its acceleration 0.
  template <class System>
  struct ClockedSystemRef {
    System* sys = nullptr;
    std::size_t n = 0;
    V qb{}, ab{};
    void operator()(const VT& q, VT& a) {
      if constexpr (!is_std_array<V>::value) {
        qb.resize(n);
        ab.resize(n);
      }
      for (std::size_t i = 0; i < n; ++i) qb[i] = q[i];
      (*sys)(static_cast<const time_type&>(q[n]), static_cast<const V&>(qb), ab);
      for (std::size_t i = 0; i < n; ++i) a[i] = ab[i];
      a[n] = typename V::value_type(0);
    }
  };
  template <class System>
  using ForceRef = std::conditional_t<time_dependent<System>, ClockedSystemRef<System>, SystemRef<System>>;
  template <class System>
  using EngineVector = std::conditional_t<time_dependent<System>, VT, V>;

  struct Holder {
    virtual ~Holder() = default;
    virtual long force_evals() const = 0;
    const std::type_info* type = nullptr;
  };
  template <class System>
  struct TypedHolder : Holder {
    TypedHolder(const MethodDef& def, EngineOptions opt)
        : integ(make_integrator<EngineVector<System>>(def, ForceRef<System>{}, opt)) {}
    long force_evals() const override { return integ.force_evals(); }
    Integrator<EngineVector<System>, ForceRef<System>> integ;
  };

  template <class System>
  void step(System& system, V& q, V& p, time_type t, time_type dt) {
    static_assert(std::is_invocable_v<System&, const V&, V&> || time_dependent<System>,
                  "nystrom::OdeintStepper: the system must be the force, callable as force(q, dpdt) or "
                  "force(t, q, dpdt) (unit mass); velocity-dependent forces a(t, q, v) are not supported");
    if (q.size() != p.size()) throw invalid_input("inconsistent state: q and p differ in size");
    auto& slot = *cache_;
    if (!slot || *slot->type != typeid(System)) {
      auto h = std::make_shared<TypedHolder<System>>(def_, opt_);
      h->type = &typeid(System);
      slot = h;
    }
    auto& integ = static_cast<TypedHolder<System>&>(*slot).integ;
    integ.force().sys = &system;
    if constexpr (!time_dependent<System>) {
      (void)t;
      State<V> s{std::move(q), std::move(p)};
      integ.integrate(s, dt, 1);
      q = std::move(s.q);
      p = std::move(s.v);
    } else {
      const std::size_t n = q.size();
      integ.force().n = n;
      State<VT> s;
      if constexpr (!is_std_array<V>::value) {
        s.q.resize(n + 1);
        s.v.resize(n + 1);
      }
      for (std::size_t i = 0; i < n; ++i) {
        s.q[i] = q[i];
        s.v[i] = p[i];
      }
      s.q[n] = t;
      s.v[n] = time_type(1);
      // The time comes from the caller at every step: while the caller does not move (q, p), the
      // compensation carries of q and p go on, and that of the time starts again.
      auto& c = integ.compensator();
      if (c.valid && c.lastq.size() == n + 1 && c.cq.size() == n + 1) {
        bool same = true;
        for (std::size_t i = 0; i < n && same; ++i) same = c.lastq[i] == s.q[i] && c.lastv[i] == s.v[i];
        if (same) {
          c.lastq[n] = s.q[n];
          c.lastv[n] = s.v[n];
          c.cq[n] = c.cv[n] = typename V::value_type(0);
        }
      }
      integ.integrate(s, dt, 1);
      for (std::size_t i = 0; i < n; ++i) {
        q[i] = s.q[i];
        p[i] = s.v[i];
      }
    }
  }

  MethodDef def_;
  EngineOptions opt_;
  // The integrator, shared by the copies odeint makes of the stepper (they pass it by value): the slot
  // exists from construction, so that the integrator a copy builds is the original's too.
  std::shared_ptr<std::shared_ptr<Holder>> cache_ = std::make_shared<std::shared_ptr<Holder>>();
};

}  // namespace nystrom
