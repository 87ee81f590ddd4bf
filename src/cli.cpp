#include "cli.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <climits>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <new>
#include <sstream>

#include <fmt/core.h>

extern char** environ;

namespace nystrom::cli {

std::vector<Command>& commands() {
  static std::vector<Command> all;
  return all;
}

// ---------------------------------------------------------------------------------------------------------
// Signals. The handler may only call async-signal-safe functions: the temporary paths are those registered
// with nystrom::TemporaryPath (fixed buffers, core/files.hpp).

namespace {

volatile pid_t g_child = 0;

void on_signal(int sig) {
  if (g_child > 0) ::kill(g_child, SIGTERM);
  nystrom::remove_temporary_paths();
  static const char msg[] = "\nnystrom: error: interrupted\n";
  [[maybe_unused]] const auto n = ::write(STDERR_FILENO, msg, sizeof msg - 1);
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

void install_signal_handlers() {
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction old {};
    ::sigaction(sig, nullptr, &old);
    if (old.sa_handler != SIG_IGN) ::sigaction(sig, &sa, nullptr);  // keep an ignored SIGHUP (nohup) ignored
  }
}

std::string errno_text(int e) { return std::strerror(e); }

constexpr std::size_t kPathMax = 4096;

}  // namespace

void set_signal_child(pid_t pid) { g_child = pid; }

// ---------------------------------------------------------------------------------------------------------
// Output files.

void write_file_atomic(const std::string& path, const std::string& content) {
  nystrom::write_file_atomic(path, content, {.streams = true, .follow_links = true});
}

// ---------------------------------------------------------------------------------------------------------
// Numbers.

std::string number_syntax_error(std::string_view t, NumberSyntax syntax) {
  const bool integer = syntax == NumberSyntax::integer;
  if (t.empty()) return "an empty string is not a number";
  std::size_t i = 0;
  if (t[i] == '+' || t[i] == '-') ++i;
  std::size_t digits = 0;
  while (i < t.size() && t[i] >= '0' && t[i] <= '9') ++i, ++digits;
  if (!integer && i < t.size() && t[i] == '.') {
    ++i;
    while (i < t.size() && t[i] >= '0' && t[i] <= '9') ++i, ++digits;
  }
  if (digits == 0) return "not a number";
  if (!integer && i < t.size() && (t[i] == 'e' || t[i] == 'E')) {
    ++i;
    if (i < t.size() && (t[i] == '+' || t[i] == '-')) ++i;
    std::size_t exp_digits = 0;
    while (i < t.size() && t[i] >= '0' && t[i] <= '9') ++i, ++exp_digits;
    if (exp_digits == 0) return "not a number (exponent without digits)";
  }
  if (i != t.size()) return integer ? "not a whole number" : "not a number";
  return "";
}

double parse_double(const std::string& text, const std::string& what, Bound bound) {
  if (const auto err = number_syntax_error(text, NumberSyntax::decimal); !err.empty())
    throw UsageError(what + " must be a number, got '" + text + "'");
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size()) throw UsageError(what + " must be a number, got '" + text + "'");
  if (!std::isfinite(v) || (errno == ERANGE && std::abs(v) > 1))
    throw UsageError(what + " must be finite, got '" + text + "'");
  if (errno == ERANGE) throw UsageError(what + " is too small to represent, got '" + text + "'");
  if (bound == Bound::positive && !(v > 0)) throw UsageError(what + " must be positive, got '" + text + "'");
  return v;
}

long long parse_integer(const std::string& text, const std::string& what, long long lo, long long hi) {
  if (!number_syntax_error(text, NumberSyntax::integer).empty())
    throw UsageError(what + " must be a whole number, got '" + text + "'");
  long long v = 0;
  const char* b = text.c_str() + (text[0] == '+' ? 1 : 0);
  const auto [ptr, ec] = std::from_chars(b, text.c_str() + text.size(), v);
  if (ec != std::errc() || ptr != text.c_str() + text.size() || v < lo || v > hi)
    throw UsageError(what + " must be between " + std::to_string(lo) + " and " + std::to_string(hi) + ", got '" + text +
                     "'");
  return v;
}

long checked_count(double value, double max, const std::string& what) {
  if (!std::isfinite(value) || !(value < max + 0.5))
    throw UsageError(fmt::format("{} would be {:.3g}, more than the limit {:.3g}", what, value, max));
  const long n = std::lround(value);
  return n < 1 ? 1 : n;
}

namespace {

// The value as quoted in a message: at most 40 characters.
std::string shown(const std::string& v) { return "'" + (v.size() > 40 ? v.substr(0, 40) + "..." : v) + "'"; }

// What a numeric option accepts: its syntax, and whether a minus sign is refused.
struct NumberRule {
  NumberSyntax syntax = NumberSyntax::decimal;
  bool non_negative = false;
};

// The syntax check of every numeric option: an empty string when `v` is a valid number of its kind.
std::string strict_number_error(const std::string& v, NumberRule rule) {
  const bool integer = rule.syntax == NumberSyntax::integer;
  if (const auto err = number_syntax_error(v, rule.syntax); !err.empty())
    return "must be " + std::string(integer ? "a whole number" : "a finite number") + ", got " + shown(v);
  if (rule.non_negative && v[0] == '-') return "must not be negative, got " + shown(v);
  if (integer) {
    long long x = 0;
    const char* b = v.c_str() + (v[0] == '+' ? 1 : 0);
    const auto [p, ec] = std::from_chars(b, v.c_str() + v.size(), x);
    if (ec != std::errc() || p != v.c_str() + v.size()) return "is out of range, got " + shown(v);
  } else {
    errno = 0;
    const double x = std::strtod(v.c_str(), nullptr);
    if (!std::isfinite(x) || (errno == ERANGE && std::abs(x) > 1)) return "must be finite, got " + shown(v);
  }
  return "";
}

// A bound as written in a message: a whole number in full up to 1e15, otherwise %g.
std::string bound_text(double x) {
  return x == std::floor(x) && std::abs(x) < 1e15 ? fmt::format("{:.0f}", x) : fmt::format("{:g}", x);
}

// Whether the lower end of a range check belongs to the range.
enum class LowerEnd { closed, open };

// A range check: the syntax of a number, then lo <= x <= hi (LowerEnd::open: lo < x).
CLI::Validator bounded(double lo, LowerEnd end, double hi, std::string description) {
  const bool lo_open = end == LowerEnd::open;
  return CLI::Validator(
      [lo, lo_open, hi](std::string& v) -> std::string {
        if (auto err = strict_number_error(v, {}); !err.empty()) return err;
        const double x = std::strtod(v.c_str(), nullptr);
        if ((lo_open ? x > lo : x >= lo) && x <= hi) return "";
        if (lo == 0 && std::isinf(hi))
          return (lo_open ? "must be positive, got " : "must not be negative, got ") + shown(v);
        return "must be between " + bound_text(lo) + " and " + bound_text(hi) + ", got " + shown(v);
      },
      std::move(description), "range");
}

}  // namespace

CLI::Validator positive_check() { return bounded(0, LowerEnd::open, HUGE_VAL, "POSITIVE"); }
CLI::Validator non_negative_check() { return bounded(0, LowerEnd::closed, HUGE_VAL, "NONNEGATIVE"); }
CLI::Validator range_check(double lo, double hi) {
  return bounded(lo, LowerEnd::closed, hi, "[" + bound_text(lo) + " - " + bound_text(hi) + "]");
}

CLI::Validator eccentricity_check() {
  return CLI::Validator(
      [](std::string& v) -> std::string {
        if (auto err = strict_number_error(v, {}); !err.empty()) return err;
        const double e = std::strtod(v.c_str(), nullptr);
        return e >= 0 && e < 1 ? "" : "the eccentricity must satisfy 0 <= e < 1, got " + shown(v);
      },
      "0 <= e < 1", "eccentricity");
}

CLI::Validator tolerance_check() {
  return CLI::Validator(
      [](std::string& v) -> std::string {
        if (auto err = strict_number_error(v, {}); !err.empty()) return err;
        const double t = std::strtod(v.c_str(), nullptr);
        return t >= 1e-300 && t < 1e300 ? "" : "the tolerance must be positive (at least 1e-300), got " + shown(v);
      },
      "positive", "tolerance");
}

double precision_cost(const std::string& precision) {
  if (precision == "double" || precision == "float") return 1;
  if (precision == "long-double") return 3;
  if (precision == "dd") return 10;
  if (precision == "float128") return 55;
  if (precision == "qd") return 100;
  if (precision.rfind("mpfr", 0) == 0) return 300;
  return 1;
}

void check_work_budget(double units, const std::string& what) {
  double limit = 1e14;
  if (const char* env = std::getenv("NYSTROM_WORK_LIMIT")) {
    char* end = nullptr;
    const double v = std::strtod(env, &end);
    if (end != env && *end == '\0' && v > 0 && std::isfinite(v)) limit = v;
  }
  if (!(units <= limit))  // also NaN
    throw UsageError(
        fmt::format("{}: the estimated work is {:.3g} force evaluations (of a double Kepler force; an N-body force "
                    "counts n(n-1)/2), above the limit {:.3g}, about {:.3g} hours (NYSTROM_WORK_LIMIT raises it)",
                    what, units, limit, units * 3e-9 / 3600));
}

std::string printable(std::string_view text, std::size_t max) {
  std::string out;
  for (unsigned char c : text) {
    if (out.size() >= max) {
      out += "...";
      break;
    }
    if (c == '\n')
      out += "\\n";
    else if (c == '\t')
      out += "\\t";
    else if (c == '\\')
      out += "\\\\";
    else if (c < 0x20 || c >= 0x7f)
      out += fmt::format("\\x{:02x}", c);
    else
      out += static_cast<char>(c);
  }
  return out;
}

std::vector<double> parse_log_range(const std::string& text, const std::string& what, RangeOrder order) {
  std::vector<std::string> parts;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ':')) parts.push_back(item);
  if (parts.size() != 3 || text.empty() || text.back() == ':')
    throw UsageError(what + " must be FROM:TO:COUNT (e.g. 1e3:1e6:20), got '" + text + "'");
  const double lo = parse_double(parts[0], what + " start", Bound::positive);
  const double hi = parse_double(parts[1], what + " end", Bound::positive);
  const int n = static_cast<int>(parse_integer(parts[2], what + " count", 1, 10000));
  if (hi < lo && order == RangeOrder::increasing) throw UsageError(what + ": end must not be below start");
  std::vector<double> v;
  for (int i = 0; i < n; ++i)
    v.push_back(n == 1 ? lo : std::exp(std::log(lo) + (std::log(hi) - std::log(lo)) * i / (n - 1)));
  return v;
}

std::vector<std::string> split_list(const std::string& text, const std::string& what) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (item.empty()) throw UsageError(what + " has an empty item: '" + text + "'");
    out.push_back(item);
  }
  if (out.empty() || text.back() == ',') throw UsageError(what + " is empty or malformed: '" + text + "'");
  return out;
}

namespace {

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::string duration_text(double s) {
  if (s < 120) return fmt::format("{:.0f} s", s);
  if (s < 7200) return fmt::format("{:.0f} min", s / 60);
  return fmt::format("{:.1f} h", s / 3600);
}

}  // namespace

Progress::Progress(std::string label, long total) : label_(std::move(label)), total_(total) {
  const char* env = std::getenv("NYSTROM_PROGRESS");
  enabled_ = (env && std::string(env) == "1") || (!env && ::isatty(STDERR_FILENO));
  start_ = now_seconds();
}

void Progress::tick(long done) {
  if (!enabled_ || total_ <= 0) return;
  const double t = now_seconds();
  if (done < total_ && last_ >= 0 && t - last_ < 0.1) return;
  last_ = t;
  done = std::clamp(done, 0L, total_);
  const int width = 30;
  const int filled = static_cast<int>(width * static_cast<double>(done) / static_cast<double>(total_));
  const double elapsed = t - start_;
  std::string eta;
  if (done > 0 && done < total_)
    eta = ", ETA " + duration_text(elapsed * static_cast<double>(total_ - done) / static_cast<double>(done));
  // the percentage rounded down: 100.0% only for a complete run
  const double percent = std::floor(1000.0 * static_cast<double>(done) / static_cast<double>(total_)) / 10;
  std::fprintf(stderr, "\r%s [%s%s] %ld/%ld (%.1f%%), %s%s   ", label_.c_str(), std::string(filled, '#').c_str(),
               std::string(width - filled, '-').c_str(), done, total_, percent, duration_text(elapsed).c_str(),
               eta.c_str());
  std::fflush(stderr);
  drawn_ = true;
}

Progress::~Progress() {
  if (enabled_ && drawn_) std::fprintf(stderr, "\n");
}

// ---------------------------------------------------------------------------------------------------------
// Plots.

namespace {

// A gnuplot single-quoted string of `s`: printable ASCII without " \\ ` @ $ (anything else becomes '?'), a quote
// doubled (gnuplot's escape inside single quotes), so no character can end the string, the line or the command,
// or start a substitution.
std::string gnuplot_literal(const std::string& s) {
  std::string out = "'";
  for (unsigned char c : s) {
    if (c == '\'') {
      out += "''";
      continue;
    }
    const bool ok = c >= 0x20 && c < 0x7f && c != '"' && c != '\\' && c != '`' && c != '@' && c != '$';
    out += ok ? static_cast<char>(c) : '?';
  }
  return out + "'";
}

std::string read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Runs gnuplot on `script` (a file name inside `dir`) with `dir` as working folder, no shell; stdout and
// stderr go to dir/gnuplot.log. Returns the exit status (-1 when it cannot start).
int run_gnuplot(const std::string& dir, const std::string& script, const std::string& log) {
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addchdir_np(&fa, dir.c_str());
  posix_spawn_file_actions_addopen(&fa, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&fa, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  posix_spawn_file_actions_adddup2(&fa, STDOUT_FILENO, STDERR_FILENO);
  std::string prog = "gnuplot", arg = script;
  char* argv[] = {prog.data(), arg.data(), nullptr};
  pid_t pid = 0;
  const int rc = ::posix_spawnp(&pid, "gnuplot", &fa, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0) return -1;
  set_signal_child(pid);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  set_signal_child(0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

}  // namespace

void plot_loglog(const std::string& png_path, const std::string& title, const std::string& xlabel,
                 const std::string& ylabel, const std::vector<Series>& series) {
  plot_xy(png_path, title, xlabel, ylabel, series, PlotAxes{});
}

void plot_xy(const std::string& png_path, const std::string& title, const std::string& xlabel,
             const std::string& ylabel, const std::vector<Series>& series, const PlotAxes& axes) {
  check_plot_target(png_path);
  std::ostringstream script;
  script << "set terminal pngcairo size 900,650 enhanced font 'Sans,11'\n"
         << "set output 'plot.png'\n"
         << (axes.logx ? "set logscale x\nset format x '10^{%L}'\n" : "")
         << (axes.logy ? "set logscale y\nset format y '10^{%L}'\n" : "") << "set grid\nset key outside right top\n"
         << "set title " << gnuplot_literal(title) << "\n"
         << "set xlabel " << gnuplot_literal(xlabel) << "\n"
         << "set ylabel " << gnuplot_literal(ylabel) << "\n";
  std::vector<std::string> plots;
  int idx = 0;
  for (const auto& s : series) {
    std::ostringstream block;
    block.precision(17);
    int points = 0;
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i)
      if ((s.x[i] > 0 || !axes.logx) && (s.y[i] > 0 || !axes.logy) && std::isfinite(s.x[i]) && std::isfinite(s.y[i])) {
        block << s.x[i] << " " << s.y[i] << "\n";
        ++points;
      }
    if (points == 0) continue;
    script << "$d" << idx << " << EOD\n" << block.str() << "EOD\n";
    const std::string pt = std::to_string(s.point_type > 0 && s.point_type < 100 ? s.point_type : 1 + idx % 12);
    std::string with;
    if (s.style.empty() || s.style == "linespoints")
      with = "linespoints lw 2 pt " + pt;
    else if (s.style == "lines")
      with = "lines lw 2";
    else if (s.style == "points")
      with = "points ps 1.3 pt " + pt;
    else if (s.style == "thick")
      with = "lines lw 6 lc rgb '#80808080'";
    else
      throw std::invalid_argument("unknown plot style '" + s.style + "'");
    // noenhanced: names such as velocity_verlet are drawn as written, without subscripts
    plots.push_back("$d" + std::to_string(idx) + " using 1:2 with " + with + " title " + gnuplot_literal(s.label) +
                    " noenhanced");
    ++idx;
  }
  if (plots.empty()) throw UsageError("nothing to plot: every value is zero, negative or not finite");
  script << "plot ";
  for (std::size_t i = 0; i < plots.size(); ++i) script << (i ? ", \\\n     " : "") << plots[i];
  script << "\n";

  render_png(png_path, script.str());
}

void check_plot_target(const std::string& png_path) {
  namespace fs = std::filesystem;
  if (png_path.empty()) throw UsageError("empty plot file name");
  struct stat st {};
  if (::stat(png_path.c_str(), &st) == 0 && S_ISDIR(st.st_mode))
    throw UsageError("cannot write '" + png_path + "': it is a folder");
  const fs::path target(png_path);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  if (::stat(dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode))
    throw UsageError("cannot write '" + png_path + "': folder '" + dir.string() + "' does not exist");
}

void render_png(const std::string& png_path, const std::string& script) {
  namespace fs = std::filesystem;
  check_plot_target(png_path);
  const char* tmp_env = std::getenv("TMPDIR");
  std::string tmpl = (fs::path(tmp_env && *tmp_env == '/' ? tmp_env : "/tmp") / "nystrom-plot.XXXXXX").string();
  if (tmpl.size() >= kPathMax - 32 || !::mkdtemp(tmpl.data()))
    throw UsageError("cannot create a temporary folder for the plot: " + errno_text(errno));
  TempFile dir(tmpl, TempFile::Kind::directory);
  // the files inside are registered before they exist, so the signal handler removes whichever were made
  TempFile script_file(tmpl + "/plot.gp"), png_file(tmpl + "/plot.png"), log_file(tmpl + "/gnuplot.log");
  {
    std::ofstream out(script_file.path(), std::ios::binary);
    out << script;
    out.flush();
    if (!out) throw UsageError("cannot write the plot script in '" + tmpl + "'");
  }
  const int rc = run_gnuplot(tmpl, "plot.gp", "gnuplot.log");
  struct stat st {};
  if (rc != 0 || ::stat(png_file.path().c_str(), &st) != 0) {
    std::string output = read_all(log_file.path());
    if (output.size() > 300) output.resize(300);
    throw std::runtime_error("gnuplot failed to draw '" + png_path + "'" +
                             (rc == -1 ? " (is gnuplot installed?)" : "") + (output.empty() ? "" : ": " + output));
  }
  write_file_atomic(png_path, read_all(png_file.path()));
}

// ---------------------------------------------------------------------------------------------------------
// The command line.

namespace {

// Checks the text of every numeric option before CLI11 converts it (CLI11 reads "" as 0 and accepts
// "inf", "nan" and trailing garbage in some conversions), and refuses an explicitly empty text option.
void add_strict_validators(CLI::App& app) {
  for (CLI::Option* opt : app.get_options()) {
    if (opt->get_expected_min() == 0) continue;  // flags
    // "FLOAT", or "FLOAT:POSITIVE" etc. once a validator with a description is attached
    const std::string full_type = opt->get_type_name();
    const std::string type = full_type.substr(0, full_type.find(':'));
    if (type == "FLOAT" || type == "INT" || type == "UINT") {
      const bool integer = type != "FLOAT";
      const bool unsigned_ = type == "UINT";
      opt->check(CLI::Validator(
          [integer, unsigned_](std::string& v) -> std::string {
            return strict_number_error(
                v, {.syntax = integer ? NumberSyntax::integer : NumberSyntax::decimal, .non_negative = unsigned_});
          },
          "", "strict number"));
    } else if (type == "TEXT") {
      opt->check(CLI::Validator([](std::string& v) -> std::string { return v.empty() ? "must not be empty" : ""; }, "",
                                "non-empty"));
    }
  }
}

struct ParsedApp {
  std::unique_ptr<CLI::App> app;
  std::vector<std::pair<CLI::App*, Action>> actions;
};

ParsedApp make_app() {
  ParsedApp p;
  p.app = std::make_unique<CLI::App>(
      "nystrom: high-order splitting, Runge-Kutta-Nystrom and multi-product integrators for q'' = a(q)");
  p.app->name("nystrom");
  p.app->set_version_flag("--version", NYSTROM_VERSION, "Print the version (the CMake project version) and exit");
  p.app->require_subcommand(1);
  for (const auto& c : commands()) {
    CLI::App* sub = p.app->add_subcommand(c.name, c.help);
    p.actions.emplace_back(sub, c.setup(*sub));
    add_strict_validators(*sub);
  }
  return p;
}

// One line: the first line of a multi-line message, printable.
std::string one_line(const std::string& msg) { return printable(msg); }

}  // namespace

Invocation parse_command_line(int argc, const char* const* argv, std::ostream& help_out) {
  ParsedApp p = make_app();
  try {
    p.app->parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return {{}, p.app->exit(e, help_out, help_out)};
  } catch (const CLI::CallForAllHelp& e) {
    return {{}, p.app->exit(e, help_out, help_out)};
  } catch (const CLI::CallForVersion& e) {
    return {{}, p.app->exit(e, help_out, help_out)};
  } catch (const CLI::ParseError& e) {
    throw UsageError(std::string(e.what()) + " (see nystrom --help)");
  }
  // CLI11 runs no validator on an empty argument and converts it to 0: refuse it here.
  for (auto& [sub, action] : p.actions)
    if (sub->parsed())
      for (const CLI::Option* opt : sub->get_options())
        for (const std::string& r : opt->results())
          if (r.empty() && opt->get_expected_min() > 0) throw UsageError(opt->get_name() + ": must not be empty");
  for (auto& [sub, action] : p.actions)
    if (sub->parsed()) return {action, -1};
  throw UsageError("no subcommand given (see nystrom --help)");
}

int run_main(int argc, char** argv) {
  install_signal_handlers();
  auto fail = [](const std::string& msg) {
    std::cout.flush();
    std::cerr << "nystrom: error: " << one_line(msg) << "\n";
    return 2;
  };
  try {
    const Invocation inv = parse_command_line(argc, argv, std::cout);
    if (inv.exit_now >= 0) return inv.exit_now;
    return inv.action();
  } catch (const std::bad_alloc&) {
    return fail("out of memory: the request is too large for this machine");
  } catch (const std::filesystem::filesystem_error& e) {
    std::string what = e.code().message();
    if (!e.path1().empty()) what = "'" + e.path1().string() + "': " + what;
    return fail("cannot access " + what);
  } catch (const std::out_of_range& e) {
    // std::stol and friends say only their own name
    const std::string w = e.what();
    return fail(w.rfind("sto", 0) == 0 ? "a number is out of range" : w);
  } catch (const std::exception& e) {
    const std::string w = e.what();
    return fail(w.rfind("sto", 0) == 0 && w.size() < 8 ? "a number is malformed or out of range" : w);
  } catch (...) {
    return fail("unexpected failure");
  }
}

}  // namespace nystrom::cli
