// method_data_for: the coefficients of a method for a working type, refined where the published
// digits do not suffice (methods/refine.hpp). Compiled in libnystrom
// (lib/method_data.cpp).
#pragma once

#include <string>

#include "nystrom/methods/method.hpp"

namespace nystrom {

/// The coefficients of `def` for a working type of `bits` bits (named `type_name` in messages), at
/// the matching reference precision (set here). Exact methods and tables with enough digits are
/// built as they are; splitting methods published with too few digits are refined (cached per
/// method and precision); anything else is refused with std::invalid_argument.
MethodData method_data_for(const MethodDef& def, long bits, const std::string& type_name);

}  // namespace nystrom
