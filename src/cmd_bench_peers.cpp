// `nystrom bench-peers [--quick] [--out DIR] [--periods N] [--ecc 0.5,0.9] [--no-plot]`:
// work-precision of nystrom's methods against Boost.Odeint's on the Kepler problem (final position error
// after N periods against force evaluations and wall time), with, for each target error 1e-6, 1e-9, 1e-12
// and 1e-13, the fastest run of each library and the ratio odeint time / nystrom time (from the sweeps, then
// from the two runs re-timed alternately); and the round-off floor of M8, SS10, DP12 and M12-adaptive
// with compensated summation on and off. See src/experiments/peers.hpp.
//
// Files in DIR: peers_runs.csv (every run), peers.json (runs and summaries), and per eccentricity E
// peers_forces_eE.png and peers_time_eE.png (gnuplot).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <set>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "experiments/peers.hpp"
#include "output_file.hpp"
#include "plot.hpp"
#include "progress.hpp"

namespace {

namespace np = nystrom::peers;

struct Options {
  bool quick = false, no_plot = false;
  std::string out = "bench-peers";
  long periods = 100;
  std::string eccs = "0.5,0.9";
};

const double kTargets[] = {1e-6, 1e-9, 1e-12, 1e-13};

std::string ecc_tag(double e) { return fmt::format("{:g}", e); }

nlohmann::json run_json(const np::PeerRun& r) {
  return {{"library", r.library},
          {"method", r.method},
          {"label", r.label},
          {"adaptive", r.adaptive},
          {"compensated", r.compensated},
          {"reference", r.reference},
          {"order", r.order},
          {"forces_per_step", r.forces_per_step},
          {"forces_extra", r.forces_extra},
          {"ecc", r.ecc},
          {"param", r.param},
          {"steps", r.steps},
          {"forces", r.forces},
          {"seconds", r.seconds},
          {"error", std::isfinite(r.error) ? nlohmann::json(r.error) : nlohmann::json(nullptr)},
          {"reps", r.reps},
          {"ok", r.ok}};
}

void plot(const std::string& dir, double ecc, const std::vector<np::PeerRun>& runs,
          const std::vector<std::string>& labels, long periods) {
  namespace cli = nystrom::cli;
  std::vector<cli::Series> by_forces, by_time;
  for (const auto& label : labels) {
    cli::Series f{label, {}, {}}, t{label, {}, {}};
    for (const auto& r : runs)
      if (r.ok && r.ecc == ecc && r.label == label && r.error < 10) {
        f.x.push_back(static_cast<double>(r.forces));
        f.y.push_back(r.error);
        t.x.push_back(r.seconds);
        t.y.push_back(r.error);
      }
    if (label.rfind("odeint", 0) == 0) f.point_type = t.point_type = 6;  // odeint: open circles
    if (!f.x.empty()) {
      by_forces.push_back(f);
      by_time.push_back(t);
    }
  }
  const std::string title = fmt::format("Kepler e = {}, {} periods: nystrom vs Boost.Odeint", ecc_tag(ecc), periods);
  cli::plot_loglog(dir + "/peers_forces_e" + ecc_tag(ecc) + ".png", title, "force evaluations", "final position error",
                   by_forces);
  cli::plot_loglog(dir + "/peers_time_e" + ecc_tag(ecc) + ".png", title, "wall time (s)", "final position error",
                   by_time);
}

nystrom::cli::Registrar reg(
    "bench-peers", "Work-precision against Boost.Odeint on Kepler (error vs force evaluations and wall time)",
    [](CLI::App& app) {
      auto o = std::make_shared<Options>();
      app.add_flag("--quick", o->quick, "Coarse sweeps, one repetition, small force budget (a test run)");
      app.add_option("--out", o->out, "Output folder (created if missing)")->capture_default_str();
      app.add_option("--periods", o->periods, "Orbital periods per run (1..10000)")
          ->capture_default_str()
          ->check(nystrom::cli::range_check(1, 10000));
      app.add_option("--ecc", o->eccs, "Comma-separated eccentricities")->capture_default_str();
      app.add_flag("--no-plot", o->no_plot, "Do not draw the PNG charts");
      return [o]() {
        using namespace nystrom::cli;
        if (o->periods <= 0) throw UsageError("--periods must be positive");
        std::vector<double> eccs;
        for (const auto& s : split_list(o->eccs, "--ecc")) {
          const double e = parse_double(s, "--ecc");
          if (!(e >= 0 && e < 1)) throw UsageError("--ecc values must satisfy 0 <= e < 1");
          eccs.push_back(e);
        }
        std::error_code ec;
        std::filesystem::create_directories(o->out, ec);
        if (!std::filesystem::is_directory(o->out)) throw UsageError("cannot create the folder '" + o->out + "'");

        np::PeerConfig cfg = o->quick ? np::quick_config() : np::PeerConfig{};
        cfg.periods = o->periods;
        cfg.eccs = eccs;

        // Every (eccentricity, method) sweep; progress per sweep.
        std::vector<std::pair<double, np::MethodSpec>> jobs;
        std::vector<std::string> labels;
        for (double e : eccs)
          for (auto& m : np::peer_methods(e, cfg.periods)) {
            if (e == eccs.front()) labels.push_back(m.label);
            jobs.emplace_back(e, std::move(m));
          }
        std::vector<np::PeerRun> runs;
        {
          Progress progress("bench-peers", static_cast<long>(jobs.size()));
          long done = 0;
          for (const auto& [e, m] : jobs) {
            const auto part = np::sweep_method(m, e, cfg);
            runs.insert(runs.end(), part.begin(), part.end());
            progress.tick(++done);
          }
        }
        // A comparison needs finished runs of both libraries; all-failed sweeps are a failure, not a result.
        for (const char* lib : {"nystrom", "odeint"})
          if (std::none_of(runs.begin(), runs.end(), [&](const np::PeerRun& r) { return r.library == lib && r.ok; }))
            throw std::runtime_error(std::string("bench-peers: no run of ") + lib +
                                     " finished with a finite error (every run diverged or exceeded its budget)");

        nlohmann::json j;
        j["problem"] = "Kepler, q0 = (1+e, 0), v0 = (0, sqrt((1-e)/(1+e))), period 2 pi";
        j["periods"] = cfg.periods;
        j["quick"] = o->quick;
        j["error"] = "final position error |q - q_exact| against the analytic solution";
        j["timing"] = fmt::format("minimum over repetitions (at least {}, at most {}, until {} s spent)", cfg.min_reps,
                                  cfg.max_reps, cfg.min_time);
        j["runs"] = nlohmann::json::array();
        for (const auto& r : runs) j["runs"].push_back(run_json(r));

        // Per method: runs, smallest error, observed order.
        fmt::print("# Kepler, {} periods, final position error; times: min of repetitions\n", cfg.periods);
        j["methods"] = nlohmann::json::array();
        for (double e : eccs) {
          fmt::print("\n## e = {}\n{:<26} {:>7} {:>5} {:>5} {:>11} {:>11} {:>10}\n", ecc_tag(e), "method", "library",
                     "order", "runs", "min error", "obs. order", "f/step");
          for (const auto& label : labels) {
            int n = 0;
            const np::PeerRun* any = nullptr;
            for (const auto& r : runs)
              if (r.ecc == e && r.label == label) ++n, any = &r;
            if (!any) continue;
            const double emin = np::min_error(runs, label, e);
            const double p = np::observed_order(runs, label, e);
            fmt::print("{:<26} {:>7} {:>5} {:>5} {:>11.3g} {:>11} {:>10}\n", label, any->library, any->order, n, emin,
                       std::isfinite(p) ? fmt::format("{:.2f}", p) : "-",
                       any->adaptive ? "-" : std::to_string(any->forces_per_step));
            j["methods"].push_back(
                {{"ecc", e},
                 {"label", label},
                 {"library", any->library},
                 {"adaptive", any->adaptive},
                 {"order", any->order},
                 {"runs", n},
                 {"min_error", std::isfinite(emin) ? nlohmann::json(emin) : nlohmann::json(nullptr)},
                 {"observed_order", std::isfinite(p) ? nlohmann::json(p) : nlohmann::json(nullptr)}});
          }
        }

        // Targets: the fastest run of each library (reference configurations; then with nystrom's
        // uncompensated variants too, which odeint's configurations all are).
        for (const bool any_config : {false, true}) {
          fmt::print("\n## fastest run reaching each target error (wall time){}\n{:>5} {:>7}  {:<58} {:<58} {:>8}\n",
                     any_config ? ", nystrom's uncompensated variants included" : "", "e", "target", "nystrom",
                     "odeint", "ratio");
          const char* key = any_config ? "targets_any_configuration" : "targets";
          j[key] = nlohmann::json::array();
          for (double e : eccs)
            for (double target : kTargets) {
              const np::PeerRun* a = np::cheapest(runs, "nystrom", e, target, !any_config);
              const np::PeerRun* b = np::cheapest(runs, "odeint", e, target);
              auto desc = [](const np::PeerRun* r) {
                if (!r) return std::string("not reached");
                return fmt::format(
                    "{} {} {:.3g}s {:.2g} {}f {:.1f}ns/f", r->label,
                    r->adaptive ? fmt::format("tol {:.0e}", r->param) : fmt::format("{:.0f}/T", r->param), r->seconds,
                    r->error, r->forces, r->seconds * 1e9 / static_cast<double>(std::max(1L, r->forces)));
              };
              const double ratio = a && b ? b->seconds / a->seconds : std::numeric_limits<double>::quiet_NaN();
              fmt::print("{:>5} {:>7.0e}  {:<58} {:<58} {:>8}\n", ecc_tag(e), target, desc(a), desc(b),
                         std::isfinite(ratio) ? fmt::format("{:.1f}x", ratio) : "-");
              auto rj = [](const np::PeerRun* r) { return r ? run_json(*r) : nlohmann::json(nullptr); };
              j[key].push_back({{"ecc", e},
                                {"target", target},
                                {"nystrom", rj(a)},
                                {"odeint", rj(b)},
                                {"ratio", std::isfinite(ratio) ? nlohmann::json(ratio) : nlohmann::json(nullptr)},
                                {"nystrom_ns_per_force",
                                 a && a->forces > 0 ? nlohmann::json(a->seconds * 1e9 / static_cast<double>(a->forces))
                                                    : nlohmann::json(nullptr)},
                                {"odeint_ns_per_force",
                                 b && b->forces > 0 ? nlohmann::json(b->seconds * 1e9 / static_cast<double>(b->forces))
                                                    : nlohmann::json(nullptr)}});
            }
        }

        // The pairs of the first table re-timed alternately (peers.hpp interleaved): the ratio of two
        // runs measured at the same moments, not minutes apart.
        {
          const int pairs = o->quick ? 2 : 25;
          fmt::print(
              "\n## the same runs re-timed alternately ({} times each, fastest of each)\n{:>5} {:>7}  {:<26} {:>11} "
              "{:<28} {:>11} {:>8}\n",
              pairs, "e", "target", "nystrom", "seconds", "odeint", "seconds", "ratio");
          auto spec = [&](const np::PeerRun& r) -> const np::MethodSpec* {
            for (const auto& [e, m] : jobs)
              if (e == r.ecc && m.label == r.label) return &m;
            return nullptr;
          };
          j["targets_interleaved"] = nlohmann::json::array();
          for (double e : eccs)
            for (double target : kTargets) {
              const np::PeerRun* a = np::cheapest(runs, "nystrom", e, target);
              const np::PeerRun* b = np::cheapest(runs, "odeint", e, target);
              const np::MethodSpec* sa = a ? spec(*a) : nullptr;
              const np::MethodSpec* sb = b ? spec(*b) : nullptr;
              if (!sa || !sb) continue;
              const auto [oa, ob] = np::interleaved(*sa, a->param, *sb, b->param, e, pairs);
              const bool ok = oa.ok && ob.ok;
              const double ratio = ok ? ob.seconds / oa.seconds : std::numeric_limits<double>::quiet_NaN();
              fmt::print("{:>5} {:>7.0e}  {:<26} {:>11.3g} {:<28} {:>11.3g} {:>8}\n", ecc_tag(e), target, a->label,
                         oa.seconds, b->label, ob.seconds, ok ? fmt::format("{:.1f}x", ratio) : "failed");
              j["targets_interleaved"].push_back(
                  {{"ecc", e},
                   {"target", target},
                   {"pairs", pairs},
                   {"nystrom", a->label},
                   {"nystrom_param", a->param},
                   {"nystrom_seconds", oa.seconds},
                   {"nystrom_error", ok ? nlohmann::json(oa.error) : nlohmann::json(nullptr)},
                   {"odeint", b->label},
                   {"odeint_param", b->param},
                   {"odeint_seconds", ob.seconds},
                   {"odeint_error", ok ? nlohmann::json(ob.error) : nlohmann::json(nullptr)},
                   {"ratio", ok ? nlohmann::json(ratio) : nlohmann::json(nullptr)}});
            }
        }

        // Round-off: compensated summation on and off.
        fmt::print(
            "\n## round-off floor: smallest error with compensated summation on / off\n{:>5} {:<13} {:>11} {:>11} "
            "{:>8}\n",
            "e", "method", "on", "off", "off/on");
        j["compensation"] = nlohmann::json::array();
        for (double e : eccs)
          for (const char* name : {"M8", "SS10", "DP12", "M12-adaptive"}) {
            const double on = np::min_error(runs, name, e),
                         off = np::min_error(runs, std::string(name) + " (no comp.)", e);
            fmt::print("{:>5} {:<13} {:>11.3g} {:>11.3g} {:>8.1f}\n", ecc_tag(e), name, on, off, off / on);
            j["compensation"].push_back(
                {{"ecc", e},
                 {"method", name},
                 {"min_error_on", std::isfinite(on) ? nlohmann::json(on) : nlohmann::json(nullptr)},
                 {"min_error_off", std::isfinite(off) ? nlohmann::json(off) : nlohmann::json(nullptr)}});
          }

        std::string csv =
            "library,method,adaptive,compensated,order,forces_per_step,ecc,param,steps,forces,seconds,error,reps,ok\n";
        for (const auto& r : runs)
          csv += fmt::format("{},{},{},{},{},{},{},{:.6g},{},{},{:.6g},{:.6g},{},{}\n", r.library, r.label,
                             r.adaptive ? 1 : 0, r.compensated ? 1 : 0, r.order, r.forces_per_step, r.ecc, r.param,
                             r.steps, r.forces, r.seconds, r.error, r.reps, r.ok ? 1 : 0);
        write_file_atomic(o->out + "/peers_runs.csv", csv);
        write_file_atomic(o->out + "/peers.json", j.dump(1) + "\n");
        if (!o->no_plot) {
          try {
            for (double e : eccs) plot(o->out, e, runs, labels, cfg.periods);
          } catch (const std::exception& ex) {
            std::cerr << "nystrom: warning: no charts: " << ex.what() << "\n";
          }
        }
        fmt::print("\nwrote {}/peers_runs.csv, {}/peers.json{}\n", o->out, o->out,
                   o->no_plot ? "" : fmt::format(", {}/peers_{{forces,time}}_e*.png", o->out));
        return 0;
      };
    });

}  // namespace
