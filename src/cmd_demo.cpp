// `nystrom demo`: the main job on a built-in default problem. A precision-effort sweep on the Kepler
// orbit at e = 0.9 (Chin's Figs 1-3 in miniature): symplectic Forest-Ruth against the RKN methods and
// the multi-product integrators of orders 4-10; a table on the terminal, demo.csv and demo.png.
#include <filesystem>
#include <memory>

#include <fmt/core.h>

#include "cli.hpp"
#include "output_file.hpp"
#include "sweep.hpp"

namespace {

struct Options {
  std::string out_dir = ".";
  std::string methods = "FR,N4,M4,A6,M6-5F,M6,M8,M10";
  std::string evals = "3e3:3e5:7";
  std::string precision = "double";
};

nystrom::cli::Registrar reg(
    "demo", "Precision-effort sweep on Kepler e = 0.9: table, demo.csv, demo.png", [](CLI::App& app) {
      auto o = std::make_shared<Options>();
      app.add_option("--out-dir", o->out_dir, "Folder for demo.csv and demo.png")->capture_default_str();
      app.add_option("--methods", o->methods, "Methods compared")->capture_default_str();
      app.add_option("--force-evals", o->evals, "FROM:TO:COUNT force evaluations per period")->capture_default_str();
      app.add_option("--precision", o->precision, "Scalar type")->capture_default_str();
      return [o]() {
        using namespace nystrom::cli;
        if (o->out_dir.empty()) throw UsageError("--out-dir must not be empty");
        if (!std::filesystem::is_directory(o->out_dir))  // before the sweep, not after it
          throw UsageError("--out-dir '" + o->out_dir + "' is not an existing folder");
        SweepRequest req;
        req.base.problem = "kepler";
        req.base.ecc = 0.9;
        req.base.periods = 1;
        req.base.precision = o->precision;
        req.methods = split_list(o->methods, "--methods");
        req.force_evals = parse_log_range(o->evals, "--force-evals");
        fmt::print("nystrom demo: Kepler orbit e = 0.9 (Chin 2010, eqs 35-36), one period, {}\n", o->precision);
        fmt::print(
            "error = precession of the Laplace-Runge-Lenz vector per period; "
            "N = force evaluations per period\n\n");
        const auto rows = run_sweep(req);
        sweep_table(rows, "precession");
        const std::string csv = o->out_dir + "/demo.csv", png = o->out_dir + "/demo.png";
        write_file_atomic(csv, sweep_csv(rows));
        sweep_plot(rows, "precession", "Kepler e = 0.9: precession error per period", png);
        fmt::print("\nwrote {} and {}\n", csv, png);
        return 0;
      };
    });

}  // namespace
