// solve() on std::vector<nystrom::double_double> states (solve/compiled.hpp).
#include "nystrom/core/precision.hpp"
#include "solve_instances.hpp"

NYSTROM_INSTANTIATE_SOLVE(nystrom::double_double)
