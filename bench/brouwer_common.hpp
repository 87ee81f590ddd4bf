// What the Brouwer's-law programs share (bench_brouwer, bench_brouwer_planetary and the IAS15 driver in
// bench/rebound): the output times, log-spaced in periods, and the slopes of log error against log time.
#pragma once

#include <cmath>
#include <vector>

namespace nystrom::bench {

struct BrouwerPoint {
  double periods, energy, position;
};

/// 1, 2, 5, 10, 20, 50, ... up to `periods`.
inline std::vector<long> brouwer_outputs(long periods) {
  std::vector<long> outs;
  for (long d = 1; d <= periods; d *= 10)
    for (long f : {1L, 2L, 5L})
      if (f * d <= periods) outs.push_back(f * d);
  return outs;
}

/// Least-squares slope of log error against log periods over the points with periods >= x_min (the energy
/// error, or the position error).
inline double brouwer_slope(const std::vector<BrouwerPoint>& pts, double x_min, bool energy) {
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (const auto& p : pts) {
    const double y = energy ? p.energy : p.position;
    if (p.periods < x_min || !(y > 0)) continue;
    const double lx = std::log10(p.periods), ly = std::log10(y);
    n += 1;
    sx += lx;
    sy += ly;
    sxx += lx * lx;
    sxy += lx * ly;
  }
  return n > 1 ? (n * sxy - sx * sy) / (n * sxx - sx * sx) : 0;
}

}  // namespace nystrom::bench
