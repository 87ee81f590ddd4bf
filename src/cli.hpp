// Shared plumbing of the nystrom command-line tool: subcommand registration, errors, output files.
//
// Each src/cmd_*.cpp registers its subcommand with a static Registrar, so a new command is one new
// file and nothing else changes:
//
//   static nystrom::cli::Registrar reg("run", "Integrate one problem with one method", [](CLI::App& app) {
//     auto opt = std::make_shared<Options>();   // options live as long as the app
//     app.add_option(...);
//     return [opt] { ...; return 0; };          // the action, run when this subcommand is chosen
//   });
//
// Errors: throw nystrom::cli::UsageError (or std::invalid_argument) with one clear sentence; main()
// prints "nystrom: error: <sentence>" on stderr and exits with status 2.
#pragma once

#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace nystrom::cli {

struct UsageError : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

using Action = std::function<int()>;
using Setup = std::function<Action(CLI::App&)>;

struct Command {
  std::string name, help;
  Setup setup;
};

std::vector<Command>& commands();

struct Registrar {
  Registrar(std::string name, std::string help, Setup setup) {
    commands().push_back({std::move(name), std::move(help), std::move(setup)});
  }
};

/// Writes `content` to `path` atomically (a temporary file in the same folder, then rename).
void write_file_atomic(const std::string& path, const std::string& content);

/// Parses a number that must be finite (and positive if `positive`); `what` names it in errors.
double parse_double(const std::string& text, const std::string& what, bool positive = false);

/// "1e3:1e6:20" -> 20 values spaced evenly in log between 1e3 and 1e6 (inclusive).
/// With allow_decreasing, TO may be below FROM (e.g. tolerances 1e-6:1e-14:9).
std::vector<double> parse_log_range(const std::string& text, const std::string& what, bool allow_decreasing = false);

/// Splits "a,b,c"; empty items are errors.
std::vector<std::string> split_list(const std::string& text, const std::string& what);

/// A progress line on stderr for long runs ("label [####----] 12/40"), only when stderr is a terminal
/// or NYSTROM_PROGRESS=1.
class Progress {
 public:
  Progress(std::string label, long total);
  void tick(long done);
  ~Progress();

 private:
  std::string label_;
  long total_;
  bool enabled_;
};

/// One curve of a plot: x, y pairs (on a log axis, non-positive values are skipped).
struct Series {
  std::string label;
  std::vector<double> x, y;
  std::string style{};  // "linespoints" (default when empty), "lines", "points", or "thick" (a wide line)
  int point_type = 0;   // gnuplot point type (0: chosen from the series index)
};

/// Axis scales of plot_xy.
struct PlotAxes {
  bool logx = true, logy = true;
};

/// Draws a log-log plot with gnuplot (pngcairo) into png_path. Throws if gnuplot is missing or fails.
void plot_loglog(const std::string& png_path, const std::string& title, const std::string& xlabel,
                 const std::string& ylabel, const std::vector<Series>& series);

/// The same with a choice of linear or logarithmic axes.
void plot_xy(const std::string& png_path, const std::string& title, const std::string& xlabel,
             const std::string& ylabel, const std::vector<Series>& series, const PlotAxes& axes);

}  // namespace nystrom::cli
