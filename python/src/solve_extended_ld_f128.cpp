// The small built-in problems in long double and float128.
#include "solve_extended.hpp"

namespace nystrom::python {

py::dict solve_small_long_double(const SmallProblemForce& force, const SolveRequest& r) {
  return solve_small<long double>(force, r);
}

py::dict solve_small_float128(const SmallProblemForce& force, const SolveRequest& r) {
  return solve_small<float128>(force, r);
}

}  // namespace nystrom::python
