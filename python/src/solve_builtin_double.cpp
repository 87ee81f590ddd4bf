// solve() on the built-in problems in double: real and complex coefficients, every engine.
#include <array>
#include <vector>

#include "nystrom/methods/compensated_force.hpp"
#include "nystrom/problems/kepler.hpp"
#include "nystrom/problems/nbody.hpp"
#include "nystrom/solve_inline.hpp"  // Kepler on std::array, the compensated N-body force: the driver compiled for them
#include "solve_binding.hpp"

namespace nystrom::python {

py::dict solve_builtin_double(const std::string& problem, const std::vector<double>& params, const SolveRequest& r) {
  // Kepler(e, compensated=True), NBody(..., compensated=True): the force in double-word, for the methods that take
  // it, with the refusal of the tool's `run --force compensated`.
  if (is_compensated_problem(problem) && !uses_compensated_force(r.method.info))
    throw invalid_input(compensated_force_refusal("compensated=True", r.method.info.name));
  if (problem == "kepler") return run_solve<std::array<double, 2>>(KeplerForce{}, r, false);
  if (problem == "kepler_compensated") return run_solve<std::array<double, 2>>(CompensatedKeplerForce{}, r, false);
  if (problem == "nbody" || problem == "nbody_compensated") {
    std::vector<double> gm(params.begin() + 1, params.end());
    if (gm.size() * 3 != r.q0.size()) throw invalid_input("N-body state must hold 3 coordinates per particle");
    if (problem == "nbody")
      return run_solve<std::vector<double>>(NBodyForce<double>(std::move(gm), params.at(0)), r, false);
    return run_solve<std::vector<double>>(CompensatedNBodyForce<double>(std::move(gm), params.at(0)), r, false);
  }
  if (problem == "henon_heiles" || problem == "harmonic")
    return run_solve<std::vector<double>>(SmallProblemForce::of(problem, params, r.q0.size()), r, false);
  throw invalid_input("unknown built-in problem '" + problem + "'");
}

}  // namespace nystrom::python
