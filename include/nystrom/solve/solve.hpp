// solve() with both paths: the compiled one (nystrom/solve.hpp) and the inline one (nystrom/solve_inline.hpp).
#pragma once

#include "nystrom/solve.hpp"
#include "nystrom/solve_inline.hpp"
