// `nystrom run --problem kepler --ecc 0.9 --method M8 --steps-per-period 1000 --periods 10 [--json]`
#include <iostream>
#include <memory>

#include <fmt/core.h>

#include "cli.hpp"
#include "nystrom/methods/catalog.hpp"
#include "runner.hpp"
#include "runner_planetary.hpp"
#include "runner_solve.hpp"
#include "sweep.hpp"

namespace {

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
                 "outer-solar-system (Hairer, GNI I.2.4; Wisdom-Holman maps WH, WH-M8, SABA3, ... or direct methods)")
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
  app.add_option("--output-times", o->sreq.output_times,
                 "Kepler: A:B:N, the state at N equally spaced times from A to B (dense output; JSON `output`)");
  app.add_option("--events", o->sreq.events,
                 "Kepler: events to locate, any of pericentre,apocentre,y=0 (JSON `events`)");
  app.add_option("--checkpoint", o->sreq.checkpoint, "Kepler: write the integrator's state to this file ...");
  app.add_option("--checkpoint-at", o->sreq.checkpoint_at, "... at the first step boundary at or after this time");
  app.add_option("--restart", o->sreq.restart,
                 "Kepler: continue from a checkpoint file (the other options must match)");
  app.add_flag("--json", o->json, "Print one JSON object");
  return [o]() {
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
    nystrom::cli::check_work_budget(nystrom::cli::run_work_units(o->req, def), "run");
    if (o->sreq.any()) {
      const auto r = nystrom::cli::run_kepler_solve(o->req, o->sreq, def);
      auto j = r.report.to_json();
      for (const auto& [k, v] : r.extra.items()) j[k] = v;
      std::cout << j.dump(2) << "\n";  // with or without --json: output times and events do not fit the table
      return 0;
    }
    o->req.progress = true;  // on a terminal, for a run that lasts more than a second
    const auto r = nystrom::cli::run_case(o->req, def);
    if (o->json) {
      std::cout << r.to_json().dump(2) << "\n";
      return 0;
    }
    fmt::print("method            {} ({}, order {})\n", r.method, r.family, r.order);
    fmt::print("problem           {}{}\n", r.problem, r.problem == "kepler" ? fmt::format(" e = {}", r.ecc) : "");
    fmt::print("precision         {}\n", r.precision);
    fmt::print("steps             {} (h = {:.6g})\n", r.steps, r.h);
    fmt::print("force evaluations {}\n", r.force_evals);
    if (r.problem == "kepler") fmt::print("precession/period {:+.6e} rad\n", r.precession_per_period);
    if (r.problem == "nbody") fmt::print("(position error against a GBS reference run at tolerance 1e-13)\n");
    fmt::print("energy error      {:.6e} (relative)\n", r.energy_error);
    fmt::print("position error    {:.6e}\n", r.position_error);
    fmt::print("time              {:.6f} s\n", r.seconds);
    return 0;
  };
});

}  // namespace
