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
// Errors: throw nystrom::cli::UsageError (or std::invalid_argument) with one clear sentence; run_main()
// prints "nystrom: error: <sentence>" on stderr (one line, non-printable bytes escaped) and exits with status 2.
// Every other failure (any exception, out of memory) ends the same way: one line, status 2.
//
// Input validation: every numeric option is checked as a whole string before CLI11 converts it (finite,
// no empty string, no trailing characters, integers without exponent or fraction), and every text option
// given explicitly must be non-empty; ranges are checked by each command. SIGINT/SIGTERM remove the temporary
// files registered with TempFile and end the process with the signal's default status (130, 143).
#pragma once

#include <sys/types.h>

#include <cstddef>
#include <functional>
#include <iosfwd>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <CLI/CLI.hpp>

#include "nystrom/core/files.hpp"

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

/// The result of parsing a command line: the chosen subcommand's action, or an exit status to return
/// at once (help was printed).
struct Invocation {
  Action action;
  int exit_now = -1;
};

/// Parses and validates a command line against the registered subcommands without running anything.
/// Throws UsageError (with one printable line) on any error; help goes to `help_out`.
Invocation parse_command_line(int argc, const char* const* argv, std::ostream& help_out);

/// The whole tool: installs the signal handlers, parses, runs the subcommand and maps every failure to
/// one line "nystrom: error: ..." on stderr and exit status 2.
int run_main(int argc, char** argv);

/// `text` with every byte outside printable ASCII written as \xNN (and \n, \t, \\), cut to `max` characters.
std::string printable(std::string_view text, std::size_t max = 400);

/// Which numbers a text may spell: decimal ones, or integers (no fraction, no exponent).
enum class NumberSyntax : unsigned char { decimal, integer };

/// Strict syntax of a decimal number: [+-]digits[.digits][(e|E)[+-]digits] (or .digits); no spaces, no
/// hex, inf or nan. Returns an empty string when `text` is valid, otherwise what is wrong.
std::string number_syntax_error(std::string_view text, NumberSyntax syntax);

/// Parses a whole-string integer (no exponent or fraction) within [lo, hi]; `what` names it in errors.
long long parse_integer(const std::string& text, const std::string& what, long long lo, long long hi);

/// A count computed from doubles (e.g. N / f, duration / h): finite, within [1, max], else a UsageError.
long checked_count(double value, double max, const std::string& what);

/// Refuses work beyond the limit (1e14 units, or NYSTROM_WORK_LIMIT): `units` is the estimate in force
/// evaluations of a double Kepler force (an N-body force of n bodies counts n(n-1)/2). The message gives the
/// estimate.
void check_work_budget(double units, const std::string& what);

/// CLI11 checks of an eccentricity (0 <= e < 1) and of a tolerance (positive, at least 1e-300).
CLI::Validator eccentricity_check();
CLI::Validator tolerance_check();

/// CLI11 range checks with one short message each ("must be positive, got '-5'", "must be between 2 and
/// 1000000, got '0'"), used instead of CLI::PositiveNumber, CLI::NonNegativeNumber and CLI::Range (whose
/// messages print the bounds of a double with hundreds of digits). Each checks the number's syntax first.
CLI::Validator positive_check();
CLI::Validator non_negative_check();
CLI::Validator range_check(double lo, double hi);

/// Relative cost of one force evaluation in a scalar type (double 1; measured ratios of bench_precision).
double precision_cost(const std::string& precision);

/// A temporary file or folder removed when this object goes, and also by the SIGINT/SIGTERM handler
/// (nystrom::TemporaryPath, core/files.hpp: the library's own temporary files are removed by it too).
using TempFile = nystrom::TemporaryPath;

/// The child process that the signal handler terminates too (gnuplot); 0: none.
void set_signal_child(pid_t pid);

struct Registrar {
  Registrar(std::string name, std::string help, Setup setup) {
    commands().push_back({std::move(name), std::move(help), std::move(setup)});
  }
};

/// Writes a result file `content` to `path` with the library's writer (nystrom::write_file_atomic,
/// core/files.hpp). A regular file (or a new path) is replaced atomically: a unique temporary file in the
/// same folder, fsync, then rename; a symbolic link is followed and its target replaced in the target's
/// folder; anything else (FIFO, device, /dev/stdout, a path under /dev or /proc) is written in place.
/// Refuses an empty path and a folder; errors carry the system's reason. (Checkpoints are stricter:
/// write_checkpoint_text refuses links and anything but a regular file.)
void write_file_atomic(const std::string& path, const std::string& content);

/// What a parsed number must be: finite, or finite and positive.
enum class Bound : unsigned char { finite, positive };

/// Parses a number that must satisfy `bound`; `what` names it in errors.
double parse_double(const std::string& text, const std::string& what, Bound bound = Bound::finite);

/// The order of the ends of a range FROM:TO:COUNT: TO at least FROM, or either way (e.g. tolerances 1e-6:1e-14:9).
enum class RangeOrder : unsigned char { increasing, either };

/// "1e3:1e6:20" -> 20 values spaced evenly in log between 1e3 and 1e6 (inclusive).
std::vector<double> parse_log_range(const std::string& text, const std::string& what,
                                    RangeOrder order = RangeOrder::increasing);

/// Splits "a,b,c"; empty items are errors.
std::vector<std::string> split_list(const std::string& text, const std::string& what);

/// A progress line on stderr for long runs ("label [####----] 12/40 (30.0%), 3 s, ETA 9 s"), only when stderr
/// is a terminal or NYSTROM_PROGRESS=1; redrawn at most ten times a second. An interrupted run leaves its last
/// line as it was drawn (the signal handler ends the process): it shows where the run stopped.
class Progress {
 public:
  Progress(std::string label, long total);
  void tick(long done);
  ~Progress();

 private:
  std::string label_;
  long total_;
  bool enabled_;
  double start_ = 0, last_ = -1;
  bool drawn_ = false;
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
/// gnuplot runs without a shell in a private temporary folder and writes a file of a fixed name there; the
/// PNG is then written to png_path by write_file_atomic, so no path reaches gnuplot. Titles and labels keep
/// only printable ASCII without double quotes, backslashes, backquotes, '@' and '$' (others become '?').
void plot_loglog(const std::string& png_path, const std::string& title, const std::string& xlabel,
                 const std::string& ylabel, const std::vector<Series>& series);

/// Refuses (UsageError) an empty plot file name, a folder, and a name in a folder that does not exist.
void check_plot_target(const std::string& png_path);

/// Runs gnuplot on `script`, which must draw to `set output 'plot.png'` and hold its data inline (datablocks),
/// in a private temporary folder (no shell; the folder, its files and gnuplot itself are removed or
/// terminated on SIGINT/SIGTERM), then writes the picture to png_path with write_file_atomic.
void render_png(const std::string& png_path, const std::string& script);

/// The same with a choice of linear or logarithmic axes.
void plot_xy(const std::string& png_path, const std::string& title, const std::string& xlabel,
             const std::string& ylabel, const std::vector<Series>& series, const PlotAxes& axes);

}  // namespace nystrom::cli
