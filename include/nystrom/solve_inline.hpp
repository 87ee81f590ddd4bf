// The inline path of solve(): the whole driver and its engines compiled in the including program for its
// own force and state type. Needed for states that libnystrom does not compile (std::array, float, a state
// type of your own: nystrom/solve.hpp's solve() then runs this), and for hot loops that want a cheap force
// inlined into the engine's loop on std::vector (call solve_inline() directly). The results are bitwise
// those of the compiled path. Includes the engines and Boost.Multiprecision: expect a longer compilation.
#pragma once

#include <string>
#include <vector>

#include "nystrom/solve.hpp"
#include "nystrom/solve/drivers.hpp"

namespace nystrom {

template <class V, class F>
Solution<V> solve_inline(const SecondOrderProblem<V, F>& problem, const MethodDef& method,
                         const SolveOptions& options = {}, const std::vector<Event<V>>& events = {}) {
  return solve_detail::solve_impl(problem, method, options, events, nullptr);
}
template <class V, class F>
Solution<V> solve_inline(const SecondOrderProblem<V, F>& problem, const std::string& method,
                         const SolveOptions& options = {}, const std::vector<Event<V>>& events = {}) {
  return solve_detail::solve_impl(problem, resolve_solve_method(method), options, events, nullptr);
}
template <class V, class F>
Solution<V> resume_inline(const SecondOrderProblem<V, F>& problem, const MethodDef& method,
                          const Checkpoint<real_t<typename V::value_type>>& from, const SolveOptions& options = {},
                          const std::vector<Event<V>>& events = {}) {
  return solve_detail::solve_impl(problem, method, options, events, &from);
}
template <class V, class F>
Solution<V> resume_inline(const SecondOrderProblem<V, F>& problem, const std::string& method,
                          const Checkpoint<real_t<typename V::value_type>>& from, const SolveOptions& options = {},
                          const std::vector<Event<V>>& events = {}) {
  return solve_detail::solve_impl(problem, resolve_solve_method(method), options, events, &from);
}

}  // namespace nystrom
