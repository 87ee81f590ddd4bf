// The order conditions of RKN methods are method data (methods/rkn_order_conditions.hpp): the catalog
// refines published coefficients with them. This header keeps the analysis-layer name.
#pragma once

#include "nystrom/methods/rkn_order_conditions.hpp"
