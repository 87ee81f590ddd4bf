// A stepper that models Boost.Odeint's Stepper concept for second-order systems, so that odeint's
// integrate functions run any nystrom method:
//
//   nystrom::OdeintStepper<std::array<double, 2>> st("M8");
//   auto x = std::make_pair(q, p);                                   // or std::make_pair(std::ref(q), std::ref(p))
//   boost::numeric::odeint::integrate_const(st, force, x, t0, t1, dt, observer);   // observer(x, t)
//
// The system is the force a(q) in the form of odeint's symplectic steppers' momentum function,
// force(q, dpdt) (unit mass: p = v). The state is a pair (q, p) of V, or of references to V
// (std::reference_wrapper or boost::reference_wrapper). Each do_step is one step of the method
// (compensated summation and FSAL forces carry over between steps while the caller does not move
// the state). This header includes no Boost header: it only names odeint's stepper_tag.
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <type_traits>
#include <typeinfo>
#include <utility>

#include "nystrom/engines/integrator.hpp"
#include "nystrom/methods/catalog.hpp"

namespace boost::numeric::odeint {
struct stepper_tag;
}  // namespace boost::numeric::odeint

namespace nystrom {

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

  /// One step of size dt from the state (q, p) in place; t is not used (the force is autonomous).
  template <class System, class StateInOut>
  void do_step(System system, StateInOut& x, time_type /*t*/, time_type dt) {
    step(system, unwrap(x.first), unwrap(x.second), dt);
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

  // The force seen by the engine: the current system, reached through a pointer that every do_step
  // sets, so that the integrator (coefficients converted once) lives across steps.
  template <class System>
  struct SystemRef {
    System* sys = nullptr;
    void operator()(const V& q, V& a) const { (*sys)(q, a); }
  };

  struct Holder {
    virtual ~Holder() = default;
    virtual long force_evals() const = 0;
    const std::type_info* type = nullptr;
  };
  template <class System>
  struct TypedHolder : Holder {
    TypedHolder(const MethodDef& def, EngineOptions opt) : integ(make_integrator<V>(def, SystemRef<System>{}, opt)) {}
    long force_evals() const override { return integ.force_evals(); }
    Integrator<V, SystemRef<System>> integ;
  };

  template <class System>
  void step(System& system, V& q, V& p, time_type dt) {
    if (q.size() != p.size()) throw invalid_input("inconsistent state: q and p differ in size");
    auto& slot = *cache_;
    if (!slot || *slot->type != typeid(System)) {
      auto h = std::make_shared<TypedHolder<System>>(def_, opt_);
      h->type = &typeid(System);
      slot = h;
    }
    auto& integ = static_cast<TypedHolder<System>&>(*slot).integ;
    integ.force().sys = &system;
    State<V> s{std::move(q), std::move(p)};
    integ.integrate(s, dt, 1);
    q = std::move(s.q);
    p = std::move(s.v);
  }

  MethodDef def_;
  EngineOptions opt_;
  // The integrator, shared by the copies odeint makes of the stepper (they pass it by value): the slot
  // exists from construction, so that the integrator a copy builds is the original's too.
  std::shared_ptr<std::shared_ptr<Holder>> cache_ = std::make_shared<std::shared_ptr<Holder>>();
};

}  // namespace nystrom
