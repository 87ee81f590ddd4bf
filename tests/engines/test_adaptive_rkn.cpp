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
#include "nystrom/methods/dop853.hpp"
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
  // The orders are kept per tableau (evaluated once per process): a weight changed by 1e-9 is another tableau,
  // of order 0 (sum B = 1 fails) or 1 (sum b = 1/2 fails), and the original keeps its order.
  RknTableau<double> u = t;
  u.B[5] += 1e-9;
  EXPECT_EQ(tableau_order(u), 0);
  u.B[5] = t.B[5];
  u.b[7] += 1e-9;
  EXPECT_EQ(tableau_order(u), 1);
  EXPECT_EQ(tableau_order(t), 14);
}

// ---- general (RKNG) pairs for y'' = f(t, y, y'): Fine's 4(3) and 5(4), DOP853 in Nystrom form ----------

namespace {

// A nonlinear force that depends on the velocity (a pendulum with quadratic drag, coupled): no part of it
// is linear, so every elementary differential of y'' = f(y, y') is present.
struct DraggedPendulum {
  template <class V>
  void operator()(const V& q, const V& v, V& a) const {
    using std::cos;
    using std::sin;
    a[0] = -sin(q[0]) - 0.3L * v[0] * v[1] + 0.1L * cos(q[1]);
    a[1] = -q[1] * (1 + q[0] * q[0]) - 0.2L * v[1] * v[1] * v[1] + 0.25L * v[0];
  }
};

const State<V2> kPendulumStart{{0.5L, -0.3L}, {0.2L, 0.7L}};

// The catalog's general pairs, as long double tableaux.
std::vector<std::pair<std::string, RknTableau<LD>>> general_pairs() {
  std::vector<std::pair<std::string, RknTableau<LD>>> out;
  for (const auto& d : catalog()) {
    BigPrecision guard(128);
    const MethodData data = d.build();
    const auto* t = std::get_if<RknTableau<bigcomplex>>(&data);
    if (!t || !t->general()) continue;
    out.emplace_back(d.info.name, convert_tableau<LD>(*t, [](const bigcomplex& x) { return to_scalar<LD>(x); }));
  }
  return out;
}

// n fixed steps of h (either sign) with the main weights of t, or with its embedded weights.
State<V2> rkng_run(RknTableau<LD> t, bool embedded, LD h, long n) {
  if (embedded) {
    t.b = t.bhat;
    t.B = t.Bhat;
  }
  t.bhat.clear();
  t.Bhat.clear();
  t.blow.clear();
  t.Blow.clear();
  RknStepper<V2, DraggedPendulum> st(t, DraggedPendulum{});
  State<V2> s = kPendulumStart;
  st.integrate(s, h, n);
  return s;
}

// The first-order Runge-Kutta form of DOP853 on z = (q, v), z' = (v, f(q, v)), written out from the published
// coefficients: the reference that the Nystrom form must reproduce.
State<V2> dop853_first_order_step(const State<V2>& s, LD h) {
  const auto& A = methods::dop853::a();
  const std::size_t st = A.size();
  std::vector<V2> kq(st), kv(st);
  auto coef = [](const std::string& x) { return std::stold(x); };
  for (std::size_t i = 0; i + 1 < st; ++i) {  // stages 1-12; the 13th row holds the weights
    State<V2> z = s;
    for (std::size_t j = 0; j < A[i].size(); ++j)
      for (int c = 0; c < 2; ++c) {
        z.q[c] += h * coef(A[i][j]) * kq[j][c];
        z.v[c] += h * coef(A[i][j]) * kv[j][c];
      }
    kq[i] = z.v;
    DraggedPendulum{}(z.q, z.v, kv[i]);
  }
  State<V2> out = s;
  for (std::size_t j = 0; j < A[st - 1].size(); ++j)
    for (int c = 0; c < 2; ++c) {
      out.q[c] += h * coef(A[st - 1][j]) * kq[j][c];
      out.v[c] += h * coef(A[st - 1][j]) * kv[j][c];
    }
  return out;
}

}  // namespace

TEST(Rkng, CatalogHoldsTheGeneralPairsWithTheirOrders) {
  const auto pairs = general_pairs();
  ASSERT_EQ(pairs.size(), 3u);
  EXPECT_EQ(pairs[0].first, "DOP853-adaptive");
  EXPECT_EQ(pairs[1].first, "Fine4-adaptive");
  EXPECT_EQ(pairs[2].first, "Fine5-adaptive");
  for (const auto& [name, t] : pairs) {
    const MethodDef& d = resolve_method(name);
    EXPECT_TRUE(d.info.velocity && d.info.adaptive) << name;
    EXPECT_EQ(d.info.order, t.general_order) << name;
    EXPECT_LT(t.general_embedded_order, t.general_order) << name;
    // Consistency: the stage nodes are the row sums of the velocity coefficients (the stage times); the
    // weights integrate constants. (Half the squares of the nodes are the row sums of the position
    // coefficients only for pairs built with that condition, Fine's; in DOP853's Nystrom form, A^2, they are
    // sum_k a_ik c_k.)
    const LD tol = std::numeric_limits<LD>::epsilon() * 64 * (d.info.published_digits ? 1e9L : 1);
    LD sb = 0, sB = 0;
    for (std::size_t i = 0; i < t.stages(); ++i) {
      LD ra = 0, rv = 0, rac = 0;
      for (std::size_t j = 0; j < i; ++j) {
        ra += t.a[i][j];
        rv += t.av[i][j];
        rac += t.av[i][j] * t.c[j];
      }
      EXPECT_NEAR(static_cast<double>(rv), static_cast<double>(t.c[i]), static_cast<double>(tol)) << name << i;
      EXPECT_NEAR(static_cast<double>(ra), static_cast<double>(name == "DOP853-adaptive" ? rac : t.c[i] * t.c[i] / 2),
                  static_cast<double>(tol))
          << name << i;
      sb += t.b[i];
      sB += t.B[i];
    }
    EXPECT_NEAR(static_cast<double>(sb), 0.5, static_cast<double>(tol)) << name;
    EXPECT_NEAR(static_cast<double>(sB), 1.0, static_cast<double>(tol)) << name;
  }
  // Stages and forces per step (first same as last: Fine5 and DOP853 reuse their last force).
  EXPECT_EQ(resolve_method("Fine4-adaptive").info.forces_per_step, 5);
  EXPECT_EQ(resolve_method("Fine5-adaptive").info.forces_per_step, 6);
  EXPECT_EQ(resolve_method("DOP853-adaptive").info.forces_per_step, 12);
  EXPECT_TRUE(resolve_method("DOP853").info.fsal);
  EXPECT_EQ(resolve_method("RKNG5(4)").info.name, "Fine5-adaptive");
}

// The order test of the general pairs: the observed order of the main and of the embedded weights on a
// velocity-dependent force, in positions and velocities, forward and backward in time (h < 0), from
// n and 2n steps over |t| = 2 (n = 16 for DOP853, 32 for Fine's pairs: errors between 1e-8 and 3e-17, above
// the rounding of long double, 1e-19 per step) against DOP853 with 1536 steps.
TEST(Rkng, EveryGeneralPairHasItsOrderOnAVelocityDependentForceBothDirections) {
  const auto pairs = general_pairs();
  const RknTableau<LD>& dop = pairs[0].second;
  for (const LD dir : {1.0L, -1.0L}) {
    const State<V2> ref = rkng_run(dop, false, dir * 2.0L / 1536, 1536);
    for (const auto& [name, t] : pairs)
      for (const bool embedded : {false, true}) {
        const int p = embedded ? t.general_embedded_order : t.general_order;
        double eq[2], ev[2];
        for (int k = 0; k < 2; ++k) {
          const long n = (t.general_order >= 8 ? 16L : 32L) << k;
          const State<V2> s = rkng_run(t, embedded, dir * 2.0L / n, n);
          eq[k] = std::hypot(static_cast<double>(s.q[0] - ref.q[0]), static_cast<double>(s.q[1] - ref.q[1]));
          ev[k] = std::hypot(static_cast<double>(s.v[0] - ref.v[0]), static_cast<double>(s.v[1] - ref.v[1]));
        }
        const double oq = std::log2(eq[0] / eq[1]), ov = std::log2(ev[0] / ev[1]);
        std::printf("%-16s %s dir %+.0f: order %d observed q %.2f v %.2f (errors %.1e %.1e)\n", name.c_str(),
                    embedded ? "embedded" : "main    ", static_cast<double>(dir), p, oq, ov, eq[1], ev[1]);
        EXPECT_NEAR(oq, p, 0.35) << name << (embedded ? " embedded" : "") << " dir " << static_cast<double>(dir);
        EXPECT_NEAR(ov, p, 0.35) << name << (embedded ? " embedded" : "") << " dir " << static_cast<double>(dir);
      }
  }
}

// The Nystrom form of DOP853 (position coefficients A^2, weights b A) is the Runge-Kutta method itself on the
// first-order system: one step of each agrees to rounding, positions and velocities.
TEST(Rkng, Dop853NystromFormIsTheRungeKuttaMethodOnTheFirstOrderSystem) {
  const auto pairs = general_pairs();
  for (const LD h : {0.3L, -0.2L}) {
    const State<V2> a = rkng_run(pairs[0].second, false, h, 1);
    const State<V2> b = dop853_first_order_step(kPendulumStart, h);
    EXPECT_LT(max_error(a, b), 1e-17) << static_cast<double>(h);
  }
}

// A first-same-as-last pair evaluates its last stage at the step's solution (q, v) and reuses it: n steps
// cost 1 + n (s - 1) forces, and the reused force is that of the state the step starts from.
TEST(Rkng, FirstSameAsLastReusesTheForceOfTheStepEnd) {
  for (const auto& [name, t] : general_pairs()) {
    long calls = 0;
    RknTableau<LD> main = t;
    main.bhat.clear();
    main.Bhat.clear();
    main.blow.clear();
    main.Blow.clear();
    auto counted = [&calls](const V2& q, const V2& v, V2& a) {
      ++calls;
      DraggedPendulum{}(q, v, a);
    };
    RknStepper<V2, decltype(counted)> st(main, counted);
    State<V2> s = kPendulumStart;
    st.integrate(s, 0.01L, 10);
    const long per_step = static_cast<long>(t.stages()) - (t.fsal() ? 1 : 0);
    EXPECT_EQ(calls, t.fsal() ? 1 + 10 * per_step : 10 * per_step) << name;
    // A state changed between calls is not mistaken for the step end: a fresh velocity means a fresh force.
    const long before = calls;
    s.v[0] += 0.1L;
    st.integrate(s, 0.01L, 1);
    EXPECT_EQ(calls - before, static_cast<long>(t.stages())) << name;
  }
}

// A tableau without velocity coefficients refuses a velocity-dependent force; the adaptive engine runs a
// general pair on one, and its error follows the tolerance.
TEST(Rkng, AdaptivePairsFollowTheToleranceAndRknTableauxRefuseTheForce) {
  const auto dp12 = convert_tableau<LD>(std::get<RknTableau<bigcomplex>>(resolve_method("DP12").build()),
                                        [](const bigcomplex& x) { return to_scalar<LD>(x); });
  EXPECT_THROW((RknStepper<V2, DraggedPendulum>(dp12, DraggedPendulum{})), std::invalid_argument);
  const auto pairs = general_pairs();
  const State<V2> ref = rkng_run(pairs[0].second, false, 2.0L / 1536, 1536);
  for (const auto& [name, t] : pairs) {
    double err[2];
    long evals[2];
    for (int k = 0; k < 2; ++k) {
      AdaptiveOptions o;
      o.rtol = o.atol = k == 0 ? 1e-6 : 1e-9;
      if (k == 1) o.h0 = 1.0;  // a first step far too long: rejected
      AdaptiveRknIntegrator<V2, DraggedPendulum> ai(t, DraggedPendulum{}, o);
      // DOP853's stretched estimate (orders 5 and 3 combined) is controlled as an error of order 7.
      EXPECT_EQ(ai.error_order(), t.blow.empty() ? t.general_embedded_order : t.general_order - 1) << name;
      EXPECT_EQ(ai.method_order(), t.general_order) << name;
      State<V2> s = kPendulumStart;
      const AdaptiveStats st = ai.integrate_to(s, 0.0L, 2.0L);
      err[k] = max_error(s, ref);
      evals[k] = st.force_evals;
      // Two forces for the first step size (unless given); every attempted step its stages, less the first force where
      // the pair reuses it (from the last step's end, or from its start after a rejection).
      const long s_ = static_cast<long>(t.stages()), attempts = st.accepted + st.rejected;
      const long start = k == 0 ? 2 : 0;
      EXPECT_EQ(st.force_evals, t.fsal() ? start + s_ + (attempts - 1) * (s_ - 1) : start + attempts * s_) << name;
      if (k == 1) {
        EXPECT_GE(st.rejected, 1) << name;
      }
    }
    std::printf("%-16s tol 1e-6 -> 1e-9: error %.2e -> %.2e, forces %ld -> %ld\n", name.c_str(), err[0], err[1],
                evals[0], evals[1]);
    EXPECT_LT(err[0], 1e-6) << name;
    EXPECT_LT(err[1], 1e-9) << name;
    EXPECT_GT(err[0], 1e-6 * 1e-4) << name;  // not a controller that ignores the tolerance
    EXPECT_GT(evals[1], evals[0]) << name;
  }
}

// DOP853's stretched estimate: the third-order weights are a solution of order 3 (observed on the velocity-
// dependent force), and the combined estimate err5^2 / sqrt(err5^2 + 0.01 err3^2) of one step shrinks like
// h^12 / h^4 = h^8 (the controller's exponent 1/8, error order 7): halving the step divides it by about 2^8.
TEST(Rkng, Dop853StretchedEstimateHasTheOrderOfTheMainSolution) {
  const auto pairs = general_pairs();
  RknTableau<LD> t = pairs[0].second;
  ASSERT_FALSE(t.blow.empty());
  {
    RknTableau<LD> low = t;
    low.bhat = low.blow;
    low.Bhat = low.Blow;
    low.blow.clear();
    low.Blow.clear();
    const State<V2> ref = rkng_run(t, false, 2.0L / 1536, 1536);
    double e[2];
    for (int k = 0; k < 2; ++k) {
      const long n = 64L << k;
      const State<V2> s = rkng_run(low, true, 2.0L / n, n);
      e[k] = max_error(s, ref);
    }
    EXPECT_NEAR(std::log2(e[0] / e[1]), 3, 0.35);
  }
  RknTableau<LD> full = pairs[0].second;
  RknStepper<V2, DraggedPendulum> st(full, DraggedPendulum{});
  auto stretched = [&](LD h) {
    State<V2> y = kPendulumStart, err;
    st.step_with_error(y, h, err);
    auto norm = [](const State<V2>& x) {
      return std::sqrt(static_cast<double>(x.q[0] * x.q[0] + x.q[1] * x.q[1] + x.v[0] * x.v[0] + x.v[1] * x.v[1]));
    };
    const double e5 = norm(err), e3 = norm(st.low_error());
    return e5 * e5 / std::sqrt(e5 * e5 + 0.01 * e3 * e3);
  };
  const double r = std::log2(stretched(0.1L) / stretched(0.05L));
  std::printf("DOP853 stretched estimate: it shrinks like h^%.2f\n", r);
  EXPECT_NEAR(r, 8, 0.35);
}
