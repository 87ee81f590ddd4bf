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

template <class R>
Observables<R> observe(const SchrodingerFlows<R>& f, const Field<R>& psi) {
  const Grid<R>& g = f.grid();
  Observables<R> o;
  o.mean_x.assign(static_cast<std::size_t>(g.dims), R(0));
  o.mean_p.assign(static_cast<std::size_t>(g.dims), R(0));
  int idx[3];
  R n = 0, v = 0, rho2 = 0;
  for (std::size_t i = 0; i < psi.size(); ++i) {
    const R rho = std::norm(psi[i]);
    n += rho;
    v += rho * f.potential()[i];
    rho2 += rho * rho;
    g.indices(i, idx);
    for (int a = 0; a < g.dims; ++a) o.mean_x[a] += rho * g.coordinate(idx[a]);
  }
  Field<R> hat = psi;
  f.fft().forward(hat);
  R nk = 0, t = 0;
  for (std::size_t i = 0; i < hat.size(); ++i) {
    const R w = std::norm(hat[i]);
    nk += w;
    t += w * f.half_k2()[i];
    g.indices(i, idx);
    for (int a = 0; a < g.dims; ++a) o.mean_p[a] += w * g.wavenumber(idx[a]);
  }
  o.norm = n * g.cell();
  if (!(n > 0) || !(nk > 0)) return o;
  for (auto& x : o.mean_x) x /= n;
  for (auto& p : o.mean_p) p /= nk;
  o.kinetic = t / nk;
  o.potential = v / n;
  // g int |psi|^4 / (int |psi|^2)^2, the integrals as sums times dx^d
  o.interaction = f.coupling() * (rho2 * g.cell()) / (o.norm * o.norm);
  o.energy = o.kinetic + o.potential + o.interaction / 2;
  o.chemical_potential = o.kinetic + o.potential + o.interaction;
  return o;
}

/// (integral |a - b|^2)^{1/2}.
template <class R>
R l2_distance(const Grid<R>& g, const Field<R>& a, const Field<R>& b) {
  R s = 0;
  for (std::size_t i = 0; i < a.size(); ++i) s += std::norm(a[i] - b[i]);
  return std::sqrt(s * g.cell());
}

}  // namespace nystrom::quantum
