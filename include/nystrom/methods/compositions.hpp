// Compositions of the leapfrog: psi_h = S(w_m h) o ... o S(w_1 h) with S a symmetric second-order
// leapfrog, w the composition weights (palindromic here, so psi is symmetric). Sources:
//   * H. Yoshida, "Construction of higher order symplectic integrators", Phys. Lett. A 150 (1990) 262:
//     the triple jump to any even order and the 7-stage sixth-order solution A;
//   * M. Suzuki, "Fractal decomposition of exponential operators ...", Phys. Lett. A 146 (1990) 319:
//     the 5-fold fractal construction to any even order;
//   * W. Kahan, R.-C. Li, "Composition constants for raising the orders of unconventional schemes
//     for ordinary differential equations", Math. Comp. 66 (1997) 1089: s9odr6a and s17odr8a;
//   * M. Sofroniou, G. Spaletta, "Derivation of symmetric composition constants for symmetric
//     integrators", Optim. Methods Softw. 20 (2005) 597: 35 stages, order 10.
// Y6, KL6, KL8 and SS10 are the methods the Chin (2010) paper compares in its Figs. 2 and 3.
//
// The base leapfrog. Both forms are offered (their error constants differ): the position-first one (PV, Chin eq 26:
// drift h/2, kick h, drift h/2) is the DEFAULT; the velocity-first one (VV, eq 25) is named with a
// "-V" suffix, as FR / FR-V in chin2010.hpp: Y6 = Y6 on PV, Y6-V = Y6 on VV. The parametric specs are
// triplejump:P / triplejump-pv:P (PV) and triplejump-vv:P (VV), suzuki:P / suzuki-pv:P / suzuki-vv:P.
// Adjacent half-steps of consecutive leapfrogs merge (compose()), so a composition of m leapfrogs
// costs m forces per step on either base (on VV through first-same-as-last).
//
// Decimal tables are taken as published with 26 digits, cross-checked against Hairer, Lubich &
// Wanner, Geometric Numerical Integration, 2nd ed. (2006), Sec. V.3.2 (eqs 3.11, 3.12, 3.14 and the
// p10s35 table; also Hairer's gni_comp.f, METHC=67 for Yoshida's solution A) and OrdinaryDiffEq.jl
// (symplectic_tableaus.jl: KahanLi6, KahanLi8, SofSpa10). Every table is checked against the
// composition order conditions in tests/methods/test_catalog_splitting.cpp (local error of the composed
// splitting on generic non-commuting matrices: observed order p+1, defect at p+1 nonzero).
//
// On the two nine-stage sixth-order sets in circulation: Kahan & Li's s9odr6a (gamma_1 =
// 0.392161444...; HLW eq 3.12, OrdinaryDiffEq KahanLi6) and McLachlan's SS9 (SIAM J. Sci. Comput. 16
// (1995) 151; gamma_1 = 0.1867, ...). The test checks both against the order conditions: both are
// genuine sixth-order compositions (neither is a corrupted copy of the other); they are different
// methods. KL6 here is s9odr6a, the Kahan-Li method the Chin paper cites (its ref. 20).
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "nystrom/methods/method.hpp"

namespace nystrom::methods {

/// The base leapfrog: "PV" (position-first, default) or "VV" (velocity-first).
inline SplittingScheme<bigcomplex> leapfrog_base(const std::string& base) {
  if (base == "PV") return position_verlet_scheme();
  if (base == "VV") return velocity_verlet_scheme();
  throw std::invalid_argument("unknown leapfrog base '" + base + "' (use PV or VV)");
}

/// Highest orders accepted for the recursive constructions: 3^9 = 19683 (triple jump) and 5^6 = 15625
/// (Suzuki) leapfrogs per step. Beyond that the step is absurdly long and the weights overflow in size.
inline constexpr int max_triple_jump_order = 20;
inline constexpr int max_suzuki_order = 14;

namespace detail {
inline void check_composition_order(int order, int max_order, const std::string& what) {
  if (order < 2 || order % 2 != 0 || order > max_order)
    throw std::invalid_argument(what + " order must be an even number between 2 and " + std::to_string(max_order) +
                                ", got " + std::to_string(order));
}
/// {c_1 w, c_2 w, ...}: each weight of the inner composition scaled by each outer factor in turn.
inline std::vector<bigcomplex> nest(const std::vector<bigfloat>& outer, const std::vector<bigcomplex>& inner) {
  std::vector<bigcomplex> w;
  w.reserve(outer.size() * inner.size());
  for (const auto& c : outer)
    for (const auto& x : inner) w.push_back(x * bigcomplex(c));
  return w;
}
}  // namespace detail

/// Yoshida's triple jump (Phys. Lett. A 150 (1990) 262): S_{2k+2}(h) =
/// S_{2k}(x1 h) S_{2k}(x0 h) S_{2k}(x1 h), x1 = 1/(2 - 2^{1/(2k+1)}), x0 = -2^{1/(2k+1)} x1
/// (= 1 - 2 x1), from S_2 = leapfrog. Order p uses 3^{p/2-1} leapfrogs.
inline std::vector<bigcomplex> triple_jump_weights(int order) {
  detail::check_composition_order(order, max_triple_jump_order, "triple-jump");
  std::vector<bigcomplex> w{bigcomplex(bigfloat(1))};
  for (int k = 1; 2 * k < order; ++k) {
    const bigfloat r = boost::multiprecision::pow(bigfloat(2), bigfloat(1) / bigfloat(2 * k + 1));
    const bigfloat x1 = 1 / (2 - r);
    const bigfloat x0 = -r * x1;
    w = detail::nest({x1, x0, x1}, w);
  }
  return w;
}

/// Suzuki's fractal (Phys. Lett. A 146 (1990) 319): S_{2k+2}(h) = S_{2k}(p h)^2
/// S_{2k}((1-4p) h) S_{2k}(p h)^2, p = 1/(4 - 4^{1/(2k+1)}). Order p uses 5^{p/2-1} leapfrogs.
inline std::vector<bigcomplex> suzuki_weights(int order) {
  detail::check_composition_order(order, max_suzuki_order, "Suzuki");
  std::vector<bigcomplex> w{bigcomplex(bigfloat(1))};
  for (int k = 1; 2 * k < order; ++k) {
    const bigfloat p = 1 / (4 - boost::multiprecision::pow(bigfloat(4), bigfloat(1) / bigfloat(2 * k + 1)));
    w = detail::nest({p, p, 1 - 4 * p, p, p}, w);
  }
  return w;
}

/// Parses the order of a parametric composition spec ("6" in "triplejump:6").
inline int parse_composition_order(const std::string& text, const std::string& spec) {
  if (text.empty() || text.size() > 4 || text.find_first_not_of("0123456789") != std::string::npos)
    throw std::invalid_argument("expected an even order after ':' in '" + spec + "'");
  return std::stoi(text);
}

namespace detail {
inline std::string base_label(const std::string& base) {
  return base == "VV" ? "velocity-first leapfrog (VV, Chin eq 25)" : "position-first leapfrog (PV, Chin eq 26)";
}
}  // namespace detail

/// Yoshida's triple jump of even order on base "PV" or "VV".
inline MethodDef triple_jump_method(int order, const std::string& base, std::string name) {
  detail::check_composition_order(order, max_triple_jump_order, "triple-jump");
  (void)leapfrog_base(base);  // validates the base name
  MethodInfo info{
      .name = std::move(name),
      .family = "composition",
      .order = order,
      .symmetric = true,
      .symplectic = true,
      .source = "Yoshida, Phys. Lett. A 150 (1990) 262 (triple jump)",
      .description = "Yoshida triple jump of order " + std::to_string(order) + " on the " + detail::base_label(base),
      .aliases = {}};
  return {info, [order, base] { return MethodData{compose(leapfrog_base(base), triple_jump_weights(order))}; }};
}

/// Suzuki's 5-fold fractal composition of even order on base "PV" or "VV".
inline MethodDef suzuki_method(int order, const std::string& base, std::string name) {
  detail::check_composition_order(order, max_suzuki_order, "Suzuki");
  (void)leapfrog_base(base);
  MethodInfo info{.name = std::move(name),
                  .family = "composition",
                  .order = order,
                  .symmetric = true,
                  .symplectic = true,
                  .source = "Suzuki, Phys. Lett. A 146 (1990) 319",
                  .description = "Suzuki 5-fold fractal composition of order " + std::to_string(order) + " on the " +
                                 detail::base_label(base),
                  .aliases = {}};
  return {info, [order, base] { return MethodData{compose(leapfrog_base(base), suzuki_weights(order))}; }};
}

/// Weights of the published symmetric compositions, built from the first half (the last entry given
/// is the central weight). Each comes with its source.
struct CompositionTable {
  std::string name;
  int order;
  std::string source;
  std::string description;
  std::vector<std::string> aliases;
  std::vector<std::string> half;  // gamma_1 ... gamma_{(s+1)/2}, as published
};

inline std::vector<CompositionTable> composition_tables() {
  return {
      // Yoshida (1990), solution A (7 stages, order 6). Yoshida prints 15 digits; the 26 below are
      // those of HLW (2006) eq V.(3.11) and gni_comp.f METHC=67. All four are taken as published: the
      // central one differs from 1 - 2(g1+g2+g3) by 1e-26 (rounding of the last digit). The same holds
      // for the other tables: the weights sum to 1 within 3e-26.
      {"Y6",
       6,
       "Yoshida, Phys. Lett. A 150 (1990) 262, solution A; digits of Hairer-Lubich-Wanner (2006) eq V.3.11",
       "Yoshida's 7-stage sixth-order composition (solution A)",
       {"yoshida6", "Y6A"},
       {"0.78451361047755726381949763", "0.23557321335935813368479318", "-1.17767998417887100694641568",
        "1.31518632068391121888424973"}},
      // Kahan & Li (1997), s9odr6a; HLW (2006) eq V.(3.12); OrdinaryDiffEq.jl KahanLi6.
      {"KL6",
       6,
       "Kahan & Li, Math. Comp. 66 (1997) 1089, s9odr6a",
       "Kahan-Li 9-stage sixth-order composition",
       {"kahan-li6", "s9odr6a"},
       {"0.39216144400731413927925056", "0.33259913678935943859974864", "-0.70624617255763935980996482",
        "0.08221359629355080023149045", "0.79854399093482996339895035"}},
      // Kahan & Li (1997), s17odr8a; HLW (2006) eq V.(3.14); OrdinaryDiffEq.jl KahanLi8.
      {"KL8",
       8,
       "Kahan & Li, Math. Comp. 66 (1997) 1089, s17odr8a",
       "Kahan-Li 17-stage eighth-order composition",
       {"kahan-li8", "s17odr8a"},
       {"0.13020248308889008087881763", "0.56116298177510838456196441", "-0.38947496264484728640807860",
        "0.15884190655515560089621075", "-0.39590389413323757733623154", "0.18453964097831570709183254",
        "0.25837438768632204729397911", "0.29501172360931029887096624", "-0.60550853383003451169892108"}},
      // Sofroniou & Spaletta (2005), 35 stages, order 10; HLW (2006) Sec. V.3.2 (p10s35); OrdinaryDiffEq.jl SofSpa10.
      {"SS10",
       10,
       "Sofroniou & Spaletta, Optim. Methods Softw. 20 (2005) 597",
       "Sofroniou-Spaletta 35-stage tenth-order composition",
       {"sofroniou-spaletta10", "SofSpa10"},
       {"0.07879572252168641926390768", "0.31309610341510852776481247", "0.02791838323507806610952027",
        "-0.22959284159390709415121340", "0.13096206107716486317465686", "-0.26973340565451071434460973",
        "0.07497334315589143566613711", "0.11199342399981020488957508", "0.36613344954622675119314812",
        "-0.39910563013603589787862981", "0.10308739852747107731580277", "0.41143087395589023782070412",
        "-0.00486636058313526176219566", "-0.39203335370863990644808194", "0.05194250296244964703718290",
        "0.05066509075992449633587434", "0.04967437063972987905456880", "0.04931773575959453791768001"}},
  };
}

/// The full weight sequence of a table (palindrome around the central weight).
inline std::vector<bigcomplex> table_weights(const CompositionTable& t) {
  std::vector<bigcomplex> half;
  for (const auto& x : t.half) half.push_back(big(x));
  return palindrome(half, PalindromeLength::odd);
}

/// The named compositions: Y4 (triple jump of order 4), Y6, KL6, KL8, SS10, each on PV (default) and
/// VV ("-V" suffix).
inline std::vector<MethodDef> compositions() {
  std::vector<MethodDef> m;
  for (const std::string base : {"PV", "VV"}) {
    const std::string suffix = base == "VV" ? "-V" : "";
    // Y4 = triple jump of order 4. On PV it equals FR (Forest-Ruth, position-first), on VV FR-V; the
    // catalog keeps both names (the test checks that the coefficients agree).
    MethodDef y4 = triple_jump_method(4, base, "Y4" + suffix);
    y4.info.description =
        "Yoshida triple jump of order 4 on the " + detail::base_label(base) + (base == "PV" ? " (= FR)" : " (= FR-V)");
    if (base == "PV") y4.info.aliases = {"yoshida4", "triplejump4"};
    m.push_back(std::move(y4));
    for (const auto& t : composition_tables()) {
      MethodInfo info{.name = t.name + suffix,
                      .family = "composition",
                      .order = t.order,
                      .symmetric = true,
                      .symplectic = true,
                      .published_digits = 26,
                      .source = t.source,
                      .description = t.description + " on the " + detail::base_label(base),
                      .aliases = base == "PV" ? t.aliases : std::vector<std::string>{}};
      m.push_back({info, [t, base] { return MethodData{compose(leapfrog_base(base), table_weights(t))}; }});
    }
  }
  return m;
}

}  // namespace nystrom::methods
