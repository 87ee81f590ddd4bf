// The order-condition search (src/experiments/discover.hpp):
//   * the fifth-order conditions (2.4) of the Gürkan paper vanish on its published methods and agree with the
//     BCH analysis;
//   * a small seeded random-start search rediscovers AR1 and AC1 (polished to 30+ digits, classified);
//   * the eq (6.1) optimisation: the published six-stage method is not a stationary point of its error norm;
//     from it, and from AC1, the optimiser reaches a six-stage method below the published 2.6e-7.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <string>
#include <vector>

#include "experiments/discover.hpp"
#include "nystrom/methods/catalog.hpp"

using namespace nystrom;
using namespace nystrom::analysis;

namespace {

std::vector<cd> coefficients_of(const std::string& name) {
  BigPrecision guard(128);
  return scheme_coefficients(std::get<SplittingScheme<bigcomplex>>(resolve_method(name).build()));
}
std::vector<bigcomplex> big_coefficients_of(const std::string& name) {
  const MethodData data = resolve_method(name).build();
  std::vector<bigcomplex> v;
  for (const auto& s : std::get<SplittingScheme<bigcomplex>>(data).steps) v.push_back(s.coef);
  return v;
}
double max_residual(RknForm form, const std::vector<cd>& sub) {
  const auto f = rkn5_conditions(form, rkn_unknowns_from(form, sub));
  double m = 0;
  for (const auto& z : f) m = std::max(m, std::abs(z));
  return m;
}

}  // namespace

TEST(Discover, ConditionsVanishOnThePublishedMethods) {
  for (const char* n : {"AR1", "AR2", "AC1", "AC2"})
    EXPECT_LT(max_residual(RknForm::A, coefficients_of(n)), 1e-15) << n;
  for (const char* n : {"BR1", "BR2", "BR3", "BC1", "BC2"})
    EXPECT_LT(max_residual(RknForm::B, coefficients_of(n)), 1e-15) << n;
  // controls: a perturbed coefficient, and the other scheme's reading of the same numbers
  auto ar1 = coefficients_of("AR1");
  ar1[3] += 1e-6;
  ar1[5] -= 1e-6;  // keep the kick sum
  EXPECT_GT(max_residual(RknForm::A, ar1), 1e-8);
  EXPECT_GT(max_residual(RknForm::B, coefficients_of("AR1")), 1e-3);
  // the unknowns round-trip through the sub-steps
  const auto x = rkn_unknowns_from(RknForm::B, coefficients_of("BR2"));
  EXPECT_LT(max_distance(rkn_substeps(RknForm::B, x), coefficients_of("BR2")), 1e-15);
}

TEST(Discover, ConditionsAgreeWithTheBchOrder) {
  // Order 5 by (2.4) <=> degrees 1..5 of the RKN Lie algebra vanish: a perturbed method fails both.
  BigPrecision guard(128);
  auto s = std::get<SplittingScheme<bigcomplex>>(resolve_method("BR1").build());
  AnalysisOptions opt;
  opt.degree = 6;
  EXPECT_EQ(analyze_scheme(s, opt, 16).order, 5);
  s.steps[2].coef = s.steps[2].coef + bigcomplex(bigfloat("1e-5"));
  s.steps[4].coef = s.steps[4].coef - bigcomplex(bigfloat("1e-5"));
  std::vector<cd> v;
  for (const auto& st : s.steps) v.push_back(to_cd(st.coef));
  EXPECT_GT(max_residual(RknForm::B, v), 1e-7);
  EXPECT_LT(analyze_scheme(s, opt, 16).order, 5);
}

TEST(Discover, SymmetriesAndStartsAreWellDefined) {
  const auto ar1 = coefficients_of("AR1");
  EXPECT_TRUE(same_up_to_symmetry(ar1, reversed(ar1), 1e-15));
  const auto ac1 = coefficients_of("AC1");
  EXPECT_TRUE(same_up_to_symmetry(ac1, conjugated(ac1), 1e-15));
  EXPECT_FALSE(same_up_to_symmetry(ac1, coefficients_of("AC2"), 1e-6));
  EXPECT_EQ(canonical_variant(ac1), canonical_variant(reversed(ac1)));
  // AC1 is skew-symmetric: reversing gives the conjugate (Table 4.2 caption)
  EXPECT_LT(max_distance(reversed(ac1), conjugated(ac1)), 1e-15);
  // the starts are reproducible and fill the box
  const auto a = random_start(7, 3, 2.0), b = random_start(7, 3, 2.0), c = random_start(7, 4, 2.0);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
  for (const auto& z : c) {
    EXPECT_LE(std::abs(z.real()), 2.0);
    EXPECT_LE(std::abs(z.imag()), 2.0);
  }
}

TEST(Discover, LocalSolversConvergeToANearbyMethod) {
  // AR1 is a well-conditioned root; AC1 has a close neighbour (AC2 differs by ~1e-3), so its basin is small.
  struct Case {
    std::string name;
    double shift, tol;
  };
  for (const auto& c : {Case{"AR1", 1e-2, 1e-10}, Case{"AC1", 1e-5, 1e-8}}) {
    auto x = rkn_unknowns_from(RknForm::A, coefficients_of(c.name));
    for (std::size_t k = 0; k < x.size(); ++k) x[k] += c.shift * cd((k % 3) - 1.0, (k % 2) - 0.5);
    for (auto solver : {Solver::newton, Solver::lm}) {
      const auto r = solve_rkn_conditions(RknForm::A, x, solver, 500);
      ASSERT_TRUE(r.converged) << c.name << (solver == Solver::lm ? " lm" : " newton");
      EXPECT_LT(r.residual, 1e-12);
      EXPECT_LT(max_distance(rkn_substeps(RknForm::A, r.x), coefficients_of(c.name)), c.tol)
          << c.name << (solver == Solver::lm ? " lm" : " newton");
    }
  }
}

TEST(Discover, SmallSeededSearchFindsAR1AndAC1) {
  DiscoverOptions opt;
  opt.form = RknForm::A;
  opt.starts = 250;
  opt.seed = 2;
  opt.threads = 2;
  opt.polish_bits = 192;
  const auto rep = discover(opt);
  EXPECT_GT(rep.converged, opt.starts / 2);
  const DiscoveredMethod* ar1 = nullptr;
  const DiscoveredMethod* ac1 = nullptr;
  for (const auto& m : rep.methods) {
    if (same_up_to_symmetry(m.coefficients_d, coefficients_of("AR1"), 1e-12)) ar1 = &m;
    if (same_up_to_symmetry(m.coefficients_d, coefficients_of("AC1"), 1e-12)) ac1 = &m;
    EXPECT_LT(m.residual, 1e-40);
    EXPECT_GE(m.digits, 30);
  }
  // duplicates, adjoints (reversal) and conjugates are merged: no two listed methods are the same
  for (std::size_t i = 0; i < rep.methods.size(); ++i)
    for (std::size_t j = i + 1; j < rep.methods.size(); ++j)
      EXPECT_FALSE(same_up_to_symmetry(rep.methods[i].coefficients_d, rep.methods[j].coefficients_d, 1e-8))
          << i << " " << j;
  long hits = 0;
  for (const auto& m : rep.methods) hits += m.hits;
  EXPECT_LE(hits, rep.converged);
  EXPECT_GT(hits, rep.converged / 2);
  ASSERT_NE(ar1, nullptr) << "AR1 not found among " << rep.methods.size() << " methods";
  ASSERT_NE(ac1, nullptr) << "AC1 not found among " << rep.methods.size() << " methods";
  EXPECT_EQ(ar1->cls, MethodClass::real);
  EXPECT_FALSE(ar1->positive);
  EXPECT_EQ(ac1->cls, MethodClass::imaginary);
  EXPECT_TRUE(ac1->positive);
  EXPECT_TRUE(ac1->skew_symmetric);
  EXPECT_NEAR(ac1->error_norm, 1.02e-5, 0.005e-5);  // Table 4.3
  EXPECT_NEAR(ar1->error_norm, 6.44e-3, 0.005e-3);
  // the polished AC1 agrees with the 17 published digits (to their rounding)
  EXPECT_TRUE(same_up_to_symmetry(ac1->coefficients_d, coefficients_of("AC1"), 2e-16));
  // every method found has order 5 by the BCH analysis, independently of (2.4)
  BigPrecision guard(192);
  AnalysisOptions ao;
  ao.degree = 6;
  for (const auto& m : rep.methods) EXPECT_EQ(analyze_scheme(m.scheme(), ao).order, 5);
  // classes are sorted REAL, IMAGINARY, OTHER
  for (std::size_t i = 1; i < rep.methods.size(); ++i)
    EXPECT_LE(static_cast<int>(rep.methods[i - 1].cls), static_cast<int>(rep.methods[i].cls));
}

TEST(Discover, PublishedSixStageMethodIsNotStationaryAndImproves) {
  // Eq (6.1) prints a method with norm 2.6e-7. Our objective is that norm; from the published coefficients the
  // reduced Newton iteration descends to a nearby local minimum with a smaller norm, of order 5, skew-symmetric,
  // with positive real parts.
  std::vector<bigcomplex> paper;
  {
    BigPrecision guard(256);
    paper = big_coefficients_of("AC1-6");
  }
  SkewSearchOptions opt;
  const auto res = optimize_skew(paper, Flow::kick, opt);
  ASSERT_FALSE(res.minima.empty());
  const auto& m = res.minima.front();
  EXPECT_NEAR(m.start_error_norm, 2.6e-7, 0.05e-7);
  EXPECT_LT(m.error_norm, 0.5 * m.start_error_norm);
  EXPECT_LT(m.constraint_residual, 1e-13);
  EXPECT_LT(max_distance(scheme_coefficients(m.scheme()), coefficients_of("AC1-6")), 0.03);
  const auto v = scheme_coefficients(m.scheme());
  EXPECT_LT(max_distance(reversed(v), conjugated(v)), 1e-15);
  for (const auto& z : v) EXPECT_GT(z.real(), 0);
}

TEST(Discover, SixStageSearchFromAC1ReachesThePublishedLevel) {
  // Eq (6.1): AC1 embedded with zero first and last kicks; the start itself descends to a different local
  // minimum (a few 1e-6), random moves along the constraint manifold (seeded) reach the basin of the published
  // method, whose minimum is below 2.6e-7.
  std::vector<bigcomplex> start;
  {
    BigPrecision guard(256);
    start = embed_rkna_in_kick_first(std::get<SplittingScheme<bigcomplex>>(resolve_method("AC1").build()));
  }
  ASSERT_EQ(start.size(), 13u);
  SkewSearchOptions opt;
  opt.tries = 6;
  opt.seed = 5;
  opt.threads = 2;
  opt.polish_bits = 160;  // the best minimum continued in MPFR (as `nystrom discover --six-stage` does by default)
  const auto res = optimize_skew(start, Flow::kick, opt);
  ASSERT_FALSE(res.minima.empty());
  EXPECT_NEAR(res.minima.front().start_error_norm, 1.02e-5, 0.005e-5);  // AC1, Table 4.3
  EXPECT_LT(res.minima.front().error_norm, 2.6e-7);
  EXPECT_LT(res.minima.front().constraint_residual, 1e-40);  // polished: the order conditions to 160 bits
  EXPECT_GE(res.minima.size(), 2u);                          // the landscape has several local minima
  // The best minimum lies in the basin of the published method (measured: 1.6e-2 apart in the coefficients) with a
  // norm of the published size or below (measured 3.6e-8: the printed method is not the bottom of its basin, see
  // PublishedSixStageMethodIsNotStationaryAndImproves); far below would mean a broken objective.
  const auto& best = res.minima.front();
  EXPECT_GT(best.error_norm, 1e-8);
  EXPECT_LT(max_distance(scheme_coefficients(best.scheme()), coefficients_of("AC1-6")), 0.03);
  // independently of the optimiser's own bookkeeping: the BCH analysis of the result
  BigPrecision guard(160);
  AnalysisOptions ao;
  ao.degree = 6;
  ao.tolerance = 1e-35;  // the coefficients carry 160 bits
  const auto a = analyze_scheme(best.scheme(), ao);
  EXPECT_EQ(a.order, 5);
  EXPECT_NEAR(a.degrees[5].norm, best.error_norm, 1e-3 * best.error_norm);
  for (const auto& t : a.degrees[5].terms) EXPECT_LT(std::abs(t.value.real()), 1e-20) << t.name;  // skew: imaginary
  const auto v = scheme_coefficients(best.scheme());
  ASSERT_EQ(v.size(), 13u);
  EXPECT_LT(max_distance(reversed(v), conjugated(v)), 1e-15);
  for (const auto& z : v) EXPECT_GT(z.real(), 0);
}

TEST(Discover, RejectsBadInput) {
  DiscoverOptions opt;
  opt.starts = 0;
  EXPECT_THROW(discover(opt), std::invalid_argument);
  opt.starts = 10;
  opt.box = -1;
  EXPECT_THROW(discover(opt), std::invalid_argument);
  opt.box = 2;
  opt.threads = 0;
  EXPECT_THROW(discover(opt), std::invalid_argument);
  EXPECT_THROW(parse_rkn_form("C"), std::invalid_argument);
  EXPECT_THROW(parse_solver("bfgs"), std::invalid_argument);
  std::vector<bigcomplex> start(13);
  SkewSearchOptions so;
  so.order = 4;
  EXPECT_THROW(optimize_skew(start, Flow::kick, so), std::invalid_argument);
  so.order = 5;
  EXPECT_THROW(optimize_skew(std::vector<bigcomplex>(12), Flow::kick, so), std::invalid_argument);
  EXPECT_THROW(optimize_skew(start, Flow::kick, so), std::invalid_argument);  // all zero: no method of order 5 near
  EXPECT_THROW(embed_rkna_in_kick_first(std::get<SplittingScheme<bigcomplex>>(resolve_method("VV").build())),
               std::invalid_argument);
}
