#include "sweep.hpp"

#include <cmath>
#include <map>
#include <sstream>

#include <fmt/core.h>

#include "cli.hpp"
#include "nystrom/methods/catalog.hpp"
#include "plot.hpp"
#include "progress.hpp"

namespace nystrom::cli {

double run_work_units(const RunRequest& req, const MethodDef& def) {
  const bool nbody = req.problem == "nbody";
  double force_cost = precision_cost(req.precision);
  if (nbody) {
    const double n = static_cast<double>(req.n);
    force_cost = std::max(1.0, n * (n - 1) / 2);
  }
  if (def.info.adaptive) return force_cost;
  const double steps = nbody ? static_cast<double>(req.steps)
                             : static_cast<double>(req.steps_per_period) * static_cast<double>(req.periods);
  return steps * std::max(1, def.info.forces_per_step) * force_cost;
}

std::vector<SweepRow> run_sweep(const SweepRequest& req) {
  if (req.methods.empty()) throw UsageError("no methods given");
  if (req.force_evals.empty()) throw UsageError("no force-evaluation counts given");
  std::vector<MethodDef> defs;
  for (const auto& m : req.methods) defs.push_back(resolve_run_method(m));  // fail early on unknown names
  long total = 0;
  double work = 0;
  for (const auto& def : defs) {
    if (def.info.adaptive && req.tols.empty())
      throw UsageError("method '" + def.info.name + "' is adaptive: give --tols FROM:TO:COUNT");
    total += static_cast<long>(def.info.adaptive ? req.tols.size() : req.force_evals.size());
    const int f = std::max(1, def.info.forces_per_step);
    for (double N : def.info.adaptive ? std::vector<double>{} : req.force_evals) {
      RunRequest r = req.base;
      const long steps = checked_count(N / f, 1e9, "--force-evals: the steps per period of " + def.info.name);
      r.steps = r.steps_per_period = steps;
      if (r.problem != "nbody") r.steps = 1;
      work += run_work_units(r, def);
    }
  }
  check_work_budget(work, "sweep");
  std::vector<SweepRow> rows;
  Progress progress("sweep", total);
  long done = 0;
  for (const auto& def : defs) {
    if (def.info.adaptive) {
      for (double tol : req.tols) {
        RunRequest r = req.base;
        r.tol = tol;
        if (r.problem == "nbody") {
          r.h = req.t_end;
          r.steps = 1;
        }
        progress.tick(++done);
        SweepRow row;
        row.report = run_case(r, def);
        row.force_evals_per_period =
            static_cast<double>(row.report.force_evals) / static_cast<double>(r.problem == "nbody" ? 1 : r.periods);
        rows.push_back(row);
      }
      continue;
    }
    const int f = std::max(1, def.info.forces_per_step);
    long last_steps = -1;
    for (double N : req.force_evals) {
      RunRequest r = req.base;
      const long steps = checked_count(N / f, 1e9, "--force-evals: the steps per period");
      progress.tick(++done);
      if (steps == last_steps) continue;  // same run as the previous N
      last_steps = steps;
      const bool span = r.problem == "nbody";  // no period: N counts the forces over t_end
      if (span) {
        r.steps = steps;
        r.h = req.t_end / static_cast<double>(steps);
      } else {
        r.steps_per_period = steps;
      }
      SweepRow row;
      row.report = run_case(r, def);
      row.force_evals_per_period =
          static_cast<double>(row.report.force_evals) / static_cast<double>(span ? 1 : r.periods);
      rows.push_back(row);
    }
  }
  return rows;
}

double sweep_error(const SweepRow& row, const std::string& metric) {
  if (metric == "precession") return std::abs(row.report.precession_per_period);
  if (metric == "position") return row.report.position_error;
  if (metric == "energy") return row.report.energy_error;
  throw UsageError("unknown error measure '" + metric + "' (precession, position, energy)");
}

std::string sweep_csv(const std::vector<SweepRow>& rows) {
  std::ostringstream out;
  out << "method,family,order,precision,problem,ecc,force_evals_per_period,steps,force_evals,h,"
         "precession_per_period,energy_error,position_error,seconds\n";
  out.precision(17);
  for (const auto& r : rows) {
    const auto& p = r.report;
    out << p.method << "," << p.family << "," << p.order << "," << p.precision << "," << p.problem << "," << p.ecc
        << "," << r.force_evals_per_period << "," << p.steps << "," << p.force_evals << "," << p.h << ","
        << p.precession_per_period << "," << p.energy_error << "," << p.position_error << "," << p.seconds << "\n";
  }
  return out.str();
}

void sweep_plot(const std::vector<SweepRow>& rows, const std::string& metric, const std::string& title,
                const std::string& png) {
  std::vector<Series> series;
  std::map<std::string, std::size_t> index;
  for (const auto& r : rows) {
    auto it = index.find(r.report.method);
    if (it == index.end()) {
      it = index.emplace(r.report.method, series.size()).first;
      series.push_back({r.report.method, {}, {}});
    }
    series[it->second].x.push_back(r.force_evals_per_period);
    series[it->second].y.push_back(sweep_error(r, metric));
  }
  const std::string ylabel = metric == "precession" ? "|precession| per period (rad)"
                             : metric == "position" ? "position error at the end"
                                                    : "relative energy error at the end";
  plot_loglog(png, title, "force evaluations per period N", ylabel, series);
}

void sweep_table(const std::vector<SweepRow>& rows, const std::string& metric) {
  fmt::print("{:<14} {:>5} {:>12} {:>10} {:>14} {:>12} {:>12} {:>9}\n", "method", "order", "N/period", "steps",
             metric == "precession" ? "|dtheta|/per" : metric, "energy err", "pos err", "seconds");
  for (const auto& r : rows) {
    const auto& p = r.report;
    fmt::print("{:<14} {:>5} {:>12.0f} {:>10} {:>14.3e} {:>12.3e} {:>12.3e} {:>9.4f}\n", p.method, p.order,
               r.force_evals_per_period, p.steps, sweep_error(r, metric), p.energy_error, p.position_error, p.seconds);
  }
}

}  // namespace nystrom::cli
