#include "cli.hpp"

#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

namespace nystrom::cli {

std::vector<Command>& commands() {
  static std::vector<Command> all;
  return all;
}

void write_file_atomic(const std::string& path, const std::string& content) {
  if (path.empty()) throw UsageError("empty output file name");
  namespace fs = std::filesystem;
  const fs::path target(path);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  if (!fs::is_directory(dir)) throw UsageError("cannot write '" + path + "': folder '" + dir.string() + "' does not exist");
  const fs::path tmp = dir / ("." + target.filename().string() + ".tmp." + std::to_string(::getpid()));
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw UsageError("cannot write '" + tmp.string() + "': " + std::strerror(errno));
    out << content;
    out.flush();
    if (!out) {
      std::error_code ec;
      fs::remove(tmp, ec);
      throw UsageError("cannot write '" + path + "': write failed");
    }
  }
  std::error_code ec;
  fs::rename(tmp, target, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw UsageError("cannot write '" + path + "': " + ec.message());
  }
}

double parse_double(const std::string& text, const std::string& what, bool positive) {
  std::size_t pos = 0;
  double v = 0;
  try {
    v = std::stod(text, &pos);
  } catch (const std::exception&) {
    throw UsageError(what + " must be a number, got '" + text + "'");
  }
  if (pos != text.size()) throw UsageError(what + " must be a number, got '" + text + "'");
  if (!std::isfinite(v)) throw UsageError(what + " must be finite, got '" + text + "'");
  if (positive && !(v > 0)) throw UsageError(what + " must be positive, got '" + text + "'");
  return v;
}

std::vector<double> parse_log_range(const std::string& text, const std::string& what, bool allow_decreasing) {
  std::vector<std::string> parts;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ':')) parts.push_back(item);
  if (parts.size() != 3 || text.back() == ':')
    throw UsageError(what + " must be FROM:TO:COUNT (e.g. 1e3:1e6:20), got '" + text + "'");
  const double lo = parse_double(parts[0], what + " start", true);
  const double hi = parse_double(parts[1], what + " end", true);
  const double cnt = parse_double(parts[2], what + " count", true);
  if (cnt != std::floor(cnt) || cnt > 10000) throw UsageError(what + " count must be a whole number up to 10000");
  if (hi < lo && !allow_decreasing) throw UsageError(what + ": end must not be below start");
  const int n = static_cast<int>(cnt);
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

Progress::Progress(std::string label, long total) : label_(std::move(label)), total_(total) {
  const char* env = std::getenv("NYSTROM_PROGRESS");
  enabled_ = (env && std::string(env) == "1") || (!env && ::isatty(STDERR_FILENO));
}

void Progress::tick(long done) {
  if (!enabled_ || total_ <= 0) return;
  const int width = 30;
  const int filled = static_cast<int>(width * done / total_);
  std::fprintf(stderr, "\r%s [%s%s] %ld/%ld", label_.c_str(), std::string(filled, '#').c_str(),
               std::string(width - filled, '-').c_str(), done, total_);
  std::fflush(stderr);
}

Progress::~Progress() {
  if (enabled_ && total_ > 0) std::fprintf(stderr, "\n");
}

namespace {

std::string quote_gnuplot(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

}  // namespace

void plot_loglog(const std::string& png_path, const std::string& title, const std::string& xlabel,
                 const std::string& ylabel, const std::vector<Series>& series) {
  plot_xy(png_path, title, xlabel, ylabel, series, PlotAxes{});
}

void plot_xy(const std::string& png_path, const std::string& title, const std::string& xlabel,
             const std::string& ylabel, const std::vector<Series>& series, const PlotAxes& axes) {
  namespace fs = std::filesystem;
  if (png_path.empty()) throw UsageError("empty plot file name");
  const fs::path target(png_path);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  if (!fs::is_directory(dir)) throw UsageError("cannot write '" + png_path + "': folder does not exist");
  const fs::path tmp_png = dir / ("." + target.filename().string() + ".tmp." + std::to_string(::getpid()) + ".png");
  std::ostringstream script;
  script << "set terminal pngcairo size 900,650 enhanced font 'Sans,11'\n"
         << "set output " << quote_gnuplot(tmp_png.string()) << "\n"
         << (axes.logx ? "set logscale x\nset format x '10^{%L}'\n" : "")
         << (axes.logy ? "set logscale y\nset format y '10^{%L}'\n" : "")
         << "set grid\nset key outside right top\n"
         << "set title " << quote_gnuplot(title) << "\n"
         << "set xlabel " << quote_gnuplot(xlabel) << "\n"
         << "set ylabel " << quote_gnuplot(ylabel) << "\n";
  std::ostringstream data;
  std::vector<std::string> plots;
  int idx = 0;
  for (const auto& s : series) {
    std::ostringstream block;
    int points = 0;
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i)
      if ((s.x[i] > 0 || !axes.logx) && (s.y[i] > 0 || !axes.logy) && std::isfinite(s.x[i]) && std::isfinite(s.y[i])) {
        block.precision(17);
        block << s.x[i] << " " << s.y[i] << "\n";
        ++points;
      }
    if (points == 0) continue;
    script << "$d" << idx << " << EOD\n" << block.str() << "EOD\n";
    const std::string pt = std::to_string(s.point_type > 0 ? s.point_type : 1 + idx % 12);
    std::string with;
    if (s.style.empty() || s.style == "linespoints") with = "linespoints lw 2 pt " + pt;
    else if (s.style == "lines") with = "lines lw 2";
    else if (s.style == "points") with = "points ps 1.3 pt " + pt;
    else if (s.style == "thick") with = "lines lw 6 lc rgb '#80808080'";
    else throw std::invalid_argument("unknown plot style '" + s.style + "'");
    plots.push_back("$d" + std::to_string(idx) + " using 1:2 with " + with + " title " + quote_gnuplot(s.label) + " noenhanced");  // names such as velocity_verlet: no subscripts
    ++idx;
  }
  if (plots.empty()) throw UsageError("nothing to plot: every value is zero, negative or not finite");
  script << "plot ";
  for (std::size_t i = 0; i < plots.size(); ++i) script << (i ? ", \\\n     " : "") << plots[i];
  script << "\n";
  const fs::path tmp_script = dir / ("." + target.filename().string() + ".gp." + std::to_string(::getpid()));
  {
    std::ofstream out(tmp_script);
    out << script.str();
    if (!out) throw UsageError("cannot write the plot script next to '" + png_path + "'");
  }
  const std::string cmd = "gnuplot " + quote_gnuplot(tmp_script.string()) + " 2>&1";
  FILE* pipe = ::popen(cmd.c_str(), "r");
  std::string output;
  if (pipe) {
    char buf[512];
    while (std::fgets(buf, sizeof buf, pipe)) output += buf;
  }
  const int rc = pipe ? ::pclose(pipe) : -1;
  std::error_code ec;
  fs::remove(tmp_script, ec);
  if (rc != 0 || !fs::exists(tmp_png)) {
    fs::remove(tmp_png, ec);
    throw std::runtime_error("gnuplot failed to draw '" + png_path + "' (is gnuplot installed?)" +
                             (output.empty() ? "" : ": " + output.substr(0, 300)));
  }
  fs::rename(tmp_png, target, ec);
  if (ec) throw std::runtime_error("cannot write '" + png_path + "': " + ec.message());
}

}  // namespace nystrom::cli
