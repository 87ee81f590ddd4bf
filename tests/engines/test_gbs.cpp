// The Gragg-Bulirsch-Stoer reference integrator: convergence to the analytic Kepler solution at its
// tolerance, in double and long double, every step-size sequence, the N-body two-body problem, bad input;
// a time-dependent force sees only times within the span, forward and backward, through the engine and
// through solve().
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "nystrom/engines/gbs.hpp"
#include "nystrom/problems/kepler.hpp"
#include "nystrom/problems/nbody.hpp"
#include "nystrom/solve/solve.hpp"

using namespace nystrom;

namespace {

template <class T>
T kepler_error(double ecc, double tol, double t_end, GbsSequence seq = GbsSequence::harmonic, long* evals = nullptr) {
  const KeplerProblem<T> prob{T(ecc)};
  auto s = prob.initial_state();
  GbsOptions o;
  o.rtol = o.atol = tol;
  o.sequence = seq;
  GbsIntegrator<std::array<T, 2>, KeplerForce> g(KeplerForce{}, o);
  g.integrate_to(s, T(t_end));
  if (evals) *evals = g.force_evals();
  const auto ex = prob.exact(T(t_end));
  using std::abs;
  using std::hypot;
  T e = 0;
  for (int i = 0; i < 2; ++i) e = std::max({e, abs(s.q[i] - ex.q[i]), abs(s.v[i] - ex.v[i])});
  return e;
}

}  // namespace

TEST(Gbs, ConvergesToTheKeplerSolutionAtItsTolerance) {
  // Spans like the steps of the local-error experiment, started on the exact orbit: the error is within a
  // few times the tolerance.
  for (double ecc : {0.2, 0.7})
    for (double tol : {1e-8, 1e-11, 1e-14}) {
      const KeplerProblem<double> prob{ecc};
      for (double t0 : {0.0, 1.0, 2.5, 4.0})
        for (double span : {0.01, 0.1, 0.5}) {
          auto s = prob.exact(t0);
          GbsOptions o;
          o.rtol = o.atol = tol;
          GbsIntegrator<std::array<double, 2>, KeplerForce> g(KeplerForce{}, o);
          g.integrate_to(s, span);
          const auto ex = prob.exact(t0 + span);
          for (int i = 0; i < 2; ++i) {
            EXPECT_LT(std::abs(s.q[i] - ex.q[i]), 10 * tol) << ecc << " " << tol << " " << t0 << " " << span;
            EXPECT_LT(std::abs(s.v[i] - ex.v[i]), 10 * tol) << ecc << " " << tol << " " << t0 << " " << span;
          }
        }
    }
  // Over 3.3 periods the global error (local errors carried along the orbit) falls with the tolerance.
  const double t = 3.3 * 2 * M_PI;
  double prev = 1;
  for (double tol : {1e-6, 1e-9, 1e-12, 1e-14}) {
    const double e = kepler_error<double>(0.2, tol, t);
    EXPECT_LT(e, 1000 * tol) << "tol = " << tol;
    EXPECT_LT(e, prev) << "tol = " << tol;
    prev = e;
  }
}

TEST(Gbs, GlobalErrorIsProportionalToTheTolerance) {
  // The controller keeps the error of every step (of any length: the order adapts) at the tolerance
  // (HNW II.9), so over a fixed time the global error is tol times the growth of local errors along
  // the orbit, which does not depend on tol: the slope of log(error) against log(tol) is 1, up to the
  // slow growth of the number of steps, N ~ tol^(-1/(2k)), k the number of columns used (6-8 here).
  // Kepler e = 0.2 over 3.3 periods in long double (tolerances 1e-8 ... 1e-16, far from its round-off).
  // Measured: error / tol between 12 and 111 (the orbit amplifies the local errors of about 100 steps),
  // slope 0.92 (= 1 - 1/(2k) for k = 6). An estimate too pessimistic by a power of the step size puts
  // the error below tol, one too optimistic above 300 tol, and either bends the slope.
  const double t = 3.3 * 2 * M_PI;
  std::vector<double> x, y;
  for (double tol : {1e-8, 1e-10, 1e-12, 1e-14, 1e-16}) {
    const double e = static_cast<double>(kepler_error<long double>(0.2, tol, t));
    std::printf("[ gbs      ] tol %.0e  error %.3e  error/tol %.2f\n", tol, e, e / tol);
    EXPECT_LT(e, 300 * tol) << "tol = " << tol;
    EXPECT_GT(e, tol) << "tol = " << tol;
    x.push_back(std::log10(tol));
    y.push_back(std::log10(e));
  }
  double mx = 0, my = 0;
  for (std::size_t i = 0; i < x.size(); ++i) mx += x[i] / x.size(), my += y[i] / y.size();
  double sxy = 0, sxx = 0;
  for (std::size_t i = 0; i < x.size(); ++i) sxy += (x[i] - mx) * (y[i] - my), sxx += (x[i] - mx) * (x[i] - mx);
  const double slope = sxy / sxx;
  std::printf("[ gbs      ] slope of log(error) against log(tol): %.3f\n", slope);
  EXPECT_NEAR(slope, 1.0, 0.15);
}

TEST(Gbs, ExtendedPrecisionGoesBelowDouble) {
  const KeplerProblem<long double> prob{0.2L};
  for (long double t0 : {0.0L, 1.0L, 2.5L}) {
    auto s = prob.exact(t0);
    GbsOptions o;
    o.rtol = o.atol = 1e-17;
    GbsIntegrator<std::array<long double, 2>, KeplerForce> g(KeplerForce{}, o);
    g.integrate_to(s, 0.3L);
    const auto ex = prob.exact(t0 + 0.3L);
    for (int i = 0; i < 2; ++i) EXPECT_LT(std::abs(s.q[i] - ex.q[i]), 2e-16L);
  }
  EXPECT_LT(kepler_error<long double>(0.2, 1e-17, 3.3 * 2 * M_PI), 1e-14L);
}

TEST(Gbs, EverySequenceConverges) {
  for (auto seq : {GbsSequence::harmonic, GbsSequence::romberg, GbsSequence::bulirsch}) {
    long evals = 0;
    EXPECT_LT(kepler_error<double>(0.2, 1e-11, 5.0, seq, &evals), 1e-9);
    EXPECT_GT(evals, 0);
  }
  EXPECT_EQ(gbs_sequence(GbsSequence::harmonic, 4), (std::vector<long>{2, 4, 6, 8}));
  EXPECT_EQ(gbs_sequence(GbsSequence::romberg, 4), (std::vector<long>{2, 4, 8, 16}));
  EXPECT_EQ(gbs_sequence(GbsSequence::bulirsch, 7), (std::vector<long>{2, 4, 6, 8, 12, 16, 24}));
  EXPECT_THROW(parse_gbs_sequence("fibonacci"), std::invalid_argument);
}

TEST(Gbs, ManyShortSpansAgreeWithOneLongSpan) {
  const KeplerProblem<double> prob{0.2};
  GbsOptions o;
  o.rtol = o.atol = 1e-13;
  auto a = prob.initial_state(), b = a;
  GbsIntegrator<std::array<double, 2>, KeplerForce> g1(KeplerForce{}, o), g2(KeplerForce{}, o);
  g1.integrate(a, 0.01, 700);
  g2.integrate_to(b, 7.0);
  const auto ex = prob.exact(7.0);
  EXPECT_LT(std::abs(a.q[0] - ex.q[0]), 1e-11);
  EXPECT_LT(std::abs(b.q[0] - ex.q[0]), 1e-11);
}

// The default first step (initial_step = 0) is the first call's span: no step size before the first call, and
// that call bitwise the one of an engine told the span, force evaluations and rejections included.
TEST(Gbs, TheDefaultFirstStepIsTheFirstCallsSpan) {
  const KeplerProblem<double> prob{0.2};
  for (const double span : {7.0, 0.3}) {
    SCOPED_TRACE(span);
    GbsOptions o;
    o.rtol = o.atol = 1e-11;
    GbsIntegrator<std::array<double, 2>, KeplerForce> by_default(KeplerForce{}, o);
    EXPECT_EQ(by_default.step_size(), 0.0);
    o.initial_step = span;
    GbsIntegrator<std::array<double, 2>, KeplerForce> told(KeplerForce{}, o);
    EXPECT_EQ(told.step_size(), span);
    auto a = prob.initial_state(), b = a;
    by_default.integrate_to(a, span);
    told.integrate_to(b, span);
    EXPECT_EQ(a.q, b.q);
    EXPECT_EQ(a.v, b.v);
    EXPECT_EQ(by_default.force_evals(), told.force_evals());
    EXPECT_EQ(by_default.rejected(), told.rejected());
    EXPECT_GT(by_default.steps(), 0);
  }
}

// The columns after an accepted step, from the work per unit step W_j of j columns (HNW I, sec. II.9, ODEX): one
// fewer when W_{k-1} < 0.8 W_k (from three columns), else one more when W_k < 0.9 W_{k-1} and the last attempt was
// not rejected, within [2, kmax - 1]. Each threshold on both sides, with the other columns' work far off.
TEST(Gbs, ColumnsFollowTheLeastWorkPerUnitStep) {
  auto next = [](int kc, std::vector<double> W, bool rejected = false) {
    return detail::gbs_next_columns(kc, W, 8, rejected);
  };
  //                      W_0 W_1  W_2   W_3   W_4  W_5
  EXPECT_EQ(next(4, {0, 0, 10.0, 0.79, 1.0, 0.1}), 3);
  EXPECT_EQ(next(4, {0, 0, 0.01, 0.81, 1.0, 0.1}), 4);
  EXPECT_EQ(next(4, {0, 0, 10.0, 1.0, 0.89, 10.0}), 5);
  EXPECT_EQ(next(4, {0, 0, 0.01, 1.0, 0.91, 0.01}), 4);
  EXPECT_EQ(next(4, {0, 0, 10.0, 1.0, 0.89, 10.0}, true), 4);  // not up after a rejection
  EXPECT_EQ(next(4, {0, 0, 10.0, 0.79, 1.0, 0.1}, true), 3);   // down also after one
  EXPECT_EQ(next(2, {0, 1.0, 0.89, 10.0}), 3);                 // two columns: up only
  EXPECT_EQ(next(2, {0, 0.01, 0.91, 0.01}), 2);
  EXPECT_EQ(next(7, {0, 0, 1, 1, 1, 1, 10.0, 0.5, 0.1}), 7);  // at most kmax - 1
  EXPECT_EQ(next(3, {0, 0, 0.5, 1.0, 0.1}), 2);               // down to two, the fewest
}

// A resume point must be one a run can have stopped at: 0 < t < span (both ends excluded), a finite step H > 0 and
// 2 to kmax - 1 columns; anything else is refused with one line, and a good one is kept.
TEST(Gbs, ResumePointsOutsideTheSpanAreRefused) {
  GbsOptions o;
  o.max_columns = 8;
  GbsIntegrator<std::array<double, 2>, KeplerForce> g(KeplerForce{}, o);
  using P = GbsIntegrator<std::array<double, 2>, KeplerForce>::ResumePoint;
  const double inf = std::numeric_limits<double>::infinity();
  for (const P& p :
       {P{0.0, 1.0, 0.1, 4, false, true}, P{1.0, 1.0, 0.1, 4, false, true}, P{-0.5, 1.0, 0.1, 4, false, true},
        P{0.5, 1.0, 0.0, 4, false, true}, P{0.5, 1.0, inf, 4, false, true}, P{0.5, 1.0, 0.1, 1, false, true},
        P{0.5, 1.0, 0.1, 8, false, true}}) {
    try {
      g.set_resume_point(p);
      ADD_FAILURE() << "t " << p.t << " span " << p.span << " H " << p.H << " k " << p.k << " accepted";
    } catch (const invalid_input& e) {
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
    }
  }
  g.set_resume_point(P{0.5, 1.0, 0.1, 7, false, true});
  EXPECT_TRUE(g.resume_point().valid);
  EXPECT_EQ(g.resume_point().t, 0.5);
  g.set_resume_point(P{0.0, 0.0, 0.0, 0, false, false});  // an invalid point is no point: nothing to check
  EXPECT_FALSE(g.resume_point().valid);
}

TEST(Gbs, FollowsTheTwoBodyProblemAsAnNBodySystem) {
  auto p = two_body(0.2);
  NBodyForce<double> f(p.m, 0.0);
  GbsOptions o;
  o.rtol = o.atol = 1e-13;
  GbsIntegrator<std::vector<double>, NBodyForce<double>> g(f, o);
  const double t = 1.7 * 2 * M_PI;
  g.integrate_to(p.s, t);
  const auto ex = KeplerProblem<double>(0.2).exact(t);
  // relative coordinates = body 1 - body 0
  EXPECT_NEAR(p.s.q[1] - p.s.q[0], ex.q[0], 1e-10);
  EXPECT_NEAR(p.s.q[3] - p.s.q[2], ex.q[1], 1e-10);
  EXPECT_NEAR(p.s.v[1] - p.s.v[0], ex.v[0], 1e-10);
}

TEST(Gbs, RejectsBadOptionsAndStopsOnASingularity) {
  GbsOptions o;
  o.rtol = o.atol = 1e-17;
  EXPECT_THROW((GbsIntegrator<std::array<double, 2>, KeplerForce>(KeplerForce{}, o)), std::invalid_argument);
  o.rtol = o.atol = -1;
  EXPECT_THROW((GbsIntegrator<std::array<double, 2>, KeplerForce>(KeplerForce{}, o)), std::invalid_argument);
  o = GbsOptions{};
  o.max_columns = 2;
  EXPECT_THROW((GbsIntegrator<std::array<double, 2>, KeplerForce>(KeplerForce{}, o)), std::invalid_argument);
  o = GbsOptions{};
  GbsIntegrator<std::array<double, 2>, KeplerForce> g(KeplerForce{}, o);
  auto s = KeplerProblem<double>(0.2).initial_state();
  EXPECT_THROW(g.integrate_to(s, -1.0), std::invalid_argument);
  // Head-on collision of two point masses at rest: the step size collapses; GBS must stop with an error.
  NBodyForce<double> f({0.5, 0.5}, 0.0);
  State<std::vector<double>> c{{-1, 1, 0, 0, 0, 0}, {0, 0, 0, 0, 0, 0}};
  GbsIntegrator<std::vector<double>, NBodyForce<double>> gc(f, o);
  EXPECT_THROW(gc.integrate_to(c, 10.0), step_size_underflow);
}

namespace {

// The driven oscillator q'' = -q + cos 2t from (q0, v0) at t0: q + cos(2t)/3 is a harmonic oscillation.
double driven_exact(double t0, double q0, double v0, double t) {
  const double p0 = q0 + std::cos(2 * t0) / 3, dp0 = v0 - 2 * std::sin(2 * t0) / 3;
  return p0 * std::cos(t - t0) + dp0 * std::sin(t - t0) - std::cos(2 * t) / 3;
}

// The times a time-dependent force was called at, against the span [lo, hi].
struct TimeRange {
  double lo, hi;
  long outside = 0, calls = 0;
  double worst = 0;  // farthest distance outside
  void see(double t) {
    ++calls;
    if (t < lo || t > hi) {
      ++outside;
      worst = std::max(worst, std::max(lo - t, t - hi));
    }
  }
};

}  // namespace

TEST(Gbs, ClockCoordinateStaysWithinTheSpanForwardAndBackward) {
  // The engine on (x, tau) with tau the time coordinate (velocity 1, acceleration 0); backward in time as
  // solve() runs it: tau = -t on the time-reversed problem (v -> -v).
  using V = std::array<double, 2>;
  const double t0 = 0.3;
  for (double len : {40.0, -40.0, 0.37})
    for (double tol : {1e-10, 1e-13}) {
      SCOPED_TRACE("span " + std::to_string(len) + ", tol " + std::to_string(tol));
      const double t1 = t0 + len, dir = len > 0 ? 1 : -1;
      TimeRange seen{std::min(t0, t1), std::max(t0, t1)};
      auto force = [&](const V& q, V& a) {
        const double t = dir * q[1];
        seen.see(t);
        a[0] = -q[0] + std::cos(2 * t);
        a[1] = 0;
      };
      GbsOptions o;
      o.rtol = o.atol = tol;
      GbsIntegrator<V, decltype(force)> g(force, o);
      g.set_clock(1, dir * t1);
      State<V> s{{1.0, dir * t0}, {dir * 0.5, 1.0}};
      g.integrate_to(s, std::abs(len));
      EXPECT_EQ(seen.outside, 0) << "farthest outside by " << seen.worst;
      EXPECT_GT(seen.calls, 10);
      // the clock ends on t1 (up to the rounding of t0 + span) and moved at velocity 1 exactly
      EXPECT_LE(s.q[1], dir * t1);
      EXPECT_NEAR(dir * s.q[1], t1, 4 * std::numeric_limits<double>::epsilon() * std::abs(t1));
      EXPECT_EQ(s.v[1], 1.0);
      EXPECT_NEAR(s.q[0], driven_exact(t0, 1.0, 0.5, t1), 200 * tol);
    }
  // A clock outside the state is refused.
  auto none = [](const V&, V& a) { a = {0, 0}; };
  GbsIntegrator<V, decltype(none)> g(none);
  g.set_clock(2, 1.0);
  State<V> s{{0, 0}, {0, 1}};
  EXPECT_THROW(g.integrate_to(s, 1.0), std::invalid_argument);
}

TEST(Gbs, TimeDependentForceThroughSolveSeesOnlyTimesWithinTheSpan) {
  // A force built on a table over [t0, t1] (an ephemeris) fails outside it: GBS through solve() never asks
  // there, forward and backward, with output times, events (partial steps) and dense output.
  using V = std::vector<double>;
  const double t0 = 0.3;
  for (double len : {40.0, -40.0})
    for (double tol : {1e-10, 1e-13}) {
      SCOPED_TRACE("span " + std::to_string(len) + ", tol " + std::to_string(tol));
      const double t1 = t0 + len;
      TimeRange seen{std::min(t0, t1), std::max(t0, t1)};
      auto force = [&seen](const double& t, const V& q, V& a) {
        seen.see(t);
        a[0] = -q[0] + std::cos(2 * t);
      };
      const auto prob = SecondOrderProblem(force, V{1.0}, V{0.5}, t0, t1);
      SolveOptions opt;
      opt.rtol = tol;
      opt.dense = true;
      for (int i = 1; i <= 7; ++i) opt.t_eval.push_back(t0 + len * i / 7);
      const std::vector<Event<V>> events = {{"q=0", [](const double&, const V& q, const V&) { return q[0]; }}};
      const auto sol = solve(prob, "GBS", opt, events);
      ASSERT_EQ(sol.status, SolveStatus::success) << sol.message;
      EXPECT_GT(sol.events.size(), 5u);
      const auto mid = sol(t0 + len * 0.123);  // dense output: a partial step after the run
      EXPECT_EQ(seen.outside, 0) << "farthest outside by " << seen.worst;
      ASSERT_EQ(sol.t.size(), opt.t_eval.size());
      for (std::size_t i = 0; i < sol.t.size(); ++i)
        EXPECT_NEAR(sol.q[i][0], driven_exact(t0, 1.0, 0.5, sol.t[i]), 200 * tol) << "t = " << sol.t[i];
      EXPECT_NEAR(mid.q[0], driven_exact(t0, 1.0, 0.5, t0 + len * 0.123), 200 * tol);
      for (const auto& e : sol.events) EXPECT_NEAR(driven_exact(t0, 1.0, 0.5, e.t), 0.0, 200 * tol);
    }
}
