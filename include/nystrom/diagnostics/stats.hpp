// Robust summary statistics: quantiles and the interquartile range (the error statistic of the Gürkan
// paper, sec. 5: the 0.75 quantile minus the 0.25 quantile of the per-component position differences).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

namespace nystrom {

/// The p-quantile (0 <= p <= 1) of the values, by linear interpolation between order statistics
/// (Hyndman & Fan type 7: the default of R and NumPy). Reorders `x`. Throws on empty input, NaN, or p
/// outside [0, 1].
template <class T>
T quantile_inplace(std::vector<T>& x, double p) {
  if (x.empty()) throw std::invalid_argument("quantile of an empty sample");
  if (!(p >= 0.0 && p <= 1.0))
    throw std::invalid_argument("quantile level must lie in [0, 1], got " + std::to_string(p));
  for (const auto& v : x) {
    using std::isnan;
    if (isnan(v)) throw std::invalid_argument("quantile of a sample containing NaN");
  }
  const double h = p * static_cast<double>(x.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(h));
  const double frac = h - static_cast<double>(lo);
  std::nth_element(x.begin(), x.begin() + static_cast<std::ptrdiff_t>(lo), x.end());
  const T a = x[lo];
  if (frac == 0.0 || lo + 1 >= x.size()) return a;
  // The next order statistic is the smallest element above position lo.
  const T b = *std::min_element(x.begin() + static_cast<std::ptrdiff_t>(lo) + 1, x.end());
  return a + static_cast<T>(frac) * (b - a);
}

/// The p-quantile of the values (copying them).
template <class T>
T quantile(std::vector<T> x, double p) {
  return quantile_inplace(x, p);
}

/// Interquartile range Q(0.75) - Q(0.25).
template <class T>
T interquartile_range(std::vector<T> x) {
  const T q3 = quantile_inplace(x, 0.75);
  const T q1 = quantile_inplace(x, 0.25);
  return q3 - q1;
}

/// Median.
template <class T>
T median(std::vector<T> x) {
  return quantile_inplace(x, 0.5);
}

}  // namespace nystrom
