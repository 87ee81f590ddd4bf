// Dense output of solve(): sol(t) between step ends keeps the method's accuracy (a partial step of the
// method from the step end before t), for every catalog method, the adaptive engines and GBS.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "nystrom/problems/kepler.hpp"
#include "nystrom/solve/solve.hpp"
#include "support/kepler.hpp"

using namespace nystrom;
using nystrom::test::kepler;
using nystrom::test::pos_err;
using nystrom::test::V2;

namespace {

constexpr double pi = std::numbers::pi;

struct Errors {
  double ends = 0, inside = 0, hermite = 0;
};

// The largest position error at the step ends of sol, and at 100 points inside each step of sol(t) and
// of the Hermite interpolant, against the analytic Kepler orbit.
Errors errors(const Solution<V2>& sol, const KeplerProblem<double>& kp) {
  Errors e;
  for (std::size_t k = 0; k < sol.t.size(); ++k) e.ends = std::max(e.ends, pos_err(sol.q[k], kp.exact(sol.t[k])));
  for (std::size_t k = 0; k + 1 < sol.t.size(); ++k)
    for (int j = 1; j <= 100; ++j) {
      const double t = sol.t[k] + (sol.t[k + 1] - sol.t[k]) * j / 101.0;
      const auto ex = kp.exact(t);
      e.inside = std::max(e.inside, pos_err(sol(t).q, ex));
      e.hermite = std::max(e.hermite, pos_err(sol.dense.hermite(t).q, ex));
    }
  return e;
}

}  // namespace

TEST(DenseOutput, InsideEveryStepWithinTenTimesTheStepEndErrorForEveryFixedStepMethod) {
  // Kepler e = 0.5 over one period. Methods of order <= 8: at about 1000 forces per period, halved until
  // the step-end error is above 1e-10 (well above rounding), the largest error inside the steps is within
  // 10x of the largest at the step ends. Higher orders: the same at two step sizes, and the observed order
  // of sol(t) inside the steps from the two, which must be that of the step ends.
  const KeplerProblem<double> kp(0.5);
  const auto prob = kepler(0.5, 0.0, 2 * pi);
  int low = 0, high = 0;
  for (const auto& def : catalog()) {
    if (def.info.adaptive || def.info.order <= 0) continue;
    SCOPED_TRACE(def.info.name);
    const long fps = std::max(1, def.info.forces_per_step);
    if (def.info.order <= 8) {
      long steps = std::max(16L, 1000L / fps);
      Errors e = errors(solve(prob, def, {.steps = steps, .dense = true}), kp);
      while (e.ends < 1e-10 && steps > 16) {
        steps /= 2;
        e = errors(solve(prob, def, {.steps = steps, .dense = true}), kp);
      }
      EXPECT_GT(e.ends, 1e-12) << steps << " steps";
      EXPECT_LE(e.inside, 10 * e.ends) << steps << " steps: step ends " << e.ends << ", inside " << e.inside;
      std::printf("dense %-10s order %2d, %5ld steps: step ends %.2e, inside %.2e (Hermite %.2e)\n",
                  def.info.name.c_str(), def.info.order, steps, e.ends, e.inside, e.hermite);
      ++low;
    } else {
      const long steps = std::max(8L, 300L / fps);
      const Errors e1 = errors(solve(prob, def, {.steps = steps, .dense = true}), kp);
      const Errors e2 = errors(solve(prob, def, {.steps = 2 * steps, .dense = true}), kp);
      const double p = std::log2(e1.inside / e2.inside), p_ends = std::log2(e1.ends / e2.ends);
      std::printf("dense %-10s order %2d, %ld/%ld steps: inside %.2e/%.2e, observed order %.1f (step ends %.1f)\n",
                  def.info.name.c_str(), def.info.order, steps, 2 * steps, e1.inside, e2.inside, p, p_ends);
      // Above rounding, so that the ratio measures the order; at these few steps per period the observed
      // order is not yet the asymptotic one, but sol(t) has the order of the step ends.
      EXPECT_GT(e2.inside, 1e-13);
      EXPECT_NEAR(p, p_ends, 0.5);
      EXPECT_LE(e1.inside, 10 * e1.ends);
      EXPECT_LE(e2.inside, 10 * e2.ends);
      ++high;
    }
  }
  EXPECT_GT(low, 30);
  EXPECT_GT(high, 5);
}

TEST(DenseOutput, AdaptiveEnginesAndGbsKeepTheirAccuracyInsideTheirSteps) {
  const KeplerProblem<double> kp(0.5);
  const auto prob = kepler(0.5, 0.0, 2 * pi);
  for (const std::string m : {"DP12-adaptive", "M12-adaptive", "M8-adaptive", "GBS"}) {
    SCOPED_TRACE(m);
    const auto sol = solve(prob, m, {.rtol = 1e-10, .dense = true});
    const Errors e = errors(sol, kp);
    std::printf("dense %-14s %4ld steps: step ends %.2e, inside %.2e (Hermite %.2e)\n", m.c_str(), sol.accepted, e.ends,
                e.inside, e.hermite);
    EXPECT_LE(e.inside, 10 * e.ends) << "step ends " << e.ends << ", inside " << e.inside;
  }
}

TEST(DenseOutput, OutlivesTheProblemAndItsForce) {
  // The force captures a vector by value; the problem and the force go out of scope before sol(t).
  const auto make = [] {
    const std::vector<double> w2 = {4.0};
    auto f = [w2](const std::vector<double>& q, std::vector<double>& a) { a[0] = -w2[0] * q[0]; };
    const SecondOrderProblem prob(f, std::vector<double>{1.0}, std::vector<double>{0.0}, 0.0, 3.0);
    return solve(prob, "M8", {.steps = 30, .dense = true});
  };
  const auto sol = make();
  const auto copy = sol;
  for (double t : {0.05, 1.234, 2.999}) {
    // q = cos 2t, v = -2 sin 2t; M8 with h = 0.1: 1e-9 at the step ends.
    EXPECT_NEAR(sol(t).q[0], std::cos(2 * t), 1e-8) << t;
    EXPECT_NEAR(copy(t).v[0], -2 * std::sin(2 * t), 1e-8) << t;
  }
}

TEST(DenseOutput, BackwardAndTimeDependentProblems) {
  // q'' = -q + cos(2t), q(0) = q'(0) = 0: q = (cos t - cos 2t) / 3, integrated from t = 5 back to 0.
  auto f = [](double t, const std::vector<double>& q, std::vector<double>& a) { a[0] = -q[0] + std::cos(2 * t); };
  auto exact = [](double t) { return (std::cos(t) - std::cos(2 * t)) / 3; };
  const SecondOrderProblem back(f, std::vector<double>{exact(5.0)},
                                std::vector<double>{(-std::sin(5.0) + 2 * std::sin(10.0)) / 3}, 5.0, 0.0);
  for (const std::string m : {"M6", "DP12-adaptive", "GBS"}) {
    SCOPED_TRACE(m);
    const auto sol = solve(back, m, {.steps = 40, .rtol = 1e-10, .dense = true});
    double ends = 0, inside = 0;
    for (std::size_t k = 0; k < sol.t.size(); ++k) ends = std::max(ends, std::abs(sol.q[k][0] - exact(sol.t[k])));
    for (std::size_t k = 0; k + 1 < sol.t.size(); ++k)
      for (int j = 1; j <= 20; ++j) {
        const double t = sol.t[k] + (sol.t[k + 1] - sol.t[k]) * j / 21.0;
        inside = std::max(inside, std::abs(sol(t).q[0] - exact(t)));
      }
    EXPECT_LE(inside, 10 * ends + 1e-15) << "step ends " << ends << ", inside " << inside;
  }
}
