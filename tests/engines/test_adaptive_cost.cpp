// What the adaptive controllers spend, asserted: accepted and rejected steps and force evaluations on fixed
// problems in windows from an independent implementation written here (DP12-adaptive: the embedded pair and
// the step-size controller of HNW I, II.4 and Gustafsson's predictive ratio, re-implemented on the harmonic
// oscillator from the catalog's tableau) or from the methods' theory (cost against tolerance for a method of
// fixed order, no rejections on a problem whose optimal step is constant); the controller's parts (error
// scale, starting step, step ratios) on known inputs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "nystrom/engines/adaptive_mpe.hpp"
#include "nystrom/engines/adaptive_rkn.hpp"
#include "nystrom/methods/catalog.hpp"
#include "nystrom/methods/method_data.hpp"
#include "nystrom/solve/solve.hpp"

using namespace nystrom;
using Vd = std::vector<double>;
using VdForce = std::function<void(const Vd&, Vd&)>;

namespace {

const VdForce oscillator = [](const Vd& q, Vd& a) {
  for (std::size_t i = 0; i < q.size(); ++i) a[i] = -q[i];
};

SecondOrderProblem<Vd, VdForce> oscillator_problem(double t1) {
  return SecondOrderProblem(oscillator, Vd{1.0}, Vd{0.0}, 0.0, t1);
}

struct Counts {
  long accepted = 0, rejected = 0, force_evals = 0;
};

// An independent adaptive RKN run of q'' = -q, q(0) = 1, v(0) = 0, over [0, t1] with the embedded pair of
// `t`: error (q1 - q1hat, v1 - v1hat) in the root-mean-square norm of its two components, each scaled by
// tol (1 + the larger of its sizes at both ends); accepted when <= 1; ratio 0.9 err^(-1/(p+1)), with
// Gustafsson's predictive ratio when smaller, within [0.2, 4] and at most 1 right after a rejection;
// 0.9 err^(-1/(p+1)) within [0.2, 1] after a rejection; Hairer's starting step (at the order p + 2 of the propagated
// solution); a step within 1% of the end stretched to it. Force evaluations: every stage of every attempt, less the
// first stage of a step that starts where an accepted step of a first-same-as-last tableau ended, plus the two of the
// starting step.
Counts reference_run(const RknTableau<double>& t, int p, double tol, double t1) {
  const std::size_t s = t.c.size();
  bool fsal = t.c[0] == 0 && t.c[s - 1] == 1;
  for (std::size_t j = 0; j + 1 < s; ++j) fsal = fsal && t.a[s - 1][j] == t.b[j];
  const auto scale = [&](double y) { return tol * (1 + y); };
  const auto rms = [](double x, double y) { return std::sqrt((x * x + y * y) / 2); };
  Counts n;
  double q = 1, v = 0, tt = 0;
  // Starting step (HNW I, II.4) at the method's order p + 2 (HNW's iord: the order of the propagated solution).
  const double a0 = -q;
  const double d0 = rms(q / scale(std::abs(q)), v / scale(std::abs(v)));
  const double d1 = rms(v / scale(std::abs(q)), a0 / scale(std::abs(v)));
  double h0 = (d0 < 1e-5 || d1 < 1e-5) ? 1e-6 : 0.01 * d0 / d1;
  h0 = std::min(h0, t1);
  const double a1 = -(q + h0 * v);
  const double d2 = rms(h0 * a0 / scale(std::abs(q)), (a1 - a0) / scale(std::abs(v))) / h0;
  double h = std::min({100 * h0, std::pow(0.01 / std::max(d1, d2), 1.0 / (p + 3)), t1});
  n.force_evals = 2;
  double q_prev = 0, h_prev = 0;
  bool after_rejection = false, cached = false;
  std::vector<double> f(s);
  while (tt < t1) {
    double hs = h;
    const bool last = tt + 1.01 * hs >= t1;
    if (last) hs = t1 - tt;
    double sq = 0, sv = 0, sqh = 0, svh = 0;
    for (std::size_t i = 0; i < s; ++i) {
      double g = q + t.c[i] * hs * v;
      for (std::size_t j = 0; j < i; ++j) g += hs * hs * t.a[i][j] * f[j];
      f[i] = -g;
      if (!(i == 0 && cached)) ++n.force_evals;
      sq += t.b[i] * f[i];
      sv += t.B[i] * f[i];
      sqh += t.bhat[i] * f[i];
      svh += t.Bhat[i] * f[i];
    }
    const double q1 = q + hs * v + hs * hs * sq, v1 = v + hs * sv;
    const double eq = hs * hs * (sq - sqh), ev = hs * (sv - svh);
    const double err =
        rms(eq / scale(std::max(std::abs(q), std::abs(q1))), ev / scale(std::max(std::abs(v), std::abs(v1))));
    const double r = err == 0 ? std::numeric_limits<double>::infinity() : std::pow(err, -1.0 / (p + 1));
    if (err <= 1) {
      ++n.accepted;
      q = q1;
      v = v1;
      tt = last ? t1 : tt + hs;
      cached = fsal;
      double fac = 0.9 * r;
      if (q_prev > 0) fac = std::min(fac, fac * (hs / h_prev) * (r / q_prev));
      q_prev = r;
      h_prev = hs;
      fac = std::clamp(fac, 0.2, 4.0);
      if (after_rejection) fac = std::min(fac, 1.0);
      h = std::min(hs * fac, t1);
      after_rejection = false;
    } else {
      ++n.rejected;
      cached = false;  // the cached force is that of the rejected step's end
      h = hs * std::clamp(0.9 * r, 0.2, 1.0);
      after_rejection = true;
    }
  }
  return n;
}

RknTableau<double> catalog_tableau(const std::string& name) {
  const MethodData data = method_data_for(resolve_method(name), 53, "double");
  const auto& t = std::get<RknTableau<bigcomplex>>(data);
  return convert_tableau<double>(t, [](const bigcomplex& x) { return static_cast<double>(x.re); });
}

}  // namespace

TEST(AdaptiveCost, Dp12AdaptiveSpendsWhatAnIndependentControllerSpends) {
  // DP12-adaptive is the 12(10) pair of Dormand, El-Mikkawy and Prince (IMA J. Numer. Anal. 7 (1987) 423): the
  // error estimate is of order p = 10. Its controller works to the calibrated tolerance 1e-15 (tol / 1e-15)^(11/13)
  // (tolerance proportionality: (p + 1) / (p + 3), engines/step_control.hpp), written out here.
  const auto t = catalog_tableau("DP12-adaptive");
  for (double tol : {1e-6, 1e-9, 1e-12}) {
    for (double t1 : {10.0, 40.0}) {
      SCOPED_TRACE("tol " + std::to_string(tol) + ", t1 " + std::to_string(t1));
      const Counts ref = reference_run(t, 10, 1e-15 * std::pow(tol / 1e-15, 11.0 / 13.0), t1);
      const auto sol = solve(oscillator_problem(t1), "DP12-adaptive", {.rtol = tol});
      // The reference works in plain double with steps as they come, the engine with compensated sums and step
      // ends rounded to exact times: a decision on the edge of acceptance may fall the other way, hence two steps
      // either way (tol 1e-12, controlled 3.4e-13: rejected 3 against 1 over t1 = 10, accepted 59 against 61 over 40).
      EXPECT_NEAR(sol.accepted, ref.accepted, 2) << "reference " << ref.accepted;
      EXPECT_NEAR(sol.rejected, ref.rejected, 2) << "reference " << ref.rejected;
      const long stages = static_cast<long>(t.c.size());
      EXPECT_NEAR(sol.force_evals, ref.force_evals, 2 * stages) << "reference " << ref.force_evals;
      EXPECT_NEAR(sol.q_final[0], std::cos(t1), 1e3 * tol);
      EXPECT_NEAR(sol.v_final[0], -std::sin(t1), 1e3 * tol);
    }
  }
}

TEST(AdaptiveCost, FixedOrderEnginesFollowTheirOrderInTolerance) {
  // A method whose error estimate is of order p takes steps h ~ tol_c^(1/(p+1)), tol_c = 1e-15 (tol /
  // 1e-15)^gamma the calibrated tolerance of its controller (gamma = (p + 1) / (p + 3), tolerance proportionality,
  // engines/step_control.hpp): over a span of many steps the accepted steps grow by (tol_1 / tol_2)^(gamma/(p+1))
  // from tol_1 to tol_2 (within 10%). And every attempt costs
  // the method's force evaluations, plus the two of the starting step: DP12 (17 stages, p = 10); the
  // multi-product expansion M<2n> on position Verlet (products of 1, 2, ..., n steps of one force each:
  // n (n + 1) / 2 per attempt), estimated by the expansion of order 2n - 2 (p = 2n - 2).
  struct Case {
    std::string method;
    int p;
    long per_attempt;
  };
  for (const Case& c : {Case{"DP12-adaptive", 10, 17}, Case{"M10-adaptive", 8, 15}, Case{"M8-adaptive", 6, 10}}) {
    SCOPED_TRACE(c.method);
    const auto prob = oscillator_problem(200.0);
    const auto loose = solve(prob, c.method, {.rtol = 1e-7});
    const auto tight = solve(prob, c.method, {.rtol = 1e-11});
    const double gamma = static_cast<double>(c.p + 1) / (c.p + 3);
    const double expected = std::pow(1e4, gamma / (c.p + 1));
    const double ratio = static_cast<double>(tight.accepted) / static_cast<double>(loose.accepted);
    EXPECT_NEAR(ratio, expected, 0.1 * expected) << loose.accepted << " -> " << tight.accepted;
    for (const auto* s : {&loose, &tight}) {
      EXPECT_EQ(s->force_evals, c.per_attempt * (s->accepted + s->rejected) + 2);
      EXPECT_EQ(s->output_force_evals, 0);
    }
  }
}

TEST(AdaptiveCost, FewRejectionsOnTheHarmonicOscillator) {
  // The optimal step changes slowly along the orbit (only through the scale tol (1 + |y|)): a controller with
  // safety 0.9 rejects a minority of its attempts, here at most one in four; and it reaches the tolerance.
  for (const std::string m : {"DP12-adaptive", "M10-adaptive", "MPE-adaptive", "GBS"}) {
    for (double tol : {1e-8, 1e-12}) {
      SCOPED_TRACE(m + " tol " + std::to_string(tol));
      const auto sol = solve(oscillator_problem(100.0), m, {.rtol = tol});
      EXPECT_LE(4 * sol.rejected, sol.accepted);
      EXPECT_GE(sol.accepted, 5);
      EXPECT_NEAR(sol.q_final[0], std::cos(100.0), 1e3 * tol);
      EXPECT_NEAR(sol.v_final[0], -std::sin(100.0), 1e3 * tol);
    }
  }
}

TEST(AdaptiveCost, OrderControlSpendsNoMoreThanTheBestFixedOrder) {
  // MPE-adaptive chooses among the orders 4 to 16 of the multi-product expansion: at tol 1e-12 over 100 time
  // units it must cost no more than 1.5 times the best fixed order it could have chosen (M8 to M16), and far
  // less than a low order (M6: steps of about tol^(1/5)).
  const auto prob = oscillator_problem(100.0);
  const SolveOptions o{.rtol = 1e-12};
  const auto control = solve(prob, "MPE-adaptive", o);
  long best = std::numeric_limits<long>::max();
  for (const std::string m : {"M8-adaptive", "M10-adaptive", "M12-adaptive", "M14-adaptive", "M16-adaptive"})
    best = std::min(best, solve(prob, m, o).force_evals);
  const auto low = solve(prob, "M6-adaptive", o);
  EXPECT_LE(2 * control.force_evals, 3 * best) << "best fixed order " << best;
  EXPECT_LT(4 * control.force_evals, low.force_evals);
}

// ---- the controller's parts on known inputs -----------------------------------------------------------

TEST(AdaptiveController, ErrorScaleIsMixedWithOneToleranceAndSplitWithTwo) {
  const adaptive_detail::ErrorScale<double> one(AdaptiveOptions{.rtol = 1e-6});
  EXPECT_DOUBLE_EQ(one(0.0), 1e-6);
  EXPECT_DOUBLE_EQ(one(3.0), 4e-6);
  const adaptive_detail::ErrorScale<double> same(AdaptiveOptions{.rtol = 1e-6, .atol = 1e-6});
  EXPECT_DOUBLE_EQ(same(3.0), 4e-6);
  const adaptive_detail::ErrorScale<double> two(AdaptiveOptions{.rtol = 1e-6, .atol = 1e-9});
  EXPECT_DOUBLE_EQ(two(0.0), 1e-9);
  EXPECT_DOUBLE_EQ(two(3.0), 1e-9 + 3e-6);
}

TEST(AdaptiveController, StepRatiosAreTheDocumentedOnes) {
  const AdaptiveOptions opt{};  // safety 0.9, fac_min 0.2, fac_max 4, predictive
  adaptive_detail::StepController c(opt);
  // No history: safety * q.
  EXPECT_DOUBLE_EQ(c.accepted(2.0, 1.0, false), 1.8);
  // Then Gustafsson: min(0.9 q, 0.9 q (h / h_prev) (q / q_prev)) = min(0.9, 0.9 * 1.8 * 0.5).
  EXPECT_DOUBLE_EQ(c.accepted(1.0, 1.8, false), 0.9 * 1.8 * 0.5);
  EXPECT_DOUBLE_EQ(c.q_prev(), 1.0);
  EXPECT_DOUBLE_EQ(c.h_prev(), 1.8);
  // A growing trend is not followed beyond 0.9 q.
  EXPECT_DOUBLE_EQ(c.accepted(2.0, 1.0, false), 1.8);
  // Clamped to [0.2, 4], at most 1 after a rejection; an error of 0 (q = inf) grows by fac_max.
  adaptive_detail::StepController d(opt);
  EXPECT_DOUBLE_EQ(d.accepted(100.0, 1.0, false), 4.0);
  adaptive_detail::StepController e(opt);
  EXPECT_DOUBLE_EQ(e.accepted(0.01, 1.0, false), 0.2);
  adaptive_detail::StepController f(opt);
  EXPECT_DOUBLE_EQ(f.accepted(2.0, 1.0, true), 1.0);
  adaptive_detail::StepController g(opt);
  EXPECT_DOUBLE_EQ(g.accepted(std::numeric_limits<double>::infinity(), 1.0, false), 4.0);
  EXPECT_DOUBLE_EQ(g.q_prev(), 0.0);
  // Rejected: 0.9 q within [0.2, 1]; an error that is not finite: 0.2.
  EXPECT_DOUBLE_EQ(c.rejected(0.5), 0.45);
  EXPECT_DOUBLE_EQ(c.rejected(0.1), 0.2);
  EXPECT_DOUBLE_EQ(c.rejected(1.5), 1.0);
  EXPECT_DOUBLE_EQ(c.rejected(std::numeric_limits<double>::quiet_NaN()), 0.2);
  // Without the predictive ratio: safety * q only.
  AdaptiveOptions plain_opt{};
  plain_opt.predictive = false;
  adaptive_detail::StepController p(plain_opt);
  EXPECT_DOUBLE_EQ(p.accepted(2.0, 1.0, false), 1.8);
  EXPECT_DOUBLE_EQ(p.accepted(1.0, 1.8, false), 0.9);
}

TEST(AdaptiveController, StartingStepIsHairersOnTheOscillator) {
  // HNW I, II.4 at q = 1, v = 0, tol 1e-6 (scales 2e-6 for q, 1e-6 for v), order p = 10:
  // d0 = |(1/2e-6, 0)| = 5e5/sqrt 2, d1 = |(0, 1/1e-6)| = 1e6/sqrt 2, h0 = 0.01 d0/d1 = 0.005,
  // d2 = |(0.005/2e-6, 0)| / 0.005 = 2500/sqrt(2)/0.005, h1 = (0.01 / max(d1, d2))^(1/11), h = min(100 h0, h1).
  const State<std::array<double, 1>> s{{1.0}, {0.0}};
  auto force = [](const std::array<double, 1>& q, std::array<double, 1>& a) { a[0] = -q[0]; };
  const adaptive_detail::ErrorScale<double> scale(AdaptiveOptions{.rtol = 1e-6});
  const double d1 = 1e6 / std::sqrt(2.0), d2 = 2500 / std::sqrt(2.0) / 0.005;
  const double h1 = std::pow(0.01 / std::max(d1, d2), 1.0 / 11);
  EXPECT_NEAR(adaptive_detail::hairer_initial_step(force, s, 100.0, scale, 10), std::min(0.5, h1), 1e-12);
  // Bounded by hmax.
  EXPECT_EQ(adaptive_detail::hairer_initial_step(force, s, 0.01, scale, 10), 0.01);
  // At order 1 the estimate h1 = (0.01 / d1)^(1/2) = 1.2e-4 is the smaller one.
  const double h1_low = std::pow(0.01 / std::max(d1, d2), 1.0 / 2);
  EXPECT_NEAR(adaptive_detail::hairer_initial_step(force, s, 100.0, scale, 1), std::min(0.5, h1_low), 1e-15);
}

TEST(AdaptiveController, StepSequenceLandsOnTheEndAndStretchesTheLastPercent) {
  const AdaptiveOptions opt{.h0 = 0.3};
  AdaptiveResumePoint<double> none;
  double carried = 0;
  adaptive_detail::StepSequence<double> seq(opt, none, carried, 0.0, 1.0, [](const double&) { return 0.0; });
  double h;
  bool last;
  ASSERT_TRUE(seq.next<false>(0.0, h, last));
  EXPECT_EQ(h, 0.3);
  EXPECT_FALSE(last);
  // 0.3 from 0.7 lands on 1 exactly; from 0.703, 0.3 * 1.01 = 0.303 > 0.297 left: stretched... shortened to land.
  ASSERT_TRUE(seq.next<false>(0.7, h, last));
  EXPECT_TRUE(last);
  EXPECT_DOUBLE_EQ(h, 0.3);
  ASSERT_TRUE(seq.next<false>(0.698, h, last));  // 1.01 * 0.3 = 0.303 >= 0.302 left: the last step, stretched
  EXPECT_TRUE(last);
  EXPECT_DOUBLE_EQ(h, 1.0 - 0.698);
  ASSERT_TRUE(seq.next<false>(0.69, h, last));  // 0.303 < 0.31 left: an ordinary step
  EXPECT_FALSE(last);
  EXPECT_DOUBLE_EQ(h, 0.3);
  // An accepted step with ratio q = 2 (no history): the next is 0.9 * 2 * 0.3; a rejection: 0.9 q within
  // [0.2, 1] of the rejected step, and no growth in the step after it.
  seq.accepted(2.0, 0.3, false, carried);
  ASSERT_TRUE(seq.next<false>(0.0, h, last));
  EXPECT_DOUBLE_EQ(h, 0.54);
  EXPECT_DOUBLE_EQ(carried, 0.54);
  seq.rejected(0.5, 0.54);
  EXPECT_TRUE(seq.after_rejection());
  ASSERT_TRUE(seq.next<false>(0.0, h, last));
  EXPECT_DOUBLE_EQ(h, 0.54 * 0.45);
}

// The step carried into the next call after the last step of a call: the controller's new proposal when the last
// step was the proposal itself, the earlier proposal when the last step was shortened to land on t1 (its length
// says nothing about the step the solution allows).
TEST(AdaptiveController, TheStepCarriedPastTheEndIsTheNewProposalUnlessTheLastStepWasShortened) {
  const AdaptiveOptions opt{.h0 = 0.5};
  AdaptiveResumePoint<double> none;
  double h, carried = 0;
  bool last;
  auto sequence = [&] {  // over [0, 1], first step 0.5
    return adaptive_detail::StepSequence<double>(opt, none, carried, 0.0, 1.0, [](const double&) { return 0.0; });
  };
  // From 0.5 the proposal 0.5 lands on 1 exactly: accepted with q = 1/2, the next proposal is 0.9 * 0.5 * 0.5.
  auto full = sequence();
  ASSERT_TRUE(full.next<true>(0.5, h, last));
  EXPECT_TRUE(last);
  EXPECT_EQ(h, 0.5);
  full.accepted(0.5, h, last, carried);
  EXPECT_DOUBLE_EQ(carried, 0.225);
  // From 0.6 the step is shortened to 0.4: accepted with q = 2 (a proposal of 0.72), it carries the earlier 0.5.
  auto cut = sequence();
  ASSERT_TRUE(cut.next<true>(0.6, h, last));
  EXPECT_TRUE(last);
  EXPECT_DOUBLE_EQ(h, 0.4);
  cut.accepted(2.0, h, last, carried);
  EXPECT_EQ(carried, 0.5);
  // Not the last step: the new proposal, whatever its length.
  auto mid = sequence();
  ASSERT_TRUE(mid.next<true>(0.0, h, last));
  EXPECT_FALSE(last);
  mid.accepted(0.5, h, last, carried);
  EXPECT_DOUBLE_EQ(carried, 0.225);
}

// Order control's choice of the next number of products on known step ratios, with the work A_n = n + 3 per step
// of n products: the work per unit step W = A / ratio, lower when W_{j-1} < 0.7 W_j, higher (step ratio
// fj A_{j+1} / A_j, at most fac_max) when W_j < W_{j-1} after an accepted step that followed no rejection,
// HNW I, eqs (9.25)-(9.28). The thresholds are checked on both sides.
TEST(AdaptiveController, OrderControlChoosesTheLeastWorkPerUnitStep) {
  std::vector<double> work(10, 0.0);
  for (std::size_t n = 1; n < work.size(); ++n) work[n] = static_cast<double>(n) + 3;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  auto choose = [&](int j, double fj, double fl, bool accepted = true, bool after_rejection = false) {
    return adaptive_detail::choose_products(j, fj, fl, work, 8, accepted, after_rejection, 4.0);
  };
  // j = 5: W_5 = 8 / fj, W_4 = 7 / fl; with fj = 1 the order drops for fl > 7 / 5.6 = 1.25.
  auto c = choose(5, 1.0, 1.3);
  EXPECT_EQ(c.next, 4);
  EXPECT_EQ(c.fac, 1.3);
  c = choose(5, 1.0, 1.2);
  EXPECT_EQ(c.next, 5);
  EXPECT_EQ(c.fac, 1.0);
  c = choose(5, 1.0, 1.3, false);  // a rejected step lowers the order too
  EXPECT_EQ(c.next, 4);
  // fj = 2: W_5 = 4 < W_4 = 7 / 1.2: up, with the ratio 2 * 9 / 8; and W_5 just above W_4: stays.
  c = choose(5, 2.0, 1.2);
  EXPECT_EQ(c.next, 6);
  EXPECT_DOUBLE_EQ(c.fac, 2.25);
  c = choose(5, 2.0, 1.7);  // W_4 = 4.12 > 4: up
  EXPECT_EQ(c.next, 6);
  c = choose(5, 2.0, 1.8);  // W_4 = 3.89 < 4 but not below 0.7 W_5 = 2.8: stays
  EXPECT_EQ(c.next, 5);
  EXPECT_EQ(c.fac, 2.0);
  // Never up after a rejection, after a rejected step, or past the largest number of products.
  EXPECT_EQ(choose(5, 2.0, 1.2, true, true).next, 5);
  EXPECT_EQ(choose(5, 2.0, 1.2, false).next, 5);
  EXPECT_EQ(choose(8, 2.0, 1.2).next, 8);
  // The ratio of the step up is capped at fac_max: 3.9 * 9 / 8 = 4.39 -> 4.
  c = choose(5, 3.9, 1.0);
  EXPECT_EQ(c.next, 6);
  EXPECT_EQ(c.fac, 4.0);
  // No estimate of the lower order (two products, or a non-finite one): up only at fac_max.
  c = choose(2, 4.0, nan);
  EXPECT_EQ(c.next, 3);
  EXPECT_EQ(c.fac, 4.0);
  c = choose(2, 3.9, nan);
  EXPECT_EQ(c.next, 2);
  EXPECT_EQ(c.fac, 3.9);
  EXPECT_EQ(choose(4, 0.5, nan, false).next, 4);
}

TEST(AdaptiveCost, NearRoundingTheStepsFollowTheOrderNotTheNoise) {
  // M16-adaptive (p = 14) on Kepler e = 0.5 over 100 periods: from tol 1e-12 to 3.2e-15 (within 15 eps of double)
  // the accepted steps grow at most by (1e-12 / 3.2e-15)^(1/15) = 1.47 (plus 10%); an estimate whose round-off
  // the controller chases instead takes several times more.
  const VdForce kepler = [](const Vd& q, Vd& a) {
    const double r2 = q[0] * q[0] + q[1] * q[1], r3 = r2 * std::sqrt(r2);
    a[0] = -q[0] / r3;
    a[1] = -q[1] / r3;
  };
  const double T = 100 * 2 * 3.14159265358979323846;
  const SecondOrderProblem prob(kepler, Vd{1.5, 0.0}, Vd{0.0, std::sqrt(1.0 / 3.0)}, 0.0, T);
  const auto loose = solve(prob, "M16-adaptive", {.rtol = 1e-12});
  const auto tight = solve(prob, "M16-adaptive", {.rtol = 3.2e-15});
  const double bound = 1.1 * static_cast<double>(loose.accepted) * std::pow(1e-12 / 3.2e-15, 1.0 / 15);
  EXPECT_LE(static_cast<double>(tight.accepted), bound) << loose.accepted << " -> " << tight.accepted;
  EXPECT_GE(tight.accepted, loose.accepted);
  EXPECT_LE(4 * tight.rejected, tight.accepted);
  // Back at the apocentre (1.5, 0) after whole periods, at the accuracy the tolerance allows.
  EXPECT_NEAR(tight.q_final[0], 1.5, 1e-9);
  EXPECT_NEAR(tight.v_final[1], std::sqrt(1.0 / 3.0), 1e-9);
}

TEST(AdaptiveCost, GbsOrderControlIsCompetitiveWithDp12) {
  // An extrapolation code with order control (HNW I, II.9) picks the order whose work per unit step is least:
  // on the harmonic oscillator at tol 1e-8 and 1e-12 it must cost no more than twice the force evaluations of
  // the order-12 Runge-Kutta-Nystrom pair, and reach the same accuracy.
  for (double tol : {1e-8, 1e-12}) {
    SCOPED_TRACE(tol);
    const auto prob = oscillator_problem(100.0);
    const auto gbs = solve(prob, "GBS", {.rtol = tol});
    const auto dp = solve(prob, "DP12-adaptive", {.rtol = tol});
    EXPECT_LE(gbs.force_evals, 2 * dp.force_evals) << "DP12 " << dp.force_evals;
    EXPECT_NEAR(gbs.q_final[0], std::cos(100.0), 1e3 * tol);
  }
}
