// `nystrom cputime --n 10000 --methods Chambers,Y4,RKNb6,RKNa14,BR1,AC1 [--steps 3] [--repeats 3] [--csv FILE]`:
// time per step of each method on an N-body system, normalised to the leapfrog measured in the same run
// (the Gürkan paper's Table 5.1). See src/experiments/localerr.hpp.
#include <iostream>
#include <memory>

#include <fmt/core.h>

#include "cli.hpp"
#include "experiments/localerr.hpp"
#include "output_file.hpp"
#include "progress.hpp"

namespace {

struct Options {
  nystrom::CpuTimeConfig cfg;
  std::string methods = "FR";
  std::string csv;
  double eps = -1;
};

nystrom::cli::Registrar reg(
    "cputime", "CPU time per step of N-body integrations, relative to the leapfrog (Gürkan Table 5.1)",
    [](CLI::App& app) {
      auto o = std::make_shared<Options>();
      auto& s = o->cfg.setup;
      app.add_option("--problem", s.problem, "Problem: nbody or twobody")->capture_default_str();
      app.add_option("--n", s.n, "Particles of the Plummer sphere")
          ->capture_default_str()
          ->check(nystrom::cli::range_check(2, 1000000));
      app.add_option("--seed", s.seed, "Seed of the Plummer sphere")->capture_default_str();
      app.add_option("--ic", s.ic_file, "Particle file instead of a Plummer sphere");
      app.add_option("--eps", o->eps, "Softening length (default 1/N)")->check(nystrom::cli::non_negative_check());
      app.add_option("--threads", s.threads, "Force threads (0: OpenMP default)")
          ->capture_default_str()
          ->check(nystrom::cli::range_check(0, 1024));
      app.add_option("--methods", o->methods, "Comma-separated methods (the leapfrog is always measured)")
          ->capture_default_str();
      app.add_option("--h", o->cfg.h, "Step size")->capture_default_str()->check(nystrom::cli::positive_check());
      app.add_option("--steps", o->cfg.steps, "Timed steps per measurement")
          ->capture_default_str()
          ->check(nystrom::cli::range_check(1, 1000000));
      app.add_option("--repeats", o->cfg.repeats, "Measurements per method (the minimum is kept)")
          ->capture_default_str()
          ->check(nystrom::cli::range_check(1, 1000));
      app.add_option("--csv", o->csv, "Write the table as CSV");
      return [o]() {
        using namespace nystrom::cli;
        auto cfg = o->cfg;
        cfg.methods = split_list(o->methods, "--methods");
        if (o->eps >= 0)
          cfg.setup.eps2 = o->eps * o->eps;
        else if (o->eps != -1)
          throw UsageError("--eps must be >= 0");
        {
          const double n = cfg.setup.ic_file.empty() ? static_cast<double>(cfg.setup.n) : 2.0;
          double forces = 1;
          for (const auto& m : cfg.methods) forces += std::max(1, nystrom::resolve_method(m).info.forces_per_step);
          check_work_budget(forces * static_cast<double>(cfg.steps) * cfg.repeats * n * (n - 1) / 2, "cputime");
        }
        std::unique_ptr<Progress> p;
        const auto res = nystrom::run_cputime(cfg, [&](long done, long all) {
          if (!p) p = std::make_unique<Progress>("cputime", all);
          p->tick(done);
        });
        p.reset();
        fmt::print("# time per step, {}, {} thread(s); leapfrog {:.4g} s per step\n", res.description,
                   cfg.setup.threads > 0 ? cfg.setup.threads : nystrom::nbody_max_threads(), res.leapfrog_seconds);
        fmt::print("{:<10} {:>8} {:>8} {:>12} {:>10} {:>14}\n", "method", "forces", "complex", "s/step", "vs LF",
                   "per force");
        std::string text = "method,forces_per_step,complex,seconds_per_step,ratio_to_leapfrog\n";
        text += fmt::format("LF,1,0,{:.6g},1\n", res.leapfrog_seconds);
        for (const auto& r : res.rows) {
          fmt::print("{:<10} {:>8} {:>8} {:>12.4g} {:>10.2f} {:>14.2f}\n", r.method, r.forces_per_step,
                     r.complex ? "yes" : "no", r.seconds_per_step, r.ratio, r.ratio / std::max(1, r.forces_per_step));
          text += fmt::format("{},{},{},{:.6g},{:.6g}\n", r.method, r.forces_per_step, r.complex ? 1 : 0,
                              r.seconds_per_step, r.ratio);
        }
        if (!o->csv.empty()) write_file_atomic(o->csv, text);
        return 0;
      };
    });

}  // namespace
