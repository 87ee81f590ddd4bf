// Precision against effort: error against force evaluations per period, for several methods.
#pragma once

#include <string>
#include <vector>

#include "runner.hpp"

namespace nystrom::cli {

struct SweepRow {
  double force_evals_per_period = 0;  // the N of Chin's Figs 2 and 3
  RunReport report;
};

struct SweepRequest {
  RunRequest base;  // problem, ecc, periods, precision
  std::vector<std::string> methods;
  std::vector<double> force_evals;  // target force evaluations per period
  std::vector<double> tols;         // adaptive methods run once per tolerance instead
  double t_end = 1.0;               // nbody: the time span of every run (N counts forces over it)
};

/// The work of one run (see check_work_budget): steps x forces per step x the cost of a force of the
/// problem and precision. Adaptive methods count the N-body cost of one force only (their steps are not known).
double run_work_units(const RunRequest& req, const MethodDef& def);

/// Runs every (method, N); N is turned into steps per period as round(N / forces_per_step).
/// Adaptive methods run once per tolerance in `tols`; their N is the force evaluations they spent.
std::vector<SweepRow> run_sweep(const SweepRequest& req);

/// The error plotted and tabulated: "precession" (|dtheta| per period), "position" or "energy".
double sweep_error(const SweepRow& row, const std::string& metric);

std::string sweep_csv(const std::vector<SweepRow>& rows);
void sweep_plot(const std::vector<SweepRow>& rows, const std::string& metric, const std::string& title,
                const std::string& png);
void sweep_table(const std::vector<SweepRow>& rows, const std::string& metric);

}  // namespace nystrom::cli
