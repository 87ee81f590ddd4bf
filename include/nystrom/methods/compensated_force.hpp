// Which catalog methods use a compensated force, force(q, cq, a, alo) (takes_carry_v, core/state.hpp): the adaptive
// RKN pairs, whose precise update takes it (engines/rkn.hpp), the adaptive multi-product expansions of one order per
// run, whose products take it (engines/adaptive_mpe_kernels.hpp, trial_carried), and the splitting, composition and
// fixed-step multi-product methods with real coefficients, whose compensated drifts and kicks take it
// (engines/splitting.hpp, engines/mpe.hpp); every other engine (the adaptive MPE with order control, the fixed-step
// RKN tableaux, complex coefficients) calls force(q, a). The tool (`run --force compensated`) and the Python module
// (`Kepler(e, compensated=True)`, `NBody(..., compensated=True)`) refuse it for any other method with the same line.
#pragma once

#include <string>

#include "nystrom/methods/method.hpp"

namespace nystrom {

inline bool uses_compensated_force(const MethodInfo& m) {
  if (m.complex) return false;
  if (m.family == "rkn") return m.adaptive;
  // the multi-product expansions but order control (MPE-adaptive, MPE-adaptive-max:N), which calls force(q, a)
  if (m.family == "mpe") return !m.order_control;
  return m.family == "splitting" || m.family == "composition";
}

/// The one-line refusal; option: how the caller asked for the force ("--force compensated", "compensated=True").
inline std::string compensated_force_refusal(const std::string& option, const std::string& method) {
  return option +
         " is used by the adaptive RKN pairs (DP12-adaptive, DOP853-adaptive), the adaptive multi-product "
         "expansions of one order (M12-adaptive, mpe-adaptive:1,2,3, ...) and the fixed-step splitting, "
         "composition and multi-product methods with real coefficients (SS10, KL8, M8, ...); '" +
         method + "' would ignore it";
}

}  // namespace nystrom
