// method_data_for: the coefficients of a method for a working type, refined where the published
// digits do not suffice (methods/refine.hpp). Its definition is in methods/impl/method_data.ipp
// (compiled once with NYSTROM_SEPARATE_COMPILATION, see core/config.hpp; inline otherwise).
#pragma once

#include <string>

#include "nystrom/core/config.hpp"
#include "nystrom/methods/method.hpp"

namespace nystrom {

/// The coefficients of `def` for a working type of `bits` bits (named `type_name` in messages), at
/// the matching reference precision (set here). Exact methods and tables with enough digits are
/// built as they are; splitting methods published with too few digits are refined (cached per
/// method and precision); anything else is refused with std::invalid_argument.
NYSTROM_DECL MethodData method_data_for(const MethodDef& def, long bits, const std::string& type_name);

}  // namespace nystrom

#ifndef NYSTROM_SEPARATE_COMPILATION
#include "nystrom/methods/impl/method_data.ipp"
#endif
