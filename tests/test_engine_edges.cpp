// The documented thresholds of the engines, on both sides of each: the rounding amplification at which a
// multi-product expansion is refused for a scalar type, and the sliver below which GBS ends its span in one step.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include "nystrom/engines/gbs.hpp"
#include "nystrom/engines/integrator.hpp"

using namespace nystrom;

namespace {

// Coefficients {A, 1 - A} (sum 1) of amplification |A| + |1 - A| = 2 A - 1 = S.
MpeCoefficients with_amplification(long S) {
  MpeCoefficients m;
  m.k = {1, 2};
  m.c = {mpq_class(S + 1, 2), mpq_class(1 - S, 2)};
  return m;
}

}  // namespace

TEST(EngineEdges, MpeIsRefusedWhenItsAmplificationReachesTheSquareRootOfTheTypesEpsilon) {
  // Refused when amp eps > sqrt(eps), eps = 2^(1 - bits): log2(amp) > (bits - 1) / 2 = 26 for double (53 bits),
  // 31.5 for long double (64 bits). Just below and just above, by a quarter of a bit.
  const long below_d = std::lround(std::exp2(25.75)), above_d = std::lround(std::exp2(26.25));
  EXPECT_NO_THROW(mpe_coefficients_as<double>(with_amplification(below_d)));
  EXPECT_THROW(mpe_coefficients_as<double>(with_amplification(above_d)), std::invalid_argument);
  const long below_ld = std::lround(std::exp2(31.25)), above_ld = std::lround(std::exp2(31.75));
  EXPECT_NO_THROW(mpe_coefficients_as<long double>(with_amplification(below_ld)));
  EXPECT_THROW(mpe_coefficients_as<long double>(with_amplification(above_ld)), std::invalid_argument);
  // The message names the order and the type.
  try {
    mpe_coefficients_as<double>(with_amplification(above_d));
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("MPE order 4"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("double"), std::string::npos) << e.what();
  }
}

TEST(EngineEdges, GbsTakesTheRestOfItsSpanInOneStepOnlyWithinOneMillionth) {
  // q'' = -q over a span of 1 with a first step of 1 - x: within x <= 1e-6 of the span (relative) the step is
  // stretched to end it (one step); a larger rest is a step of its own (two steps).
  using V = std::array<double, 1>;
  auto force = [](const V& q, V& a) { a[0] = -q[0]; };
  for (double x : {0.5e-6, 1.5e-6, 1e-3}) {
    SCOPED_TRACE(x);
    GbsOptions o;
    o.rtol = o.atol = 1e-6;
    o.initial_step = 1 - x;
    GbsIntegrator<V, decltype(force)> g(force, o);
    State<V> s{{1.0}, {0.0}};
    g.integrate_to(s, 1.0);
    EXPECT_EQ(g.rejected(), 0);
    EXPECT_EQ(g.steps(), x <= 1e-6 ? 1 : 2);
    EXPECT_NEAR(s.q[0], std::cos(1.0), 1e-5);
    EXPECT_NEAR(s.v[0], -std::sin(1.0), 1e-5);
  }
}
