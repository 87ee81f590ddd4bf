// solve() on std::vector<nystrom::float128> states (solve/compiled.hpp).
#include "nystrom/core/precision.hpp"
#include "solve_instances.hpp"

NYSTROM_INSTANTIATE_SOLVE(nystrom::float128)
