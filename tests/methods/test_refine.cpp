// Refinement of decimal coefficient tables to the working precision (methods/refine.hpp): Newton's
// method in MPFR on each method's own order conditions, from the published digits.
//
// The checks are independent of the refinement's own arithmetic: the refined scheme is converted
// with to_rkn_tableau and its order conditions evaluated by the plain (bigfloat / bigcomplex)
// order-condition code.
#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <vector>

#include "nystrom/analysis/rkn_order_conditions.hpp"
#include "nystrom/methods/catalog.hpp"
#include "nystrom/methods/refine.hpp"
#include "support/catalog.hpp"

using namespace nystrom;

namespace {

std::vector<MethodDef> decimal_splittings() {
  std::vector<MethodDef> out;
  for (const auto& d : catalog()) {
    if (d.info.published_digits == 0) continue;
    BigPrecision guard(128);
    if (std::holds_alternative<SplittingScheme<bigcomplex>>(d.build())) out.push_back(d);
  }
  return out;
}

/// max |residual| of the consistency and order conditions of a scheme, by the reference code.
bigfloat condition_defect(const SplittingScheme<bigcomplex>& s, int order) {
  bigcomplex drift(bigfloat(0)), kick(bigfloat(0));
  for (const auto& st : s.steps) (st.flow == Flow::drift ? drift : kick) += st.coef;
  const bigcomplex one(bigfloat(1));
  bigfloat m = std::max(rkn_abs(drift - one), rkn_abs(kick - one));
  return std::max(m, max_residual(to_rkn_tableau(s, 1e-6), order));
}

bigfloat max_change(const Refinement& r) {
  bigfloat m(0);
  for (std::size_t k = 0; k < r.refined.size(); ++k) m = std::max(m, bigfloat(abs(r.refined[k] - r.published[k])));
  return m;
}

/// Reversal symmetry of a scheme: +1 palindromic, -1 conjugate-palindromic, 0 neither (exactly).
int reversal_symmetry(const SplittingScheme<bigcomplex>& s) {
  const std::size_t m = s.steps.size();
  bool pal = true, skew = true;
  for (std::size_t k = 0; k < m; ++k) {
    const auto& a = s.steps[k];
    const auto& b = s.steps[m - 1 - k];
    pal = pal && a.flow == b.flow && a.coef == b.coef;
    skew = skew && a.flow == b.flow && a.coef == b.coef.conj();
  }
  return pal ? 1 : (skew ? -1 : 0);
}

}  // namespace

TEST(Refine, CatalogHasDecimalMethods) {
  std::vector<std::string> names;
  for (const auto& d : decimal_splittings()) names.push_back(d.info.name);
  // The decimal tables: Yoshida 6, Kahan-Li, Sofroniou-Spaletta, Blanes-Moan, Gürkan.
  for (const std::string n : {"Y6", "KL6", "KL8", "SS10", "RKNb6", "RKNa14", "AR1", "AC1", "BC1"})
    EXPECT_NE(std::find(names.begin(), names.end(), n), names.end()) << n;
}

TEST(Refine, WhenPublishedDigitsSuffice) {
  EXPECT_TRUE(published_digits_suffice(0, 100000));  // exact
  EXPECT_TRUE(published_digits_suffice(26, 53));
  EXPECT_TRUE(published_digits_suffice(26, 64));
  EXPECT_FALSE(published_digits_suffice(26, 105));
  EXPECT_FALSE(published_digits_suffice(26, 113));
  EXPECT_TRUE(published_digits_suffice(15, 53));  // 49.8 bits: within 16 ulps of double
  EXPECT_FALSE(published_digits_suffice(14, 53));
  EXPECT_FALSE(published_digits_suffice(16, 64));  // long double needs 19
  EXPECT_TRUE(published_digits_suffice(19, 64));
}

// Every decimal splitting of the catalog, refined at 256 bits: all order conditions (also those not
// used as Newton equations) hold to the precision, the structure (symmetry, skew-symmetry) is kept
// exactly, and the coefficients move by no more than the published rounding allows.
TEST(Refine, EveryDecimalSplittingRefinesTo256Bits) {
  const int bits = 256;
  for (const auto& d : decimal_splittings()) {
    SCOPED_TRACE(d.info.name);
    BigPrecision guard(bits);
    const auto published = normalized(std::get<SplittingScheme<bigcomplex>>(d.build()));
    const auto t0 = std::chrono::steady_clock::now();
    const Refinement r = refine_splitting(published, d.info.order, d.info.name);
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const bigfloat defect = condition_defect(r.scheme, d.info.order);
    EXPECT_LE(defect, ldexp(bigfloat(1), 32 - bits)) << "residual " << short_str(defect);
    EXPECT_LE(r.residual, ldexp(bigfloat(1), 32 - bits));
    EXPECT_EQ(reversal_symmetry(r.scheme), reversal_symmetry(published));
    EXPECT_EQ(r.scheme.steps.size(), published.steps.size());
    for (std::size_t k = 0; k < published.steps.size(); ++k) {
      EXPECT_EQ(r.scheme.steps[k].flow, published.steps[k].flow);
      EXPECT_EQ(r.scheme.steps[k].coef.is_real(), published.steps[k].coef.is_real()) << k;
    }
    if (d.info.family == "composition") {
      EXPECT_TRUE(r.composition);
    }
    // The change: a few units of the last published digit. One table is known to be less consistent
    // than its digits: Gürkan's eq (6.1) method (AC1-6), printed with 18 digits, satisfies its own
    // order conditions only to 7e-13 (already those of order 2); its bound follows that residual.
    const bigfloat change = max_change(r);
    const bigfloat unit = pow(bigfloat(10), -d.info.published_digits);
    if (r.published_residual > 1000 * unit) {
      EXPECT_EQ(d.info.name, "AC1-6") << "published table consistent only to " << short_str(r.published_residual)
                                      << ", declared " << d.info.published_digits << " digits";
      EXPECT_LE(change, 100 * r.published_residual) << "change " << short_str(change);
    } else {
      EXPECT_LE(change, 100 * unit) << "change " << short_str(change) << ", published unit " << short_str(unit);
    }
    EXPECT_GT(change, 0);  // the published digits were not already the solution
    std::printf(
        "  %-8s %2zu parameters, %3zu equations (%2zu independent), %d Newton steps, published residual %s, "
        "refined %s, largest change %s, %.2f s\n",
        d.info.name.c_str(), r.parameters.size(), r.equations, r.independent, r.iterations,
        short_str(r.published_residual).c_str(), short_str(r.residual).c_str(), short_str(change).c_str(), secs);
  }
}

// Far beyond quadruple precision: the same Newton iteration reaches 1200 bits.
TEST(Refine, ReachesVeryHighPrecision) {
  const auto def = resolve_method("KL8");
  BigPrecision guard(1200);
  const auto published = std::get<SplittingScheme<bigcomplex>>(def.build());
  const Refinement r = refine_splitting(published, 8, "KL8");
  EXPECT_LE(condition_defect(r.scheme, 8), ldexp(bigfloat(1), 32 - 1200));
  EXPECT_GT(condition_defect(published, 8), bigfloat("1e-30"));  // the published digits alone: ~1e-27
  EXPECT_LE(max_change(r), bigfloat("1e-24"));
}

// The same refined set whatever precision it was computed at, and whichever way it is reached (the
// solution in the affine space through the published point spanned by the selected gradients is
// well defined): chord steps only, Newton steps only, or the automatic mix.
TEST(Refine, SolutionIsIndependentOfPrecisionAndStrategy) {
  for (const std::string name : {"KL6", "AC1"}) {  // KL6 has a free parameter; AC1 is complex
    SCOPED_TRACE(name);
    const auto def = resolve_method(name);
    auto refined_at = [&](unsigned bits, RefineStrategy how) {
      BigPrecision guard(bits);
      return refine_splitting(std::get<SplittingScheme<bigcomplex>>(def.build()), def.info.order, name, how).refined;
    };
    const auto a = refined_at(256, RefineStrategy::automatic);
    const auto chord = refined_at(1000, RefineStrategy::chord);
    const auto newton = refined_at(1000, RefineStrategy::newton);
    BigPrecision guard(1000);
    ASSERT_EQ(a.size(), chord.size());
    for (std::size_t k = 0; k < a.size(); ++k) {
      EXPECT_LE(abs(a[k] - chord[k]), ldexp(bigfloat(1), 16 - 256)) << k;
      EXPECT_LE(abs(newton[k] - chord[k]), ldexp(bigfloat(1), 16 - 1000)) << k;
    }
  }
}

// method_data_for: published tables where their digits suffice, refined ones (cached) beyond.
TEST(Refine, MethodDataForUsesPublishedOrRefinedCoefficients) {
  const auto def = resolve_method("KL8");
  auto coef = [](const MethodData& d, std::size_t k) {
    return std::get<SplittingScheme<bigcomplex>>(d).steps.at(k).coef.re;
  };
  const MethodData dbl = method_data_for(def, 53, "double");
  const MethodData quad = method_data_for(def, 113, "float128");
  BigPrecision guard(256);
  const MethodData pub = def.build();
  EXPECT_TRUE(coef(dbl, 1) == coef(pub, 1));                        // 26 digits are plenty for double
  EXPECT_FALSE(coef(quad, 1) == coef(pub, 1));                      // float128 gets the refined set ...
  EXPECT_LE(abs(coef(quad, 1) - coef(pub, 1)), bigfloat("1e-25"));  // ... close to the published one
  EXPECT_LE(condition_defect(std::get<SplittingScheme<bigcomplex>>(quad), 8), ldexp(bigfloat(1), 32 - 256));
  const auto t0 = std::chrono::steady_clock::now();
  const MethodData again = method_data_for(def, 113, "float128");
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_TRUE(coef(again, 1) == coef(quad, 1));
  std::printf("  cached refinement returned in %.4f s\n", secs);
}

// A table far from any solution is not "refined" into something else: clear error.
TEST(Refine, TableThatMissesItsConditionsIsRefused) {
  MethodDef bad = resolve_method("KL8");
  auto build = bad.build;
  bad.info.name = "KL8-corrupted";
  bad.build = [build] {
    auto s = std::get<SplittingScheme<bigcomplex>>(build());
    s.steps[3].coef = s.steps[3].coef + bigcomplex(big("1e-5"));
    s.steps[s.steps.size() - 4].coef = s.steps[3].coef;
    return MethodData{s};
  };
  try {
    method_data_for(bad, 113, "float128");
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("KL8-corrupted"), std::string::npos) << msg;
    EXPECT_NE(msg.find("misses its order-8 conditions"), std::string::npos) << msg;
  }
}

// Decimal tables that are not splittings cannot be refined: asking for more precision than their
// digits is an error, not silently rounded coefficients.
TEST(Refine, DecimalRknTableauBeyondItsDigitsIsRefused) {
  const MethodDef n4 = test::decimal_n4();
  EXPECT_NO_THROW(method_data_for(n4, 53, "double"));
  try {
    method_data_for(n4, 113, "float128");
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("N4-decimal's coefficients are published with 16 digits, too few for float128 (113 bits)"),
              std::string::npos)
        << msg;
  }
}
