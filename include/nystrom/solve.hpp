// solve(): one driver for every method. solve(problem, method, options, events) integrates a
// SecondOrderProblem with any catalog method or specification and returns a Solution.
//
//   auto prob = nystrom::SecondOrderProblem(force, q0, v0, 0.0, 20.0);       // force(q, a) or force(t, q, a)
//   auto sol  = nystrom::solve(prob, "M8", {.steps = 2000});                  // fixed step (or .h = 0.01)
//   auto sol  = nystrom::solve(prob, "DP12-adaptive", {.rtol = 1e-12});       // adaptive (also M10-adaptive, ...)
//   auto sol  = nystrom::solve(prob, "GBS", {.rtol = 1e-12});                 // Gragg-Bulirsch-Stoer
//   force(q, v, a) or force(t, q, v, a): velocity-dependent forces (GBS; other methods are refused)
//   nystrom::FirstOrderProblem(fun, y0, t0, t1): y' = f(t, y), fun(t, y, dy) (solve/first_order.hpp)
//   sol.t, sol.q, sol.v         saved times and states (options.t_eval, or every step end)
//   sol(t)                      the state at any t of the span (options.dense; solve/dense.hpp)
//   sol.events                  located events (Event: g(t, q, v) = 0, direction, terminal)
//   sol.force_evals, sol.accepted, sol.rejected, sol.status, sol.message
//
// This header is light: on std::vector states of double, long double (and, with nystrom/core/precision.hpp,
// float128, double-double, quad-double and MPFR) solve() calls the drivers compiled in libnystrom, with the
// force behind ErasedForce (one indirect call per force evaluation); link nystrom::nystrom (or -lnystrom).
// Other states (std::array, float, a state type of your own) and forces with the compensated form
// force(q, cq, a, alo) (core/state.hpp, takes_carry_v; the compiled drivers call force(q, a) only) run on the inline
// path, where the whole driver is compiled in your program for your force: #include <nystrom/solve_inline.hpp> for
// them, or to inline a cheap force into the engine's loop on std::vector (solve_inline(), the same arguments and
// bitwise the same results). How the drivers work: nystrom/solve/drivers.hpp.
#pragma once

#include <string>
#include <vector>

#include "nystrom/core/error.hpp"
#include "nystrom/solve/checkpoint.hpp"
#include "nystrom/solve/compiled.hpp"
#include "nystrom/solve/dense.hpp"
#include "nystrom/solve/first_order.hpp"
#include "nystrom/solve/options.hpp"
#include "nystrom/solve/problem.hpp"
#include "nystrom/solve/solution.hpp"

namespace nystrom {

/// Whether solve() and resume() run a problem with state V and force F on the drivers compiled in libnystrom (the
/// states of is_compiled_state, a force without the compensated form) rather than on the inline path.
template <class V, class F>
inline constexpr bool runs_compiled_v = is_compiled_state<V>::value && !takes_carry_v<F, V>;

/// Integrates `problem` with `method` (a catalog entry or specification, see methods/catalog.hpp) and
/// returns the solution. Throws invalid_input for a problem, method or options that cannot be integrated,
/// step_size_underflow / too_many_steps when an adaptive run cannot go on, nystrom::error when the state
/// becomes NaN or infinite.
template <class V, class F>
Solution<V> solve(const SecondOrderProblem<V, F>& problem, const std::string& method, const SolveOptions& options = {},
                  const std::vector<Event<V>>& events = {}) {
  if constexpr (runs_compiled_v<V, F>) {
    return compiled::solve<typename V::value_type>(erase(problem), nullptr, method, options, events, nullptr);
  } else {
    return solve_inline(problem, method, options, events);  // std::array etc.: #include <nystrom/solve_inline.hpp>
  }
}

/// The same with a method already resolved (resolve_method, methods/catalog.hpp).
template <class V, class F>
Solution<V> solve(const SecondOrderProblem<V, F>& problem, const MethodDef& method, const SolveOptions& options = {},
                  const std::vector<Event<V>>& events = {}) {
  if constexpr (runs_compiled_v<V, F>) {
    return compiled::solve<typename V::value_type>(erase(problem), &method, std::string(), options, events, nullptr);
  } else {
    return solve_inline(problem, method, options, events);  // std::array etc.: #include <nystrom/solve_inline.hpp>
  }
}

/// Continues a run from a checkpoint (Solution::checkpoint) to problem.t1: the same problem, method and
/// options as the run that took it (the method and options.checkpoint_problem are checked); the result
/// is bitwise that of the run that was never interrupted. The problem's q0, v0 are not used.
template <class V, class F>
Solution<V> resume(const SecondOrderProblem<V, F>& problem, const MethodDef& method,
                   const Checkpoint<real_t<typename V::value_type>>& from, const SolveOptions& options = {},
                   const std::vector<Event<V>>& events = {}) {
  if constexpr (runs_compiled_v<V, F>) {
    return compiled::solve<typename V::value_type>(erase(problem), &method, std::string(), options, events, &from);
  } else {
    return resume_inline(problem, method, from, options, events);  // std::array: #include <nystrom/solve_inline.hpp>
  }
}
/// The same with the method given by its specification.
template <class V, class F>
Solution<V> resume(const SecondOrderProblem<V, F>& problem, const std::string& method,
                   const Checkpoint<real_t<typename V::value_type>>& from, const SolveOptions& options = {},
                   const std::vector<Event<V>>& events = {}) {
  if constexpr (runs_compiled_v<V, F>) {
    return compiled::solve<typename V::value_type>(erase(problem), nullptr, method, options, events, &from);
  } else {
    return resume_inline(problem, method, from, options, events);  // std::array: #include <nystrom/solve_inline.hpp>
  }
}

/// Throws invalid_input (methods/catalog.hpp's first_order_refusal line) unless the method integrates
/// first-order systems (the methods for velocity-dependent forces). In libnystrom.
void require_first_order(const MethodDef& method);
/// The same for a method given by its specification (resolved in libnystrom).
void require_first_order(const std::string& method);

namespace first_order_detail {
template <class V, class F, class M>
FirstOrderSolution<V> solve_first_order(const FirstOrderProblem<V, F>& problem, const M& method,
                                        const SolveOptions& options, const std::vector<FirstOrderEvent<V>>& events) {
  require_first_order(method);
  const SecondOrderProblem<V, FirstOrderForce<V, F>> p(FirstOrderForce<V, F>{problem.fun}, zeros_like(problem.y0),
                                                       problem.y0, problem.t0, problem.t1);
  return from_second_order(solve(p, method, options, second_order_events(events)));
}
}  // namespace first_order_detail

/// Integrates a first-order system y' = f(t, y) (solve/first_order.hpp) with a method for velocity-dependent
/// forces (velocity_methods(): DOP853-adaptive, Fine4-adaptive, Fine5-adaptive, GBS, mpe-midpoint:K1,K2,...,
/// mpe-midpoint-adaptive:K1,K2,...); any other method is refused with one line (invalid_input).
template <class V, class F>
FirstOrderSolution<V> solve(const FirstOrderProblem<V, F>& problem, const MethodDef& method,
                            const SolveOptions& options = {}, const std::vector<FirstOrderEvent<V>>& events = {}) {
  return first_order_detail::solve_first_order(problem, method, options, events);
}

/// The same with the method given by its specification.
template <class V, class F>
FirstOrderSolution<V> solve(const FirstOrderProblem<V, F>& problem, const std::string& method,
                            const SolveOptions& options = {}, const std::vector<FirstOrderEvent<V>>& events = {}) {
  return first_order_detail::solve_first_order(problem, method, options, events);
}

}  // namespace nystrom
