// `nystrom run --problem kepler --ecc 0.9 --method M8 --steps-per-period 1000 --periods 10 [--json]`
#include <cstddef>
#include <iostream>
#include <memory>
#include <string>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "nystrom/methods/catalog.hpp"
#include "runner.hpp"
#include "runner_planetary.hpp"
#include "runner_solve.hpp"
#include "runner_velocity.hpp"
#include "sweep.hpp"

namespace {

// The report of one run as a table. The step of an adaptive method is the mean accepted step (span / steps).
void print_report(const nystrom::cli::RunReport& r) {
  fmt::print("method            {} ({}, order {})\n", r.method, r.family, r.order);
  fmt::print("problem           {}{}\n", r.problem, r.problem == "kepler" ? fmt::format(" e = {}", r.ecc) : "");
  fmt::print("precision         {}\n", r.precision);
  if (!r.adaptive)
    fmt::print("steps             {} (h = {:.6g})\n", r.steps, r.h);
  else
    fmt::print("steps             {} accepted, {} rejected (mean h = {:.6g})\n", r.steps, r.rejected, r.h);
  fmt::print("force evaluations {}\n", r.force_evals);
  if (r.precise_products) fmt::print("products          precise (each carries its own rounding)\n");
  if (r.problem == "kepler") fmt::print("precession/period {:+.6e} rad\n", r.precession_per_period);
  if (r.problem == "nbody") fmt::print("(position error against a GBS reference run at tolerance 1e-13)\n");
  fmt::print("energy error      {:.6e} (relative)\n", r.energy_error);
  fmt::print("position error    {:.6e}\n", r.position_error);
  fmt::print("time              {:.6f} s\n", r.seconds);
}

// "(x, y)" of a JSON array of numbers, each the shortest decimal that reads back to the same double.
std::string vec_text(const nlohmann::json& a) {
  std::string s = "(";
  for (std::size_t i = 0; i < a.size(); ++i) s += fmt::format("{}{}", i ? ", " : "", a[i].get<double>());
  return s + ")";
}

// What a run through solve() adds to the table: the final state, output times, events, checkpoint.
void print_solve_extra(const nlohmann::json& x) {
  fmt::print("output forces     {} (force evaluations of the partial steps for output times and events)\n",
             x.at("output_force_evals").get<long>());
  fmt::print("final state       t = {}, q = {}, v = {}\n", x.at("t").get<double>(), vec_text(x.at("q")),
             vec_text(x.at("v")));
  if (x.contains("checkpoint_t")) fmt::print("checkpoint        at t = {}\n", x["checkpoint_t"].get<double>());
  if (x.contains("output")) {
    fmt::print("output times      {}\n", x["output"].size());
    for (const auto& o : x["output"])
      fmt::print("  t = {}  q = {}  v = {}\n", o["t"].get<double>(), vec_text(o["q"]), vec_text(o["v"]));
  }
  if (x.contains("events")) {
    fmt::print("events            {}\n", x["events"].size());
    for (const auto& e : x["events"])
      fmt::print("  {:<10}  t = {}  q = {}  v = {}\n", e["name"].get<std::string>(), e["t"].get<double>(),
                 vec_text(e["q"]), vec_text(e["v"]));
  }
}

struct Options {
  nystrom::cli::RunRequest req;
  nystrom::cli::SolveRequest sreq;
  std::string method;
  bool json = false;
  double years = 0;  // outer-solar-system
  bool no_reference = false;
  bool h_given = false;  // --h on the command line (outer-solar-system's default step differs from nbody's)
};

nystrom::cli::Registrar reg("run", "Integrate one problem with one method and report its errors", [](CLI::App& app) {
  auto o = std::make_shared<Options>();
  app.add_option("--problem", o->req.problem,
                 "Problem: kepler (Chin eqs 35-36), harmonic, twobody (two equal masses), nbody (Plummer sphere), "
                 "outer-solar-system (Hairer, GNI I.2.4; Wisdom-Holman maps WH, WH-M8, SABA3, ... or direct methods); "
                 "with velocity-dependent forces (GBS): arenstorf (Hairer-Norsett-Wanner I, II.0), damped-oscillator")
      ->capture_default_str();
  app.add_option("--n", o->req.n, "nbody: number of particles of the Plummer sphere")
      ->capture_default_str()
      ->check(nystrom::cli::range_check(2, 1000000));
  app.add_option("--seed", o->req.seed, "nbody: seed of the Plummer sample")->capture_default_str();
  app.add_option("--ic", o->req.ic_file, "nbody: particle file (m x y z vx vy vz per line)");
  app.add_option("--eps2", o->req.eps2, "nbody: softening squared (default (1/N)^2; twobody 0)")
      ->check(nystrom::cli::non_negative_check());
  // Recorded while parsing: the action runs after the parser (and its options) are gone.
  app.add_option("--h", o->req.h, "nbody: step size; outer-solar-system: step in days (default 100)")
      ->capture_default_str()
      ->check(nystrom::cli::positive_check())
      ->each([o](const std::string&) { o->h_given = true; });
  app.add_option("--years", o->years, "outer-solar-system: years of 365.25 days (default 1000)")
      ->check(nystrom::cli::positive_check());
  app.add_flag("--no-reference", o->no_reference, "outer-solar-system: skip the long double reference run");
  app.add_option("--steps", o->req.steps, "nbody: number of steps")
      ->capture_default_str()
      ->check(nystrom::cli::positive_check());
  app.add_option("--ecc", o->req.ecc, "Kepler eccentricity, 0 <= e < 1")
      ->capture_default_str()
      ->check(nystrom::cli::eccentricity_check());
  app.add_option("--method", o->method,
                 "Method name or spec (see `nystrom methods`; with --restart, the checkpoint's)");
  app.add_option("--steps-per-period", o->req.steps_per_period, "Steps per orbital period")
      ->capture_default_str()
      ->check(nystrom::cli::positive_check());
  app.add_option("--periods", o->req.periods, "Number of whole periods")
      ->capture_default_str()
      ->check(nystrom::cli::positive_check());
  app.add_option("--precision", o->req.precision, "Scalar type (double, long-double, ...)")->capture_default_str();
  app.add_option("--tol", o->req.tol, "Tolerance of an adaptive method (e.g. DP12-adaptive)")
      ->check(nystrom::cli::tolerance_check());
  app.add_flag("--keep-complex", o->req.keep_complex, "Complex methods: keep the complex state between steps");
  app.add_option("--force", o->req.force,
                 "kepler, twobody, nbody: plain, or compensated (the force with its rounding error, double-word; "
                 "used in double by the fixed-step splitting, composition and multi-product methods, by the "
                 "adaptive RKN pairs and by the adaptive multi-product expansions of one order, whose tolerance may "
                 "then go down to eps/2)")
      ->capture_default_str();
  app.add_option("--output-times", o->sreq.output_times,
                 "Kepler: A:B:N, the state at N equally spaced times from A to B (listed after the table; JSON "
                 "`output`)");
  app.add_option("--events", o->sreq.events,
                 "Kepler: events to locate, any of pericentre,apocentre,y=0 (listed after the table; JSON `events`)");
  app.add_option("--checkpoint", o->sreq.checkpoint, "Kepler: write the integrator's state to this file ...");
  app.add_option("--checkpoint-at", o->sreq.checkpoint_at, "... at the first step boundary at or after this time");
  app.add_option("--restart", o->sreq.restart,
                 "Kepler: continue from a checkpoint file (the other options must match)");
  app.add_flag("--json", o->json, "Print one JSON object");
  return [o]() {
    nystrom::cli::check_force_option(o->req);  // the problems that have no compensated force refuse it
    if (o->req.problem == "outer-solar-system") {
      nystrom::cli::PlanetaryRequest p{.method = o->method,
                                       .h = o->h_given ? o->req.h : 100.0,
                                       .years = o->years > 0 ? o->years : 1e3,
                                       .precision = o->req.precision,
                                       .tol = o->req.tol,
                                       .reference = !o->no_reference};
      const auto r = nystrom::cli::run_planetary(p);
      if (o->json)
        std::cout << r.dump(2) << "\n";
      else
        nystrom::cli::print_planetary(r);
      return 0;
    }
    if (o->years > 0 || o->no_reference)
      throw nystrom::cli::UsageError("--years and --no-reference apply to --problem outer-solar-system only");
    if (o->method.empty()) {
      if (o->sreq.restart.empty()) throw nystrom::cli::UsageError("--method is required");
      o->method = nystrom::cli::checkpoint_method(o->sreq.restart);
    }
    const auto def = nystrom::cli::resolve_run_method(o->method);
    if (nystrom::cli::is_velocity_problem(o->req.problem)) {
      if (o->sreq.any())
        throw nystrom::cli::UsageError(
            "--output-times, --events, --checkpoint and --restart run on the kepler problem");
      const auto r = nystrom::cli::run_velocity_problem(o->req, def);
      if (o->json)
        std::cout << r.dump(2) << "\n";
      else
        nystrom::cli::print_velocity_report(r);
      return 0;
    }
    nystrom::cli::check_work_budget(nystrom::cli::run_work_units(o->req, def), "run");
    if (o->sreq.any()) {
      const auto r = nystrom::cli::run_kepler_solve(o->req, o->sreq, def);
      if (o->json) {
        auto j = r.report.to_json();
        for (const auto& [k, v] : r.extra.items()) j[k] = v;
        std::cout << j.dump(2) << "\n";
      } else {
        print_report(r.report);
        print_solve_extra(r.extra);
      }
      return 0;
    }
    o->req.progress = true;  // on a terminal, for a run that lasts more than a second
    const auto r = nystrom::cli::run_case(o->req, def);
    if (o->json) {
      auto j = r.to_json();
      std::cout << j.dump(2) << "\n";
      return 0;
    }
    print_report(r);
    return 0;
  };
});

}  // namespace
