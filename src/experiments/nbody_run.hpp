// One measured N-body run (problems nbody and twobody) for `nystrom run` and `nystrom sweep`, through
// solve(): `steps` steps of size h with a catalog method (real or complex coefficients), or GBS at a
// tolerance (method "GBS"), and report the relative energy error and the position error against a GBS
// reference run of the same length (tolerance ref_tol). For twobody the position error is also measured
// against the exact orbit of the initial relative state (problems/reference.hpp).
// run_nbody<CompensatedNBodyForce<double>> runs the compensated force (the force's rounding error in double-word),
// which solve() runs on the inline path.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <type_traits>

#include "localerr.hpp"
#include "nystrom/methods/catalog.hpp"
#include "nystrom/problems/kepler.hpp"
#include "nystrom/problems/reference.hpp"
#include "nystrom/solve.hpp"

namespace nystrom {

struct NBodyRunResult {
  std::string method;
  long steps = 0;
  long force_evals = 0;
  long rejected = 0;              // adaptive methods and GBS: the rejected steps
  bool precise_products = false;  // adaptive multi-product methods: Solution::precise_products
  double h = 0;
  double energy_error = 0;    // |E - E0| / |E0|
  double position_error = 0;  // max over components of |q - q_ref|
  double seconds = 0;
  std::string reference;  // what position_error compares with
};

/// `method` is a catalog specification, or GBS or an adaptive method (then `tol` is its tolerance, rtol = atol). h is
/// in time units: the run is solve() over [0, h steps] in `steps` equal steps (GBS chooses its own). The reference of
/// nbody is solve() with GBS at ref_tol. Force: another force type built from the masses and the softening (with
/// CompensatedNBodyForce solve() runs the inline path, where the engines take the force's low parts: instantiate it
/// where nystrom/solve_inline.hpp is included); the energy and the reference as with NBodyForce.
template <class Force = NBodyForce<double>>
NBodyRunResult run_nbody(const std::string& method, const NBodySetup& setup, double h, long steps, double tol = 0,
                         double ref_tol = 1e-13) {
  if (!(h > 0) || !std::isfinite(h)) throw std::invalid_argument("the step size must be positive");
  if (steps <= 0 || steps > 100000000) throw std::invalid_argument("the number of steps must be between 1 and 1e8");
  const MethodDef def = resolve_solve_method(method);
  const bool adaptive = def.info.adaptive;  // GBS and the adaptive RKN and MPE methods: a tolerance, not steps
  if (adaptive && !(tol > 0))
    throw std::invalid_argument("'" + def.info.name + "' is adaptive: it needs a positive --tol");
  if (!adaptive && tol != 0) throw std::invalid_argument("--tol applies to adaptive methods only");
  const NBodyInstance inst = make_nbody_instance(setup);
  const auto& s0 = inst.particles.s;
  const double span = h * static_cast<double>(steps);
  const SecondOrderProblem prob(inst.force, s0.q, s0.v, 0.0, span);
  SolveOptions opt;
  opt.t_eval = {0.0};  // only the final state is kept
  if (adaptive) {
    opt.rtol = opt.atol = tol;
  } else {
    opt.steps = steps;
    opt.max_steps = std::max(opt.max_steps, steps);
  }
  NBodyRunResult r;
  const auto t0 = std::chrono::steady_clock::now();
  const auto sol = [&] {
    if constexpr (std::is_same_v<Force, NBodyForce<double>>) {
      return solve(prob, def, opt);
    } else {
      Force force(inst.force.masses(), inst.force.eps2());
      force.threads = inst.force.threads;
      return solve(SecondOrderProblem(force, s0.q, s0.v, 0.0, span), def, opt);
    }
  }();
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.method = def.info.name;
  r.force_evals = sol.force_evals;
  r.steps = sol.accepted;
  r.rejected = sol.rejected;
  r.precise_products = sol.precise_products;
  r.h = span / static_cast<double>(std::max(1L, sol.accepted));  // fixed steps: the step solve() takes
  const State<std::vector<double>> s{sol.q_final, sol.v_final};
  const double e0 = nbody_energy(inst.force, s0);
  r.energy_error = std::abs((nbody_energy(inst.force, s) - e0) / e0);
  if (setup.problem == "twobody") {
    // the relative orbit (x_1 - x_0, y_1 - y_0) against the exact orbit of its initial state at time r.h steps
    // (fixed steps; adaptive: the span as one step)
    const auto rel = [](const State<std::vector<double>>& x) {
      return State<std::array<double, 2>>{{x.q[1] - x.q[0], x.q[3] - x.q[2]}, {x.v[1] - x.v[0], x.v[3] - x.v[2]}};
    };
    r.position_error = (adaptive ? kepler_reference_errors(rel(s0), rel(s), span, 1)
                                 : kepler_reference_errors(rel(s0), rel(s), r.h, sol.accepted))
                           .position;
    r.reference = "exact Kepler orbit of the initial state";
  } else {
    SolveOptions ro;
    ro.t_eval = {0.0};
    ro.rtol = ro.atol = ref_tol;
    const auto ref = solve(prob, "GBS", ro);
    for (std::size_t i = 0; i < s.q.size(); ++i)
      r.position_error = std::max(r.position_error, std::abs(s.q[i] - ref.q_final[i]));
    r.reference = "GBS, tol " + std::to_string(ref_tol);
  }
  return r;
}

/// run_nbody<CompensatedNBodyForce<double>>, compiled once in the tool (src/runner_nbody_compensated.cpp).
NBodyRunResult run_nbody_compensated(const std::string& method, const NBodySetup& setup, double h, long steps,
                                     double tol);

}  // namespace nystrom
