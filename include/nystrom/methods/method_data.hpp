// method_data_for: the coefficients of a method for a working type, refined where the published
// digits do not suffice (methods/refine.hpp). Compiled in libnystrom
// (lib/method_data.cpp).
#pragma once

#include <memory>
#include <string>

#include "nystrom/methods/method.hpp"

namespace nystrom {

/// The coefficients of `def` for a working type of `bits` bits (named `type_name` in messages), at
/// the matching reference precision (set here). Exact methods and tables with enough digits are
/// built as they are; splitting methods published with too few digits are refined (cached per
/// method and precision); anything else is refused with std::invalid_argument.
MethodData method_data_for(const MethodDef& def, long bits, const std::string& type_name);
/// The same without a copy: the coefficients that the library keeps (for a catalog entry, built once per
/// precision and shared by every run; a copy of a table in MPFR costs 5-20 microseconds per run).
std::shared_ptr<const MethodData> shared_method_data_for(const MethodDef& def, long bits, const std::string& type_name);

}  // namespace nystrom
