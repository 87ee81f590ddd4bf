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
#include "nystrom/methods/blanes_moan2002.hpp"
#include "nystrom/methods/catalog.hpp"
#include "nystrom/methods/chin2010.hpp"
#include "nystrom/methods/compositions.hpp"
#include "nystrom/methods/dormand_prince1987.hpp"
#include "nystrom/methods/gurkan.hpp"
#include "nystrom/methods/method_data.hpp"
#include "nystrom/problems/kepler.hpp"
