// Thermal density matrices on the grid: the partition function Z(beta) = Tr e^{-beta H} and the energy
// <H> = -d ln Z / d beta of H = -d^2/dx^2 / 2 + V (hbar = m = 1) from N-bead products of the second-order
// (symmetric primitive) propagator
//   K(eps) = e^{-eps V/2} e^{-eps T} e^{-eps V/2},  eps = beta / N,  Z_N = Tr K(eps)^N,
// and of its multi-product extrapolation P(eps) = sum_i c_i K(eps / k_i)^{k_i} (Chin's eq 14 coefficients), the
// short-time propagator of R. E. Zillich, J. M. Mayrhofer and S. A. Chin, "Extrapolated high-order propagators for
// path integral Monte Carlo", J. Chem. Phys. 132 (2010) 044103: Z = Tr P(beta/N)^N, with an error that falls as
// N^{-2n} for n terms. Evaluated exactly on the periodic grid of one dimension (the traces of products of n x n
// matrices, no sampling): e^{-eps T} is the circulant matrix of the kinetic factor e^{-eps k^2/2}, so every
// matrix is real and symmetric. The energy is the exact derivative, -Tr(P^{N-1} dP/d eps) / Z, with
// dK/d eps = -(V/2) K - K (V/2) - e^{-eps V/2} T e^{-eps T} e^{-eps V/2}. The reference is the grid Hamiltonian's
// own Z and energy, from its eigenvalues (cyclic Jacobi).
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "nystrom/methods/mpe_coefficients.hpp"
#include "nystrom/quantum/grid.hpp"

namespace nystrom::quantum {

template <class R>
struct ThermalProblem {
  int grid = 64;
  R box = 20;
  std::string potential = "harmonic";  // a name of named_potential(), ignored when `user` or `values` is set
  PotentialFunction<R> user;
  std::vector<R> values;  // V on the grid, x_i = -L/2 + i L/n; replaces `potential` and `user`
  R beta = 1;
  std::vector<long> beads = {4, 8, 16};       // the numbers N of beads, one row of the result each
  std::vector<long> extrapolate = {1, 2, 3};  // the multi-product sequence k_i ({1}: the primitive alone)
  bool exact = true;                          // the grid Hamiltonian's Z and energy from its eigenvalues
};

struct ThermalRow {
  long beads = 0;
  double z_primitive = 0, energy_primitive = 0;        // Tr K(beta/N)^N
  double z_extrapolated = 0, energy_extrapolated = 0;  // Tr P(beta/N)^N
};

struct ThermalResult {
  double beta = 0;
  std::vector<long> extrapolate;
  int order = 2;  // of the extrapolated short-time propagator: 2 n
  std::vector<ThermalRow> rows;
  double z_exact = std::numeric_limits<double>::quiet_NaN();  // of the grid Hamiltonian
  double energy_exact = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> levels;  // its lowest eigenvalues (at most 10)
  double seconds = 0;
};

namespace detail {

/// A dense n x n matrix, row-major.
template <class R>
struct Matrix {
  std::size_t n = 0;
  std::vector<R> a;
  explicit Matrix(std::size_t size = 0) : n(size), a(size * size, R(0)) {}
  R& operator()(std::size_t i, std::size_t j) { return a[i * n + j]; }
  R operator()(std::size_t i, std::size_t j) const { return a[i * n + j]; }
};

template <class R>
Matrix<R> identity(std::size_t n) {
  Matrix<R> m(n);
  for (std::size_t i = 0; i < n; ++i) m(i, i) = 1;
  return m;
}

template <class R>
Matrix<R> operator*(const Matrix<R>& x, const Matrix<R>& y) {
  Matrix<R> z(x.n);
  for (std::size_t i = 0; i < x.n; ++i)
    for (std::size_t k = 0; k < x.n; ++k) {
      const R xik = x(i, k);
      if (xik == 0) continue;
      R* zi = &z.a[i * x.n];
      const R* yk = &y.a[k * x.n];
      for (std::size_t j = 0; j < x.n; ++j) zi[j] += xik * yk[j];
    }
  return z;
}

template <class R>
void add_scaled(Matrix<R>& x, R c, const Matrix<R>& y) {
  for (std::size_t i = 0; i < x.a.size(); ++i) x.a[i] += c * y.a[i];
}

/// Tr(x y).
template <class R>
R trace_of_product(const Matrix<R>& x, const Matrix<R>& y) {
  R s = 0;
  for (std::size_t i = 0; i < x.n; ++i)
    for (std::size_t j = 0; j < x.n; ++j) s += x(i, j) * y(j, i);
  return s;
}

/// x^m, m >= 0, by squaring.
template <class R>
Matrix<R> power(Matrix<R> x, long m) {
  Matrix<R> r = identity<R>(x.n);
  while (m > 0) {
    if (m & 1) r = r * x;
    m >>= 1;
    if (m > 0) x = x * x;
  }
  return r;
}

/// The circulant matrix of the kinetic symbol s(k) on the grid: (1/n) sum_m s(k_m) cos(k_m (x_i - x_j)).
template <class R, class S>
Matrix<R> kinetic_matrix(const Grid<R>& g, S symbol) {
  const std::size_t n = static_cast<std::size_t>(g.n);
  std::vector<R> c(n, R(0));
  for (std::size_t d = 0; d < n; ++d) {
    R s = 0;
    for (int m = 0; m < g.n; ++m) s += symbol(g.wavenumber(m)) * std::cos(g.wavenumber(m) * static_cast<R>(d) * g.dx());
    c[d] = s / static_cast<R>(n);
  }
  Matrix<R> t(n);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j) t(i, j) = c[i >= j ? i - j : j - i];
  return t;
}

/// diag(a) x diag(b).
template <class R>
Matrix<R> sandwich(const std::vector<R>& a, const Matrix<R>& x, const std::vector<R>& b) {
  Matrix<R> y = x;
  for (std::size_t i = 0; i < x.n; ++i)
    for (std::size_t j = 0; j < x.n; ++j) y(i, j) *= a[i] * b[j];
  return y;
}

/// The eigenvalues of a symmetric matrix, ascending (cyclic Jacobi rotations until the off-diagonal part is below
/// rounding of the whole).
template <class R>
std::vector<R> symmetric_eigenvalues(Matrix<R> a) {
  const std::size_t n = a.n;
  R total = 0;
  for (R x : a.a) total += x * x;
  const R eps = std::numeric_limits<R>::epsilon();
  for (int sweep = 0; sweep < 100; ++sweep) {
    R off = 0;
    for (std::size_t p = 0; p < n; ++p)
      for (std::size_t q = p + 1; q < n; ++q) off += a(p, q) * a(p, q);
    if (off <= eps * eps * total) break;
    for (std::size_t p = 0; p < n; ++p)
      for (std::size_t q = p + 1; q < n; ++q) {
        const R apq = a(p, q);
        if (apq == 0) continue;
        const R theta = (a(q, q) - a(p, p)) / (2 * apq);
        const R t = (theta >= 0 ? 1 : -1) / (std::abs(theta) + std::sqrt(theta * theta + 1));
        const R c = 1 / std::sqrt(t * t + 1), s = t * c;
        for (std::size_t k = 0; k < n; ++k) {
          const R akp = a(k, p), akq = a(k, q);
          a(k, p) = c * akp - s * akq;
          a(k, q) = s * akp + c * akq;
        }
        for (std::size_t k = 0; k < n; ++k) {
          const R apk = a(p, k), aqk = a(q, k);
          a(p, k) = c * apk - s * aqk;
          a(q, k) = s * apk + c * aqk;
        }
        a(p, q) = a(q, p) = 0;
      }
  }
  std::vector<R> e(n);
  for (std::size_t i = 0; i < n; ++i) e[i] = a(i, i);
  std::sort(e.begin(), e.end());
  return e;
}

}  // namespace detail

/// Z and the energy of e^{-beta H} on the grid for each number of beads, from the primitive propagator and from its
/// multi-product extrapolation over `extrapolate`. Throws std::invalid_argument for bad input.
template <class R>
ThermalResult thermal(const ThermalProblem<R>& p) {
  if (!(p.beta > 0) || !std::isfinite(static_cast<double>(p.beta)))
    throw std::invalid_argument("beta must be positive and finite");
  if (p.grid < 4 || p.grid > 512)
    throw std::invalid_argument("the grid must have between 4 and 512 points (the matrices are dense), got " +
                                std::to_string(p.grid));
  if (p.beads.empty()) throw std::invalid_argument("give at least one number of beads");
  for (long b : p.beads)
    if (b < 1 || b > 1000000) throw std::invalid_argument("the number of beads must be between 1 and 1000000");
  validate_mpe_sequence(p.extrapolate);
  for (long k : p.extrapolate)
    if (k > 64) throw std::invalid_argument("the extrapolation sequence's members must be at most 64");
  const Grid<R> g(1, p.grid, p.box);
  std::vector<R> v;
  if (!p.values.empty()) {
    if (p.values.size() != g.size())
      throw std::invalid_argument("the potential has " + std::to_string(p.values.size()) + " values for " +
                                  std::to_string(g.size()) + " grid points");
    for (R x : p.values)
      if (!std::isfinite(static_cast<double>(x))) throw std::invalid_argument("the potential is not finite");
    v = p.values;
  } else {
    v = sample_potential(g, p.user ? p.user : named_potential<R>(p.potential));
  }
  // V - min V >= 0 keeps every factor at most 1; Z = e^{-beta min V} Z', E = E' + min V
  const R vmin = *std::min_element(v.begin(), v.end());
  for (auto& x : v) x -= vmin;
  const auto t0 = std::chrono::steady_clock::now();
  const std::size_t n = g.size();
  const MpeCoefficients mc = mpe_coefficients(p.extrapolate);
  std::vector<R> c;
  for (const auto& x : mc.c) c.push_back(static_cast<R>(x.get_d()));

  // K(e) and dK/de
  auto propagator = [&](R e, detail::Matrix<R>* derivative) {
    std::vector<R> half(n);
    for (std::size_t i = 0; i < n; ++i) half[i] = std::exp(-e * v[i] / 2);
    const auto gk = detail::kinetic_matrix(g, [e](R k) { return std::exp(-e * k * k / 2); });
    detail::Matrix<R> k = detail::sandwich(half, gk, half);
    if (derivative) {
      const auto tg = detail::kinetic_matrix(g, [e](R q) { return q * q / 2 * std::exp(-e * q * q / 2); });
      detail::Matrix<R> d = detail::sandwich(half, tg, half);
      for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = 0; j < n; ++j) d(i, j) = -d(i, j) - (v[i] + v[j]) / 2 * k(i, j);
      *derivative = std::move(d);
    }
    return k;
  };
  // P(e) = sum_i c_i K(e/k_i)^{k_i} and dP/de = sum_i (c_i / k_i) sum_j K^j K' K^{k_i - 1 - j}
  auto extrapolated = [&](R e, const std::vector<long>& seq, const std::vector<R>& coef, detail::Matrix<R>& dp) {
    detail::Matrix<R> pm(n);
    dp = detail::Matrix<R>(n);
    for (std::size_t i = 0; i < seq.size(); ++i) {
      const long ki = seq[i];
      detail::Matrix<R> kd;
      const detail::Matrix<R> k = propagator(e / static_cast<R>(ki), &kd);
      std::vector<detail::Matrix<R>> pw{detail::identity<R>(n)};
      for (long j = 1; j <= ki; ++j) pw.push_back(pw.back() * k);
      detail::add_scaled(pm, coef[i], pw[static_cast<std::size_t>(ki)]);
      for (long j = 0; j < ki; ++j)
        detail::add_scaled(dp, coef[i] / static_cast<R>(ki),
                           pw[static_cast<std::size_t>(j)] * kd * pw[static_cast<std::size_t>(ki - 1 - j)]);
    }
    return pm;
  };
  // Z' = Tr P^N and E' = -Tr(P^{N-1} dP/de) / Z'
  auto trace = [&](const detail::Matrix<R>& pm, const detail::Matrix<R>& dp, long beads, double& z, double& e) {
    const detail::Matrix<R> pw = detail::power(pm, beads - 1);
    const R zz = detail::trace_of_product(pw, pm);
    const R ee = -detail::trace_of_product(pw, dp) / zz;
    z = static_cast<double>(zz * std::exp(-p.beta * vmin));
    e = static_cast<double>(ee + vmin);
  };

  ThermalResult r;
  r.beta = static_cast<double>(p.beta);
  r.extrapolate = p.extrapolate;
  r.order = mc.order();
  for (long beads : p.beads) {
    const R e = p.beta / static_cast<R>(beads);
    ThermalRow row;
    row.beads = beads;
    detail::Matrix<R> d1, dn;
    const detail::Matrix<R> k1 = extrapolated(e, {1}, {R(1)}, d1);
    trace(k1, d1, beads, row.z_primitive, row.energy_primitive);
    const detail::Matrix<R> pn = extrapolated(e, p.extrapolate, c, dn);
    trace(pn, dn, beads, row.z_extrapolated, row.energy_extrapolated);
    if (!std::isfinite(row.z_primitive) || !std::isfinite(row.z_extrapolated) || !(row.z_extrapolated > 0))
      throw std::runtime_error(
          "the partition function is not finite and positive on this grid (beta too large or "
          "too small for double; try a shift of the potential or fewer beads)");
    r.rows.push_back(row);
  }
  if (p.exact) {
    detail::Matrix<R> h = detail::kinetic_matrix(g, [](R k) { return k * k / 2; });
    for (std::size_t i = 0; i < n; ++i) h(i, i) += v[i];
    const std::vector<R> lev = detail::symmetric_eigenvalues(h);
    R z = 0, ez = 0;
    for (R x : lev) {
      const R w = std::exp(-p.beta * (x - lev.front()));
      z += w;
      ez += w * x;
    }
    r.energy_exact = static_cast<double>(ez / z + vmin);
    r.z_exact = static_cast<double>(z * std::exp(-p.beta * (lev.front() + vmin)));
    for (std::size_t i = 0; i < std::min<std::size_t>(10, lev.size()); ++i)
      r.levels.push_back(static_cast<double>(lev[i] + vmin));
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace nystrom::quantum
