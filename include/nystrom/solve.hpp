// The driver layer: a problem, one solve() for every method, its solution with dense output, events and
// checkpoints (nystrom/solve/solve.hpp).
#pragma once

#include "nystrom/core/error.hpp"
#include "nystrom/solve/checkpoint.hpp"
#include "nystrom/solve/dense.hpp"
#include "nystrom/solve/problem.hpp"
#include "nystrom/solve/solve.hpp"
