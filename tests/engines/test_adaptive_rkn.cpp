// The adaptive RKN engine (engines/adaptive_rkn.hpp) with the Dormand-El-Mikkawy-Prince RKN12(10)
// pair: the error tracks the tolerance on Kepler, the end time is hit exactly, force evaluations are
// counted exactly, and bad input or an unattainable tolerance fails with a clear exception.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "nystrom/engines/adaptive_rkn.hpp"
#include "nystrom/methods/catalog.hpp"
#include "nystrom/methods/rkn_order_conditions.hpp"
#include "nystrom/problems/counting_force.hpp"
#include "nystrom/problems/kepler.hpp"

using namespace nystrom;

namespace {

using LD = long double;
using V2 = std::array<LD, 2>;

template <class T>
double max_error(const State<std::array<T, 2>>& a, const State<std::array<T, 2>>& b) {
  T e = 0;
  for (int i = 0; i < 2; ++i) e = std::max({e, std::abs(a.q[i] - b.q[i]), std::abs(a.v[i] - b.v[i])});
  return static_cast<double>(e);
}

using CountingKepler = CountingForce<KeplerForce>;

// q'' = 2 q^3, q(0) = 1, v(0) = 1: q = 1 / (1 - t), singular at t = 1.
struct BlowUp {
  template <class V>
  void operator()(const V& q, V& a) const {
    for (std::size_t i = 0; i < q.size(); ++i) a[i] = 2 * q[i] * q[i] * q[i];
  }
};

AdaptiveOptions with_tol(double tol) {
  AdaptiveOptions o;
  o.rtol = tol;
  return o;
}

}  // namespace

// Kepler e = 0.5 over one period in long double: the error follows the tolerance (below it: the
// 12th-order solution is propagated while the 10th-order one is controlled; measured 0.007-0.034 tol,
// asserted within [1e-3 tol, tol]) and the work grows slowly, like tol^(-1/11).
TEST(AdaptiveRkn, KeplerErrorTracksTheTolerance) {
  const KeplerProblem<LD> kp(0.5L);
  const MethodDef def = resolve_method("DP12-adaptive");
  std::vector<double> errs, work;
  for (double tol : {1e-8, 1e-10, 1e-12}) {
    auto ai = make_adaptive_integrator<V2>(def, KeplerForce{}, with_tol(tol));
    EXPECT_EQ(ai.error_order(), 10);
    EXPECT_EQ(ai.method_order(), 12);
    auto s = kp.initial_state();
    const AdaptiveStats st = ai.integrate_to(s, 0.0L, KeplerProblem<LD>::period());
    const double e = max_error(s, kp.exact(KeplerProblem<LD>::period()));
    EXPECT_LE(e, tol) << "tol " << tol;
    EXPECT_GE(e, 1e-3 * tol) << "tol " << tol;
    errs.push_back(e);
    work.push_back(static_cast<double>(st.force_evals));
    std::printf("[ adaptive ] tol %.0e  error %.3e  error/tol %.3g  forces %ld\n", tol, e, e / tol, st.force_evals);
    EXPECT_EQ(st.force_evals, 17 * (st.accepted + st.rejected) + 2);
  }
  // Steps h ~ tol^(1/11) (the 10th-order estimate is controlled), local errors of the propagated 12th-order
  // solution h^13: the global error goes like tol^(12/11). Measured over 1e-8 ... 1e-12: slope 1.17.
  const double slope = std::log10(errs[0] / errs[2]) / 4;
  EXPECT_NEAR(slope, 12.0 / 11.0, 0.2);
  EXPECT_GT(work[2], work[0]);
  EXPECT_LT(work[2], 4 * work[0]);  // 1e4 in tolerance, (1e4)^(1/11) = 2.3 in work
}

TEST(AdaptiveRkn, LandsExactlyOnTheEndAndObservesEveryAcceptedStep) {
  const KeplerProblem<LD> kp(0.5L);
  auto ai = make_adaptive_integrator<V2>(resolve_method("DP12-adaptive"), KeplerForce{}, with_tol(1e-10));
  auto s = kp.initial_state();
  const LD t0 = 0.25L, t1 = 3.7L;
  std::vector<LD> times;
  const AdaptiveStats st = ai.integrate_to(s, t0, t1, [&](LD t, const State<V2>& y) {
    times.push_back(t);
    EXPECT_TRUE(std::isfinite(static_cast<double>(y.q[0])));
  });
  ASSERT_EQ(times.size(), static_cast<std::size_t>(st.accepted + 1));
  EXPECT_EQ(times.front(), t0);
  EXPECT_EQ(times.back(), t1);  // exactly
  for (std::size_t i = 1; i < times.size(); ++i) EXPECT_GT(times[i], times[i - 1]);
  EXPECT_GT(st.last_h, 0.0);
  // Started at t0 = 0.25 from the t = 0 initial state: compare with the solution shifted in time.
  EXPECT_LE(max_error(s, kp.exact(t1 - t0)), 1e-9);
  // A zero-length interval does nothing.
  auto s2 = s;
  const AdaptiveStats none = ai.integrate_to(s2, t1, t1);
  EXPECT_EQ(none.accepted + none.rejected + none.force_evals, 0);
  EXPECT_EQ(s2.q, s.q);
}

TEST(AdaptiveRkn, ContinuesAcrossCallsAndCountsForcesExactly) {
  const KeplerProblem<LD> kp(0.9L);
  long calls = 0;
  auto ai = make_adaptive_integrator<V2>(resolve_method("DP12-adaptive"), CountingKepler{&calls}, with_tol(1e-11));
  auto s = kp.initial_state();
  const LD T = KeplerProblem<LD>::period();
  AdaptiveStats a = ai.integrate_to(s, 0.0L, T / 3);
  AdaptiveStats b = ai.integrate_to(s, T / 3, T);
  EXPECT_EQ(a.force_evals + b.force_evals, calls);
  EXPECT_EQ(ai.total().force_evals, calls);
  EXPECT_EQ(ai.total().accepted, a.accepted + b.accepted);
  EXPECT_EQ(b.force_evals, 17 * (b.accepted + b.rejected));  // the second call reuses the last step size
  EXPECT_LE(max_error(s, kp.exact(T)), 1e-9);
  EXPECT_GT(a.rejected + b.rejected + a.accepted, 0);
}

TEST(AdaptiveRkn, WorksInDoubleWithVectors) {
  using V = std::vector<double>;
  AdaptiveOptions o = with_tol(1e-9);
  o.h0 = 0.01;
  auto ai = make_adaptive_integrator<V>(resolve_method("DP12-adaptive"), HarmonicForce{}, o);
  State<V> s{{1.0}, {0.0}};
  const AdaptiveStats st = ai.integrate_to(s, 0.0, 10.0);
  EXPECT_NEAR(s.q[0], std::cos(10.0), 1e-8);
  EXPECT_NEAR(s.v[0], -std::sin(10.0), 1e-8);
  EXPECT_EQ(st.force_evals, 17 * (st.accepted + st.rejected));  // h0 given: no starting-step estimate
}

TEST(AdaptiveRkn, RejectsBadInput) {
  const MethodDef def = resolve_method("DP12-adaptive");
  for (double tol : {0.0, -1e-8, std::nan(""), std::numeric_limits<double>::infinity()})
    EXPECT_THROW(make_adaptive_integrator<V2>(def, KeplerForce{}, with_tol(tol)), std::invalid_argument) << tol;
  AdaptiveOptions bad = with_tol(1e-8);
  bad.safety = 1.5;
  EXPECT_THROW(make_adaptive_integrator<V2>(def, KeplerForce{}, bad), std::invalid_argument);
  // A method without an embedded pair cannot run with a tolerance.
  EXPECT_THROW(make_adaptive_integrator<V2>(resolve_method("DP12"), KeplerForce{}, with_tol(1e-8)),
               std::invalid_argument);
  EXPECT_THROW(make_adaptive_integrator<V2>(resolve_method("VV"), KeplerForce{}, with_tol(1e-8)),
               std::invalid_argument);

  auto ai = make_adaptive_integrator<V2>(def, KeplerForce{}, with_tol(1e-8));
  auto s = KeplerProblem<LD>(0.5L).initial_state();
  EXPECT_THROW(ai.integrate_to(s, 1.0L, 0.5L), std::invalid_argument);  // t1 < t0
  EXPECT_THROW(ai.integrate_to(s, 0.0L, std::numeric_limits<LD>::infinity()), std::invalid_argument);
  auto nan_state = s;
  nan_state.v[1] = std::numeric_limits<LD>::quiet_NaN();
  EXPECT_THROW(ai.integrate_to(nan_state, 0.0L, 1.0L), std::invalid_argument);
}

TEST(AdaptiveRkn, SingularSolutionEndsWithAStepSizeUnderflow) {
  using V = std::array<double, 1>;
  auto ai = make_adaptive_integrator<V>(resolve_method("DP12-adaptive"), BlowUp{}, with_tol(1e-10));
  State<V> s{{1.0}, {1.0}};
  double t_last = 0;
  EXPECT_THROW(ai.integrate_to(s, 0.0, 2.0, [&](double t, const State<V>&) { t_last = t; }), StepSizeUnderflow);
  EXPECT_GT(t_last, 0.99);  // it got close to the singularity at t = 1 before giving up
  EXPECT_LT(t_last, 1.0);
}

TEST(AdaptiveRkn, RejectsAToleranceBelowTheRoundingLevel) {
  // 10 eps: about 2e-15 in double, 1e-18 in long double.
  using VD = std::array<double, 2>;
  EXPECT_THROW(make_adaptive_integrator<VD>(resolve_method("DP12-adaptive"), KeplerForce{}, with_tol(1e-16)),
               std::invalid_argument);
  EXPECT_NO_THROW(make_adaptive_integrator<V2>(resolve_method("DP12-adaptive"), KeplerForce{}, with_tol(1e-16)));
}

TEST(AdaptiveRkn, StepLimitIsAClearError) {
  AdaptiveOptions o = with_tol(1e-12);
  o.max_steps = 5;
  auto ai = make_adaptive_integrator<V2>(resolve_method("DP12-adaptive"), KeplerForce{}, o);
  auto s = KeplerProblem<LD>(0.5L).initial_state();
  EXPECT_THROW(ai.integrate_to(s, 0.0L, 100.0L), TooManySteps);
}

// The default controller (safety 0.9, fac_min 0.2, predictive ratio; engines/adaptive_rkn.hpp) rejects
// a few steps but not many: its documented behaviour is 5-15% rejected steps on Kepler. A smaller
// safety factor rejects almost none and spends more forces; a larger fac_min shrinks too little after
// a rejection and rejects again. DP12-adaptive, Kepler e = 0.9, 3 periods, long double.
TEST(AdaptiveRkn, DefaultControllerRejectsAFewSteps) {
  const KeplerProblem<LD> kp(0.9L);
  const MethodDef def = resolve_method("DP12-adaptive");
  for (double tol : {1e-9, 1e-12}) {
    auto ao = make_adaptive_integrator<V2>(def, KeplerForce{}, with_tol(tol));
    auto s = kp.initial_state();
    const AdaptiveStats st = ao.integrate_to(s, 0.0L, 3 * KeplerProblem<LD>::period());
    const double frac = static_cast<double>(st.rejected) / static_cast<double>(st.accepted + st.rejected);
    std::printf("[ adaptive ] e 0.9 tol %.0e  accepted %ld rejected %ld (%.1f%%)  forces %ld\n", tol, st.accepted,
                st.rejected, 100 * frac, st.force_evals);
    EXPECT_GT(frac, 0.03) << "tol " << tol;
    EXPECT_LT(frac, 0.2) << "tol " << tol;
  }
}

// The step ratio (shared by both adaptive engines): standard = safety * err^(-1/(p+1)); predictive
// (Gustafsson) also follows the trend of the last two accepted steps, and only ever shrinks.
TEST(AdaptiveRkn, StepControllerRatios) {
  AdaptiveOptions o;
  o.safety = 0.5;
  o.fac_min = 0.2;
  o.fac_max = 4.0;
  for (bool predictive : {false, true}) {
    o.predictive = predictive;
    adaptive_detail::StepController c(o);
    EXPECT_DOUBLE_EQ(c.accepted(2.0, 1.0, false), 1.0);  // the first step: no trend yet
    // The error grew (q fell from 2 to 1.6) and the step fell from 1 to 0.8: predictive shrinks by
    // (0.8 / 1) * (1.6 / 2) = 0.64 more.
    const double f = c.accepted(1.6, 0.8, false);
    EXPECT_DOUBLE_EQ(f, predictive ? 0.5 * 1.6 * 0.64 : 0.5 * 1.6);
    // The error fell: the trend factor would grow the step; the standard ratio is kept.
    EXPECT_DOUBLE_EQ(c.accepted(3.2, 0.8, false), 1.6);
    EXPECT_DOUBLE_EQ(c.accepted(100.0, 1.0, false), 4.0);     // clamped to fac_max
    EXPECT_DOUBLE_EQ(c.accepted(100.0, 1.0, true), 1.0);      // no growth right after a rejection
    EXPECT_DOUBLE_EQ(c.accepted(INFINITY, 1.0, false), 4.0);  // err = 0
    EXPECT_DOUBLE_EQ(c.rejected(0.5), 0.25);
    EXPECT_DOUBLE_EQ(c.rejected(0.01), 0.2);  // clamped to fac_min
    EXPECT_DOUBLE_EQ(c.rejected(0.0), 0.2);   // err = inf
    EXPECT_DOUBLE_EQ(c.rejected(NAN), 0.2);   // err NaN
  }
}

// tableau_order caps the order it reports at 14 unless asked for more. A tableau of a higher order: the
// multi-product expansion of order 16 over the Stormer-Verlet products k = 1..8 (Chin, eq 14: c_i = prod_{j != i}
// k_i^2 / (k_i^2 - k_j^2)), written as one explicit tableau, the direct sum of the products' tableaux with their
// weights times c_i.
TEST(AdaptiveRkn, TableauOrderIsCappedAtFourteenUnlessAskedForMore) {
  RknTableau<double> t;
  std::size_t off = 0;
  for (int ki = 1; ki <= 8; ++ki) {
    double ci = 1;
    for (int kj = 1; kj <= 8; ++kj)
      if (kj != ki) ci *= double(ki * ki) / double(ki * ki - kj * kj);
    const double h = 1.0 / ki;
    SplittingScheme<double> vv;  // k_i velocity-Verlet steps of 1 / k_i, kicks of adjacent steps merged
    vv.steps.push_back({Flow::kick, h / 2});
    for (int r = 1; r < ki; ++r) {
      vv.steps.push_back({Flow::drift, h});
      vv.steps.push_back({Flow::kick, h});
    }
    vv.steps.push_back({Flow::drift, h});
    vv.steps.push_back({Flow::kick, h / 2});
    const auto p = to_rkn_tableau(vv);
    const std::size_t s = p.stages(), n = off + s;
    for (auto& row : t.a) row.resize(n, 0.0);
    for (std::size_t i = 0; i < s; ++i) {
      t.c.push_back(p.c[i]);
      t.b.push_back(ci * p.b[i]);
      t.B.push_back(ci * p.B[i]);
      std::vector<double> row(n, 0.0);
      for (std::size_t j = 0; j < i; ++j) row[off + j] = p.a[i][j];
      t.a.push_back(row);
    }
    off = n;
  }
  t.validate();
  EXPECT_EQ(t.stages(), 44u);
  EXPECT_EQ(tableau_order(t), 14);
  EXPECT_EQ(tableau_order(t, 15), 15);
  EXPECT_EQ(tableau_order(t, 10), 10);
}
