// The methods of S. A. Chin, "Multi-product splitting and Runge-Kutta-Nyström integrators",
// Celest. Mech. Dyn. Astron. 106 (2010) 391-406:
//   * velocity and position Verlet (eqs 25, 26), Forest-Ruth (position-first form compared in Fig 1);
//   * the force-consolidated RKN methods as tableaux: Nyström 4 (eqs 28, 32), M4 (eqs 33-34),
//     the new 5-force sixth-order method (eqs 39-47), Albrecht's A6 (eqs 61-62);
//   * the forward fourth-order integrator A' (Fig 1; after Chin 2007 and Omelyan 2006);
//   * the multi-product integrators M4 ... M16 (natural sequence, PV base) of eq (17).
// Tableau rows below are transcribed from the cited equations; the derivation is in the comments.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "nystrom/methods/method.hpp"

namespace nystrom::methods {

inline std::vector<MethodDef> chin2010() {
  std::vector<MethodDef> m;
  const std::string chin = "Chin, Celest. Mech. Dyn. Astron. 106 (2010) 391";

  m.push_back({{.name = "VV",
                .family = "splitting",
                .order = 2,
                .symmetric = true,
                .symplectic = true,
                .source = "Verlet; Chin (2010) eq (25)",
                .description = "velocity Verlet: kick h/2, drift h, kick h/2",
                .aliases = {"velocity-verlet", "LF"}},
               [] { return MethodData{velocity_verlet_scheme()}; }});
  m.push_back({{.name = "PV",
                .family = "splitting",
                .order = 2,
                .symmetric = true,
                .symplectic = true,
                .source = "Verlet; Chin (2010) eq (26)",
                .description = "position Verlet: drift h/2, kick h, drift h/2",
                .aliases = {"position-verlet"}},
               [] { return MethodData{position_verlet_scheme()}; }});
  // Forest & Ruth, Physica D 43 (1990) 105; theta = 1/(2 - 2^(1/3)); the position-first form Chin compares.
  m.push_back({{.name = "FR",
                .family = "splitting",
                .order = 4,
                .symmetric = true,
                .symplectic = true,
                .source = "Forest & Ruth, Physica D 43 (1990) 105",
                .description = "Forest-Ruth, position-first",
                .aliases = {"forest-ruth"}},
               [] {
                 const bigfloat theta = 1 / (2 - boost::multiprecision::cbrt(bigfloat(2)));
                 const bigfloat half = big("1/2");
                 return MethodData{
                     scheme({drift(theta * half), kick(theta), drift((1 - theta) * half), kick(1 - 2 * theta),
                             drift((1 - theta) * half), kick(theta), drift(theta * half)})};
               }});
  // Forest-Ruth in the velocity-first form (opposite sign and a several times larger error constant).
  m.push_back({{.name = "FR-V",
                .family = "splitting",
                .order = 4,
                .symmetric = true,
                .symplectic = true,
                .source = "Forest & Ruth, Physica D 43 (1990) 105",
                .description = "Forest-Ruth, velocity-first",
                .aliases = {}},
               [] {
                 const bigfloat theta = 1 / (2 - boost::multiprecision::cbrt(bigfloat(2)));
                 const bigfloat half = big("1/2");
                 return MethodData{
                     scheme({kick(theta * half), drift(theta), kick((1 - theta) * half), drift(1 - 2 * theta),
                             kick((1 - theta) * half), drift(theta), kick(theta * half)})};
               }});

  // Nyström's fourth-order method from the {1,2} VV expansion with force consolidation, eqs (28)-(32):
  // stages a_0 = a(q0), a_1/2 = a(q0 + h/2 v0 + h^2/8 a_0), a~ = a(q0 + h v0 + h^2/2 a_1/2);
  // q = q0 + h v0 + h^2/6 (a_0 + 2 a_1/2);  v = v0 + h/6 (a_0 + 4 a_1/2 + a~).
  m.push_back({{.name = "N4",
                .family = "rkn",
                .order = 4,
                .symmetric = false,
                .symplectic = false,
                .source = "Nystrom (1925); Chin (2010) eqs (28), (32)",
                .description = "Nystrom's 4th-order RKN",
                .aliases = {"N", "nystrom4"}},
               [] {
                 return MethodData{tableau({"0", "1/2", "1"}, {{}, {"1/8"}, {"0", "1/2"}}, {"1/6", "1/3", "0"},
                                           {"1/6", "2/3", "1/6"})};
               }});
  // M4 as the explicit PV-based {1,2} formula, eqs (33)-(34):
  // x_1/4 = x0 + h/4 v0; x_1/2 = x0 + h/2 v0; x_3/4 = x0 + 3h/4 v0 + h^2/4 a_1/4;
  // x = x0 + h v0 + h^2/6 (3 a_1/4 - a_1/2 + a_3/4); v = v0 + h/3 (2 a_1/4 - a_1/2 + 2 a_3/4).
  m.push_back({{.name = "M4-RKN",
                .family = "rkn",
                .order = 4,
                .symmetric = false,
                .symplectic = false,
                .source = chin + ", eqs (33)-(34)",
                .description = "M4 written as an RKN tableau",
                .aliases = {}},
               [] {
                 return MethodData{
                     tableau({"1/4", "1/2", "3/4"}, {{}, {}, {"1/4"}}, {"1/2", "-1/6", "1/6"}, {"2/3", "-1/3", "2/3"})};
               }});
  // The new 5-force sixth-order method, eqs (39)-(47): {1,2,3} VV expansion, the three forces at h
  // consolidated into a(q~_1), eq (46).
  m.push_back({{.name = "M6-5F",
                .family = "rkn",
                .order = 6,
                .symmetric = false,
                .symplectic = false,
                .source = chin + ", eqs (39)-(47)",
                .description = "Chin's 5-force 6th-order RKN from {1,2,3}",
                .aliases = {"C6"}},
               [] {
                 return MethodData{tableau({"0", "1/3", "1/2", "2/3", "1"},
                                           {{}, {"1/18"}, {"1/8"}, {"1/9", "1/9"}, {"0", "18/22", "-16/22", "9/22"}},
                                           {"11/120", "54/120", "-32/120", "27/120", "0"},
                                           {"22/240", "162/240", "-128/240", "162/240", "22/240"})};
               }});
  // Albrecht's sixth-order method, Z. Angew. Math. Mech. 35 (1955) 100, as derived in eqs (51)-(62).
  m.push_back({{.name = "A6",
                .family = "rkn",
                .order = 6,
                .symmetric = false,
                .symplectic = false,
                .source = "Albrecht, ZAMM 35 (1955) 100; Chin (2010) eqs (61)-(62)",
                .description = "Albrecht's 5-force 6th-order RKN",
                .aliases = {"albrecht6"}},
               [] {
                 return MethodData{tableau(
                     {"0", "1/4", "1/2", "3/4", "1"},
                     {{}, {"1/32"}, {"-1/24", "4/24"}, {"3/32", "4/32", "2/32"}, {"0", "6/14", "-1/14", "2/14"}},
                     {"7/90", "24/90", "6/90", "8/90", "0"}, {"7/90", "32/90", "12/90", "32/90", "7/90"})};
               }});
  // The forward integrator A' (all splitting coefficients positive), Fig 1; Chin, Int. J. Comput. Math.
  // 84 (2007) 729 and Omelyan, Phys. Rev. E 74 (2006) 036703: one step is
  // v += h/6 a(q); q += h/2 v; v += 2h/3 a(q + h^2/24 a(q)); q += h/2 v; v += h/6 a(q).
  // As a tableau: y1 = q0; y2 = q0 + h/2 v0 + h^2/12 a1; y3 = y2 + h^2/24 a2; y4 = q1 (FSAL).
  m.push_back({{.name = "Aprime",
                .family = "rkn",
                .order = 4,
                .symmetric = true,
                .symplectic = false,
                .source = "Chin, Int. J. Comput. Math. 84 (2007) 729; Omelyan, PRE 74 (2006) 036703",
                .description = "forward 4th-order A' (gradient-like shifted force)",
                .aliases = {"A'", "4A'"}},
               [] {
                 return MethodData{tableau({"0", "1/2", "1/2", "1"},
                                           {{}, {"1/12"}, {"1/12", "1/24"}, {"1/6", "0", "1/3"}},
                                           {"1/6", "0", "1/3", "0"}, {"1/6", "0", "2/3", "1/6"})};
               }});
  return m;
}

/// The multi-product method on sequence k with base "PV" or "VV".
inline MethodDef mpe_method(const std::vector<long>& k, const std::string& base, std::string name) {
  validate_mpe_sequence(k);
  std::string seq;
  for (std::size_t i = 0; i < k.size(); ++i) {
    if (i) seq += ',';
    seq += std::to_string(k[i]);
  }
  MethodInfo info{.name = std::move(name),
                  .family = "mpe",
                  .order = 2 * static_cast<int>(k.size()),
                  .symmetric = false,
                  .symplectic = false,  // a sum of symmetric maps is not symmetric
                  .source = "Chin (2010) eqs (14), (17); base " + base + (base == "VV" ? " eq (25)" : " eq (26)"),
                  .description = "multi-product expansion {" + seq + "} over " + base,
                  .aliases = {}};
  return {info, [k, base] {
            return MethodData{MpeDef{k, base, base == "VV" ? velocity_verlet_scheme() : position_verlet_scheme()}};
          }};
}

/// The natural-sequence MPE on position Verlet with order and step control (engines/adaptive_mpe.hpp): each
/// step runs the products k = 1..n, n from 2 to max_order / 2 chosen per step by work per unit step, as ODEX
/// chooses its columns (Hairer, Norsett & Wanner, Solving Ordinary Differential Equations I, 2nd ed., sec. II.9).
/// Its MethodInfo describes the largest step (order, stages, forces per step).
inline MethodDef mpe_order_control_method(int max_order, std::string name) {
  if (max_order < 4 || max_order > 16 || max_order % 2 != 0)
    throw std::invalid_argument(
        "the largest order of adaptive MPE order control must be an even number from 4 to "
        "16, got " +
        std::to_string(max_order));
  std::vector<long> k;
  for (long i = 1; i <= max_order / 2; ++i) k.push_back(i);
  MethodDef d = mpe_method(k, "PV", std::move(name));
  d.info.adaptive = true;
  d.info.order_control = true;
  d.info.source = "Chin (2010) eqs (14), (17); order control after Hairer, Norsett & Wanner, Solving ODEs I, sec. II.9";
  d.info.description = "multi-product expansion over PV, order 4.." + std::to_string(max_order) +
                       " and step chosen per step by work per unit step (estimates: the products without the "
                       "largest k)";
  d.build = [k] {
    MpeDef m{k, "PV", position_verlet_scheme()};
    m.order_control = true;
    return MethodData{std::move(m)};
  };
  return d;
}

/// M4, M6, ..., M16: natural sequences on position Verlet (eq 17); MPE-adaptive: the same with order control.
inline std::vector<MethodDef> chin2010_mpe() {
  std::vector<MethodDef> m;
  for (long n = 2; n <= 8; ++n) {
    std::vector<long> k;
    for (long i = 1; i <= n; ++i) k.push_back(i);
    m.push_back(mpe_method(k, "PV", "M" + std::to_string(2 * n)));
  }
  m.push_back(mpe_order_control_method(16, "MPE-adaptive"));
  return m;
}

}  // namespace nystrom::methods
