// `nystrom run --problem arenstorf | damped-oscillator` (runner_velocity.hpp).
#include "runner_velocity.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "cli.hpp"
#include "nystrom/methods/catalog.hpp"
#include "nystrom/problems/arenstorf.hpp"
#include "nystrom/problems/damped_oscillator.hpp"
#include "nystrom/solve.hpp"

namespace nystrom::cli {

namespace {

using Vd = std::vector<double>;

// The Jacobi constant of the restricted three-body problem: C = 2 Omega(q) - |v|^2, Omega = |q|^2 / 2 +
// mu' / r1 + mu / r2 (conserved by the exact flow).
double jacobi(const Vd& q, const Vd& v) {
  const double mu = Arenstorf<double>::mu(), mup = 1 - mu;
  const double r1 = std::hypot(q[0] + mu, q[1]), r2 = std::hypot(q[0] - mup, q[1]);
  return q[0] * q[0] + q[1] * q[1] + 2 * mup / r1 + 2 * mu / r2 - (v[0] * v[0] + v[1] * v[1]);
}

// The damped driven oscillator of the command: omega0 = 2, gamma = 0.15, F = 0.7, omega = 1.3, from q = 1, v = 0.
const DampedOscillator<double> oscillator(2.0, 0.15, 0.7, 1.3);

nlohmann::json vec(const Vd& x) { return nlohmann::json(x); }

}  // namespace

bool is_velocity_problem(const std::string& problem) {
  return problem == "arenstorf" || problem == "damped-oscillator";
}

nlohmann::json run_velocity_problem(const RunRequest& req, const MethodDef& def) {
  if (!def.info.velocity) throw UsageError(velocity_refusal(def.info.name));
  if (def.info.adaptive && !(req.tol > 0 && std::isfinite(req.tol)))
    throw UsageError("method '" + def.info.name + "' is adaptive: give a positive --tol");
  if (!def.info.adaptive && req.tol != 0)
    throw UsageError("--tol applies to adaptive methods only; '" + def.info.name + "' runs with fixed steps");
  if (!def.info.adaptive && req.steps_per_period > 1'000'000'000L / std::max(1L, req.periods))
    throw UsageError("too many steps requested (steps-per-period x periods must be at most 1e9)");
  if (req.precision != "double") throw UsageError("--problem " + req.problem + " runs in double precision only");
  if (req.keep_complex) throw UsageError("--keep-complex is not available for --problem " + req.problem);
  if (req.periods <= 0) throw UsageError("--periods must be a positive integer");
  if (req.periods > 100000) throw UsageError("--periods must be at most 100000 for --problem " + req.problem);
  const bool arenstorf = req.problem == "arenstorf";
  const double period = arenstorf ? Arenstorf<double>::period() : 2 * std::numbers::pi / oscillator.omega;
  const double t_end = period * static_cast<double>(req.periods);
  const Vd q0 = arenstorf ? Vd{Arenstorf<double>::q0x(), 0.0} : Vd{1.0};
  const Vd v0 = arenstorf ? Vd{0.0, Arenstorf<double>::v0y()} : Vd{0.0};
  SolveOptions opt;
  if (def.info.adaptive)
    opt.rtol = req.tol;
  else
    opt.steps = req.steps_per_period * req.periods;
  const auto w0 = std::chrono::steady_clock::now();
  Solution<Vd> sol;
  try {
    sol = arenstorf ? solve(SecondOrderProblem(ArenstorfForce{}, q0, v0, 0.0, t_end), def, opt)
                    : solve(SecondOrderProblem(oscillator, q0, v0, 0.0, t_end), def, opt);
  } catch (const invalid_input& e) {
    throw UsageError(e.what());
  }
  const auto w1 = std::chrono::steady_clock::now();
  nlohmann::json j;
  j["method"] = def.info.name;
  j["family"] = def.info.family;
  j["problem"] = req.problem;
  j["precision"] = req.precision;
  j["adaptive"] = def.info.adaptive;
  if (def.info.adaptive)
    j["tol"] = req.tol;
  else
    j["steps_per_period"] = req.steps_per_period;
  j["periods"] = req.periods;
  j["period"] = period;
  j["steps"] = sol.accepted;
  j["rejected"] = sol.rejected;
  j["force_evals"] = sol.force_evals;
  j["seconds"] = std::chrono::duration<double>(w1 - w0).count();
  j["t"] = sol.t_final;
  j["q"] = vec(sol.q_final);
  j["v"] = vec(sol.v_final);
  if (arenstorf) {
    j["return_error"] = std::hypot(sol.q_final[0] - q0[0], sol.q_final[1] - q0[1]);
    const double c0 = jacobi(q0, v0);
    j["jacobi_error"] = std::abs((jacobi(sol.q_final, sol.v_final) - c0) / c0);
  } else {
    double q = 0, v = 0;
    oscillator.exact(q0[0], v0[0], t_end, q, v);
    j["position_error"] = std::abs(sol.q_final[0] - q);
    j["velocity_error"] = std::abs(sol.v_final[0] - v);
  }
  return j;
}

void print_velocity_report(const nlohmann::json& r) {
  fmt::print("method            {} ({})\n", r["method"].get<std::string>(), r["family"].get<std::string>());
  fmt::print("problem           {} ({} periods of {})\n", r["problem"].get<std::string>(), r["periods"].get<long>(),
             r["period"].get<double>());
  fmt::print("precision         {}\n", r["precision"].get<std::string>());
  if (r.contains("tol"))
    fmt::print("steps             {} accepted, {} rejected (tol {})\n", r["steps"].get<long>(),
               r["rejected"].get<long>(), r["tol"].get<double>());
  else
    fmt::print("steps             {} ({} per period)\n", r["steps"].get<long>(), r["steps_per_period"].get<long>());
  fmt::print("force evaluations {}\n", r["force_evals"].get<long>());
  if (r.contains("return_error")) {
    fmt::print("return error      {:.6e} (|q(T) - q0|)\n", r["return_error"].get<double>());
    fmt::print("Jacobi constant   {:.6e} (relative error)\n", r["jacobi_error"].get<double>());
  } else {
    fmt::print("position error    {:.6e}\n", r["position_error"].get<double>());
    fmt::print("velocity error    {:.6e}\n", r["velocity_error"].get<double>());
  }
  fmt::print("time              {:.6f} s\n", r["seconds"].get<double>());
}

}  // namespace nystrom::cli
