// One measured run on the Kepler problem: the numbers `nystrom run` prints and `nystrom sweep` plots.
#pragma once

#include <array>
#include <chrono>
#include <cmath>
#include <complex>
#include <stdexcept>
#include <string>

#include "nystrom/engines/adaptive_mpe.hpp"
#include "nystrom/engines/adaptive_rkn.hpp"
#include "nystrom/engines/gbs.hpp"
#include "nystrom/engines/integrator.hpp"
#include "nystrom/methods/catalog.hpp"
#include "nystrom/problems/kepler.hpp"
#include "nystrom/problems/reference.hpp"

namespace nystrom {

struct KeplerRunResult {
  std::string method;
  int order = 0;
  std::string precision;
  double ecc = 0;
  long steps = 0;
  long force_evals = 0;
  double h = 0;
  double precession_per_period = 0;  // signed LRL rotation per period (rad), counter-clockwise positive
  double energy_error = 0;           // relative |E - E0| / |E0| at the end
  double position_error = 0;         // |q - q_exact| at the end
  double velocity_error = 0;         // |v - v_exact| at the end
  double seconds = 0;
  double t = 0;                    // the end time (nearest double)
  std::array<double, 2> q{}, v{};  // the final state (nearest doubles)
};

namespace detail {

/// Fills the diagnostics of a Kepler run that went from s0 to s in n steps of size h (an adaptive run
/// to t_end: h = t_end, n = 1). The errors are against the exact orbit of s0 (the initial state as
/// rounded to T) at the exact end time h n, evaluated in quad-double or better (problems/reference.hpp):
/// they measure the integrator alone.
template <class T>
void kepler_diagnostics(KeplerRunResult& r, const State<std::array<T, 2>>& s0, const State<std::array<T, 2>>& s,
                        const T& h, long n, long periods) {
  const T angle = signed_angle(lrl_vector(s0), lrl_vector(s));
  r.precession_per_period = as_double(angle / T(periods));
  const ReferenceErrors err = kepler_reference_errors(s0, s, h, n);
  r.energy_error = err.energy;
  r.position_error = err.position;
  r.velocity_error = err.velocity;
  r.t = as_double(h * T(n));
  r.q = {as_double(s.q[0]), as_double(s.q[1])};
  r.v = {as_double(s.v[0]), as_double(s.v[1])};
}

}  // namespace detail

/// Integrates `periods` orbits with an adaptive method at tolerance `tol`, in real type T: an RKN
/// tableau with an embedded pair (DP12-adaptive) or a multi-product method (M10-adaptive,
/// mpe-adaptive:K; engines/adaptive_mpe.hpp). `steps` in the result counts accepted steps.
template <class T>
KeplerRunResult run_kepler_adaptive(const MethodDef& def, double ecc, double tol, long periods) {
  if (periods <= 0) throw std::invalid_argument("number of periods must be positive");
  if (!std::isfinite(ecc)) throw std::invalid_argument("eccentricity is not finite");
  const KeplerProblem<T> prob(static_cast<T>(ecc));
  AdaptiveOptions opt;
  opt.rtol = tol;
  const auto s0 = prob.initial_state();
  auto s = s0;
  const T t_end = KeplerProblem<T>::period() * T(periods);
  const auto t0 = std::chrono::steady_clock::now();
  AdaptiveStats st;
  if (std::holds_alternative<MpeDef>(def.build())) {
    auto integ = make_adaptive_mpe_integrator<std::array<T, 2>>(def, KeplerForce{}, opt);
    st = integ.integrate_to(s, T(0), t_end);
  } else {
    auto integ = make_adaptive_integrator<std::array<T, 2>>(def, KeplerForce{}, opt);
    st = integ.integrate_to(s, T(0), t_end);
  }
  const auto t1 = std::chrono::steady_clock::now();
  KeplerRunResult r;
  r.method = def.info.name;
  r.order = def.info.order;
  r.precision = scalar_traits<T>::name();
  r.ecc = ecc;
  r.steps = st.accepted;
  r.force_evals = st.force_evals;
  r.h = as_double(t_end / T(st.accepted > 0 ? st.accepted : 1));  // mean accepted step
  r.seconds = std::chrono::duration<double>(t1 - t0).count();
  detail::kepler_diagnostics(r, s0, s, t_end, 1, periods);
  return r;
}

/// Integrates `periods` orbits with the Gragg-Bulirsch-Stoer extrapolation integrator at tolerance `tol`
/// (relative and absolute), in real type T. `steps` counts accepted steps.
template <class T>
KeplerRunResult run_kepler_gbs(double ecc, double tol, long periods) {
  if (periods <= 0) throw std::invalid_argument("number of periods must be positive");
  if (!(tol > 0) || !std::isfinite(tol)) throw std::invalid_argument("GBS needs a positive, finite tolerance");
  const KeplerProblem<T> prob(static_cast<T>(ecc));
  GbsOptions opt;
  opt.rtol = opt.atol = tol;
  GbsIntegrator<std::array<T, 2>, KeplerForce> integ(KeplerForce{}, opt);
  const auto s0 = prob.initial_state();
  auto s = s0;
  const T t_end = KeplerProblem<T>::period() * T(periods);
  const auto t0 = std::chrono::steady_clock::now();
  integ.integrate_to(s, t_end);
  const auto t1 = std::chrono::steady_clock::now();
  KeplerRunResult r;
  r.method = "GBS";
  r.order = 0;
  r.precision = scalar_traits<T>::name();
  r.ecc = ecc;
  r.steps = integ.steps();
  r.force_evals = integ.force_evals();
  r.h = as_double(t_end / T(r.steps > 0 ? r.steps : 1));
  r.seconds = std::chrono::duration<double>(t1 - t0).count();
  detail::kepler_diagnostics(r, s0, s, t_end, 1, periods);
  return r;
}

/// Integrates `periods` orbits with `steps_per_period` steps each, in real type T.
template <class T>
KeplerRunResult run_kepler(const MethodDef& def, double ecc, long steps_per_period, long periods,
                           EngineOptions opt = {}) {
  if (steps_per_period <= 0) throw std::invalid_argument("steps per period must be positive");
  if (periods <= 0) throw std::invalid_argument("number of periods must be positive");
  if (!std::isfinite(ecc)) throw std::invalid_argument("eccentricity is not finite");
  const KeplerProblem<T> prob(static_cast<T>(ecc));
  const long n = steps_per_period * periods;
  const T h = KeplerProblem<T>::period() / T(steps_per_period);
  const auto s0 = prob.initial_state();
  State<std::array<T, 2>> s = s0;
  const auto t0 = std::chrono::steady_clock::now();
  RealStateIntegrator<std::array<T, 2>, KeplerForce> integ(def, KeplerForce{}, opt);
  integ.integrate(s, h, n);
  const long evals = integ.force_evals();
  const auto t1 = std::chrono::steady_clock::now();
  KeplerRunResult r;
  r.method = def.info.name;
  r.order = def.info.order;
  r.precision = scalar_traits<T>::name();
  r.ecc = ecc;
  r.steps = n;
  r.force_evals = evals;
  r.h = as_double(h);
  r.seconds = std::chrono::duration<double>(t1 - t0).count();
  detail::kepler_diagnostics(r, s0, s, h, n, periods);
  return r;
}

}  // namespace nystrom
