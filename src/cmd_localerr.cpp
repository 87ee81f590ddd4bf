// `nystrom localerr --problem nbody --n 400 --methods LF,Y4,RKNb6,RKNa14,BR1,AC1,Chambers --h 0.001:0.1:8
//                   [--csv FILE] [--plot FILE.png]`: the local-error statistics of the Gürkan paper, sec. 5
// (Figs. 5.1 and 5.2). See include/nystrom/experiments/localerr.hpp for the procedure.
#include <algorithm>
#include <iostream>
#include <memory>

#include <fmt/core.h>

#include "cli.hpp"
#include "nystrom/experiments/localerr.hpp"

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
      app.add_option("--problem", s.problem, "Problem: nbody (Plummer sphere or --ic file) or twobody")->capture_default_str();
      app.add_option("--n", s.n, "Particles of the Plummer sphere")->capture_default_str();
      app.add_option("--seed", s.seed, "Seed of the Plummer sphere")->capture_default_str();
      app.add_option("--ic", s.ic_file, "Particle file (m,x,y,z,vx,vy,vz per line) instead of a Plummer sphere");
      app.add_option("--ecc", s.ecc, "Two-body eccentricity")->capture_default_str();
      app.add_option("--eps", o->eps, "Softening length (default 1/N for nbody, 0 for twobody)");
      app.add_option("--threads", s.threads, "Force threads (0: OpenMP default)")->capture_default_str();
      app.add_option("--methods", o->methods, "Comma-separated methods")->capture_default_str();
      app.add_option("--h", o->hs, "FROM:TO:COUNT step sizes, log-spaced (orbital periods for twobody, time units for nbody)")
          ->capture_default_str();
      app.add_option("--duration", o->cfg.duration,
                     "Length of the run (default: 50 periods for twobody, 1 time unit for nbody)");
      app.add_option("--tol", o->cfg.tol, "GBS tolerance")->capture_default_str();
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
        if (o->eps >= 0) cfg.setup.eps2 = o->eps * o->eps;
        else if (o->eps != -1) throw UsageError("--eps must be >= 0");
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
        fmt::print("# local errors of one step against GBS (tol {:g}), {}; h in {}\n", cfg.tol, res.description, res.h_unit);
        fmt::print("{:<10} {:>12} {:>9} {:>10} {:>14} {:>14} {:>14}\n", "method", "h", "steps", "samples", "q25", "q75", "IQR");
        std::string text = "method,h,h_time,steps,samples,q25,q75,iqr\n";
        std::vector<Series> series;
        for (const auto& r : res.rows) {
          fmt::print("{:<10} {:>12.5g} {:>9} {:>10} {:>14.6e} {:>14.6e} {:>14.6e}\n", r.method, r.h, r.steps, r.samples, r.q25,
                     r.q75, r.iqr);
          text += fmt::format("{},{:.17g},{:.17g},{},{},{:.17g},{:.17g},{:.17g}\n", r.method, r.h, r.h_time, r.steps, r.samples,
                              r.q25, r.q75, r.iqr);
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
