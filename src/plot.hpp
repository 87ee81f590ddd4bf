// Plots with gnuplot (pngcairo): curves on linear or logarithmic axes, or a caller's own gnuplot script. gnuplot
// runs without a shell in a private temporary folder, and the picture is written with write_file_atomic
// (output_file.hpp), so no path and no text of the user's reaches gnuplot's command line.
#pragma once

#include <string>
#include <vector>

namespace nystrom::cli {

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

/// The same with a choice of linear or logarithmic axes.
void plot_xy(const std::string& png_path, const std::string& title, const std::string& xlabel,
             const std::string& ylabel, const std::vector<Series>& series, const PlotAxes& axes);

/// Refuses (UsageError) an empty plot file name, a folder, and a name in a folder that does not exist.
void check_plot_target(const std::string& png_path);

/// Runs gnuplot on `script`, which must draw to `set output 'plot.png'` and hold its data inline (datablocks),
/// in a private temporary folder (no shell; the folder, its files and gnuplot itself are removed or
/// terminated on SIGINT/SIGTERM, signals.hpp), then writes the picture to png_path with write_file_atomic.
void render_png(const std::string& png_path, const std::string& script);

}  // namespace nystrom::cli
