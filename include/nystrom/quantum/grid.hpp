// A periodic grid [-L/2, L/2)^d with n points per axis (units hbar = m = 1), the potentials of the quantum
// layer and Gaussian initial states.
#pragma once

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstddef>
#include <functional>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "nystrom/quantum/fftw.hpp"

namespace nystrom::quantum {

template <class R>
struct Grid {
  int dims = 1;
  int n = 64;
  R box = 20;

  Grid() = default;
  Grid(int d, int points, R length) : dims(d), n(points), box(length) {
    if (d < 1 || d > 3) throw std::invalid_argument("dims must be 1, 2 or 3, got " + std::to_string(d));
    if (points < 2)
      throw std::invalid_argument("grid must have at least 2 points per axis, got " + std::to_string(points));
    if (!(length > 0) || !std::isfinite(static_cast<double>(length)))
      throw std::invalid_argument("box must be positive and finite");
    std::size_t total = 1;
    for (int i = 0; i < d; ++i) {
      if (total > (std::size_t{1} << 31) / static_cast<std::size_t>(points))
        throw std::invalid_argument("grid too large: " + std::to_string(points) + "^" + std::to_string(d) + " points");
      total *= static_cast<std::size_t>(points);
    }
  }

  std::size_t size() const {
    std::size_t s = 1;
    for (int i = 0; i < dims; ++i) s *= static_cast<std::size_t>(n);
    return s;
  }
  std::vector<int> shape() const { return std::vector<int>(static_cast<std::size_t>(dims), n); }
  R dx() const { return box / static_cast<R>(n); }
  /// Volume element dx^d.
  R cell() const { return std::pow(dx(), static_cast<R>(dims)); }
  R coordinate(int i) const { return -box / 2 + static_cast<R>(i) * dx(); }
  /// Wave number of FFT index i: 2 pi m / L with m in [-n/2, n/2).
  R wavenumber(int i) const {
    const int m = i < (n + 1) / 2 ? i : i - n;
    return 2 * std::numbers::pi_v<R> * static_cast<R>(m) / box;
  }
  /// Per-axis indices of flat index idx (last axis fastest).
  void indices(std::size_t idx, int* out) const {
    for (int a = dims - 1; a >= 0; --a) {
      out[a] = static_cast<int>(idx % static_cast<std::size_t>(n));
      idx /= static_cast<std::size_t>(n);
    }
  }
};

/// A potential as a function of the position (dims coordinates).
template <class R>
using PotentialFunction = std::function<R(const R* x, int dims)>;

/// Named potentials (docs/quantum.md):
///   harmonic      |x|^2 / 2 (ground state d/2)
///   anisotropic   sum_j w_j^2 x_j^2 / 2, w = 1, sqrt 2, sqrt 3 (ground state (1 + sqrt 2 + sqrt 3)/2 in 3D)
///   morse         sum_j D (1 - e^{-a x_j})^2, D = 8, a = 1/2 (levels per axis (v+1/2) w - ((v+1/2) w)^2/(4D),
///                 w = a sqrt(2D) = 2)
///   double-well   (x_0^2 - 1)^2 + sum_{j>0} x_j^2 / 2
///   soft-coulomb  -1 / sqrt(|x|^2 + 1)
///   free          0
inline std::vector<std::string> potential_names() {
  return {"harmonic", "anisotropic", "morse", "double-well", "soft-coulomb", "free"};
}

template <class R>
PotentialFunction<R> named_potential(const std::string& name) {
  if (name == "harmonic")
    return [](const R* x, int d) {
      R v = 0;
      for (int j = 0; j < d; ++j) v += x[j] * x[j] / 2;
      return v;
    };
  if (name == "anisotropic")
    return [](const R* x, int d) {
      R v = 0;
      for (int j = 0; j < d; ++j) v += static_cast<R>(j + 1) * x[j] * x[j] / 2;
      return v;
    };
  if (name == "morse")
    return [](const R* x, int d) {
      R v = 0;
      for (int j = 0; j < d; ++j) {
        const R e = 1 - std::exp(-x[j] / 2);
        v += 8 * e * e;
      }
      return v;
    };
  if (name == "double-well")
    return [](const R* x, int d) {
      R v = (x[0] * x[0] - 1) * (x[0] * x[0] - 1);
      for (int j = 1; j < d; ++j) v += x[j] * x[j] / 2;
      return v;
    };
  if (name == "soft-coulomb")
    return [](const R* x, int d) {
      R r2 = 1;
      for (int j = 0; j < d; ++j) r2 += x[j] * x[j];
      return -1 / std::sqrt(r2);
    };
  if (name == "free") return [](const R*, int) { return R(0); };
  std::string known;
  for (const auto& p : potential_names()) known += (known.empty() ? "" : ", ") + p;
  throw std::invalid_argument("unknown potential '" + name + "' (known: " + known + ")");
}

/// The points [first, first + count) of the flat (row-major) grid that one process holds: the whole grid by
/// default, a slab of the first axis on a distributed grid (FftTransforms::first(), local_size()).
struct PointRange {
  std::size_t first = 0;
  std::size_t count = static_cast<std::size_t>(-1);  // -1: to the end of the grid

  template <class R>
  std::size_t size(const Grid<R>& g) const {
    if (first > g.size()) throw std::invalid_argument("point range beyond the grid");
    return count == static_cast<std::size_t>(-1) ? g.size() - first : count;
  }
};

/// Calls f(i, idx) for every point of the range: i counts from 0 within the range, idx holds the point's
/// per-axis indices on the whole grid.
template <class R, class F>
void for_each_point(const Grid<R>& g, PointRange r, F f) {
  const std::size_t n = r.size(g);
  int idx[3] = {0, 0, 0};
  for (std::size_t i = 0; i < n; ++i) {
    g.indices(r.first + i, idx);
    f(i, idx);
  }
}

/// The field prod_j w(j, x_j) on the points of the range (the per-axis factors are tabulated once per axis).
template <class R, class W>
Field<R> separable_field(const Grid<R>& g, PointRange r, W w) {
  std::vector<std::vector<std::complex<R>>> table(static_cast<std::size_t>(g.dims));
  for (int a = 0; a < g.dims; ++a)
    for (int i = 0; i < g.n; ++i) table[a].push_back(w(a, g.coordinate(i)));
  Field<R> psi(r.size(g));
  for_each_point(g, r, [&](std::size_t i, const int* idx) {
    std::complex<R> v(1);
    for (int a = 0; a < g.dims; ++a) v *= table[a][idx[a]];
    psi[i] = v;
  });
  return psi;
}

/// The potential's values on the points of the range.
template <class R>
std::vector<R> sample_potential(const Grid<R>& g, const PotentialFunction<R>& v, PointRange r = {}) {
  std::vector<R> out(r.size(g));
  for_each_point(g, r, [&](std::size_t i, const int* idx) {
    R x[3];
    for (int a = 0; a < g.dims; ++a) x[a] = g.coordinate(idx[a]);
    out[i] = v(x, g.dims);
    if (!std::isfinite(static_cast<double>(out[i])))
      throw std::invalid_argument("the potential is not finite on the grid");
  });
  return out;
}

/// |grad V|^2 on the points of the range, each partial derivative by the five-point central difference of v
/// at spacing d = 2^-10 max(1, |x_j|) (truncation d^4 |V^(5)| / 30, rounding eps |V| / d: both far below
/// what a gradient term weighted by h^3 / 72 can show).
template <class R>
std::vector<R> sample_gradient_squared(const Grid<R>& g, const PotentialFunction<R>& v, PointRange r = {}) {
  std::vector<R> out(r.size(g));
  for_each_point(g, r, [&](std::size_t i, const int* idx) {
    R x[3];
    for (int a = 0; a < g.dims; ++a) x[a] = g.coordinate(idx[a]);
    R sum = 0;
    for (int a = 0; a < g.dims; ++a) {
      const R x0 = x[a], d = std::max(R(1), std::abs(x0)) / 1024;
      auto at = [&](R t) {
        x[a] = x0 + t * d;
        return v(x, g.dims);
      };
      const R dv = (8 * (at(1) - at(-1)) - (at(2) - at(-2))) / (12 * d);
      x[a] = x0;
      sum += dv * dv;
    }
    out[i] = sum;
    if (!std::isfinite(static_cast<double>(sum)))
      throw std::invalid_argument("the gradient of the potential is not finite on the grid");
  });
  return out;
}

namespace detail {

template <class R>
R component(const std::vector<R>& v, int a) {
  return a < static_cast<int>(v.size()) ? v[a] : R(0);
}

}  // namespace detail

/// A Gaussian wave packet prod_j (pi s^2)^{-1/4} exp(-(x_j - x0_j)^2 / (2 s^2) + i p0_j x_j) (missing
/// components of x0, p0 are 0). With s = 1 it is the coherent state of the harmonic oscillator.
template <class R>
Field<R> gaussian_packet(const Grid<R>& g, const std::vector<R>& x0, const std::vector<R>& p0, R s = 1,
                         PointRange r = {}) {
  if (!(s > 0)) throw std::invalid_argument("the width of the wave packet must be positive");
  const R norm1 = std::pow(std::numbers::pi_v<R> * s * s, R(-0.25));
  return separable_field(g, r, [&](int a, R x) {
    const R c = detail::component(x0, a), p = detail::component(p0, a);
    return norm1 * std::exp(std::complex<R>(-(x - c) * (x - c) / (2 * s * s), p * x));
  });
}

/// Exact solution of the isotropic harmonic oscillator (w = 1) from gaussian_packet(x0, p0, 1) at time t:
/// the coherent state keeps its shape and its centre follows the classical orbit q(t) = x0 cos t + p0 sin t,
/// p(t) = p0 cos t - x0 sin t: psi = prod_j pi^{-1/4} exp(-(x - q)^2/2 + i p x - i t/2 - i (q p - x0 p0)/2)
/// (substituting into i psi_t = (-d^2/dx^2 + x^2)/2 psi gives the phase; docs/quantum.md).
template <class R>
Field<R> harmonic_coherent_state(const Grid<R>& g, const std::vector<R>& x0, const std::vector<R>& p0, R t,
                                 PointRange r = {}) {
  const R norm1 = std::pow(std::numbers::pi_v<R>, R(-0.25));
  return separable_field(g, r, [&](int a, R x) {
    const R c0 = detail::component(x0, a), m0 = detail::component(p0, a);
    const R q = c0 * std::cos(t) + m0 * std::sin(t);
    const R p = m0 * std::cos(t) - c0 * std::sin(t);
    return norm1 * std::exp(std::complex<R>(-(x - q) * (x - q) / 2, p * x - t / 2 - (q * p - c0 * m0) / 2));
  });
}

/// Exact free evolution of gaussian_packet(x0, p0, s) at time t (no periodic images: valid while the
/// packet stays far from the box edges).
template <class R>
Field<R> free_gaussian(const Grid<R>& g, const std::vector<R>& x0, const std::vector<R>& p0, R s, R t,
                       PointRange r = {}) {
  const std::complex<R> w = std::complex<R>(1, t / (s * s));  // 1 + i t / s^2
  const std::complex<R> norm1 = std::pow(std::numbers::pi_v<R> * s * s, R(-0.25)) / std::sqrt(w);
  return separable_field(g, r, [&](int a, R x) {
    const R c = detail::component(x0, a), p = detail::component(p0, a);
    const R y = x - c - p * t;
    return norm1 * std::exp(-y * y / (2 * s * s * w) + std::complex<R>(0, p * x - p * p * t / 2));
  });
}

}  // namespace nystrom::quantum
