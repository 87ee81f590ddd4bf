// `nystrom sweep --problem kepler --ecc 0.9 --methods FR,N4,M4,M6,A6 --force-evals 1e3:1e6:20
//                [--csv FILE] [--plot FILE.png]`: precision against effort, as in Chin's Figs 2-3.
//
// N is the number of force evaluations spent on one orbital period: a method with f forces per step
// runs round(N / f) steps per period (h = 2 pi f / N). The error is the LRL precession per period.
#include <cmath>
#include <iostream>
#include <memory>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "output_file.hpp"
#include "sweep.hpp"

namespace {

struct Options {
  nystrom::cli::RunRequest base;
  std::string methods = "FR,N4,M4,M6,A6";
  std::string evals = "1e3:1e6:20";
  std::string tols;
  double t_end = 1.0;
  std::string csv, plot, metric;  // metric: precession for kepler, position otherwise
  bool json = false;
};

using nystrom::cli::eccentricity_check;

nystrom::cli::Registrar reg(
    "sweep", "Error against force evaluations for several methods (precision-effort)", [](CLI::App& app) {
      auto o = std::make_shared<Options>();
      o->base.periods = 1;
      app.add_option("--problem", o->base.problem, "Problem (kepler, harmonic, twobody, nbody)")->capture_default_str();
      app.add_option("--n", o->base.n, "nbody: particles")
          ->capture_default_str()
          ->check(nystrom::cli::range_check(2, 1000000));
      app.add_option("--seed", o->base.seed, "nbody: Plummer seed")->capture_default_str();
      app.add_option("--ic", o->base.ic_file, "nbody: particle file");
      app.add_option("--eps2", o->base.eps2, "nbody: softening squared")->check(nystrom::cli::non_negative_check());
      app.add_option("--t-end", o->t_end, "nbody: time span of each run (N counts forces over it)")
          ->capture_default_str()
          ->check(nystrom::cli::positive_check());
      app.add_option("--ecc", o->base.ecc, "Kepler eccentricity")->capture_default_str()->check(eccentricity_check());
      app.add_option("--methods", o->methods, "Comma-separated methods")->capture_default_str();
      app.add_option("--force-evals", o->evals, "FROM:TO:COUNT force evaluations per period (log-spaced)")
          ->capture_default_str();
      app.add_option("--tols", o->tols, "FROM:TO:COUNT tolerances for adaptive methods");
      app.add_option("--periods", o->base.periods, "Periods integrated per run")
          ->capture_default_str()
          ->check(nystrom::cli::positive_check());
      app.add_option("--precision", o->base.precision, "Scalar type")->capture_default_str();
      app.add_option("--error", o->metric,
                     "Error measure: precession (default for kepler), position (default otherwise), energy");
      app.add_option("--csv", o->csv, "Write the data as CSV");
      app.add_option("--plot", o->plot, "Draw a log-log PNG plot (gnuplot)");
      app.add_flag("--json", o->json, "Print JSON rows instead of a table");
      return [o]() {
        using namespace nystrom::cli;
        SweepRequest req;
        req.base = o->base;
        if (!(o->t_end > 0) || !std::isfinite(o->t_end)) throw UsageError("--t-end must be positive");
        req.t_end = o->t_end;
        req.methods = split_list(o->methods, "--methods");
        req.force_evals = parse_log_range(o->evals, "--force-evals");
        if (!o->tols.empty()) req.tols = parse_log_range(o->tols, "--tols", RangeOrder::either);
        if (o->metric.empty()) o->metric = req.base.problem == "kepler" ? "precession" : "position";
        if (o->metric == "precession" && req.base.problem != "kepler")
          throw UsageError("--error precession is defined for --problem kepler only");
        sweep_error(SweepRow{}, o->metric);  // validate the measure before running
        const auto rows = run_sweep(req);
        if (!o->csv.empty()) write_file_atomic(o->csv, sweep_csv(rows));
        if (!o->plot.empty())
          sweep_plot(rows, o->metric, fmt::format("{} e = {} ({})", req.base.problem, req.base.ecc, req.base.precision),
                     o->plot);
        if (o->json) {
          nlohmann::json arr = nlohmann::json::array();
          for (const auto& r : rows) {
            auto j = r.report.to_json();
            j["force_evals_per_period"] = r.force_evals_per_period;
            arr.push_back(j);
          }
          std::cout << arr.dump(2) << "\n";
        } else {
          sweep_table(rows, o->metric);
        }
        return 0;
      };
    });

}  // namespace
