// The law of a Langevin splitting on a phase-space grid (stochastic/splitting_law.hpp): the harmonic oscillator's
// closed-form stationary variances of BAOAB and OBABO and of OBABO's extrapolation; in the double well, the
// Boltzmann averages against Simpson's rule and the observed weak orders 2, 4 and 6 of BAOAB and its two- and
// three-term extrapolations; refusals.
#include <gtest/gtest.h>

#include <cmath>
#include <span>
#include <string>
#include <vector>

#include "nystrom/stochastic/potentials.hpp"
#include "nystrom/stochastic/splitting_law.hpp"
#include "support/double_well.hpp"

namespace st = nystrom::stochastic;

namespace {

std::size_t index_of(const st::StationaryLawResult& r, const std::string& name) {
  for (std::size_t j = 0; j < r.observable_names.size(); ++j)
    if (r.observable_names[j] == name) return j;
  throw std::runtime_error("no observable " + name);
}

std::string refusal(const auto& problem, const st::StationaryLawOptions& o) {
  try {
    (void)st::stationary_law(problem, o);
  } catch (const nystrom::error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

// Harmonic oscillator at h w = 1 (far from the continuum): BAOAB samples q exactly, <q^2> = kT / w^2, with
// <v^2> = kT (1 - h^2 w^2 / 4); OBABO samples v exactly, <q^2> = kT / (w^2 (1 - h^2 w^2 / 4)) (Leimkuhler and
// Matthews, AMRX 2013; the stationary Lyapunov equation of the linear map). OBABO's extrapolation with 1,2,3 is
// the combination of the closed forms at h / k_i.
TEST(SplittingLaw, HarmonicStationaryVariancesAreTheClosedForms) {
  const double w = 1, kT = 1, h = 1, x = h * h * w * w / 4;
  const auto p = st::builtin_problem_1d("harmonic", 1, kT, 10, 1, 0, w);
  st::StationaryLawOptions o;
  o.h = h;
  const auto b = st::stationary_law(p, o);
  const std::size_t q2 = index_of(b, "q2"), v2 = index_of(b, "v2"), q = index_of(b, "q");
  EXPECT_NEAR(b.members[0][q2], kT / (w * w), 1e-11);
  EXPECT_NEAR(b.members[0][v2], kT * (1 - x), 1e-11);
  EXPECT_NEAR(b.members[0][q], 0, 1e-12);
  EXPECT_NEAR(b.boltzmann[q2], kT / (w * w), 1e-12);
  EXPECT_NEAR(b.boltzmann[v2], kT, 1e-12);
  EXPECT_LT(b.resolution, 1e-8);
  EXPECT_LT(b.edge, 1e-12);
  o.method = "OBABO";
  o.extrapolate = {1, 2, 3};
  std::vector<std::size_t> reported;  // progress: once per member, with the number done
  o.progress = [&](std::size_t done, std::size_t total) {
    reported.push_back(done);
    EXPECT_EQ(total, 3u);
  };
  const auto ob = st::stationary_law(p, o);
  EXPECT_EQ(reported, (std::vector<std::size_t>{1, 2, 3}));
  const auto c = test_support::chin_coefficients({1, 2, 3});
  double predicted = 0;
  for (std::size_t i = 0; i < 3; ++i) {
    const double hi = h / static_cast<double>(i + 1), xi = hi * hi * w * w / 4;
    EXPECT_NEAR(ob.members[i][q2], kT / (w * w * (1 - xi)), 1e-11) << "OBABO at h / " << i + 1;
    EXPECT_NEAR(ob.members[i][v2], kT, 1e-11) << "OBABO at h / " << i + 1;
    EXPECT_NEAR(ob.coefficients[i], c[i], 1e-14);
    predicted += c[i] * kT / (w * w * (1 - xi));
  }
  EXPECT_NEAR(ob.averages[q2], predicted, 1e-11);
  EXPECT_GT(std::abs(ob.averages[q2] - kT), 1e-4);  // 6.4e-4: the combination's own bias, resolved
  EXPECT_EQ(ob.order, 6);
}

// Double well U = (q^2 - 1)^2, kT = 0.5, gamma = 1: the stationary biases of <q^2> and <q^4> against Simpson's rule
// for the Boltzmann density, for BAOAB and its extrapolations 1,2 and 1,2,3, at h = 0.2 and 0.1. Observed orders
// from the two steps: 2 (BAOAB), at least 4 and at least 6 (measured: BAOAB 2.01, 1.93; 1,2 6.8 on <q^2>, whose h^4
// term is small, and 4.4 on <q^4>; 1,2,3 6.8 and 6.4).
TEST(SplittingLaw, DoubleWellWeakOrdersTwoFourAndSix) {
  const double kT = 0.5;
  const auto [m2, m4] = test_support::double_well_moments(kT);
  const auto p = st::builtin_problem_1d("double-well", 1, kT, 10);
  std::vector<st::StationaryLawResult> runs;
  for (const double h : {0.2, 0.1}) {
    st::StationaryLawOptions o;
    o.h = h;
    o.extrapolate = {1, 2, 3};
    runs.push_back(st::stationary_law(p, o));
  }
  const std::size_t q2 = index_of(runs[0], "q2"), q4 = index_of(runs[0], "q4");
  EXPECT_NEAR(runs[0].boltzmann[q2], m2, 1e-13);
  EXPECT_NEAR(runs[0].boltzmann[q4], m4, 1e-13);
  for (const auto& [j, exact, what] : {std::tuple{q2, m2, "<q^2>"}, std::tuple{q4, m4, "<q^4>"}}) {
    double bias[3][2];
    for (int n = 1; n <= 3; ++n) {
      std::vector<double> k;
      for (int i = 1; i <= n; ++i) k.push_back(i);
      const auto c = test_support::chin_coefficients(k);
      for (int s = 0; s < 2; ++s) {
        double a = 0;
        for (int i = 0; i < n; ++i)
          a += c[static_cast<std::size_t>(i)] * runs[static_cast<std::size_t>(s)].members[i][j];
        bias[n - 1][s] = a - exact;
      }
      const double order = std::log2(std::abs(bias[n - 1][0] / bias[n - 1][1]));
      if (n == 1) {
        EXPECT_NEAR(order, 2, 0.1) << what;
      } else {
        EXPECT_GT(order, 2 * n - 0.2) << what << " with " << n << " terms: bias " << bias[n - 1][0] << " at 0.2, "
                                      << bias[n - 1][1] << " at 0.1";
      }
    }
    EXPECT_NEAR(runs[1].averages[j] - exact, bias[2][1], 1e-15) << what;  // the result's own combination
    EXPECT_LT(std::abs(bias[2][1]), 1e-8) << what;
    EXPECT_GT(std::abs(bias[0][1]), 1e-4) << what;  // BAOAB's bias at 0.1: 2e-4
  }
}

TEST(SplittingLaw, BadInputIsRefusedWithOneLine) {
  const auto p = st::builtin_problem_1d("double-well", 1, 0.5, 10);
  st::StationaryLawOptions o;
  const auto expect_refusal = [&](const auto& problem, const st::StationaryLawOptions& opt, const std::string& part) {
    const std::string what = refusal(problem, opt);
    EXPECT_NE(what.find(part), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  };
  o.method = "BAXAB";
  expect_refusal(p, o, "'X' is not A");
  o.method = "BAO";
  o.extrapolate = {1, 2};
  expect_refusal(p, o, "symmetric");
  o = {};
  o.extrapolate = {1, 1};
  expect_refusal(p, o, "duplicate");
  o = {};
  o.grid.nq = 64;
  expect_refusal(p, o, "odd");
  o = {};
  o.h = 0.35;  // near BAOAB's stability bound on the quartic wall: the density leaves the default grid
  expect_refusal(p, o, "grid");
  o = {};
  auto cold = p;
  cold.gamma = 0;
  expect_refusal(cold, o, "friction");
  auto frozen = p;
  frozen.kT = 0;
  expect_refusal(frozen, o, "temperature");
  auto two = p;
  two.q0 = {1, 0};
  two.v0 = {0, 0};
  expect_refusal(two, o, "one degree of freedom");
  auto free = st::builtin_problem_1d("harmonic", 1, 1, 10, 1, 0, 1);
  free.acceleration.omega2 = 0;
  expect_refusal(free, o, "does not confine");
}
