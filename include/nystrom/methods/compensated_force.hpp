// Which catalog methods use a compensated force, force(q, cq, a, alo) (takes_carry_v, core/state.hpp): the adaptive
// RKN pairs, whose precise update takes it (engines/rkn.hpp); every other engine calls force(q, a). The tool
// (`run --force compensated`) and the Python module (`Kepler(e, compensated=True)`) refuse it for any other method
// with the same line.
#pragma once

#include <string>

#include "nystrom/methods/method.hpp"

namespace nystrom {

inline bool uses_compensated_force(const MethodInfo& m) { return m.adaptive && m.family == "rkn"; }

/// The one-line refusal; option: how the caller asked for the force ("--force compensated", "compensated=True").
inline std::string compensated_force_refusal(const std::string& option, const std::string& method) {
  return option + " is used by the adaptive RKN pairs (DP12-adaptive, DOP853-adaptive); '" + method +
         "' would ignore it";
}

}  // namespace nystrom
