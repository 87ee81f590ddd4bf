// The documented thresholds of the engines, on both sides of each: the rounding amplification at which a
// multi-product expansion is refused for a scalar type, the sliver below which GBS ends its span in one step, the
// bounds of an MPFR precision; the energy of a planetary system on a case computed by hand.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "nystrom/core/extended.hpp"
#include "nystrom/engines/gbs.hpp"
#include "nystrom/engines/integrator.hpp"
#include "nystrom/planetary/democratic.hpp"
#include "nystrom/planetary/system.hpp"
#include "nystrom/planetary/wisdom_holman.hpp"

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
  // At the threshold itself half of the digits are lost, not more: accepted (double: amp = 2^26; float128, 113 bits:
  // 2^56), and refused just above it.
  EXPECT_NO_THROW(mpe_coefficients_as<double>(with_amplification(1L << 26)));
  EXPECT_THROW(mpe_coefficients_as<double>(with_amplification((1L << 26) + 1)), std::invalid_argument);
  EXPECT_NO_THROW(mpe_coefficients_as<float128>(with_amplification(1L << 56)));
  EXPECT_THROW(mpe_coefficients_as<float128>(with_amplification((1L << 56) + (1L << 8))), std::invalid_argument);
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

TEST(EngineEdges, MpfrPrecisionIsAcceptedUpToItsBoundsInclusive) {
  EXPECT_EQ(parse_mpfr_bits(std::to_string(MpfrPrecision::min_bits)), MpfrPrecision::min_bits);
  EXPECT_EQ(parse_mpfr_bits(std::to_string(MpfrPrecision::max_bits)), MpfrPrecision::max_bits);
  EXPECT_THROW(parse_mpfr_bits(std::to_string(MpfrPrecision::min_bits - 1)), std::invalid_argument);
  EXPECT_THROW(parse_mpfr_bits(std::to_string(MpfrPrecision::max_bits + 1)), std::invalid_argument);
}

TEST(EngineEdges, PlanetaryEnergyOfTwoBodiesIsTheAnalyticOne) {
  // E = m1 |v1|^2 / 2 + m2 |v2|^2 / 2 - G m1 m2 / r: G = 2, m = (1, 0.5), r = |(1, 2, 2)| = 3,
  // |v1|^2 = 0.01 + 0.04, |v2|^2 = 0.09 + 0.09 + 0.16: E = 0.025 + 0.085 - 1/3.
  using planetary::Vec3;
  const std::vector<double> m = {1.0, 0.5};
  const std::vector<Vec3<double>> x = {{0.5, 0.5, 0.5}, {1.5, 2.5, 2.5}};
  const std::vector<Vec3<double>> v = {{0.0, 0.1, 0.2}, {0.3, -0.3, 0.4}};
  EXPECT_NEAR(planetary::energy(2.0, m, x, v), 0.025 + 0.085 - 1.0 / 3, 1e-15);
}

TEST(EngineEdges, WisdomHolmanMapsAreOfSecondOrder) {
  // The map, and the map with a symplectic corrector of any order n (error O(eps h^(n+1) + eps^2 h^2)), are of
  // order 2 in h (Wisdom, Holman & Touma 1996); both are symmetric and symplectic.
  for (const std::string m : {"WH", "WHC3", "WHC17"}) {
    SCOPED_TRACE(m);
    const auto fm = planetary::resolve_wh_method(m, 53, "double");
    EXPECT_EQ(fm.info.order, 2);
    EXPECT_TRUE(fm.info.symmetric);
    EXPECT_TRUE(fm.info.symplectic);
    EXPECT_EQ(fm.info.forces_per_step, 1);
  }
}

TEST(EngineEdges, DemocraticHeliocentricCoordinatesRoundTrip) {
  // The inertial positions and velocities come back from the democratic heliocentric state (to rounding), not
  // merely their differences: a uniform shift of every body would leave the dynamics unchanged.
  const auto sys = planetary::outer_solar_system<double>();
  const auto s = planetary::to_democratic(sys);
  std::vector<planetary::Vec3<double>> x, v;
  planetary::from_democratic(sys.mass, s, x, v);
  ASSERT_EQ(x.size(), sys.x.size());
  for (std::size_t i = 0; i < x.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(x[i][k], sys.x[i][k], 1e-13) << i << " " << k;
      EXPECT_NEAR(v[i][k], sys.v[i][k], 1e-15) << i << " " << k;
    }
}
