// Umbrella header: the whole nystrom library.
#pragma once

#include "nystrom/core/bignum.hpp"
#include "nystrom/core/precision.hpp"
#include "nystrom/core/scalar.hpp"
#include "nystrom/core/state.hpp"
#include "nystrom/engines/integrator.hpp"
#include "nystrom/engines/mpe.hpp"
#include "nystrom/engines/rkn.hpp"
#include "nystrom/engines/splitting.hpp"
#include "nystrom/experiments/kepler.hpp"
#include "nystrom/methods/catalog.hpp"
#include "nystrom/problems/kepler.hpp"
