// A method's descriptive record (MethodInfo) as an ordered list of named fields: the one list of keys that
// `nystrom methods --json` and Python's nystrom.methods() / method_info() both print, each layer converting
// the values to its own types.
#pragma once

#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "nystrom/methods/method.hpp"

namespace nystrom {

/// A field's value: null (std::monostate), a flag, a count, a number, a text or a list of texts.
using RecordValue = std::variant<std::monostate, bool, int, double, std::string, std::vector<std::string>>;
using MethodRecord = std::vector<std::pair<std::string, RecordValue>>;

/// The record of a method, in the order the tool prints it. The force count and the velocity flag carry two
/// keys each (force_evals_per_step and forces_per_step, velocity_dependent and velocity), so that scripts
/// written against either name read the same record. tolerance_exponent and tolerance_anchor are null for
/// fixed-step methods.
MethodRecord method_record(const MethodInfo& m);

}  // namespace nystrom
