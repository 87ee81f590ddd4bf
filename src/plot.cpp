#include "plot.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "nystrom/core/files.hpp"
#include "output_file.hpp"
#include "signals.hpp"
#include "usage_error.hpp"

extern char** environ;

namespace nystrom::cli {

namespace {

constexpr std::size_t kPathMax = 4096;

std::string errno_text(int e) { return std::strerror(e); }

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
  TemporaryPath dir(tmpl, TemporaryPath::Kind::directory);
  // the files inside are registered before they exist, so the signal handler removes whichever were made
  TemporaryPath script_file(tmpl + "/plot.gp"), png_file(tmpl + "/plot.png"), log_file(tmpl + "/gnuplot.log");
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

}  // namespace nystrom::cli
