// The options of the adaptive engines (the adaptive RKN and multi-product controllers, GBS): plain data,
// light enough for the public solve() header (solve/options.hpp).
#pragma once

#include <cmath>
#include <stdexcept>

#include "nystrom/methods/gbs_def.hpp"

namespace nystrom {

struct AdaptiveOptions {
  double rtol = 1e-10;        // relative tolerance, and the absolute one when atol is 0 (engines/step_control.hpp)
  double atol = 0;            // absolute tolerance; 0 (or equal to rtol): the mixed norm with rtol alone
  double safety = 0.9;        // safety factor on the optimal step (see below)
  double fac_min = 0.2;       // smallest step ratio per step
  double fac_max = 4.0;       // largest step ratio per step
  double h0 = 0.0;            // first step; 0: automatic
  double h_max = 0.0;         // largest step; 0: |t1 - t0|
  long max_steps = 10000000;  // accepted + rejected steps per integrate_to call
  int error_order = 0;        // p, the lower order of the pair; 0: determined from the tableau
  bool predictive = true;     // Gustafsson's predictive step ratio as well (adaptive_detail::StepController)
  // The tolerance the controller works to, tol_c = anchor (tol / anchor)^gamma above the anchor and tol below it
  // (tolerance proportionality: the global error follows tol; adaptive_detail::controlled_tolerance): the exponent
  // gamma and the anchor. 0: the method's (MethodInfo::tolerance_exponent and tolerance_anchor, set by
  // make_adaptive_integrator and make_adaptive_mpe_integrator; gamma 1 for an engine built directly, anchor
  // 1e-15); gamma 1: tol itself (plain error-per-step control).
  double tolerance_exponent = 0;
  double tolerance_anchor = 0;

  void validate() const {
    if (!std::isfinite(rtol) || !(rtol >= 0)) throw std::invalid_argument("tolerance must be a finite number >= 0");
    if (!std::isfinite(atol) || !(atol >= 0))
      throw std::invalid_argument("absolute tolerance must be a finite number >= 0");
    if (!(rtol > 0) && !(atol > 0)) throw std::invalid_argument("tolerance and absolute tolerance are both zero");
    if (!(safety > 0 && safety <= 1)) throw std::invalid_argument("safety factor must be in (0, 1]");
    if (!(fac_min > 0 && fac_min < 1)) throw std::invalid_argument("fac_min must be in (0, 1)");
    if (!(fac_max > 1 && std::isfinite(fac_max))) throw std::invalid_argument("fac_max must be a finite number > 1");
    if (!std::isfinite(h0) || h0 < 0) throw std::invalid_argument("initial step h0 must be finite and >= 0");
    if (!std::isfinite(h_max) || h_max < 0) throw std::invalid_argument("h_max must be finite and >= 0");
    if (max_steps <= 0) throw std::invalid_argument("max_steps must be positive");
    if (error_order < 0) throw std::invalid_argument("error_order must be >= 0");
    if (!(tolerance_exponent == 0 || (tolerance_exponent >= 0.5 && tolerance_exponent <= 1)))
      throw std::invalid_argument("tolerance_exponent must be 0 (the method's) or in [0.5, 1]");
    if (!std::isfinite(tolerance_anchor) || !(tolerance_anchor >= 0) || tolerance_anchor > 1e-3)
      throw std::invalid_argument("tolerance_anchor must be 0 (the method's) or in (0, 1e-3]");
  }
};

struct GbsOptions {
  double rtol = 1e-12;
  double atol = 1e-12;
  int max_columns = 12;  // kmax: columns of the extrapolation table (order up to 2 kmax)
  GbsSequence sequence = GbsSequence::harmonic;
  double initial_step = 0;    // 0: the first call's span
  long max_steps = 10000000;  // per integrate_to call, accepted and rejected
};

}  // namespace nystrom
