// Small dense linear solvers for the order-condition searches (Gaussian elimination with partial pivoting),
// for std::complex<double>, bigcomplex, double and bigfloat.
#pragma once

#include <cmath>
#include <complex>
#include <cstddef>
#include <utility>
#include <vector>

#include "nystrom/analysis/coef.hpp"

namespace nystrom::analysis {

inline double pivot_size(const std::complex<double>& z) { return std::abs(z.real()) + std::abs(z.imag()); }
inline double pivot_size(const bigcomplex& z) { return std::abs(re_d(z)) + std::abs(im_d(z)); }
inline double pivot_size(double x) { return std::abs(x); }
inline double pivot_size(const bigfloat& x) { return std::abs(static_cast<double>(x)); }
inline std::complex<double> divide(const std::complex<double>& a, const std::complex<double>& b) { return a / b; }
inline bigcomplex divide(const bigcomplex& a, const bigcomplex& b) { return cdiv(a, b); }
inline double divide(double a, double b) { return a / b; }
inline bigfloat divide(const bigfloat& a, const bigfloat& b) { return a / b; }

/// Solves A x = b in place (b becomes x). Returns false if A is numerically singular.
template <class S>
bool solve_linear(std::vector<std::vector<S>> a, std::vector<S>& b) {
  const std::size_t n = b.size();
  double scale = 0;
  for (const auto& row : a)
    for (const auto& x : row) scale = std::max(scale, pivot_size(x));
  if (!(scale > 0)) return false;
  for (std::size_t c = 0; c < n; ++c) {
    std::size_t p = c;
    double best = pivot_size(a[c][c]);
    for (std::size_t r = c + 1; r < n; ++r)
      if (pivot_size(a[r][c]) > best) {
        best = pivot_size(a[r][c]);
        p = r;
      }
    if (!(best > scale * 1e-300) || !std::isfinite(best)) return false;
    std::swap(a[p], a[c]);
    std::swap(b[p], b[c]);
    for (std::size_t r = c + 1; r < n; ++r) {
      if (pivot_size(a[r][c]) == 0) continue;
      const S f = divide(a[r][c], a[c][c]);
      for (std::size_t k = c; k < n; ++k) a[r][k] = a[r][k] - f * a[c][k];
      b[r] = b[r] - f * b[c];
    }
  }
  for (std::size_t c = n; c-- > 0;) {
    S s = b[c];
    for (std::size_t k = c + 1; k < n; ++k) s = s - a[c][k] * b[k];
    b[c] = divide(s, a[c][c]);
  }
  return true;
}

}  // namespace nystrom::analysis
