// solve() on std::vector<nystrom::quad_double> states (solve/compiled.hpp).
#include "nystrom/core/precision.hpp"
#include "solve_instances.hpp"

NYSTROM_INSTANTIATE_SOLVE(nystrom::quad_double)
