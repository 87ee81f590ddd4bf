// A force that counts its calls: CountingForce<F> forwards every call to F and first increments a
// counter that lives outside the functor, so that the count is right whatever an integrator does with
// the copies of the force it is given.
//
//   long calls = 0;
//   auto integ = make_integrator<V>(def, CountingForce<KeplerForce>{&calls}, opt);
//
// The counter is any type with a prefix ++ (long, or a counter that enforces a budget by throwing).
// The wrapper is callable exactly where F is, so the detection of a time-dependent force a(t, q) and
// of complex states sees F through it.
#pragma once

#include <concepts>
#include <utility>

namespace nystrom {

template <class F, class Counter = long>
struct CountingForce {
  Counter* calls;
  F force{};

  template <class... A>
  requires std::invocable<F&, A...>
  decltype(auto) operator()(A&&... a) {
    ++*calls;
    return force(std::forward<A>(a)...);
  }
  template <class... A>
  requires std::invocable<const F&, A...>
  decltype(auto) operator()(A&&... a) const {
    ++*calls;
    return force(std::forward<A>(a)...);
  }
};

}  // namespace nystrom
