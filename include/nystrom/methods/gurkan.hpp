// The fifth-order RKN splittings of M. A. Gürkan, "Fifth order Runge-Kutta-Nyström methods with
// complex coefficients" (preprint, Leiden/Sabanci, 2012; the author's repository
// atakan/Complex_Coeff_RKN gives it as submitted to Math. Comp.), and the
// complex third-order method of J. E. Chambers, "Symplectic integrators with complex time steps",
// Astron. J. 126 (2003) 1119, which that paper compares (its ref. [11]).
//
// Operator order. The paper writes its schemes as operator products, applied right to left:
//   RKNA, eq (3.6): e^{a6 tT} e^{b5 tV} e^{a5 tT} ... e^{b1 tV} e^{a1 tT}
//   RKNB, eq (3.7): e^{b6 tV} e^{a5 tT} e^{b5 tV} ... e^{a1 tT} e^{b1 tV}
// so in time order (the catalog's convention) RKNA is drift a1, kick b1, drift a2, ..., kick b5,
// drift a6 (the procedure after eq (3.5): y_1 = y_0 + h (c_1 - c_0) v first), and RKNB is kick b1,
// drift a1, kick b2, ..., drift a5, kick b6. The authors' test program (testing/
// err_check_dynamics_integrator.c: move_stars_RKNar1, _RKNbr1, _RKNac1) applies them the same way.
//
// Table 4.1 (real): all coefficients are printed; they are used as printed (16-17 digits; the sums
// are 1 within 1e-16). Table 4.2 (complex, skew-symmetric): only the first half is printed; the
// rest follows from skew-symmetry (reversing the list gives its complex conjugate) and from
// sum(alpha) = sum(beta) = 1, as the caption says: for AC the central kick b3 is real,
// b3 = 1 - 2 Re(b1 + b2); for BC the central drift a3 = 1 - 2 Re(a1 + a2). The reconstructed values
// agree with the authors' program (b3 = 0.27970515920361567 for AC1, a3 = 0.29929785469808900 for BC1).
//
// The optimized six-stage method of eq (6.1): 7 kicks and 6 drifts, skew-symmetric, kick first:
// kick b1', drift a1, kick b2', drift a2, kick b3', drift a3, kick b4' (real), drift conj(a3),
// kick conj(b3'), ..., drift conj(a1), kick conj(b1'). (The starting point was AC1 embedded with
// b1' = b7' = 0; the optimum has them nonzero.) The printed 18 digits are consistent only to about
// 16: the kicks sum to 1 - 2.5e-16. The authors' program has a slightly different optimum
// (move_stars_RKNbco2, differing in the 11th digit); we use the paper's numbers.
//
// Complex methods run on the complexified state; by default the engine drops the imaginary parts
// of q and v after every step (Gürkan sec. 5), which makes AC1 behave as a sixth-order and Chambers
// as a fourth-order method on the two-body problem (Fig. 5.1; measured in the tests).
#pragma once

#include <string>
#include <vector>

#include <boost/multiprecision/mpfr.hpp>

#include "nystrom/methods/method.hpp"
#include "nystrom/methods/splitting_tables.hpp"

namespace nystrom::methods {

/// RKNA scheme (eq 3.6) in time order: drift alpha_1, kick beta_1, ..., kick beta_s, drift alpha_{s+1}.
inline SplittingScheme<bigcomplex> rkna_scheme(const std::vector<bigcomplex>& alpha,
                                               const std::vector<bigcomplex>& beta) {
  return alternating(Flow::drift, alpha, beta);
}
/// RKNB scheme (eq 3.7) in time order: kick beta_1, drift alpha_1, ..., drift alpha_s, kick beta_{s+1}.
inline SplittingScheme<bigcomplex> rknb_scheme(const std::vector<bigcomplex>& alpha,
                                               const std::vector<bigcomplex>& beta) {
  return alternating(Flow::kick, beta, alpha);
}

namespace detail {
inline std::vector<bigcomplex> complex_list(const std::vector<std::pair<std::string, std::string>>& xs) {
  std::vector<bigcomplex> out;
  for (const auto& [re, im] : xs) out.push_back(bigc(re, im));
  return out;
}
}  // namespace detail

// ---- Table 4.1: real fifth-order methods ----------------------------------------------------------

inline SplittingScheme<bigcomplex> gurkan_ar1() {
  return rkna_scheme(bigs({"0.96172990014645096", "-0.09525408032034999", "-0.73942683539212613", "0.62730935078241887",
                           "-0.52506178465602220", "0.77070344943962849"}),
                     bigs({"0.39682804502722538", "-0.824377563589592", "0.2042028689314904", "1.0021847152077973",
                           "0.22116193442307898"}));
}
inline SplittingScheme<bigcomplex> gurkan_ar2() {
  return rkna_scheme(bigs({"0.69883375727545265", "-0.49469565362085154", "0.81641946634957295", "-0.65762956677338285",
                           "-0.057841894299102682", "0.69491389106831146"}),
                     bigs({"0.40090379269659899", "0.95997088013405985", "0.0884951581272243", "1.2214390923487315",
                           "-1.6708089233066146"}));
}
inline SplittingScheme<bigcomplex> gurkan_br1() {
  return rknb_scheme(bigs({"0.54200976680171613", "-0.04060817665564392", "-0.87779698530109766", "0.86474236062251646",
                           "0.51165303453250898"}),
                     bigs({"0.24566294009066009", "1.1433587581365421", "-1.3796706973507000", "-0.019611260781217307",
                           "0.87087215441178844", "0.13938810549292669"}));
}
inline SplittingScheme<bigcomplex> gurkan_br2() {
  return rknb_scheme(bigs({"0.42637413177222316", "-0.82438794434938248", "-0.63140077574154094", "0.38590710518893978",
                           "1.6435074831297605"}),
                     bigs({"0.15102308452230116", "0.72768821316253478", "-0.26217627934521390",
                           "-0.044211509719803855", "0.23596222045571453", "0.19171427092446728"}));
}
inline SplittingScheme<bigcomplex> gurkan_br3() {
  return rknb_scheme(bigs({"1.0413749845202060", "-0.61784769849171965", "0.62570540985789957", "-0.63446409452971410",
                           "0.58523139864332822"}),
                     bigs({"0.12696076271851077", "-1.4166626058695677", "-0.62172666654176438", "0.69301448863793809",
                           "1.2079876026916669", "1.0104264183632164"}));
}

// ---- Table 4.2: complex skew-symmetric fifth-order methods -----------------------------------------

/// RKNA with printed alpha_1..3, beta_1..2: alpha = (a1, a2, a3, conj a3, conj a2, conj a1),
/// beta = (b1, b2, 1 - 2 Re(b1 + b2), conj b2, conj b1).
inline SplittingScheme<bigcomplex> gurkan_ac(const std::vector<bigcomplex>& a, const std::vector<bigcomplex>& b) {
  return rkna_scheme(skew_palindrome(a), skew_palindrome(b, skew_middle(b, 1)));
}
/// RKNB with printed beta_1..3, alpha_1..2: beta = (b1, b2, b3, conj b3, conj b2, conj b1),
/// alpha = (a1, a2, 1 - 2 Re(a1 + a2), conj a2, conj a1).
inline SplittingScheme<bigcomplex> gurkan_bc(const std::vector<bigcomplex>& a, const std::vector<bigcomplex>& b) {
  return rknb_scheme(skew_palindrome(a, skew_middle(a, 1)), skew_palindrome(b));
}

inline SplittingScheme<bigcomplex> gurkan_ac1() {
  return gurkan_ac(detail::complex_list({{"0.087808410045663212", "0.028523844251341822"},
                                         {"0.17916539354193987", "-0.067857083007249973"},
                                         {"0.23302619641239692", "-0.097952003128893425"}}),
                   detail::complex_list({{"0.17526734338348050", "0.057642040076250593"},
                                         {"0.18488007701471166", "-0.19410647329733509"}}));
}
inline SplittingScheme<bigcomplex> gurkan_ac2() {
  return gurkan_ac(detail::complex_list({{"0.087634204536037057", "0.028807372065269351"},
                                         {"0.18007104463252914", "-0.068253589313355443"},
                                         {"0.23229475083143381", "-0.097060961378624794"}}),
                   detail::complex_list({{"0.17526840907207411", "0.057614744130538702"},
                                         {"0.18487368019298416", "-0.19412192275724959"}}));
}
inline SplittingScheme<bigcomplex> gurkan_bc1() {
  return gurkan_bc(detail::complex_list({{"0.15950063058390336", "-0.060127448366782494"},
                                         {"0.19085044206705213", "0.20369642527600502"}}),
                   detail::complex_list({{"0.093106790861751605", "-0.026812950639104607"},
                                         {"0.14578332225686154", "0.076033669531385746"},
                                         {"0.26110988688138685", "0.10851236434561279"}}));
}
inline SplittingScheme<bigcomplex> gurkan_bc2() {
  return gurkan_bc(detail::complex_list({{"0.26934942679787788", "-0.093675141997563700"},
                                         {"0.14580813747862993", "0.49930185549019606"}}),
                   detail::complex_list({{"0.10625796854753310", "-0.037213537431233983"},
                                         {"0.35767992721948460", "-0.022169204268009056"},
                                         {"0.036062104232982296", "0.057072185585748646"}}));
}

/// Eq (6.1): the six-stage skew-symmetric method optimized from AC1 (all coefficients printed).
inline SplittingScheme<bigcomplex> gurkan_ac1_6() {
  const auto a = detail::complex_list({{"0.101907705405177865", "0.130701756906677735"},
                                       {"0.218628781976265590", "0.0126440811480678494"},
                                       {"0.179463512618556560", "-0.148112326926992222"}});
  const auto b = detail::complex_list({{"0.0489489561074426954", "0.0669384556781967844"},
                                       {"0.166479171860817010", "0.0764027877516731402"},
                                       {"0.192297943665939275", "-0.0835834606213808479"}});
  return alternating(Flow::kick, skew_palindrome(b, bigc("0.184547856731601789")), skew_palindrome(a));
}

/// Chambers (2003): drift a1, kick b1, drift a2, kick b2, drift a3 with a1 = (1 + i/sqrt 3)/4,
/// a2 = 1/2, a3 = conj a1, b1 = 2 a1, b2 = conj b1 (Chambers' DKDKD form, upper signs).
inline SplittingScheme<bigcomplex> chambers2003() {
  const bigfloat s3 = boost::multiprecision::sqrt(bigfloat(3));
  const bigcomplex a1(big("1/4"), 1 / (4 * s3));
  const bigcomplex b1 = a1 * bigcomplex(bigfloat(2));
  return alternating(Flow::drift, skew_palindrome({a1}, bigcomplex(big("1/2"))), skew_palindrome({b1}));
}

inline std::vector<MethodDef> gurkan() {
  const std::string src = "Gurkan, Fifth order RKN methods with complex coefficients (2012)";
  std::vector<MethodDef> m;
  auto add = [&m](MethodInfo info, SplittingScheme<bigcomplex> (*f)()) {
    m.push_back({std::move(info), [f] { return MethodData{f()}; }});
  };
  const std::string rkna = "RKNA scheme, eq (3.6), drift first";
  const std::string rknb = "RKNB scheme, eq (3.7), kick first";
  add({.name = "AR1",
       .family = "splitting",
       .order = 5,
       .symmetric = false,
       .symplectic = true,
       .published_digits = 16,
       .source = src + ", Table 4.1",
       .description = "real fifth-order RKN splitting AR1, " + rkna,
       .aliases = {"RKNar1"}},
      gurkan_ar1);
  add({.name = "AR2",
       .family = "splitting",
       .order = 5,
       .symmetric = false,
       .symplectic = true,
       .published_digits = 16,
       .source = src + ", Table 4.1",
       .description = "real fifth-order RKN splitting AR2, " + rkna,
       .aliases = {"RKNar2"}},
      gurkan_ar2);
  add({.name = "BR1",
       .family = "splitting",
       .order = 5,
       .symmetric = false,
       .symplectic = true,
       .published_digits = 16,
       .source = src + ", Table 4.1",
       .description = "real fifth-order RKN splitting BR1, " + rknb,
       .aliases = {"RKNbr1"}},
      gurkan_br1);
  add({.name = "BR2",
       .family = "splitting",
       .order = 5,
       .symmetric = false,
       .symplectic = true,
       .published_digits = 16,
       .source = src + ", Table 4.1",
       .description = "real fifth-order RKN splitting BR2, " + rknb,
       .aliases = {"RKNbr2"}},
      gurkan_br2);
  add({.name = "BR3",
       .family = "splitting",
       .order = 5,
       .symmetric = false,
       .symplectic = true,
       .published_digits = 16,
       .source = src + ", Table 4.1",
       .description = "real fifth-order RKN splitting BR3, " + rknb,
       .aliases = {"RKNbr3"}},
      gurkan_br3);
  const std::string cx = " (complex, skew-symmetric; missing coefficients from skew-symmetry and sum = 1)";
  add({.name = "AC1",
       .family = "splitting",
       .order = 5,
       .symmetric = false,
       .symplectic = true,
       .published_digits = 16,
       .source = src + ", Table 4.2",
       .description = "complex fifth-order RKN splitting AC1, " + rkna + cx,
       .aliases = {"RKNac1"}},
      gurkan_ac1);
  add({.name = "AC2",
       .family = "splitting",
       .order = 5,
       .symmetric = false,
       .symplectic = true,
       .published_digits = 16,
       .source = src + ", Table 4.2",
       .description = "complex fifth-order RKN splitting AC2, " + rkna + cx,
       .aliases = {"RKNac2"}},
      gurkan_ac2);
  add({.name = "BC1",
       .family = "splitting",
       .order = 5,
       .symmetric = false,
       .symplectic = true,
       .published_digits = 16,
       .source = src + ", Table 4.2",
       .description = "complex fifth-order RKN splitting BC1, " + rknb + cx,
       .aliases = {"RKNbc1"}},
      gurkan_bc1);
  add({.name = "BC2",
       .family = "splitting",
       .order = 5,
       .symmetric = false,
       .symplectic = true,
       .published_digits = 16,
       .source = src + ", Table 4.2",
       .description = "complex fifth-order RKN splitting BC2, " + rknb + cx,
       .aliases = {"RKNbc2"}},
      gurkan_bc2);
  add({.name = "AC1-6",
       .family = "splitting",
       .order = 5,
       .symmetric = false,
       .symplectic = true,
       .published_digits = 16,
       .source = src + ", eq (6.1)",
       .description = "complex six-stage fifth-order RKN splitting optimized from AC1, kick first (skew-symmetric)",
       .aliases = {"RKNac1-6"}},
      gurkan_ac1_6);
  add({.name = "Chambers",
       .family = "splitting",
       .order = 3,
       .symmetric = false,
       .symplectic = true,
       .source = "Chambers, Astron. J. 126 (2003) 1119",
       .description = "Chambers' complex third-order splitting, drift first",
       .aliases = {"chambers3"}},
      chambers2003);
  return m;
}

}  // namespace nystrom::methods
