// Method specifications outside the catalog's table resolve to what their names say: M<2n> and M<2n>-adaptive
// (the natural sequence 1..n on position Verlet), mpe-pv: and mpe-vv: sequences, and adjoint: (the sub-steps in
// reverse order).
#include <gtest/gtest.h>

#include <string>
#include <variant>
#include <vector>

#include "nystrom/core/error.hpp"
#include "nystrom/methods/catalog.hpp"

using namespace nystrom;

namespace {

std::vector<long> natural(long n) {
  std::vector<long> k;
  for (long i = 1; i <= n; ++i) k.push_back(i);
  return k;
}

}  // namespace

TEST(CatalogSpecs, MultiProductExpansionsOfAnyEvenOrder) {
  BigPrecision guard(128);
  for (long order : {18L, 20L, 24L}) {
    for (const bool adaptive : {false, true}) {
      const std::string name = "M" + std::to_string(order) + (adaptive ? "-adaptive" : "");
      SCOPED_TRACE(name);
      const MethodDef d = resolve_method(name);
      EXPECT_EQ(d.info.name, name);
      EXPECT_EQ(d.info.order, order);
      EXPECT_EQ(d.info.adaptive, adaptive);
      const auto data = d.build();
      const auto* m = std::get_if<MpeDef>(&data);
      ASSERT_NE(m, nullptr);
      EXPECT_EQ(m->k, natural(order / 2));
      EXPECT_EQ(m->base_name, "PV");
    }
  }
  EXPECT_THROW(resolve_method("M19-adaptive"), invalid_input);
  EXPECT_THROW(resolve_method("M2-adaptive"), invalid_input);
}

TEST(CatalogSpecs, SequencesOnEitherBase) {
  BigPrecision guard(128);
  for (const std::string base : {"PV", "VV"}) {
    const std::string spec = "mpe-" + std::string(base == "PV" ? "pv" : "vv") + ":1,3,4";
    SCOPED_TRACE(spec);
    const MethodDef d = resolve_method(spec);
    EXPECT_EQ(d.info.order, 6);
    const auto data = d.build();
    const auto* m = std::get_if<MpeDef>(&data);
    ASSERT_NE(m, nullptr);
    EXPECT_EQ(m->k, (std::vector<long>{1, 3, 4}));
    EXPECT_EQ(m->base_name, base);
  }
}

TEST(CatalogSpecs, AdjointReversesTheSubSteps) {
  BigPrecision guard(128);
  for (const std::string base : {"AR1", "BR2", "FR"}) {
    SCOPED_TRACE(base);
    const MethodDef b = resolve_method(base), a = resolve_method("adjoint:" + base);
    EXPECT_EQ(a.info.name, "adjoint:" + base);
    EXPECT_EQ(a.info.order, b.info.order);
    const auto sb = std::get<SplittingScheme<bigcomplex>>(b.build());
    const auto sa = std::get<SplittingScheme<bigcomplex>>(a.build());
    ASSERT_EQ(sa.steps.size(), sb.steps.size());
    const std::size_t m = sb.steps.size();
    for (std::size_t i = 0; i < m; ++i) {
      EXPECT_EQ(sa.steps[i].flow, sb.steps[m - 1 - i].flow) << i;
      EXPECT_TRUE(sa.steps[i].coef == sb.steps[m - 1 - i].coef) << i;
    }
    // The adjoint of the adjoint is the method.
    EXPECT_EQ(resolve_method("adjoint:adjoint:" + base).info.name, b.info.name);
  }
}
