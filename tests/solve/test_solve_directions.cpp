// Every feature of solve() in both time directions on the same problem, against the analytic answer, positions
// and velocities: the harmonic oscillator q'' = -q, q = cos t, v = -sin t, integrated over [0, 7] forward and
// over [7, 0] backward from the exact state at 7. Output times, dense output, events (direction and terminal
// flags), checkpoints and partial results of failed runs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <string>
#include <vector>

#include "nystrom/solve/solve.hpp"

using namespace nystrom;
using Vd = std::vector<double>;
using VdForce = std::function<void(const Vd&, Vd&)>;

namespace {

constexpr double pi = std::numbers::pi;
constexpr double T = 7.0;

const VdForce oscillator = [](const Vd& q, Vd& a) { a[0] = -q[0]; };

// The run from 0 to 7 (dir = +1) or from 7 to 0 (dir = -1), starting on the exact solution.
SecondOrderProblem<Vd, VdForce> problem(int dir) {
  const double t0 = dir > 0 ? 0.0 : T, t1 = dir > 0 ? T : 0.0;
  return SecondOrderProblem(oscillator, Vd{std::cos(t0)}, Vd{-std::sin(t0)}, t0, t1);
}

struct Case {
  std::string method;
  SolveOptions opt;
};

// One method of each engine: fixed step, adaptive RKN, adaptive multi-product expansion, GBS.
std::vector<Case> cases() {
  return {{"M8", {.h = 0.01}},
          {"DP12-adaptive", {.rtol = 1e-12}},
          {"M10-adaptive", {.rtol = 1e-12}},
          {"GBS", {.rtol = 1e-12}}};
}

void expect_exact(double t, double q, double v, double tol) {
  EXPECT_NEAR(q, std::cos(t), tol) << "position at t = " << t;
  EXPECT_NEAR(v, -std::sin(t), tol) << "velocity at t = " << t;
}

}  // namespace

TEST(SolveDirections, OutputTimesHaveTheAnalyticPositionsAndVelocities) {
  for (int dir : {1, -1}) {
    std::vector<double> te;
    for (int i = 0; i <= 14; ++i) te.push_back(dir > 0 ? 0.5 * i : T - 0.5 * i);
    for (auto c : cases()) {
      SCOPED_TRACE(c.method + (dir > 0 ? " forward" : " backward"));
      c.opt.t_eval = te;
      const auto sol = solve(problem(dir), c.method, c.opt);
      EXPECT_EQ(sol.status, SolveStatus::success);
      ASSERT_EQ(sol.t.size(), te.size());
      for (std::size_t i = 0; i < te.size(); ++i) {
        EXPECT_EQ(sol.t[i], te[i]);
        expect_exact(sol.t[i], sol.q[i][0], sol.v[i][0], 1e-9);
      }
      EXPECT_EQ(sol.t_final, dir > 0 ? T : 0.0);
      expect_exact(sol.t_final, sol.q_final[0], sol.v_final[0], 1e-9);
    }
  }
}

TEST(SolveDirections, EveryStepEndIsOnTheSolution) {
  for (int dir : {1, -1}) {
    for (const auto& c : cases()) {
      SCOPED_TRACE(c.method + (dir > 0 ? " forward" : " backward"));
      const auto sol = solve(problem(dir), c.method, c.opt);
      ASSERT_EQ(sol.t.size(), static_cast<std::size_t>(sol.accepted + 1));
      for (std::size_t i = 0; i < sol.t.size(); ++i) {
        if (i > 0) {
          EXPECT_GT(dir * (sol.t[i] - sol.t[i - 1]), 0.0);
        }
        expect_exact(sol.t[i], sol.q[i][0], sol.v[i][0], 1e-9);
      }
    }
  }
}

TEST(SolveDirections, FixedStepsTakeTheSameStepsBothWays) {
  // Step size 0.03 over a span of 7: 233 steps and a last one of 0.01, in either direction.
  for (int dir : {1, -1}) {
    SCOPED_TRACE(dir);
    const auto sol = solve(problem(dir), "M8", {.h = 0.03});
    EXPECT_EQ(sol.accepted, 234);
    EXPECT_NEAR(sol.t[233], dir > 0 ? 6.99 : 0.01, 1e-12);
    expect_exact(sol.t_final, sol.q_final[0], sol.v_final[0], 1e-10);
  }
}

// A span that is a whole number of steps up to rounding (3 x 0.1 = 0.30000000000000004, and that over 0.1 is
// 3.0000000000000004) takes that number of steps, with no sliver of a fourth, in either direction.
TEST(SolveDirections, ASpanOfWholeStepsUpToRoundingTakesNoSliverStep) {
  const double span = 3 * 0.1;
  ASSERT_GT(span / 0.1, 3.0);
  for (int dir : {1, -1}) {
    SCOPED_TRACE(dir);
    const double t0 = dir > 0 ? 0.0 : span, t1 = dir > 0 ? span : 0.0;
    const auto sol =
        solve(SecondOrderProblem(oscillator, Vd{std::cos(t0)}, Vd{-std::sin(t0)}, t0, t1), "M8", {.h = 0.1});
    EXPECT_EQ(sol.accepted, 3);
    ASSERT_EQ(sol.t.size(), 4u);
    for (std::size_t i = 1; i < 4; ++i) EXPECT_NEAR(std::abs(sol.t[i] - sol.t[i - 1]), 0.1, 1e-15) << i;
    EXPECT_EQ(sol.t_final, t1);
    expect_exact(sol.t_final, sol.q_final[0], sol.v_final[0], 1e-12);
  }
}

TEST(SolveDirections, DenseOutputHasTheAnalyticPositionsAndVelocitiesInsideTheSteps) {
  for (int dir : {1, -1}) {
    for (const std::string m : {"M8", "FR", "DP12-adaptive"}) {
      SCOPED_TRACE(m + (dir > 0 ? " forward" : " backward"));
      SolveOptions o{.h = 0.01, .rtol = 1e-12, .dense = true};
      const auto sol = solve(problem(dir), m, o);
      // The Hermite interpolant between step ends of a fixed 0.01 (order 6: 1e-12 and its derivative 1e-10);
      // DP12-adaptive's steps are long (the interpolant's error reaches about 1e-7 between them).
      const double tol = m == "DP12-adaptive" ? 1e-5 : (m == "FR" ? 1e-8 : 1e-9);
      for (double t : {0.004, 0.123, 1.0, 2.345, 3.3337, 5.55, 6.996}) {
        const auto s = sol(t);
        expect_exact(t, s.q[0], s.v[0], tol);
      }
      // At both ends: the initial state and the final one.
      const double t0 = dir > 0 ? 0.0 : T, t1 = T - t0;
      expect_exact(t0, sol(t0).q[0], sol(t0).v[0], 1e-15);
      EXPECT_EQ(sol(t1).q, sol.q_final);
      EXPECT_EQ(sol(t1).v, sol.v_final);
      EXPECT_THROW(sol(dir > 0 ? 7.5 : -0.5), invalid_input);
      EXPECT_THROW(sol(dir > 0 ? -0.5 : 7.5), invalid_input);
    }
  }
}

TEST(SolveDirections, EventDirectionIsThatOfGInTimeEitherWay) {
  // g = q = cos t crosses zero falling at pi/2 and rising at 3 pi/2 (t increasing). Backward, the
  // integration meets them in the other order; the flag selects by the sign of dg/dt.
  for (int dir : {1, -1}) {
    for (const auto& c : cases()) {
      for (int flag : {0, 1, -1}) {
        SCOPED_TRACE(c.method + (dir > 0 ? " forward" : " backward") + " direction " + std::to_string(flag));
        const std::vector<Event<Vd>> ev = {{"q=0", [](double, const Vd& q, const Vd&) { return q[0]; }, flag, false}};
        const auto sol = solve(problem(dir), c.method, c.opt, ev);
        std::vector<double> expected;
        if (flag <= 0) expected.push_back(pi / 2);
        if (flag >= 0) expected.push_back(3 * pi / 2);
        if (dir < 0) std::reverse(expected.begin(), expected.end());
        ASSERT_EQ(sol.events.size(), expected.size());
        for (std::size_t i = 0; i < expected.size(); ++i) {
          EXPECT_NEAR(sol.events[i].t, expected[i], 1e-9);
          EXPECT_NEAR(sol.events[i].q[0], 0.0, 1e-9);
          // The velocity there: -1 at pi/2, +1 at 3 pi/2.
          EXPECT_NEAR(sol.events[i].v[0], -std::sin(expected[i]), 1e-9);
        }
        EXPECT_EQ(sol.status, SolveStatus::success);
      }
    }
  }
}

TEST(SolveDirections, TerminalEventEndsTheRunAtTheFirstZeroMetEitherWay) {
  for (int dir : {1, -1}) {
    for (auto c : cases()) {
      SCOPED_TRACE(c.method + (dir > 0 ? " forward" : " backward"));
      c.opt.dense = true;
      const std::vector<Event<Vd>> ev = {{"q=0", [](double, const Vd& q, const Vd&) { return q[0]; }, 0, true}};
      const auto sol = solve(problem(dir), c.method, c.opt, ev);
      const double te = dir > 0 ? pi / 2 : 3 * pi / 2;
      EXPECT_EQ(sol.status, SolveStatus::terminated_by_event);
      ASSERT_EQ(sol.events.size(), 1u);
      EXPECT_NEAR(sol.t_final, te, 1e-9);
      EXPECT_EQ(sol.events[0].t, sol.t_final);
      EXPECT_NEAR(sol.q_final[0], 0.0, 1e-9);
      EXPECT_NEAR(sol.v_final[0], -std::sin(te), 1e-9);
      EXPECT_EQ(sol.v_final, sol.events[0].v);
      // Nothing saved past the event; the dense output ends there and holds the event's state.
      for (double t : sol.t) EXPECT_LE(dir * t, dir * sol.t_final);
      EXPECT_EQ(sol.dense.times().back(), sol.t_final);
      const auto s = sol(sol.t_final);
      EXPECT_EQ(s.q, sol.q_final);
      EXPECT_EQ(s.v, sol.v_final);
    }
  }
}

TEST(SolveDirections, CheckpointIsTakenAtTheFirstBoundaryPastItsTimeAndRestartsBitwise) {
  for (int dir : {1, -1}) {
    for (auto c : cases()) {
      SCOPED_TRACE(c.method + (dir > 0 ? " forward" : " backward"));
      const auto prob = problem(dir);
      const auto plain = solve(prob, c.method, c.opt);
      const double at = 3.305;
      c.opt.checkpoint_at = at;
      c.opt.checkpoint_problem = "oscillator";
      const auto first = solve(prob, c.method, c.opt);
      ASSERT_TRUE(first.checkpoint.has_value());
      const auto& cp = *first.checkpoint;
      // At or after `at` in the direction of integration, and the first such boundary: the step before it ended
      // before `at`.
      EXPECT_GE(dir * (cp.t - at), 0.0);
      bool found = false;
      for (std::size_t i = 1; i < plain.t.size(); ++i) {
        if (plain.t[i] == cp.t) {
          found = true;
          EXPECT_LT(dir * (plain.t[i - 1] - at), 0.0);
        }
      }
      EXPECT_TRUE(found) << "the checkpoint's time " << cp.t << " is not a step end";
      // Its state is the solution's there, positions and velocities: the engine's state, q then v, which
      // backward is that of the time-reversed problem (v -> -v).
      ASSERT_EQ(cp.state.size(), 2u);
      expect_exact(cp.t, cp.state[0], dir * cp.state[1], 1e-9);
      const auto second = resume(prob, c.method, cp, c.opt);
      EXPECT_EQ(second.q_final, plain.q_final);
      EXPECT_EQ(second.v_final, plain.v_final);
      EXPECT_EQ(second.accepted, plain.accepted);
      EXPECT_EQ(second.rejected, plain.rejected);
    }
  }
}

TEST(SolveDirections, AFailedRunReturnsWhatItReachedEitherWay) {
  // q'' = 1 from rest at t = 0: q = t^2 / 2, v = t in both directions; the force is NaN once q > 0.5 (|t| > 1).
  // The fixed-step engines fail in the step that crosses |t| = 1, the adaptive ones and GBS when their step has
  // shrunk to the rounding level of t there (a step-size underflow), with the default max_steps.
  const VdForce f = [](const Vd& q, Vd& a) { a[0] = q[0] > 0.5 ? NAN : 1.0; };
  for (int dir : {1, -1}) {
    const SecondOrderProblem prob(f, Vd{0.0}, Vd{0.0}, 0.0, 2.0 * dir);
    for (const std::string m : {"VV", "M8", "DP12-adaptive", "M10-adaptive", "GBS"}) {
      SCOPED_TRACE(m + (dir > 0 ? " forward" : " backward"));
      SolveOptions opt{.steps = 100, .rtol = 1e-10, .partial_on_failure = true};
      const auto sol = solve(prob, m, opt);
      EXPECT_EQ(sol.status, SolveStatus::failed);
      const bool said =
          sol.message.find("NaN") != std::string::npos || sol.message.find("underflow") != std::string::npos;
      EXPECT_TRUE(said) << sol.message;
      ASSERT_GE(sol.t.size(), 2u);
      EXPECT_LE(dir * sol.t.back(), 1.0 + 1e-12);
      EXPECT_GT(dir * sol.t.back(), 0.5);
      EXPECT_LT(sol.accepted, 100000);
      for (std::size_t i = 0; i < sol.t.size(); ++i) {
        EXPECT_NEAR(sol.q[i][0], sol.t[i] * sol.t[i] / 2, 1e-12);
        EXPECT_NEAR(sol.v[i][0], sol.t[i], 1e-12);
      }
      EXPECT_EQ(sol.t_final, sol.t.back());
      EXPECT_EQ(sol.q_final, sol.q.back());
      EXPECT_EQ(sol.v_final, sol.v.back());
      EXPECT_GT(sol.force_evals, 0);
    }
  }
}

TEST(SolveDirections, TooManyStepsIsReportedEitherWay) {
  for (int dir : {1, -1}) {
    for (const std::string m : {"DP12-adaptive", "M10-adaptive", "GBS"}) {
      SCOPED_TRACE(m + (dir > 0 ? " forward" : " backward"));
      SolveOptions o{.rtol = 1e-12, .max_steps = 3};
      EXPECT_THROW(solve(problem(dir), m, o), too_many_steps);
      o.partial_on_failure = true;
      const auto sol = solve(problem(dir), m, o);
      EXPECT_EQ(sol.status, SolveStatus::failed);
      EXPECT_NE(sol.message.find("steps"), std::string::npos) << sol.message;
      // At most three steps from the start, each on the solution.
      ASSERT_GE(sol.t.size(), 1u);
      EXPECT_LE(sol.t.size(), 4u);
      EXPECT_EQ(sol.t.front(), dir > 0 ? 0.0 : T);
      for (std::size_t i = 0; i < sol.t.size(); ++i) expect_exact(sol.t[i], sol.q[i][0], sol.v[i][0], 1e-9);
      EXPECT_LT(dir * sol.t.back(), dir * (dir > 0 ? T : 0.0));
    }
  }
  // A fixed step that needs more than max_steps is refused before it starts.
  EXPECT_THROW(solve(problem(-1), "M8", {.h = 0.01, .max_steps = 50}), too_many_steps);
}

TEST(SolveDirections, ACheckpointDueInTheLastStepIsNotTakenAndChangesNothing) {
  // The first step boundary at or after checkpoint_at is the end of the span: no checkpoint (nothing is left to
  // resume), and the run is the one without it, in either direction and for every engine.
  for (int dir : {1, -1}) {
    for (auto c : cases()) {
      SCOPED_TRACE(c.method + (dir > 0 ? " forward" : " backward"));
      const auto prob = problem(dir);
      const auto plain = solve(prob, c.method, c.opt);
      c.opt.checkpoint_at = dir > 0 ? T - 1e-6 : 1e-6;
      const auto sol = solve(prob, c.method, c.opt);
      EXPECT_FALSE(sol.checkpoint.has_value());
      EXPECT_EQ(sol.t_final, plain.t_final);
      EXPECT_EQ(sol.q_final, plain.q_final);
      EXPECT_EQ(sol.v_final, plain.v_final);
      EXPECT_EQ(sol.accepted, plain.accepted);
      EXPECT_EQ(sol.t.size(), plain.t.size());
      expect_exact(sol.t_final, sol.q_final[0], sol.v_final[0], 1e-9);
    }
  }
}

TEST(SolveDirections, TimeDependentForceEitherWay) {
  // q'' = -q + cos 2t from rest at 0: q = (cos t - cos 2t) / 3, v = (2 sin 2t - sin t) / 3; the engines carry t as
  // a coordinate (GBS sets it exactly at every substep), backward on the time-reversed problem.
  const std::function<void(double, const Vd&, Vd&)> f = [](double t, const Vd& q, Vd& a) {
    a[0] = -q[0] + std::cos(2 * t);
  };
  const auto qx = [](double t) { return (std::cos(t) - std::cos(2 * t)) / 3; };
  const auto vx = [](double t) { return (2 * std::sin(2 * t) - std::sin(t)) / 3; };
  for (int dir : {1, -1}) {
    const double t0 = dir > 0 ? 0.0 : 5.0, t1 = 5.0 - t0;
    const SecondOrderProblem prob(f, Vd{qx(t0)}, Vd{vx(t0)}, t0, t1);
    std::vector<double> te;
    for (int i = 1; i <= 10; ++i) te.push_back(t0 + dir * 0.5 * i);
    for (auto c : cases()) {
      SCOPED_TRACE(c.method + (dir > 0 ? " forward" : " backward"));
      c.opt.t_eval = te;
      const auto sol = solve(prob, c.method, c.opt);
      ASSERT_EQ(sol.t.size(), te.size());
      for (std::size_t i = 0; i < te.size(); ++i) {
        EXPECT_NEAR(sol.q[i][0], qx(te[i]), 1e-9) << te[i];
        EXPECT_NEAR(sol.v[i][0], vx(te[i]), 1e-9) << te[i];
      }
    }
  }
}
