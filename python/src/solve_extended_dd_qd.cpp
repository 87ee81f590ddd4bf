// The small built-in problems in double-double and quad-double.
#include "solve_extended.hpp"

namespace nystrom::python {

py::dict solve_small_dd(const SmallProblemForce& force, const SolveRequest& r) {
  return solve_small<double_double>(force, r);
}

py::dict solve_small_qd(const SmallProblemForce& force, const SolveRequest& r) {
  return solve_small<quad_double>(force, r);
}

}  // namespace nystrom::python
