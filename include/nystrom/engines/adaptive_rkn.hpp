// Step-size control for an embedded RKN pair (e.g. the Dormand-El-Mikkawy-Prince RKN12(10),
// catalog entry "DP12-adaptive").
//
// API (what the CLI calls for `nystrom run --method DP12-adaptive --tol 1e-12`):
//
//   nystrom::AdaptiveOptions opt;            // all fields optional except rtol
//   opt.rtol = 1e-12;
//   auto ai = nystrom::make_adaptive_integrator<V>(def, force, opt);   // def: a MethodDef whose
//                                            // tableau carries bhat/Bhat (info.adaptive == true)
//   nystrom::AdaptiveStats st = ai.integrate_to(state, t0, t1);        // lands exactly on t1
//   nystrom::AdaptiveStats st = ai.integrate_to(state, t0, t1,
//       [](auto t, const nystrom::State<V>& s) { ... });               // observer: t0, then every accepted step
//   st.accepted, st.rejected, st.force_evals, st.last_h                 // this call; ai.total() sums all calls
//
// V is std::array<T, N> or std::vector<T> with a real T (double, long double, float128, ...).
// A general (RKNG) pair (RknTableau::general(), e.g. "Fine5-adaptive") also takes a velocity-dependent force
// force(q, v, a).
// Errors: std::invalid_argument for bad input (rtol or atol negative or not finite, both zero, rtol
// below 10 eps of the scalar type, t1 < t0, t0/t1 not finite,
// NaN/inf or inconsistent state, a tableau without embedded weights, bad options);
// nystrom::StepSizeUnderflow (a std::runtime_error) when the step size falls below the rounding
// level of t, which happens when the tolerance cannot be met (too strict for the scalar type) or
// the solution is singular; nystrom::TooManySteps (std::runtime_error) after opt.max_steps steps.
// After such an exception the state holds the last accepted step (the observer has seen its time).
//
// The step loop is that of every embedded pair (engines/embedded_pair.hpp), with the controller all adaptive
// engines share (engines/step_control.hpp): the error estimate is
// the difference of the two solutions of the pair, in q (h^2 sum (b - bhat) f) and v (h sum (B - Bhat) f),
// in the mixed norm; p is the lower order of the pair (the embedded weights' order unless opt.error_order).
// The accepted increments are added with compensated summation (EngineOptions::compensated, on by default in
// double and float; the carries live in compensator()). With the exact step ends of the controller it lowers
// the round-off floor: Kepler, 100 periods, final position error at the four tightest tolerances
// (1.8e-14 .. 3.2e-15), e = 0.5: 8.4e-12, 7.5e-12, 4.8e-13, 3.3e-12 without, 5.5e-13, 2.1e-12, 1.7e-12,
// 1.5e-12 with; e = 0.9: 1.8e-11, 7.2e-11, 6.7e-12, 4.8e-12 without, 5.3e-13, 3.9e-12, 1.7e-12, 1.2e-12
// with. What remains is the rounding of the force and of the increments themselves (the same tableau in
// long double with the force rounded to double: 1e-13 .. 6e-13).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <map>
#include <mutex>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "nystrom/core/bignum.hpp"
#include "nystrom/core/error.hpp"
#include "nystrom/core/state.hpp"
#include "nystrom/engines/embedded_pair.hpp"
#include "nystrom/engines/options.hpp"
#include "nystrom/engines/rkn.hpp"
#include "nystrom/engines/step_control.hpp"
#include "nystrom/methods/method.hpp"
#include "nystrom/methods/method_data.hpp"
#include "nystrom/methods/rkn_order_conditions.hpp"

namespace nystrom {

/// The order of the main weights of a real tableau, from its order conditions evaluated in double (a
/// condition counts as satisfied below 1e-10; far above rounding, far below a failing condition of
/// a practical method). embedded_order: the same for the embedded weights.
/// Evaluated once per tableau and process: the conditions up to order 14 took 0.3 ms per integrator for DP12, a
/// fifth of a 100-period Kepler run at tolerance 1e-12.
template <class S>
int tableau_order(const RknTableau<S>& t, int max_order = 14) {
  auto d = convert_tableau<double>(t, [](const S& x) { return as_double(x); });
  std::vector<double> key{static_cast<double>(max_order), static_cast<double>(d.c.size())};
  for (const auto& row : d.a) key.insert(key.end(), row.begin(), row.end());
  for (const auto* w : {&d.c, &d.b, &d.B}) key.insert(key.end(), w->begin(), w->end());
  static std::mutex mutex;
  static std::map<std::vector<double>, int> known;  // at most 256 tableaux
  {
    const std::lock_guard<std::mutex> lock(mutex);
    if (const auto it = known.find(key); it != known.end()) return it->second;
  }
  const int order = rkn_order(d, 1e-10, max_order);
  const std::lock_guard<std::mutex> lock(mutex);
  if (known.size() >= 256) known.clear();
  known.emplace(std::move(key), order);
  return order;
}
template <class S>
int embedded_order(const RknTableau<S>& t, int max_order = 14) {
  return tableau_order(embedded_tableau(t), max_order);
}

template <class V, class Force>
class AdaptiveRknIntegrator : public EmbeddedPairIntegrator<V, RknStepper<V, Force>> {
  using Base = EmbeddedPairIntegrator<V, RknStepper<V, Force>>;

 public:
  using scalar_type = typename Base::scalar_type;

  /// eopt.compensated: compensated summation of the accepted increments (automatic: in double and float).
  AdaptiveRknIntegrator(RknTableau<scalar_type> t, Force force, AdaptiveOptions opt = {}, EngineOptions eopt = {})
      : Base(RknStepper<V, Force>(check(std::move(t)), std::move(force)), opt, eopt, "adaptive RKN") {
    // A general (RKNG) tableau carries its orders for y'' = f(t, y, y'); the order conditions of
    // y'' = f(y) decide those of the others. With a second, lower-order estimate (DOP853) the stretched
    // error behaves like that of the main solution.
    const auto& tab = this->stepper().tableau();
    int error_order = 0;
    if (this->options().error_order == 0)
      error_order = !tab.blow.empty() ? tab.general_order - 1
                    : tab.general()   ? tab.general_embedded_order
                                      : embedded_order(tab);
    const int high = tab.general() ? tab.general_order : tableau_order(tab);
    this->set_orders(error_order, high, !tab.blow.empty());
  }

 private:
  static RknTableau<scalar_type> check(RknTableau<scalar_type> t) {
    t.validate();
    if (t.bhat.empty())
      throw std::invalid_argument("adaptive step control needs a tableau with embedded weights (bhat, Bhat)");
    return t;
  }
};

/// Builds an adaptive integrator for a catalog method with embedded weights, at a reference
/// precision matched to V's scalar type.
template <class V, class F>
AdaptiveRknIntegrator<V, F> make_adaptive_integrator(const MethodDef& def, F force, AdaptiveOptions opt = {},
                                                     EngineOptions eopt = {}) {
  using S = typename V::value_type;
  opt.validate();
  if (opt.tolerance_exponent == 0) opt.tolerance_exponent = def.info.tolerance_exponent;
  if (opt.tolerance_anchor == 0) opt.tolerance_anchor = def.info.tolerance_anchor;
  // Coefficients at the reference precision; the working values are created outside it (mpfr_real).
  const auto data = shared_method_data_for(def, scalar_traits<S>::bits(), scalar_traits<S>::name());
  const auto* t = std::get_if<RknTableau<bigcomplex>>(data.get());
  if (!t || t->bhat.empty())
    throw std::invalid_argument("method '" + def.info.name + "' has no embedded pair: it cannot run with a tolerance");
  auto conv = [](const bigcomplex& x) { return to_scalar<S>(x); };
  RknTableau<S> tab = convert_tableau<S>(*t, conv);
  if constexpr (RknStepper<V, F>::carried_force) {
    // The rounding residuals of c, b and B: with a compensated force the step runs with the exact weights (the
    // rounded ones bias every step the same way, below the force's rounding but above the compensated force's).
    auto residuals = [](const std::vector<bigcomplex>& exact, const std::vector<S>& rounded) {
      std::vector<S> r;
      r.reserve(exact.size());
      for (std::size_t i = 0; i < exact.size(); ++i) r.push_back(rounding_residual(exact[i], rounded[i]));
      return r;
    };
    tab.c_lo = residuals(t->c, tab.c);
    tab.b_lo = residuals(t->b, tab.b);
    tab.B_lo = residuals(t->B, tab.B);
  }
  return AdaptiveRknIntegrator<V, F>(std::move(tab), std::move(force), opt, eopt);
}

}  // namespace nystrom
