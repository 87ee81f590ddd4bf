// solve() on std::vector<nystrom::mpfr_real> states (solve/compiled.hpp).
#include "nystrom/core/precision.hpp"
#include "solve_instances.hpp"

NYSTROM_INSTANTIATE_SOLVE(nystrom::mpfr_real)
