// S. Blanes and P. C. Moan, "Practical symplectic partitioned Runge-Kutta and Runge-Kutta-Nyström
// methods", J. Comput. Appl. Math. 142 (2002) 313-330: the optimized symmetric RKN splittings
// SRKN6b (order 4, 6 forces) and SRKN14a (order 6, 14 forces), which the Gürkan paper compares as
// "RKNb6" and "RKNa14" (its Fig. 5.1, ref. [8]).
//
// Flow order. These are RKN splittings: the order conditions use [V,[V,[T,V]]] = 0, which holds for
// q'' = a(q) but is not symmetric in T and V, so the roles of drift and kick cannot be exchanged.
// The "b" method starts (and ends) with a kick, the "a" method with a drift:
//   SRKN6b : kick b1, drift a1, kick b2, drift a2, kick b3, drift a3, kick b4, drift a3, ..., kick b1;
//   SRKN14a: drift a1, kick b1, drift a2, ..., kick b7, drift a8, kick b7, ..., kick b1, drift a1.
// The test measures both on Kepler: as written they converge with orders 4 and 6; with drift and
// kick exchanged they drop to order 2.
//
// Coefficients as published (15 digits); the last of each list follows from consistency
// (sum of drifts = sum of kicks = 1). Cross-checked with Principia, integrators/methods.hpp
// (BlanesMoan2002SRKN6B, BlanesMoan2002SRKN14A) and with the Gürkan authors' repository
// atakan/Complex_Coeff_RKN, testing/err_check_dynamics_integrator.c (move_stars_RKNb6, _RKNa14).
#pragma once

#include <vector>

#include "nystrom/methods/method.hpp"
#include "nystrom/methods/splitting_tables.hpp"

namespace nystrom::methods {

/// SRKN6b: 7 kicks (first same as last: 6 forces per step), 6 drifts, order 4.
inline SplittingScheme<bigcomplex> blanes_moan_srkn6b() {
  const auto a = bigs({"0.245298957184271", "0.604872665711080"});
  const auto b = bigs({"0.0829844064174052", "0.396309801498368", "-0.0390563049223486"});
  const bigcomplex a3 = big("1/2") - a[0].re - a[1].re;
  const bigcomplex b4 = 1 - 2 * (b[0].re + b[1].re + b[2].re);
  const auto kicks = palindrome({b[0], b[1], b[2], b4}, PalindromeLength::odd);
  const auto drifts = palindrome({a[0], a[1], a3}, PalindromeLength::even);
  return alternating(Flow::kick, kicks, drifts);
}

/// SRKN14a: 14 kicks, 15 drifts, order 6.
inline SplittingScheme<bigcomplex> blanes_moan_srkn14a() {
  const auto a = bigs({"0.0378593198406116", "0.102635633102435", "-0.0258678882665587", "0.314241403071447",
                       "-0.130144459517415", "0.106417700369543", "-0.00879424312851058"});
  const auto b = bigs({"0.09171915262446165", "0.183983170005006", "-0.05653436583288827", "0.004914688774712854",
                       "0.143761127168358", "0.328567693746804"});
  bigfloat sa = 0, sb = 0;
  for (const auto& x : a) sa += x.re;
  for (const auto& x : b) sb += x.re;
  std::vector<bigcomplex> ha = a, hb = b;
  ha.push_back(bigcomplex(1 - 2 * sa));       // a8, the central drift
  hb.push_back(bigcomplex(big("1/2") - sb));  // b7 (twice, around the central drift)
  return alternating(Flow::drift, palindrome(ha, PalindromeLength::odd), palindrome(hb, PalindromeLength::even));
}

inline std::vector<MethodDef> blanes_moan2002() {
  const std::string src = "Blanes & Moan, J. Comput. Appl. Math. 142 (2002) 313";
  std::vector<MethodDef> m;
  m.push_back({{.name = "RKNb6",
                .family = "splitting",
                .order = 4,
                .symmetric = true,
                .symplectic = true,
                .published_digits = 15,
                .source = src + ", SRKN6b",
                .description = "Blanes-Moan optimized 4th-order RKN splitting, 6 forces, kick first",
                .aliases = {"SRKN6b", "BM4"}},
               [] { return MethodData{blanes_moan_srkn6b()}; }});
  m.push_back({{.name = "RKNa14",
                .family = "splitting",
                .order = 6,
                .symmetric = true,
                .symplectic = true,
                .published_digits = 15,
                .source = src + ", SRKN14a",
                .description = "Blanes-Moan optimized 6th-order RKN splitting, 14 forces, drift first",
                .aliases = {"SRKN14a", "BM6"}},
               [] { return MethodData{blanes_moan_srkn14a()}; }});
  return m;
}

}  // namespace nystrom::methods
