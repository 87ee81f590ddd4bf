// `nystrom flows --problem arenstorf|helix|penning|damped [--method KL8] [--periods 1] [--steps-per-period N]
//  [--samples N] [--mu] [--b x,y,z] [--e x,y,z] [--kappa] [--gamma] [--omega0] [--drive] [--drive-frequency]
//  [--q0 ...] [--v0 ...] [--precision double|long-double] [--json]`: a built-in problem with a velocity-dependent
// force and an exact flow (nystrom/velocity/solve.hpp), integrated by a splitting or multi-product method.
#include <cmath>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "nystrom/velocity/solve.hpp"

namespace {

using nystrom::cli::Bound;
using nystrom::cli::UsageError;
using namespace nystrom::velocity;

std::string text(double x) { return fmt::format("{}", x); }

struct Options {
  BuiltinSetup setup;  // the library's defaults, which Python's nystrom.flows shares
  // the numbers as text (checked by cli::parse_double), their defaults the library's
  std::string periods = text(setup.periods), mu = text(setup.mu), kappa = text(setup.kappa), gamma = text(setup.gamma),
              omega0 = text(setup.omega0), drive = text(setup.drive), drive_frequency = text(setup.drive_frequency);
  std::string b, e, q0, v0;
  std::string precision = "double";
  bool json = false;
};

std::vector<double> parse_list(const std::string& text, const std::string& what) {
  if (text.empty()) return {};
  return nystrom::cli::parse_double_list(text, what);
}

nlohmann::json to_json(const Options& o, const FlowResult& r) {
  auto num = [](double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); };
  nlohmann::json j;
  j["problem"] = o.setup.problem;
  j["method"] = r.method;
  j["order"] = r.order;
  j["symplectic"] = r.symplectic;
  j["precision"] = o.precision;
  j["dt"] = r.dt;
  j["steps"] = r.steps;
  j["time"] = r.time;
  j["q"] = r.q;
  j["v"] = r.v;
  j["force_evals"] = r.force_evals;
  j["flows"] = r.flows;
  j["invariant_name"] = r.invariant_name.empty() ? nlohmann::json(nullptr) : nlohmann::json(r.invariant_name);
  j["invariant0"] = num(r.invariant0);
  j["invariant"] = num(r.invariant);
  j["invariant_error"] = num(r.invariant_error);
  j["position_error"] = num(r.position_error);
  j["velocity_error"] = num(r.velocity_error);
  j["return_error"] = num(r.return_error);
  j["periods"] = num(r.periods);
  j["seconds"] = r.seconds;
  if (!r.samples.empty()) {
    auto& s = j["samples"] = nlohmann::json::array();
    for (const auto& x : r.samples)
      s.push_back({{"t", x.time}, {"q", x.q}, {"v", x.v}, {"invariant", num(x.invariant)}});
  }
  return j;
}

nystrom::cli::Registrar reg(
    "flows", "Velocity-dependent forces with exact flows: rotating frame, magnetic field, friction", [](CLI::App& app) {
      auto o = std::make_shared<Options>();
      app.add_option("--problem", o->setup.problem, "arenstorf, helix, penning or damped (docs/velocity.md)")
          ->capture_default_str();
      app.add_option("--method", o->setup.method,
                     "Real splitting or multi-product method (see `nystrom methods`; also mpe4:1,2,3); default KL8");
      app.add_option("--periods", o->periods,
                     "Span in periods of the problem (Arenstorf's orbit, the gyration, 2 pi/omega0); negative: "
                     "backward")
          ->capture_default_str();
      app.add_option("--steps-per-period", o->setup.steps_per_period,
                     "Steps per period (default: arenstorf 20000, helix and penning 32, damped 64)");
      app.add_option("--samples", o->setup.samples, "Record this many evenly spaced states (JSON: samples)")
          ->capture_default_str();
      app.add_option("--mu", o->mu, "arenstorf: the Moon's mass fraction")->capture_default_str();
      app.add_option("--b", o->b, "helix, penning: (charge/mass) B as x,y,z (default 0,0,1)");
      app.add_option("--e", o->e, "helix: the uniform (charge/mass) E as x,y,z (default 0.1,0,0.05)");
      app.add_option("--kappa", o->kappa, "penning: the quadrupole's strength (axial frequency squared)")
          ->capture_default_str();
      app.add_option("--gamma", o->gamma, "damped: the friction coefficient")->capture_default_str();
      app.add_option("--omega0", o->omega0, "damped: the natural frequency")->capture_default_str();
      app.add_option("--drive", o->drive, "damped: the driving amplitude F")->capture_default_str();
      app.add_option("--drive-frequency", o->drive_frequency, "damped: the driving frequency")->capture_default_str();
      app.add_option("--q0", o->q0, "Initial position, comma-separated (default: the problem's own)");
      app.add_option("--v0", o->v0, "Initial velocity, comma-separated (default: the problem's own)");
      app.add_option("--precision", o->precision, "double or long-double")->capture_default_str();
      app.add_flag("--json", o->json, "Print one JSON object");
      return [o]() {
        BuiltinSetup& s = o->setup;
        s.periods = nystrom::cli::parse_double(o->periods, "--periods");
        s.mu = nystrom::cli::parse_double(o->mu, "--mu");
        s.kappa = nystrom::cli::parse_double(o->kappa, "--kappa");
        s.gamma = nystrom::cli::parse_double(o->gamma, "--gamma");
        s.omega0 = nystrom::cli::parse_double(o->omega0, "--omega0");
        s.drive = nystrom::cli::parse_double(o->drive, "--drive");
        s.drive_frequency = nystrom::cli::parse_double(o->drive_frequency, "--drive-frequency");
        s.b = parse_list(o->b, "--b");
        s.e = parse_list(o->e, "--e");
        s.q0 = parse_list(o->q0, "--q0");
        s.v0 = parse_list(o->v0, "--v0");
        if (o->precision != "double" && o->precision != "long-double")
          throw UsageError("--precision must be double or long-double, got '" + o->precision + "'");
        if (s.steps_per_period < 0) throw UsageError("--steps-per-period must not be negative");
        if (s.samples < 0 || s.samples > 1000000) throw UsageError("--samples must be between 0 and 1000000");
        const double per =
            static_cast<double>(s.steps_per_period > 0 ? s.steps_per_period : default_steps_per_period(s.problem));
        nystrom::cli::check_work_budget(std::abs(s.periods) * per * 40, "nystrom flows");
        const FlowResult r = o->precision == "double" ? solve_builtin<double>(s) : solve_builtin<long double>(s);
        if (o->json) {
          std::cout << to_json(*o, r).dump(2) << "\n";
          return 0;
        }
        auto vec = [](const std::vector<double>& x) {
          std::string t;
          for (double c : x) t += fmt::format(" {:.15g}", c);
          return t;
        };
        fmt::print("problem        {} ({})\n", s.problem, o->precision);
        fmt::print("method         {} (order {}{})\n", r.method, r.order, r.symplectic ? ", symplectic" : "");
        fmt::print("steps          {} of {:.6g} (time {:.10g})\n", r.steps, r.dt, r.time);
        fmt::print("q             {}\n", vec(r.q));
        fmt::print("v             {}\n", vec(r.v));
        if (std::isfinite(r.return_error))
          fmt::print("return error   {:.6e} (|q - q0| after {:.6g} periods)\n", r.return_error, r.periods);
        if (std::isfinite(r.position_error))
          fmt::print("exact error    {:.6e} in q, {:.6e} in v\n", r.position_error, r.velocity_error);
        if (!r.invariant_name.empty())
          fmt::print("{:<14} {:.15g} (largest change {:.3e})\n", r.invariant_name, r.invariant, r.invariant_error);
        fmt::print("force evals    {}\n", r.force_evals);
        fmt::print("time           {:.6f} s\n", r.seconds);
        return 0;
      };
    });

}  // namespace
