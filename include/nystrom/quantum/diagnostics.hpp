// Observables of a wave function on the grid: norm, energy (and the Gross-Pitaevskii chemical potential),
// <x>, <p>, and the L2 distance to a reference solution. Kinetic quantities are evaluated in Fourier space
// with the flows' plans (these transforms are not counted in fft_count()).
#pragma once

#include <cmath>
#include <complex>
#include <cstddef>
#include <vector>

#include "nystrom/quantum/schrodinger.hpp"

namespace nystrom::quantum {

template <class R>
struct Observables {
  R norm = 0;                // integral |psi|^2
  R energy = 0;              // <T + V> + (g/2) int |psi|^4, per unit norm
  R chemical_potential = 0;  // <T + V> + g int |psi|^4 (the GPE eigenvalue mu; equals energy for g = 0)
  R kinetic = 0, potential = 0, interaction = 0;
  std::vector<R> mean_x, mean_p;
};

/// Collective on a distributed grid: every process calls it and gets the observables of the whole grid.
template <class R>
Observables<R> observe(const SchrodingerFlows<R>& f, const Field<R>& psi) {
  const Grid<R>& g = f.grid();
  const std::size_t d = static_cast<std::size_t>(g.dims);
  // the sums of one reduction: n, v, rho^2, nk, t, then x_a and p_a per axis
  std::vector<R> s(5 + 2 * d, R(0));
  for_each_point(g, f.range(), [&](std::size_t i, const int* idx) {
    const R rho = std::norm(psi[i]);
    s[0] += rho;
    s[1] += rho * f.potential()[i];
    s[2] += rho * rho;
    for (std::size_t a = 0; a < d; ++a) s[5 + a] += rho * g.coordinate(idx[a]);
  });
  Field<R> hat = psi;
  f.fft().forward(hat);
  for_each_point(g, f.range(), [&](std::size_t i, const int* idx) {
    const R w = std::norm(hat[i]);
    s[3] += w;
    s[4] += w * f.half_k2()[i];
    for (std::size_t a = 0; a < d; ++a) s[5 + d + a] += w * g.wavenumber(idx[a]);
  });
  f.fft().sum(s.data(), static_cast<int>(s.size()));
  const R n = s[0], nk = s[3];
  Observables<R> o;
  o.mean_x.assign(s.begin() + 5, s.begin() + 5 + static_cast<std::ptrdiff_t>(d));
  o.mean_p.assign(s.begin() + 5 + static_cast<std::ptrdiff_t>(d), s.end());
  o.norm = n * g.cell();
  if (!(n > 0) || !(nk > 0)) {
    o.mean_x.assign(d, R(0));
    o.mean_p.assign(d, R(0));
    return o;
  }
  for (auto& x : o.mean_x) x /= n;
  for (auto& p : o.mean_p) p /= nk;
  o.kinetic = s[4] / nk;
  o.potential = s[1] / n;
  // g int |psi|^4 / (int |psi|^2)^2, the integrals as sums times dx^d
  o.interaction = f.coupling() * (s[2] * g.cell()) / (o.norm * o.norm);
  o.energy = o.kinetic + o.potential + o.interaction / 2;
  o.chemical_potential = o.kinetic + o.potential + o.interaction;
  return o;
}

/// <a|b> = integral conj(a) b over the whole grid (collective on a distributed grid).
template <class R>
std::complex<R> overlap(const SchrodingerFlows<R>& f, const Field<R>& a, const Field<R>& b) {
  R s[2] = {0, 0};
  for (std::size_t i = 0; i < a.size(); ++i) {
    const std::complex<R> x = std::conj(a[i]) * b[i];
    s[0] += x.real();
    s[1] += x.imag();
  }
  f.fft().sum(s, 2);
  return std::complex<R>(s[0], s[1]) * f.grid().cell();
}

/// (integral |a - b|^2)^{1/2} over the whole grid (collective on a distributed grid).
template <class R>
R l2_distance(const SchrodingerFlows<R>& f, const Field<R>& a, const Field<R>& b) {
  R s = 0;
  for (std::size_t i = 0; i < a.size(); ++i) s += std::norm(a[i] - b[i]);
  f.fft().sum(&s, 1);
  return std::sqrt(s * f.grid().cell());
}

}  // namespace nystrom::quantum
