// The small built-in problems in MPFR (the caller holds the MpfrPrecision scope of the run).
#include "solve_extended.hpp"

namespace nystrom::python {

py::dict solve_small_mpfr(const SmallProblemForce& force, const SolveRequest& r, long bits) {
  return solve_small<mpfr_real>(force, r, bits);
}

}  // namespace nystrom::python
