// The entry points of solve() compiled in libnystrom: the drivers and every engine instantiated once for
// std::vector states of each supported scalar type (is_compiled_scalar, core/scalar.hpp: double and long
// double; float128, double-double, quad-double and MPFR with core/extended.hpp) and a force behind
// ErasedForce. Declarations only: a program that calls them compiles none of the engines.
#pragma once

#include <string>
#include <vector>

#include "nystrom/core/scalar.hpp"
#include "nystrom/solve/checkpoint.hpp"
#include "nystrom/solve/erased_force.hpp"
#include "nystrom/solve/options.hpp"
#include "nystrom/solve/solution.hpp"

namespace nystrom {

struct MethodDef;

/// The states solve() runs in the compiled library: std::vector of a compiled scalar type.
template <class V>
struct is_compiled_state : std::false_type {};
template <class T>
struct is_compiled_state<std::vector<T>> : is_compiled_scalar<T> {};

namespace compiled {

/// Integrates `problem` with the method `*def` (when not null) or the specification `spec`, from the
/// checkpoint `resume` when not null. Defined and instantiated in libnystrom (lib/solve_instances.hpp).
template <class T>
Solution<std::vector<T>> solve(const ErasedProblem<T>& problem, const MethodDef* def, const std::string& spec,
                               const SolveOptions& options, const std::vector<Event<std::vector<T>>>& events,
                               const Checkpoint<T>* resume);

}  // namespace compiled
}  // namespace nystrom
