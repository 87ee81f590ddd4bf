// The definition of compiled::solve (solve/compiled.hpp), instantiated for one scalar type per file of lib/:
// the inline path's drivers (solve/drivers.hpp) on std::vector<T> with the erased force, in its
// time-independent, time-dependent and velocity-dependent forms (the last only with the methods for
// y'' = f(t, y, y')).
#pragma once

#include <string>
#include <vector>

#include "nystrom/solve/compiled.hpp"
#include "nystrom/solve/drivers.hpp"

namespace nystrom::compiled {

template <class T>
Solution<std::vector<T>> solve(const ErasedProblem<T>& p, const MethodDef* def, const std::string& spec,
                               const SolveOptions& options, const std::vector<Event<std::vector<T>>>& events,
                               const Checkpoint<T>* resume) {
  using V = std::vector<T>;
  const MethodDef resolved = def ? MethodDef{} : resolve_solve_method(spec);
  const MethodDef& method = def ? *def : resolved;
  if (p.force.velocity_dependent()) {
    const SecondOrderProblem<V, ErasedVelocity<T>> prob(ErasedVelocity<T>{p.force}, p.q0, p.v0, p.t0, p.t1);
    return solve_detail::solve_impl(prob, method, options, events, resume);
  }
  if (p.force.time_dependent()) {
    const SecondOrderProblem<V, ErasedTimed<T>> prob(ErasedTimed<T>{p.force}, p.q0, p.v0, p.t0, p.t1);
    return solve_detail::solve_impl(prob, method, options, events, resume);
  }
  const SecondOrderProblem<V, ErasedAutonomous<T>> prob(ErasedAutonomous<T>{p.force}, p.q0, p.v0, p.t0, p.t1);
  return solve_detail::solve_impl(prob, method, options, events, resume);
}

}  // namespace nystrom::compiled

#define NYSTROM_INSTANTIATE_SOLVE(T)                                                                                 \
  template nystrom::Solution<std::vector<T>> nystrom::compiled::solve<T>(                                            \
      const nystrom::ErasedProblem<T>&, const nystrom::MethodDef*, const std::string&, const nystrom::SolveOptions&, \
      const std::vector<nystrom::Event<std::vector<T>>>&, const nystrom::Checkpoint<T>*);
