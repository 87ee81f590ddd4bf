// First-order systems y' = f(t, y), y(t0) = y0 on [t0, t1] (t1 < t0 integrates backward), for solve():
//
//   auto prob = nystrom::FirstOrderProblem(fun, y0, 0.0, 20.0);     // fun(t, y, dy) or fun(y, dy)
//   auto sol  = nystrom::solve(prob, "GBS", {.rtol = 1e-10});
//   sol.t, sol.y, sol.y_final, sol(t), sol.events, sol.force_evals   (force_evals: calls of fun)
//
// solve() runs it as the velocity-dependent second-order problem q'' = f(t, q', ...) with v = y and q its
// integral (q0 = 0): q' = v = y, v' = f(t, v). Every method for velocity-dependent forces (MethodInfo::
// velocity: GBS, whose base is then Gragg's modified midpoint rule on y, with q carried along) integrates
// it, with output times, events (g(t, y)), dense output and checkpoints; fun is called once per stage and q
// costs no evaluation. Other methods are refused with one line (first_order_refusal, methods/catalog.hpp).
#pragma once

#include <concepts>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "nystrom/core/error.hpp"
#include "nystrom/core/scalar.hpp"
#include "nystrom/core/state.hpp"
#include "nystrom/solve/problem.hpp"
#include "nystrom/solve/solution.hpp"

namespace nystrom {

/// A right-hand side for state type V: fun(y, dy) or fun(t, y, dy).
template <class F, class V>
concept AutonomousRhs = std::invocable<F&, const V&, V&>;
template <class F, class V>
concept TimeDependentRhs = std::invocable < F&,
        const real_t<typename V::value_type>
&, const V&, V& > ;

template <class V, class F>
class FirstOrderProblem {
 public:
  using vector_type = V;
  using real_type = real_t<typename V::value_type>;
  static_assert(AutonomousRhs<F, V> || TimeDependentRhs<F, V>,
                "nystrom: the right-hand side must be callable as fun(y, dy) or fun(t, y, dy), with const V& y, "
                "V& dy of the problem's state type V and t of its real type");

  FirstOrderProblem(F f, V y_0, real_type t_0, real_type t_1)
      : fun(std::move(f)), y0(std::move(y_0)), t0(std::move(t_0)), t1(std::move(t_1)) {}

  F fun;
  V y0;
  real_type t0, t1;
};

template <class F, class V, class T0, class T1>
FirstOrderProblem(F, V, T0, T1) -> FirstOrderProblem<V, F>;

/// The first-order system as a velocity-dependent force: a(t, q, v) = f(t, v).
template <class V, class F>
struct FirstOrderForce {
  F fun;
  void operator()(const real_t<typename V::value_type>& t, const V& /*q*/, const V& y, V& dy) {
    if constexpr (AutonomousRhs<F, V>) {
      (void)t;
      fun(y, dy);
    } else {
      fun(t, y, dy);
    }
  }
};

/// An event of a first-order system: g(t, y) = 0 (direction and terminal as Event).
template <class V>
struct FirstOrderEvent {
  using real_type = real_t<typename V::value_type>;
  std::string name;
  std::function<real_type(const real_type& t, const V& y)> g;
  int direction = 0;
  bool terminal = false;
};

template <class V>
struct FirstOrderEventHit {
  using real_type = real_t<typename V::value_type>;
  std::string name;
  std::size_t index = 0;
  real_type t{};
  V y;
};

/// The solution of a first-order problem (Solution's fields with y for the state).
template <class V>
struct FirstOrderSolution {
  using real_type = real_t<typename V::value_type>;
  std::vector<real_type> t;
  std::vector<V> y;
  real_type t_final{};
  V y_final;
  long force_evals = 0;         // calls of fun by the method
  long output_force_evals = 0;  // for output times, events and dense output
  long accepted = 0, rejected = 0;
  SolveStatus status = SolveStatus::success;
  std::string message;
  std::vector<FirstOrderEventHit<V>> events;
  std::optional<Checkpoint<real_type>> checkpoint;
  /// The second-order solution it was read from (its v is y): the dense output.
  Solution<V> second_order;

  /// y at any t within the integrated span (options.dense).
  V operator()(const real_type& tt) const { return second_order(tt).v; }
};

namespace first_order_detail {

template <class V>
V zeros_like(const V& y) {
  V z = y;
  for (auto& x : z) x = typename V::value_type(0);
  return z;
}

template <class V>
std::vector<Event<V>> second_order_events(const std::vector<FirstOrderEvent<V>>& events) {
  using R = real_t<typename V::value_type>;
  std::vector<Event<V>> out;
  for (const auto& e : events) {
    if (!e.g) throw invalid_input("event '" + e.name + "' has no function");
    out.push_back({e.name, [g = e.g](const R& t, const V&, const V& y) { return g(t, y); }, e.direction, e.terminal});
  }
  return out;
}

template <class V>
FirstOrderSolution<V> from_second_order(Solution<V>&& s) {
  FirstOrderSolution<V> r;
  r.t = s.t;
  r.y = s.v;
  r.t_final = s.t_final;
  r.y_final = s.v_final;
  r.force_evals = s.force_evals;
  r.output_force_evals = s.output_force_evals;
  r.accepted = s.accepted;
  r.rejected = s.rejected;
  r.status = s.status;
  r.message = s.message;
  for (const auto& h : s.events) r.events.push_back({h.name, h.index, h.t, h.v});
  r.checkpoint = s.checkpoint;
  r.second_order = std::move(s);
  return r;
}

}  // namespace first_order_detail

}  // namespace nystrom
