// `nystrom reproduce`: the figures and tables of the two papers, recomputed and set beside the published
// numbers. Shared types of the targets (src/reproduce_*.cpp) and of the command (src/cmd_reproduce.cpp).
//
// A target computes its data, writes <out>/<target>.csv and <out>/<target>.png, and returns a
// TargetResult: the claims the paper makes about that figure or table, each with the published number,
// the measured one and whether it holds, plus the interpretation chosen where the paper is silent.
// The command stores each result as <out>/<target>.json and assembles the report (markdown) and
// <out>/summary.json from every result present, so running one target refreshes its own section only.
#pragma once

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sweep.hpp"

namespace nystrom::cli::reproduce {

inline constexpr double nan = std::numeric_limits<double>::quiet_NaN();

/// One statement of a paper, checked against this run.
struct Claim {
  std::string id;             // short key, unique within the target, e.g. "kl8_over_m8"
  std::string paper;          // what the paper says, with its numbers
  std::string criterion;      // the numeric test applied to `measured` for `holds`
  double published = nan;     // the published number, where the paper gives one
  double measured = nan;      // the number this run measured
  std::string measured_text;  // `measured` as shown in the report
  bool holds = false;         // the numeric statement holds as published (within the stated tolerance)
  std::string qualitative;    // the claim in words: the direction / ordering the paper asserts
  bool qualitative_holds = false;
  bool timing = false;  // depends on measured CPU times (machine-dependent; not asserted by the tests)

  nlohmann::json to_json() const;
  static Claim from_json(const nlohmann::json& j);
};

struct TargetResult {
  std::string name, title, paper;  // paper: the figure or table and the publication
  bool quick = false;
  double seconds = 0;
  std::string precision;                    // scalar type(s) used
  std::vector<std::string> files;           // written next to the report, names relative to the output folder
  std::vector<std::string> interpretation;  // choices where the paper does not say (markdown bullets)
  std::string table;                        // a markdown table of the key numbers
  std::vector<Claim> claims;

  nlohmann::json to_json() const;
  static TargetResult from_json(const nlohmann::json& j);
};

struct Context {
  std::string out_dir;      // CSV, PNG and JSON files
  bool quick = false;       // the reduced version (CI)
  std::string quad = "dd";  // the quadruple-precision type of the Chin Figs 2-3 (dd or float128)
  int threads = 0;          // N-body force threads (0: OpenMP default)
  std::string path(const std::string& file) const { return out_dir + "/" + file; }
};

struct Target {
  std::string name, help;
  std::function<TargetResult(const Context&)> run;
};

/// Every target in the order `all` runs them.
const std::vector<Target>& targets();

// The targets (reproduce_chin.cpp, reproduce_gurkan.cpp).
TargetResult chin_fig1(const Context& ctx);
TargetResult chin_fig2(const Context& ctx);
TargetResult chin_fig3(const Context& ctx);
TargetResult gurkan_table43(const Context& ctx);  // reproduce_bch.cpp
TargetResult gurkan_fig51(const Context& ctx);
TargetResult gurkan_fig52(const Context& ctx);
TargetResult gurkan_table51(const Context& ctx);
TargetResult gurkan_fig53(const Context& ctx);

// --- helpers shared by the targets (reproduce.cpp) ---

/// One point of a precision-effort curve: the nominal N asked for and the run that realised it.
struct GridRow {
  double nominal_n = 0;
  SweepRow row;
};

/// Runs every method at every nominal N (force evaluations per period; round(N / f) steps per period) on the
/// Kepler orbit, one period each, with a progress bar named `label` weighted by force evaluations.
std::vector<GridRow> kepler_grid(const std::string& label, const std::vector<std::string>& methods,
                                 const std::vector<double>& ns, double ecc, const std::string& precision);

/// |precession| per period of `method` at nominal N, or NaN if not run.
double error_at(const std::vector<GridRow>& rows, const std::string& method, double nominal_n);

/// Log-spaced values: `per_decade` points per decade from 10^lo to 10^hi (inclusive).
std::vector<double> log_grid(double lo_exp, double hi_exp, int per_decade);

/// A claim whose numeric test is lo <= measured <= hi (hi may be infinite, lo may be -infinity).
Claim band_claim(std::string id, std::string paper, double published, double measured, double lo, double hi,
                 std::string qualitative, bool qualitative_holds);

std::string fmt_g(double x, int digits = 3);

}  // namespace nystrom::cli::reproduce
