// `nystrom langevin --potential double-well|harmonic [--omega 1] --gamma 1 --kT 0.5 [--q0 1] [--v0 0]
//  --method BAOAB --h 0.05 --paths 10000 --t-end 100 [--extrapolate 1,2,3] [--seed 1] [--threads 0] [--json]`
//
// Langevin dynamics of one particle of unit mass (include/nystrom/stochastic/langevin.hpp, docs/stochastic.md):
// averages of q, q^2, q^4, v^2 and the energy over the paths, as time averages over the second half of the run
// ("averages") and at the end ("final"), with standard errors, extrapolated with the multi-product sequence
// given. The numbers do not depend on --threads.
//
// `nystrom langevin --stationary-law [--grid-points 65] ...` computes instead the scheme's stationary averages and
// those of its extrapolation exactly, from the scheme's law on a phase-space grid
// (include/nystrom/stochastic/splitting_law.hpp): no paths, no statistical error.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "nystrom/stochastic/potentials.hpp"
#include "nystrom/stochastic/splitting_law.hpp"
#include "progress.hpp"

namespace {

using nystrom::cli::UsageError;
namespace st = nystrom::stochastic;

struct Options {
  std::string potential = "harmonic";
  double omega = 1, gamma = 1, kT = 1, q0 = 1, v0 = 0;
  std::string method = "BAOAB";
  double h = 0.05, t_end = 10;
  long paths = 1000;
  std::uint64_t seed = 1;
  std::string extrapolate = "1";
  int threads = 0;
  bool json = false;
  bool stationary_law = false;
  int grid_points = 65;
};

int thread_count(int t) {
  if (t > 0) return t;
  const unsigned n = std::thread::hardware_concurrency();
  return n == 0 ? 1 : static_cast<int>(std::min(n, 64u));
}

// "1,2,3"
std::string sequence_text(const std::vector<long>& k) {
  std::string s;
  for (long x : k) s += (s.empty() ? "" : ",") + std::to_string(x);
  return s;
}

nlohmann::json estimate(const st::Estimate& e) { return {{"value", e.value}, {"stderr", e.stderr_}}; }

nlohmann::json to_json(const Options& o, const st::LangevinResult& r) {
  nlohmann::json j;
  j["problem"] = {
      {"potential", o.potential}, {"gamma", o.gamma}, {"kT", o.kT}, {"mass", 1.0}, {"q0", o.q0}, {"v0", o.v0}};
  if (o.potential == "harmonic") j["problem"]["omega"] = o.omega;
  j["method"] = r.method;
  j["h"] = r.h;
  j["t_end"] = r.t_end;
  j["steps"] = r.steps;
  j["window"] = {r.window_start, r.t_end};
  j["paths"] = r.paths;
  j["seed"] = o.seed;
  j["extrapolate"] = r.extrapolate;
  j["coefficients"] = r.coefficients;
  j["order"] = r.order;
  j["force_evaluations"] = r.force_evaluations;
  auto& avg = j["averages"] = nlohmann::json::object();
  auto& fin = j["final"] = nlohmann::json::object();
  for (const auto& ob : r.observables) {
    avg[ob.name] = estimate(ob.average);
    fin[ob.name] = estimate(ob.final);
  }
  auto& members = j["members"] = nlohmann::json::array();
  for (std::size_t i = 0; i < r.extrapolate.size(); ++i) {
    nlohmann::json m{{"k", r.extrapolate[i]}, {"h", r.h / static_cast<double>(r.extrapolate[i])}};
    for (const auto& ob : r.observables) {
      m["averages"][ob.name] = estimate(ob.member_average[i]);
      m["final"][ob.name] = estimate(ob.member_final[i]);
    }
    members.push_back(std::move(m));
  }
  return j;
}

nlohmann::json law_to_json(const Options& o, const st::StationaryLawResult& r) {
  nlohmann::json j;
  j["problem"] = {{"potential", o.potential}, {"gamma", o.gamma}, {"kT", o.kT}, {"mass", 1.0}};
  if (o.potential == "harmonic") j["problem"]["omega"] = o.omega;
  j["method"] = r.method;
  j["h"] = r.h;
  j["extrapolate"] = r.extrapolate;
  j["coefficients"] = r.coefficients;
  j["order"] = r.order;
  auto& avg = j["stationary"] = nlohmann::json::object();
  auto& boltzmann = j["boltzmann"] = nlohmann::json::object();
  for (std::size_t b = 0; b < r.observable_names.size(); ++b) {
    avg[r.observable_names[b]] = r.averages[b];
    boltzmann[r.observable_names[b]] = r.boltzmann[b];
  }
  auto& members = j["members"] = nlohmann::json::array();
  for (std::size_t i = 0; i < r.extrapolate.size(); ++i) {
    nlohmann::json m{
        {"k", r.extrapolate[i]}, {"h", r.h / static_cast<double>(r.extrapolate[i])}, {"steps", r.steps[i]}};
    for (std::size_t b = 0; b < r.observable_names.size(); ++b)
      m["stationary"][r.observable_names[b]] = r.members[i][b];
    members.push_back(std::move(m));
  }
  j["grid"] = {{"points", {r.grid.nq, r.grid.nv}}, {"q", {r.grid.q_min, r.grid.q_max}}, {"v_max", r.grid.v_max}};
  j["resolution"] = r.resolution;
  j["edge"] = r.edge;
  return j;
}

int run_stationary_law(const Options& o, const std::vector<long>& extrapolate) {
  st::check_front_end_grid_points(o.grid_points, "--grid-points");
  const auto problem = st::builtin_problem_1d(o.potential, o.gamma, o.kT, 1.0, o.q0, o.v0, o.omega);
  st::StationaryLawOptions opt;
  opt.method = o.method;
  opt.h = o.h;
  opt.extrapolate = extrapolate;
  opt.grid.nq = opt.grid.nv = o.grid_points;
  // The most work the run may take: every member up to max_steps steps of about 5 n^3 multiply-adds, counted as
  // n^3 / 2 force evaluations of the work limit's unit.
  const double n = o.grid_points;
  nystrom::cli::check_work_budget(
      static_cast<double>(extrapolate.size()) * static_cast<double>(opt.max_steps) * n * n * n / 2,
      "langevin --stationary-law");
  nystrom::cli::Progress progress("stationary law (members)", static_cast<long>(extrapolate.size()));
  opt.progress = [&progress](std::size_t done, std::size_t) { progress.tick(static_cast<long>(done)); };
  const st::StationaryLawResult r = st::stationary_law(problem, opt);
  if (o.json) {
    std::cout << law_to_json(o, r).dump(2) << "\n";
    return 0;
  }
  const std::string seq = sequence_text(r.extrapolate);
  fmt::print("problem        {} (gamma {}, kT {})\n", o.potential, o.gamma, o.kT);
  fmt::print("method         {}, h {}, extrapolated with {} (weak order {})\n", r.method, r.h, seq, r.order);
  fmt::print("stationary law on a {} x {} grid, q in [{:.4g}, {:.4g}), |v| < {:.4g}; steps to the fixed point:",
             r.grid.nq, r.grid.nv, r.grid.q_min, r.grid.q_max, r.grid.v_max);
  for (long n : r.steps) fmt::print(" {}", n);
  fmt::print("\nresolution     {:.1e} (spectrum's outer quarter), edge {:.1e}\n", r.resolution, r.edge);
  fmt::print("{:<8} {:>20} {:>20} {:>12}\n", "", "stationary", "Boltzmann", "bias");
  for (std::size_t b = 0; b < r.observable_names.size(); ++b)
    fmt::print("{:<8} {:>20.15f} {:>20.15f} {:>+12.3e}\n", r.observable_names[b], r.averages[b], r.boltzmann[b],
               r.averages[b] - r.boltzmann[b]);
  return 0;
}

nystrom::cli::Registrar reg(
    "langevin", "Langevin dynamics: averages over paths by BAOAB-type splittings, with extrapolation",
    [](CLI::App& app) {
      auto o = std::make_shared<Options>();
      app.add_option("--potential", o->potential, "harmonic (omega^2 q^2 / 2) or double-well ((q^2 - 1)^2)")
          ->capture_default_str();
      app.add_option("--omega", o->omega, "harmonic: angular frequency")->capture_default_str();
      app.add_option("--gamma", o->gamma, "Friction")->capture_default_str();
      app.add_option("--kT", o->kT, "Temperature (Boltzmann's constant times T)")->capture_default_str();
      app.add_option("--q0", o->q0, "Initial position")->capture_default_str();
      app.add_option("--v0", o->v0, "Initial velocity")->capture_default_str();
      app.add_option("--method", o->method,
                     "Splitting over A (drift), B (kick), O (Ornstein-Uhlenbeck): BAOAB, OBABO, ABOBA, ...")
          ->capture_default_str();
      app.add_option("--h", o->h, "Step")->capture_default_str();
      auto* t_end = app.add_option("--t-end", o->t_end, "End time T (a whole number of steps)")->capture_default_str();
      auto* paths = app.add_option("--paths", o->paths, "Independent paths")->capture_default_str();
      auto* seed =
          app.add_option("--seed", o->seed, "Seed of the counter-based generator (Philox)")->capture_default_str();
      app.add_option("--extrapolate", o->extrapolate,
                     "Multi-product sequence k_1,...,k_n: runs at h / k_i combined (1: the scheme alone)")
          ->capture_default_str();
      auto* threads = app.add_option("--threads", o->threads, "Threads (0: all cores); the results do not depend on it")
                          ->capture_default_str();
      app.add_flag("--json", o->json, "Print one JSON object");
      auto* law =
          app.add_flag(
                 "--stationary-law", o->stationary_law,
                 "No paths: the exact stationary averages of the scheme (and of its extrapolation) from its law on a "
                 "phase-space grid")
              ->excludes(t_end)
              ->excludes(paths)
              ->excludes(seed)
              ->excludes(threads);
      app.add_option("--grid-points", o->grid_points, "--stationary-law: grid points per axis (odd, 9..257)")
          ->capture_default_str()
          ->needs(law);
      return [o]() {
        const auto positive = [](double x, const char* what) {
          if (!(x > 0)) throw UsageError(fmt::format("{} must be positive, got {}", what, x));
        };
        const auto non_negative = [](double x, const char* what) {
          if (!(x >= 0)) throw UsageError(fmt::format("{} must not be negative, got {}", what, x));
        };
        st::parse_potential_1d(o->potential);
        positive(o->omega, "--omega");
        non_negative(o->gamma, "--gamma");
        non_negative(o->kT, "--kT");
        positive(o->h, "--h");
        std::vector<long> sequence;
        try {
          sequence = nystrom::parse_sequence(o->extrapolate);
        } catch (const std::invalid_argument& e) {
          throw UsageError(std::string("--extrapolate: ") + e.what());
        }
        if (o->stationary_law) return run_stationary_law(*o, sequence);
        positive(o->t_end, "--t-end");
        if (o->paths < 1) throw UsageError("--paths must be positive, got " + std::to_string(o->paths));
        if (o->threads < 0) throw UsageError("--threads must not be negative");
        st::LangevinOptions opt;
        opt.method = o->method;
        opt.h = o->h;
        opt.paths = o->paths;
        opt.seed = o->seed;
        opt.extrapolate = sequence;
        opt.threads = thread_count(o->threads);
        const auto problem = st::builtin_problem_1d(o->potential, o->gamma, o->kT, o->t_end, o->q0, o->v0, o->omega);
        double members = 0;
        for (long k : opt.extrapolate) members += static_cast<double>(k);
        nystrom::cli::check_work_budget(static_cast<double>(o->paths) * (o->t_end / o->h) * members, "langevin");
        nystrom::cli::Progress progress("langevin (paths)", o->paths);
        opt.progress = [&progress](long done, long) { progress.tick(done); };
        const auto start = std::chrono::steady_clock::now();
        const st::LangevinResult r = st::langevin(problem, opt);
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        progress.tick(o->paths);
        if (o->json) {
          std::cout << to_json(*o, r).dump(2) << "\n";
          return 0;
        }
        const std::string seq = sequence_text(r.extrapolate);
        fmt::print("problem        {} (gamma {}, kT {}), q0 {}, v0 {}\n", o->potential, o->gamma, o->kT, o->q0, o->v0);
        fmt::print("method         {}, h {}, {} steps to t = {}, extrapolated with {} (weak order {})\n", r.method, r.h,
                   r.steps, r.t_end, seq, r.order);
        fmt::print("paths          {} (seed {}), {} force evaluations, {:.2f} s\n", r.paths, o->seed,
                   r.force_evaluations, seconds);
        fmt::print("{:<8} {:>22} {:>22}\n", "", fmt::format("average [{:g}, {:g}]", r.window_start, r.t_end),
                   fmt::format("at t = {:g}", r.t_end));
        for (const auto& ob : r.observables)
          fmt::print("{:<8} {:>13.8f} +- {:.1e} {:>13.8f} +- {:.1e}\n", ob.name, ob.average.value, ob.average.stderr_,
                     ob.final.value, ob.final.stderr_);
        return 0;
      };
    });

}  // namespace
