// solve() on std::vector<long double> states (solve/compiled.hpp).
#include "solve_instances.hpp"

NYSTROM_INSTANTIATE_SOLVE(long double)
