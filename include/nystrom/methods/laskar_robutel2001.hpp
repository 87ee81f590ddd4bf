// The SABA_n and SBAB_n integrators of J. Laskar and P. Robutel, "High order symplectic integrators for
// perturbed Hamiltonian systems", Celest. Mech. Dyn. Astron. 80 (2001) 39-62, for H = A + eps B with A
// integrable (a Kepler drift) and B a small perturbation. Their error is O(eps h^{2n} + eps^2 h^2): order 2
// in the usual sense, order 2n in the perturbation (the first error terms that survive are eps^2 h^2).
//
//   SABA_n: drift c_1, kick d_1, drift c_2, ..., kick d_n, drift c_{n+1}: the kicks at the n Gauss-Legendre
//           nodes tau_i of [0, 1] with their weights d_i; the drifts are the gaps c_1 = tau_1,
//           c_{i+1} = tau_{i+1} - tau_i, c_{n+1} = 1 - tau_n (LR2001 Table 1).
//   SBAB_n: kick d_1, drift c_2, kick d_2, ..., drift c_{n+1}, kick d_{n+1}: the kicks at the n + 1
//           Gauss-Lobatto nodes of [0, 1] (including 0 and 1) with their weights (LR2001 Table 2).
// Sub-steps are listed in time order (the schemes are palindromes). The closed forms of the nodes for
// n <= 4 are the ones printed in LR2001.
#pragma once

#include <string>
#include <vector>

#include "nystrom/methods/method.hpp"

namespace nystrom::methods {

namespace detail {

/// A SABA (kicks at `nodes`) or SBAB (Lobatto `nodes`, first 0 and last 1) scheme from quadrature nodes.
inline SplittingScheme<bigcomplex> quadrature_splitting(const std::vector<bigfloat>& nodes,
                                                        const std::vector<bigfloat>& weights) {
  SplittingScheme<bigcomplex> s;
  bigfloat at = 0;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    if (nodes[i] != at) s.steps.push_back(drift(nodes[i] - at));
    s.steps.push_back(kick(weights[i]));
    at = nodes[i];
  }
  if (at != 1) s.steps.push_back(drift(1 - at));
  return s;
}

/// Gauss-Legendre nodes and weights on [0, 1], n = 1..4, in closed form.
inline void gauss_legendre01(int n, std::vector<bigfloat>& x, std::vector<bigfloat>& w) {
  using boost::multiprecision::sqrt;
  const bigfloat half = big("1/2");
  x.clear();
  w.clear();
  if (n == 1) {
    x = {half};
    w = {bigfloat(1)};
  } else if (n == 2) {
    const bigfloat d = sqrt(bigfloat(3)) / 6;
    x = {half - d, half + d};
    w = {half, half};
  } else if (n == 3) {
    const bigfloat d = sqrt(bigfloat(15)) / 10;
    x = {half - d, half, half + d};
    w = {big("5/18"), big("4/9"), big("5/18")};
  } else {
    // nodes 1/2 -+ sqrt(525 -+ 70 sqrt 30) / 70, weights 1/4 +- sqrt(30) / 72 (inner ones heavier)
    const bigfloat r30 = sqrt(bigfloat(30));
    const bigfloat outer = sqrt(525 + 70 * r30) / 70, inner = sqrt(525 - 70 * r30) / 70;
    const bigfloat w_outer = big("1/4") - r30 / 72, w_inner = big("1/4") + r30 / 72;
    x = {half - outer, half - inner, half + inner, half + outer};
    w = {w_outer, w_inner, w_inner, w_outer};
  }
}

/// Gauss-Lobatto nodes (n + 1 of them, 0 and 1 included) and weights on [0, 1], n = 1..4, in closed form.
inline void gauss_lobatto01(int n, std::vector<bigfloat>& x, std::vector<bigfloat>& w) {
  using boost::multiprecision::sqrt;
  const bigfloat half = big("1/2");
  if (n == 1) {
    x = {bigfloat(0), bigfloat(1)};
    w = {half, half};
  } else if (n == 2) {
    x = {bigfloat(0), half, bigfloat(1)};
    w = {big("1/6"), big("2/3"), big("1/6")};
  } else if (n == 3) {
    const bigfloat d = sqrt(bigfloat(5)) / 10;
    x = {bigfloat(0), half - d, half + d, bigfloat(1)};
    w = {big("1/12"), big("5/12"), big("5/12"), big("1/12")};
  } else {
    const bigfloat d = sqrt(bigfloat(21)) / 14;
    x = {bigfloat(0), half - d, half, half + d, bigfloat(1)};
    w = {big("1/20"), big("49/180"), big("16/45"), big("49/180"), big("1/20")};
  }
}

}  // namespace detail

/// SABA1..SABA4 and SBAB1..SBAB4. SABA1 is the Wisdom-Holman drift-kick-drift, SBAB1 kick-drift-kick.
inline std::vector<MethodDef> laskar_robutel2001() {
  std::vector<MethodDef> m;
  const std::string source = "Laskar & Robutel, Celest. Mech. Dyn. Astron. 80 (2001) 39";
  for (int n = 1; n <= 4; ++n) {
    const std::string order_text = "error O(eps h^" + std::to_string(2 * n) + " + eps^2 h^2) for H = A + eps B";
    m.push_back({{.name = "SABA" + std::to_string(n),
                  .family = "splitting",
                  .order = 2,
                  .symmetric = true,
                  .symplectic = true,
                  .source = source,
                  .description = "kicks at the " + std::to_string(n) + " Gauss-Legendre nodes; " + order_text,
                  .aliases = {}},
                 [n] {
                   std::vector<bigfloat> x, w;
                   detail::gauss_legendre01(n, x, w);
                   return MethodData{detail::quadrature_splitting(x, w)};
                 }});
    m.push_back({{.name = "SBAB" + std::to_string(n),
                  .family = "splitting",
                  .order = 2,
                  .symmetric = true,
                  .symplectic = true,
                  .source = source,
                  .description = "kicks at the " + std::to_string(n + 1) + " Gauss-Lobatto nodes; " + order_text,
                  .aliases = {}},
                 [n] {
                   std::vector<bigfloat> x, w;
                   detail::gauss_lobatto01(n, x, w);
                   return MethodData{detail::quadrature_splitting(x, w)};
                 }});
  }
  return m;
}

}  // namespace nystrom::methods
