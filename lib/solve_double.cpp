// solve() on std::vector<double> states (solve/compiled.hpp).
#include "solve_instances.hpp"

NYSTROM_INSTANTIATE_SOLVE(double)
