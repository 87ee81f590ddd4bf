// Velocity-dependent forces with exact flows (velocity/flows.hpp, velocity/solve.hpp): a rotating frame (the
// Arenstorf orbit of the restricted three-body problem), a charged particle in a uniform magnetic field (the exact
// helix with the E x B drift, a Penning trap) and linear friction (the damped driven oscillator). Catalog methods
// of orders 2 to 8 show their order in both time directions, in positions and velocities, against the exact
// solution or a long double reference; the symplectic methods keep the Jacobi integral without drift; the
// friction splitting contracts phase space by exactly e^{-gamma t}; methods that do not apply are refused.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <string>
#include <vector>

#include "nystrom/methods/catalog.hpp"
#include "nystrom/velocity/solve.hpp"

using namespace nystrom;
using namespace nystrom::velocity;

namespace {

/// Largest component difference of q and v between a result and a reference.
double state_error(const FlowResult& r, const FlowResult& ref) {
  double e = 0;
  for (std::size_t i = 0; i < r.q.size(); ++i)
    e = std::max({e, std::abs(r.q[i] - ref.q[i]), std::abs(r.v[i] - ref.v[i])});
  return e;
}

struct OrderCase {
  std::string method;
  int order;
};

/// log2 of the error ratio between n and 2 n steps.
double slope(double e1, double e2) { return std::log2(e1 / e2); }

// ---- rotating frame ----------------------------------------------------------------------------------------

TEST(RotatingFrame, DriftSolvesTheCoriolisAndCentrifugalEquation) {
  // Without potential, q'' = -2 Omega x v - Omega x (Omega x q): central second differences of the exact drift
  // agree with the right-hand side to O(h^2), and the velocity is the derivative of the position.
  using R = long double;
  RotatingFrameFlows<R> f({R(0.3), R(-0.2), R(0.9)}, [](const Vec3<R>&, Vec3<R>& g) { g = {0, 0, 0}; });
  const std::vector<R> s0{R(0.7), R(-0.4), R(0.2), R(0.1), R(0.5), R(-0.3)};
  const R h = R(1e-4);
  auto at = [&](R t) {
    auto s = s0;
    f.apply_a(s, t);
    return s;
  };
  const auto m = at(-h), c = at(0), p = at(h);
  const Vec3<R> om = f.omega(), q{c[0], c[1], c[2]}, v{c[3], c[4], c[5]};
  const Vec3<R> ov = velocity::detail::cross(om, v), oq = velocity::detail::cross(om, q);
  const Vec3<R> ooq = velocity::detail::cross(om, oq);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(static_cast<double>((p[i] - 2 * c[i] + m[i]) / (h * h)), static_cast<double>(-2 * ov[i] - ooq[i]),
                1e-7);
    EXPECT_NEAR(static_cast<double>((p[i] - m[i]) / (2 * h)), static_cast<double>(v[i]), 1e-8);
  }
  // the flow is a group: e^{aA} e^{bA} = e^{(a+b)A}, also for a negative coefficient
  auto s = s0;
  f.apply_a(s, R(0.7));
  f.apply_a(s, R(-1.9));
  const auto t = at(R(-1.2));
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(static_cast<double>(s[i]), static_cast<double>(t[i]), 1e-15);
}

TEST(RotatingFrame, ArenstorfInitialStateAndPeriodAreHairerNorsettWanners) {
  const auto p = arenstorf<long double>();
  EXPECT_EQ(p.q0[0], 0.994L);
  EXPECT_EQ(p.v0[1], -2.00158510637908252240537862224L);
  EXPECT_EQ(p.period, 17.0652165601579625588917206249L);
  // one period with KL8 returns to the start (the orbit is periodic)
  const FlowResult r = solve(p, "KL8", p.period / 20000, 20000);
  EXPECT_LT(r.return_error, 1e-8);
  EXPECT_NEAR(r.periods, 1.0, 1e-15);
  EXPECT_LT(std::abs(r.v[1] - static_cast<double>(p.v0[1])), 1e-6);
}

/// Observed order on Arenstorf over a quarter of the period (through the close approach to the Moon at the
/// start), forward and backward, in double against a long double reference (KL8 with 25600 steps, whose error is
/// below 1e-15). The close approach makes the convergence uneven from one doubling to the next: the slope is
/// taken over two doublings (n and 4 n steps).
TEST(RotatingFrame, ArenstorfObservedOrderBothDirections) {
  const auto pd = arenstorf<double>();
  const auto pl = arenstorf<long double>();
  const double span = 0.25 * static_cast<double>(pl.period);
  const std::vector<std::pair<OrderCase, long>> cases{
      {{"VV", 2}, 20000}, {{"FR", 4}, 2000}, {{"RKNa14", 6}, 1000}, {{"KL8", 8}, 1600}, {{"M8", 8}, 1600}};
  for (double dir : {1.0, -1.0}) {
    const long nref = 25600;
    const FlowResult ref = solve(pl, "KL8", static_cast<long double>(dir * span) / nref, nref);
    for (const auto& [c, n] : cases) {
      const FlowResult a = solve(pd, c.method, dir * span / static_cast<double>(n), n);
      const FlowResult b = solve(pd, c.method, dir * span / static_cast<double>(4 * n), 4 * n);
      const double ea = state_error(a, ref), eb = state_error(b, ref);
      const double s = slope(ea, eb) / 2;
      EXPECT_GT(s, c.order - 0.5) << c.method << " dir " << dir << " errors " << ea << " " << eb;
      EXPECT_LT(s, c.order + 1.0) << c.method << " dir " << dir << " errors " << ea << " " << eb;
      EXPECT_LT(eb, 1e-3) << c.method;
    }
  }
}

TEST(RotatingFrame, SymplecticMethodKeepsTheJacobiIntegralWithoutDrift) {
  // Ten periods with FR: the Jacobi integral's error over the last period is no larger than over the first
  // (bounded oscillation, no secular drift).
  const auto p = arenstorf<double>();
  const long per = 20000;
  const FlowResult fr = solve(p, "FR", p.period / per, 10 * per, 100);
  ASSERT_EQ(fr.samples.size(), 101u);
  EXPECT_TRUE(fr.symplectic);
  double first = 0, last = 0;  // the largest error over the first and over the last period
  for (std::size_t i = 0; i < fr.samples.size(); ++i) {
    const double d = std::abs(fr.samples[i].invariant - fr.invariant0);
    if (i <= 10) first = std::max(first, d);
    if (i >= 90) last = std::max(last, d);
  }
  EXPECT_GT(first, 0);
  EXPECT_LT(last, 2 * first) << "first period " << first << ", last " << last;
  EXPECT_LT(fr.invariant_error, 1e-4);
  EXPECT_EQ(fr.invariant_name, "Jacobi integral");
}

// ---- magnetic field -------------------------------------------------------------------------------------

TEST(Magnetic, GyrationIsTheExactHelix) {
  // Without electric field a single drift of any length is the exact solution (any B direction).
  const Vec3<double> b{0.3, -0.6, 1.1}, q0{1, 2, -1}, v0{0.4, -0.2, 0.7};
  auto p = helix<double>(b, {0, 0, 0}, q0, v0);
  for (double t : {0.3, -5.0, 40.0}) {
    std::vector<double> s{q0[0], q0[1], q0[2], v0[0], v0[1], v0[2]};
    MagneticFlows<double> f(b, {});
    f.apply_a(s, t);
    Vec3<double> q = q0, v = v0;
    p.exact(t, q, v);
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(s[i], q[i], 1e-13);
      EXPECT_NEAR(s[3 + i], v[i], 1e-13);
    }
  }
  // and v' = v x b: the central difference of v
  std::vector<double> sp{q0[0], q0[1], q0[2], v0[0], v0[1], v0[2]}, sm = sp;
  MagneticFlows<double> f(b, {});
  f.apply_a(sp, 1e-5);
  f.apply_a(sm, -1e-5);
  const auto vxb = velocity::detail::cross(v0, b);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR((sp[3 + i] - sm[3 + i]) / 2e-5, vxb[i], 1e-9);
    EXPECT_NEAR((sp[i] - sm[i]) / 2e-5, v0[i], 1e-9);
  }
}

TEST(Magnetic, HelixWithDriftObservedOrderBothDirections) {
  // Uniform B (oblique) and uniform E: against the exact helix with the E x B drift over 7.3 gyrations. (Over
  // whole gyrations the splitting error, a translation per step, averages out: the methods are exact there.)
  using R = long double;
  const Vec3<R> b{R(0.2), 0, 1}, e{R(0.3), R(-0.1), R(0.05)}, q0{1, 0, 0}, v0{0, 1, R(0.2)};
  const auto p = helix<R>(b, e, q0, v0);
  const R span = R(7.3) * 2 * R(3.14159265358979323846L) / velocity::detail::norm(b);
  const std::vector<std::pair<OrderCase, long>> cases{{{"VV", 2}, 2000}, {{"PV", 2}, 2000}, {{"FR", 4}, 400},
                                                      {{"KL6", 6}, 200}, {{"KL8", 8}, 100}, {{"M8", 8}, 50}};
  for (R dir : {R(1), R(-1)})
    for (const auto& [c, n] : cases) {
      const FlowResult a = solve(p, c.method, dir * span / n, n);
      const FlowResult bb = solve(p, c.method, dir * span / (2 * n), 2 * n);
      const double ea = std::max(a.position_error, a.velocity_error);
      const double eb = std::max(bb.position_error, bb.velocity_error);
      EXPECT_GT(slope(ea, eb), c.order - 0.35) << c.method << " " << ea << " " << eb;
      EXPECT_LT(slope(ea, eb), c.order + 1.0) << c.method << " " << ea << " " << eb;
      EXPECT_GT(bb.velocity_error, 0) << c.method;
      EXPECT_LT(bb.position_error, 1e-3) << c.method;
      EXPECT_NEAR(a.time, static_cast<double>(dir * span), 1e-9);
    }
}

TEST(Magnetic, PenningTrapAgainstTheExactSolution) {
  // The quadrupole force is not uniform; M8 and KL8 reach order 8 and the energy stays put with KL8.
  const auto p = penning<long double>(1, 0.02L, {1, 0, 0.5L}, {0, 1, 0.1L});
  const long double span = 50 * 2 * 3.14159265358979323846L;
  for (const std::string m : {"KL8", "M8"}) {
    const FlowResult a = solve(p, m, span / 400, 400), b = solve(p, m, span / 800, 800);
    const double ea = std::max(a.position_error, a.velocity_error);
    const double eb = std::max(b.position_error, b.velocity_error);
    EXPECT_GT(slope(ea, eb), 7.65) << m << " " << ea << " " << eb;
    EXPECT_LT(eb, 1e-8) << m;
  }
  const FlowResult k = solve(p, "KL8", span / 400, 400, 50);
  EXPECT_LT(k.invariant_error, 1e-9);
}

// ---- friction -----------------------------------------------------------------------------------------------

TEST(Damped, FreeFrictionFlowIsExact) {
  // No force: every splitting is the exact flow, for either sign of the step.
  DampedProblem<double> p;
  p.gamma = 0.7;
  p.q0 = {1, -2};
  p.v0 = {0.5, 3};
  p.exact = [g = p.gamma](double t, std::vector<double>& q, std::vector<double>& v) {
    for (std::size_t i = 0; i < q.size(); ++i) {
      q[i] += v[i] * (1 - std::exp(-g * t)) / g;
      v[i] *= std::exp(-g * t);
    }
  };
  for (double dt : {0.1, -0.1}) {
    const FlowResult r = solve(p, "KL8", dt, 50);
    EXPECT_LT(r.position_error, 1e-12);
    EXPECT_LT(r.velocity_error, 1e-12);
  }
}

TEST(Damped, DrivenOscillatorObservedOrderBothDirections) {
  using R = long double;
  const auto p = damped_oscillator<R>(R(0.3), 1, R(0.5), R(0.7), 1, 0);
  const R span = 10;
  const std::vector<std::pair<OrderCase, long>> cases{{{"VV", 2}, 400}, {{"FR", 4}, 100}, {{"KL6", 6}, 50},
                                                      {{"KL8", 8}, 40}, {{"M6", 6}, 50},  {{"M8", 8}, 40}};
  for (R dir : {R(1), R(-1)})
    for (const auto& [c, n] : cases) {
      const FlowResult a = solve(p, c.method, dir * span / n, n);
      const FlowResult b = solve(p, c.method, dir * span / (2 * n), 2 * n);
      const double ea = std::max(a.position_error, a.velocity_error);
      const double eb = std::max(b.position_error, b.velocity_error);
      EXPECT_GT(slope(ea, eb), c.order - 0.35) << c.method << " " << ea << " " << eb;
      EXPECT_LT(slope(ea, eb), c.order + 1.0) << c.method << " " << ea << " " << eb;
      EXPECT_LT(b.position_error, 1e-3) << c.method;
    }
}

TEST(Damped, SplittingIsConformallySymplectic) {
  // On the linear oscillator q'' = -gamma q' - q the one-step map is linear; its determinant is e^{-gamma h}
  // for a splitting (the exact contraction), not for a multi-product expansion.
  const double gamma = 0.4, h = 0.3;
  auto det = [&](const std::string& m) {
    double col[2][2];
    for (int j = 0; j < 2; ++j) {
      DampedProblem<double> p;
      p.gamma = gamma;
      p.q0 = {j == 0 ? 1.0 : 0.0};
      p.v0 = {j == 1 ? 1.0 : 0.0};
      p.force = [](double, const std::vector<double>& q, std::vector<double>& a) { a[0] = -q[0]; };
      const FlowResult r = solve(p, m, h, 1);
      col[j][0] = r.q[0];
      col[j][1] = r.v[0];
    }
    return col[0][0] * col[1][1] - col[1][0] * col[0][1];
  };
  for (const std::string m : {"VV", "FR", "KL8"}) EXPECT_NEAR(det(m), std::exp(-gamma * h), 1e-15) << m;
  EXPECT_GT(std::abs(det("M4") - std::exp(-gamma * h)), 1e-7);
}

// ---- the whole catalog ------------------------------------------------------------------------------------

/// Every method of the catalog either runs on these flows with its declared order (the Penning trap, long double,
/// both time directions, positions and velocities against the exact solution; the damped driven oscillator too up
/// to order 10, beyond which its errors reach the long double floor before the asymptotic regime) or is refused:
/// the RKN tableaux, the adaptive methods and those with complex coefficients.
TEST(VelocityFlows, EveryApplicableCatalogMethodShowsItsOrder) {
  using R = long double;
  const auto trap = penning<R>(1, R(0.02), {1, 0, R(0.5)}, {0, 1, R(0.1)});
  const auto osc = damped_oscillator<R>(R(0.3), 1, R(0.5), R(0.7), 1, 0);
  int ran = 0;
  for (const auto& def : catalog()) {
    const std::string m = def.info.name;
    const bool refuse = def.info.family == "rkn" || def.info.adaptive || def.info.complex;
    if (refuse) {
      EXPECT_THROW(resolve_velocity_method(m, 64, "long-double"), invalid_input) << m;
      continue;
    }
    ++ran;
    for (R dir : {R(1), R(-1)}) {
      // the first n (doubling from 4) whose error is below `below`, and 2 n (the optimised methods, e.g.
      // RKNb6, reach their asymptotic slope late: their leading error term is small; orders above 10 reach the
      // rounding floor within a few doublings)
      auto measure = [&](double below, auto error) {
        long n = 4;
        double ea = error(n);
        while (ea > below && n < 100000) ea = error(n *= 2);
        return std::pair{ea, error(2 * n)};
      };
      // the trap's error: the largest over four evenly spaced times (at one time alone the oscillating modes'
      // errors can partly cancel for some n, which hides the asymptotic slope)
      const auto [ta, tb] = measure(def.info.order > 10 ? 1e-6 : 1e-9, [&](long n) {
        const FlowResult r = solve(trap, m, dir * R(30) / static_cast<R>(n), n, 4);
        double e = 0;
        for (std::size_t i = 1; i < r.samples.size(); ++i) {
          Vec3<R> q = trap.q0, v = trap.v0;
          trap.exact(dir * R(30) * static_cast<R>(i) / 4, q, v);
          for (std::size_t c = 0; c < 3; ++c)
            e = std::max({e, std::abs(r.samples[i].q[c] - static_cast<double>(q[c])),
                          std::abs(r.samples[i].v[c] - static_cast<double>(v[c]))});
        }
        return e;
      });
      EXPECT_GT(slope(ta, tb), def.info.order - 0.4) << m << " penning " << ta << " " << tb;
      EXPECT_LT(slope(ta, tb), def.info.order + 1.2) << m << " penning " << ta << " " << tb;
      if (def.info.order > 10) continue;
      const auto [da, db] = measure(1e-7, [&](long n) {
        const FlowResult r = solve(osc, m, dir * R(10) / static_cast<R>(n), n);
        return std::max(r.position_error, r.velocity_error);
      });
      EXPECT_GT(slope(da, db), def.info.order - 0.4) << m << " damped " << da << " " << db;
      EXPECT_LT(slope(da, db), def.info.order + 1.0) << m << " damped " << da << " " << db;
    }
  }
  EXPECT_GE(ran, 28);
}

// ---- methods and input ---------------------------------------------------------------------------------

TEST(VelocityFlows, MethodsOutsideTheirDomainAreRefused) {
  const auto p = arenstorf<double>();
  EXPECT_THROW(solve(p, "nonsense", 1e-3, 10), invalid_input);
  for (const std::string m : {"N4", "DP12-adaptive", "AC1", "4A", "MPE-adaptive"}) {
    try {
      solve(p, m, 1e-3, 10);
      ADD_FAILURE() << m << " was accepted";
    } catch (const invalid_input& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
      EXPECT_NE(what.find("KL8"), std::string::npos) << what;
    }
  }
  EXPECT_THROW(solve(p, "KL8", 0.0, 10), invalid_input);
  EXPECT_THROW(solve(p, "KL8", std::nan(""), 10), invalid_input);
  auto bad = p;
  bad.q0[0] = INFINITY;
  EXPECT_THROW(solve(bad, "KL8", 1e-3, 10), invalid_input);
  BuiltinSetup s;
  s.problem = "nope";
  EXPECT_THROW(solve_builtin<double>(s), invalid_input);
  s.problem = "penning";
  s.b = {1, 0, 1};
  EXPECT_THROW(solve_builtin<double>(s), invalid_input);
  s = {};
  s.problem = "damped";
  s.q0 = {1, 2};
  EXPECT_THROW(solve_builtin<double>(s), invalid_input);
}

TEST(VelocityFlows, BuiltinDefaultsAreCheapAndAccurate) {
  for (const auto& name : builtin_names()) {
    BuiltinSetup s;
    s.problem = name;
    const FlowResult r = solve_builtin<double>(s);
    EXPECT_EQ(r.method, "KL8") << name;
    if (name == "arenstorf") {
      EXPECT_LT(r.return_error, 1e-8);
    } else {
      EXPECT_LT(std::max(r.position_error, r.velocity_error), 1e-6) << name;
    }
    s.periods = -1;  // backward
    const FlowResult b = solve_builtin<double>(s);
    EXPECT_LT(b.time, 0) << name;
  }
}

}  // namespace
