// One measured N-body run (problems nbody and twobody) for `nystrom run` and `nystrom sweep`:
// integrate `steps` steps of size h with a catalog method (real or complex coefficients), or with GBS at a
// tolerance (method "GBS"), and report the relative energy error and the position error against a GBS
// reference run of the same length (tolerance ref_tol). For twobody the position error is also measured
// against the exact orbit of the initial relative state (problems/reference.hpp).
#pragma once

#include <chrono>
#include <cmath>
#include <string>

#include "localerr.hpp"
#include "nystrom/engines/gbs.hpp"
#include "nystrom/problems/kepler.hpp"
#include "nystrom/problems/reference.hpp"

namespace nystrom {

struct NBodyRunResult {
  std::string method;
  long steps = 0;
  long force_evals = 0;
  double h = 0;
  double energy_error = 0;    // |E - E0| / |E0|
  double position_error = 0;  // max over components of |q - q_ref|
  double seconds = 0;
  std::string reference;  // what position_error compares with
};

/// `method` is a catalog specification or "GBS" (then `tol` is its tolerance). h is in time units.
inline NBodyRunResult run_nbody(const std::string& method, const NBodySetup& setup, double h, long steps,
                                double tol = 0, double ref_tol = 1e-13) {
  if (!(h > 0) || !std::isfinite(h)) throw std::invalid_argument("the step size must be positive");
  if (steps <= 0 || steps > 100000000) throw std::invalid_argument("the number of steps must be between 1 and 1e8");
  const NBodyInstance inst = make_nbody_instance(setup);
  NBodyRunResult r;
  auto s = inst.particles.s;
  const auto t0 = std::chrono::steady_clock::now();
  if (method == "GBS" || method == "gbs") {
    if (!(tol > 0)) throw std::invalid_argument("GBS needs a positive --tol");
    GbsOptions o;
    o.rtol = o.atol = tol;
    GbsIntegrator<std::vector<double>, NBodyForce<double>> g(inst.force, o);
    g.integrate(s, h, steps);
    r.method = "GBS";
    r.force_evals = g.force_evals();
  } else {
    if (tol != 0) throw std::invalid_argument("--tol applies to GBS only here");
    NBodyMethodStepper st(resolve_method(method), inst.force);
    st.integrate(s, h, steps);
    r.method = st.info().name;
    r.force_evals = st.force_evals();
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.steps = steps;
  r.h = h;
  const double e0 = nbody_energy(inst.force, inst.particles.s);
  r.energy_error = std::abs((nbody_energy(inst.force, s) - e0) / e0);
  if (setup.problem == "twobody") {
    // the relative orbit (x_1 - x_0, y_1 - y_0) against the exact orbit of its initial state at time h steps
    const auto rel = [](const State<std::vector<double>>& x) {
      return State<std::array<double, 2>>{{x.q[1] - x.q[0], x.q[3] - x.q[2]}, {x.v[1] - x.v[0], x.v[3] - x.v[2]}};
    };
    r.position_error = kepler_reference_errors(rel(inst.particles.s), rel(s), h, steps).position;
    r.reference = "exact Kepler orbit of the initial state";
  } else {
    GbsOptions o;
    o.rtol = o.atol = ref_tol;
    GbsIntegrator<std::vector<double>, NBodyForce<double>> g(inst.force, o);
    auto ref = inst.particles.s;
    g.integrate_to(ref, h * static_cast<double>(steps));
    for (std::size_t i = 0; i < s.q.size(); ++i)
      r.position_error = std::max(r.position_error, std::abs(s.q[i] - ref.q[i]));
    r.reference = "GBS, tol " + std::to_string(ref_tol);
  }
  return r;
}

}  // namespace nystrom
