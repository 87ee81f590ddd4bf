// solve() on the small built-in problems in one extended precision T (solve_extended_*.cpp).
#pragma once

#include <vector>

#include "solve_binding.hpp"

namespace nystrom::python {

template <class T>
py::dict solve_small(const SmallProblemForce& force, const SolveRequest& r, long mpfr_bits = 0) {
  return run_solve<std::vector<T>>(force, r, false, mpfr_bits);
}

py::dict solve_small_long_double(const SmallProblemForce& force, const SolveRequest& r);
py::dict solve_small_float128(const SmallProblemForce& force, const SolveRequest& r);
py::dict solve_small_dd(const SmallProblemForce& force, const SolveRequest& r);
py::dict solve_small_qd(const SmallProblemForce& force, const SolveRequest& r);
py::dict solve_small_mpfr(const SmallProblemForce& force, const SolveRequest& r, long bits);

}  // namespace nystrom::python
