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

// GBS:SEQUENCE:COLUMNS: the sequence and the number of columns its name gives (order twice the columns, from 3 to
// 20 columns); a columns field that is empty, not a number, too long or out of range is refused with one line.
TEST(CatalogSpecs, GbsWithItsSequenceAndColumns) {
  const MethodDef d8 = resolve_solve_method("GBS:harmonic:8");
  EXPECT_EQ(d8.info.order, 16);
  EXPECT_EQ(std::get<GbsDef>(d8.build()).max_columns, 8);
  EXPECT_EQ(std::get<GbsDef>(d8.build()).sequence, GbsSequence::harmonic);
  const MethodDef b20 = resolve_solve_method("gbs:Bulirsch:20");
  EXPECT_EQ(b20.info.order, 40);
  EXPECT_EQ(std::get<GbsDef>(b20.build()).sequence, GbsSequence::bulirsch);
  EXPECT_EQ(resolve_solve_method("GBS:romberg:3").info.order, 6);
  EXPECT_EQ(resolve_solve_method("GBS:romberg").info.order, resolve_solve_method("GBS").info.order);
  for (const std::string spec : {"GBS:harmonic:", "GBS:harmonic:x", "GBS:harmonic:1e1", "GBS:harmonic:-8",
                                 "GBS:harmonic:123", "GBS:harmonic:2", "GBS:harmonic:21", "GBS:fibonacci:8"}) {
    try {
      (void)resolve_solve_method(spec);
      ADD_FAILURE() << spec << " was accepted";
    } catch (const invalid_input& e) {
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
      EXPECT_NE(std::string(e.what()).find("GBS:SEQUENCE:COLUMNS"), std::string::npos) << e.what();
    }
  }
}
