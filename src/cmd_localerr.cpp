// `nystrom localerr --problem nbody --n 400 --methods LF,Y4,RKNb6,RKNa14,BR1,AC1,Chambers --h 0.001:0.1:8
//                   [--csv FILE] [--plot FILE.png]`: the local-error statistics of the Gürkan paper, sec. 5
// (Figs. 5.1 and 5.2). See src/experiments/localerr.hpp for the procedure.
#include <algorithm>
#include <iostream>
#include <memory>

#include <fmt/core.h>

#include "cli.hpp"
#include "experiments/localerr.hpp"
#include "output_file.hpp"
#include "plot.hpp"
#include "progress.hpp"

namespace {

struct Options {
  nystrom::LocalErrConfig cfg;
  std::string methods = "LF,FR";
  std::string hs = "0.001:0.1:8";
  std::string csv, plot, sequence = "harmonic";
  double eps = -1;
};

nystrom::cli::Registrar reg(
    "localerr", "Local errors against the GBS reference (interquartile range, Gürkan sec. 5)", [](CLI::App& app) {
      auto o = std::make_shared<Options>();
      auto& s = o->cfg.setup;
      app.add_option("--problem", s.problem, "Problem: nbody (Plummer sphere or --ic file) or twobody")
          ->capture_default_str();
      app.add_option("--n", s.n, "Particles of the Plummer sphere")
          ->capture_default_str()
          ->check(nystrom::cli::range_check(2, 1000000));
      app.add_option("--seed", s.seed, "Seed of the Plummer sphere")->capture_default_str();
      app.add_option("--ic", s.ic_file, "Particle file (m,x,y,z,vx,vy,vz per line) instead of a Plummer sphere");
      app.add_option("--ecc", s.ecc, "Two-body eccentricity")
          ->capture_default_str()
          ->check(nystrom::cli::eccentricity_check());
      app.add_option("--eps", o->eps, "Softening length (default 1/N for nbody, 0 for twobody)")
          ->check(nystrom::cli::non_negative_check());
      app.add_option("--threads", s.threads, "Force threads (0: OpenMP default)")
          ->capture_default_str()
          ->check(nystrom::cli::range_check(0, 1024));
      app.add_option("--methods", o->methods, "Comma-separated methods")->capture_default_str();
      app.add_option("--h", o->hs,
                     "FROM:TO:COUNT step sizes, log-spaced (orbital periods for twobody, time units for nbody)")
          ->capture_default_str();
      app.add_option("--duration", o->cfg.duration,
                     "Length of the run (default: 50 periods for twobody, 1 time unit for nbody)")
          ->check(nystrom::cli::positive_check());
      app.add_option("--tol", o->cfg.tol, "GBS tolerance")
          ->capture_default_str()
          ->check(nystrom::cli::tolerance_check());
      app.add_option("--gbs-sequence", o->sequence, "GBS step-size sequence: harmonic, romberg, bulirsch")
          ->capture_default_str();
      app.add_option("--csv", o->csv, "Write the table as CSV");
      app.add_option("--plot", o->plot, "Draw IQR against h (log-log PNG, gnuplot)");
      return [o]() {
        using namespace nystrom::cli;
        auto cfg = o->cfg;
        cfg.methods = split_list(o->methods, "--methods");
        cfg.hs = parse_log_range(o->hs, "--h");
        cfg.sequence = nystrom::parse_gbs_sequence(o->sequence);
        if (o->eps >= 0)
          cfg.setup.eps2 = o->eps * o->eps;
        else if (o->eps != -1)
          throw UsageError("--eps must be >= 0");
        {  // steps per h and the work: every method and the GBS reference (about 100 forces per step) per step
          const bool two = cfg.setup.problem == "twobody";
          const double duration = cfg.duration > 0 ? cfg.duration : (two ? 50.0 : 1.0);
          const double n = two ? 2.0 : cfg.setup.ic_file.empty() ? static_cast<double>(cfg.setup.n) : 2.0;
          double forces = 100;
          for (const auto& m : cfg.methods) forces += std::max(1, nystrom::resolve_method(m).info.forces_per_step);
          double work = 0;
          for (double h : cfg.hs) {
            const long steps = checked_count(duration / h, 1e8, "--duration / --h: the number of steps");
            work += static_cast<double>(steps) * forces * n * (n - 1) / 2;
          }
          check_work_budget(work, "localerr");
        }
        long total = 0;
        std::unique_ptr<Progress> p;
        const auto res = nystrom::run_localerr(cfg, [&](long done, long all) {
          if (!p || total != all) {
            total = all;
            p = std::make_unique<Progress>("localerr", all);
          }
          if (done % 16 == 0 || done == all) p->tick(done);
        });
        p.reset();
        fmt::print("# local errors of one step against GBS (tol {:g}), {}; h in {}\n", cfg.tol, res.description,
                   res.h_unit);
        fmt::print("{:<10} {:>12} {:>9} {:>10} {:>14} {:>14} {:>14}\n", "method", "h", "steps", "samples", "q25", "q75",
                   "IQR");
        std::string text = "method,h,h_time,steps,samples,q25,q75,iqr\n";
        std::vector<Series> series;
        for (const auto& r : res.rows) {
          fmt::print("{:<10} {:>12.5g} {:>9} {:>10} {:>14.6e} {:>14.6e} {:>14.6e}\n", r.method, r.h, r.steps, r.samples,
                     r.q25, r.q75, r.iqr);
          text += fmt::format("{},{:.17g},{:.17g},{},{},{:.17g},{:.17g},{:.17g}\n", r.method, r.h, r.h_time, r.steps,
                              r.samples, r.q25, r.q75, r.iqr);
          auto it = std::find_if(series.begin(), series.end(), [&](const Series& x) { return x.label == r.method; });
          if (it == series.end()) {
            series.push_back({r.method, {}, {}});
            it = series.end() - 1;
          }
          it->x.push_back(r.h);
          it->y.push_back(r.iqr);
        }
        fmt::print("# GBS force evaluations {}, {:.1f} s\n", res.gbs_force_evals, res.seconds);
        if (!o->csv.empty()) write_file_atomic(o->csv, text);
        if (!o->plot.empty())
          plot_loglog(o->plot, "local position error, " + res.description, "h (" + res.h_unit + ")",
                      "interquartile range of position error", series);
        return 0;
      };
    });

}  // namespace
