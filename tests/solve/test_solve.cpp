// solve(): one driver for every method family, its options, dense output, events and checkpoints.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "nystrom/problems/counting_force.hpp"
#include "nystrom/problems/kepler.hpp"
#include "nystrom/solve/recorder.hpp"
#include "nystrom/solve/solve.hpp"
#include "support/kepler.hpp"

using namespace nystrom;
using nystrom::test::kepler;
using nystrom::test::pos_err;
using nystrom::test::V2;
using Vd = std::vector<double>;
// One force type for the tests of user-written forces on a std::vector state (each force type compiles
// every engine once more); the capturing-lambda test keeps its own lambda type.
using VdForce = std::function<void(const Vd&, Vd&)>;
using VdTimeForce = std::function<void(double, const Vd&, Vd&)>;

namespace {

constexpr double pi = std::numbers::pi;

}  // namespace

TEST(Solve, EveryFamilyReachesTheAnalyticKeplerOrbit) {
  const KeplerProblem<double> kp(0.5);
  const double t1 = 2.5;  // not a multiple of the period
  const auto prob = kepler(0.5, 0.0, t1);
  const auto ex = kp.exact(t1);
  struct Case {
    std::string method;
    SolveOptions opt;
    double tol;
  };
  const std::vector<Case> cases = {
      {"VV", {.steps = 20000}, 1e-6},
      {"FR", {.steps = 2000}, 1e-6},
      {"M8", {.steps = 400}, 1e-9},
      {"A6", {.h = 0.003}, 1e-9},
      {"DP12-adaptive", {.rtol = 1e-12}, 1e-9},
      {"M12-adaptive", {.rtol = 1e-12}, 1e-9},
      {"MPE-adaptive", {.rtol = 1e-12}, 1e-9},
      {"GBS", {.rtol = 1e-12}, 1e-9},
      {"Chambers", {.steps = 20000}, 1e-6},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.method);
    const auto sol = solve(prob, c.method, c.opt);
    EXPECT_EQ(sol.status, SolveStatus::success);
    EXPECT_EQ(sol.t_final, t1);
    EXPECT_LT(pos_err(sol.q_final, ex), c.tol);
    EXPECT_GT(sol.force_evals, 0);
    EXPECT_GT(sol.accepted, 0);
    // Every step end is saved (no t_eval), from t0 to t1.
    ASSERT_EQ(sol.t.size(), static_cast<std::size_t>(sol.accepted + 1));
    EXPECT_EQ(sol.t.front(), 0.0);
    EXPECT_EQ(sol.t.back(), t1);
  }
}

TEST(Solve, FixedStepCountsAndStepSizeLandOnTheEnd) {
  const auto prob = kepler(0.2, 0.0, 1.0);
  const auto a = solve(prob, "VV", {.steps = 100});
  EXPECT_EQ(a.accepted, 100);
  // Velocity Verlet is FSAL: one force per step plus the first.
  EXPECT_EQ(a.force_evals, 101);
  const auto b = solve(prob, "VV", {.h = 0.03});  // 34 steps, the last one shortened
  EXPECT_EQ(b.accepted, 34);
  EXPECT_EQ(b.t.back(), 1.0);
  EXPECT_NEAR(b.t[33], 0.99, 1e-15);
}

TEST(Solve, BackwardInTimeRetracesTheOrbit) {
  const KeplerProblem<double> kp(0.5);
  const auto ex = kp.exact(3.0);
  const auto back = SecondOrderProblem(KeplerForce{}, ex.q, ex.v, 3.0, 0.0);
  const auto s0 = kp.initial_state();
  for (const std::string m : {"DP12-adaptive", "M10-adaptive", "GBS", "M8"}) {
    SCOPED_TRACE(m);
    SolveOptions o{.rtol = 1e-12};
    if (m == "M8") o = {.steps = 600};
    const auto sol = solve(back, m, o);
    EXPECT_EQ(sol.t_final, 0.0);
    EXPECT_LT(pos_err(sol.q_final, s0), 1e-9);
    EXPECT_LT(std::hypot(sol.v_final[0] - s0.v[0], sol.v_final[1] - s0.v[1]), 1e-9);
    // Times decrease.
    for (std::size_t i = 1; i < sol.t.size(); ++i) EXPECT_LT(sol.t[i], sol.t[i - 1]);
  }
}

TEST(Solve, TimeDependentForceMatchesTheForcedOscillator) {
  // q'' = -q + cos(2t), q(0) = 0, q'(0) = 0: q = (cos t - cos 2t) / 3.
  VdTimeForce f = [](double t, const Vd& q, Vd& a) { a[0] = -q[0] + std::cos(2 * t); };
  const SecondOrderProblem prob(f, Vd{0.0}, Vd{0.0}, 0.0, 5.0);
  const double exact = (std::cos(5.0) - std::cos(10.0)) / 3;
  const double exact_v = (-std::sin(5.0) + 2 * std::sin(10.0)) / 3;
  for (const std::string m : {"M8", "RKNb6", "A6", "DP12-adaptive", "M12-adaptive", "GBS"}) {
    SCOPED_TRACE(m);
    const auto sol = solve(prob, m, {.steps = 500, .rtol = 1e-12});
    EXPECT_NEAR(sol.q_final[0], exact, 1e-9);
    EXPECT_NEAR(sol.v_final[0], exact_v, 1e-9);
  }
  // And backward from the end to the start.
  const SecondOrderProblem back(f, Vd{exact}, Vd{exact_v}, 5.0, 0.0);
  const auto b = solve(back, "DP12-adaptive", {.rtol = 1e-12});
  EXPECT_NEAR(b.q_final[0], 0.0, 1e-9);
  EXPECT_NEAR(b.v_final[0], 0.0, 1e-9);
}

TEST(Solve, CapturingLambdaOnAVectorStateRunsEveryEngineAndSchedule) {
  // The harmonic oscillator with a captured frequency (a functor that cannot be copy-assigned).
  const double w = 2.0;
  auto f = [w](const std::vector<double>& q, std::vector<double>& a) {
    for (std::size_t i = 0; i < q.size(); ++i) a[i] = -w * w * q[i];
  };
  const SecondOrderProblem prob(f, std::vector<double>{1.0, 0.0}, std::vector<double>{0.0, w}, 0.0, 1.0);
  SolveOptions o{.steps = 200};
  o.mpe_schedule = MpeSchedule::concurrent;
  for (const std::string m : {"M8", "FR", "N4", "DP12-adaptive", "M10-adaptive"}) {
    SCOPED_TRACE(m);
    o.rtol = 1e-12;
    if (m == "M10-adaptive") o.mpe_schedule = MpeSchedule::automatic;
    const auto sol = solve(prob, m, o);
    EXPECT_NEAR(sol.q_final[0], std::cos(w), 1e-7);
    EXPECT_NEAR(sol.q_final[1], std::sin(w), 1e-7);
  }
}

TEST(Solve, OutputTimesComeFromTheDenseOutput) {
  const KeplerProblem<double> kp(0.5);
  const auto prob = kepler(0.5, 0.0, 2 * pi);
  std::vector<double> te;
  for (int i = 0; i <= 50; ++i) te.push_back(2 * pi * i / 50);
  const auto sol = solve(prob, "M8", {.steps = 2000, .t_eval = te, .dense = true});
  ASSERT_EQ(sol.t.size(), te.size());
  for (std::size_t i = 0; i < te.size(); ++i) {
    EXPECT_EQ(sol.t[i], te[i]);
    EXPECT_LT(pos_err(sol.q[i], kp.exact(te[i])), 1e-10) << te[i];
  }
  // sol(t) anywhere inside.
  for (double t : {0.123, 1.0, 3.3, 6.2}) EXPECT_LT(pos_err(sol(t).q, kp.exact(t)), 1e-10) << t;
  EXPECT_THROW(sol(7.0), invalid_input);
}

TEST(Solve, OutputTimesOnlyAtTheEndsKeepNoCopyOfTheMethod) {
  // Output times at the start and the end of the span are step ends: such a run, like one that saves every
  // step end, takes no partial steps and keeps no copy of the method (and of its force) for them, while an
  // output time inside the span does. The copies are counted while the force runs (the copies of a
  // shared_ptr it holds); the states are the same, bit for bit. Fixed steps, an adaptive pair and GBS, both
  // directions.
  for (const std::string m : {"M8", "DP12-adaptive", "GBS"}) {
    for (const double t1 : {3.0, -3.0}) {
      SCOPED_TRACE(m + (t1 > 0 ? " forward" : " backward"));
      const auto token = std::make_shared<int>(0);
      long most = 0;  // the most copies of the force alive at once
      VdForce f = [token, &most](const Vd& q, Vd& a) {
        most = std::max(most, token.use_count());
        a[0] = -q[0];
      };
      const SecondOrderProblem prob(f, Vd{1.0}, Vd{0.5}, 0.0, t1);
      auto run = [&](std::vector<double> t_eval, long& copies) {
        most = 0;
        SolveOptions opt{.t_eval = std::move(t_eval)};
        if (m == "M8")
          opt.steps = 30;
        else
          opt.rtol = 1e-10;
        auto sol = solve(prob, m, opt);
        copies = most;
        return sol;
      };
      long every = 0, ends = 0, start = 0, end = 0, inside = 0;
      const auto a = run({}, every);
      const auto b = run({0.0, t1}, ends);
      const auto c = run({0.0}, start);
      const auto d = run({t1}, end);
      const auto e = run({0.0, 0.45 * t1, t1}, inside);  // inside a fixed step
      EXPECT_EQ(ends, every);
      EXPECT_EQ(start, every);
      EXPECT_EQ(end, every);
      EXPECT_GT(inside, every);
      ASSERT_EQ(b.q.size(), 2u);
      EXPECT_EQ(b.t, (std::vector<double>{0.0, t1}));
      EXPECT_EQ(b.q[0], prob.q0);
      EXPECT_EQ(b.v[0], prob.v0);
      for (const auto* s : {&b, &c, &d, &e}) {
        EXPECT_EQ(s->q_final, a.q_final);
        EXPECT_EQ(s->v_final, a.v_final);
        EXPECT_EQ(s->force_evals, a.force_evals);
      }
      EXPECT_EQ(b.q[1], a.q_final);
      EXPECT_EQ(b.v[1], a.v_final);
      EXPECT_EQ(d.q.at(0), a.q_final);
      EXPECT_EQ(b.output_force_evals, 0);
      EXPECT_GT(e.output_force_evals, 0);
      EXPECT_NEAR(e.q.at(1)[0], std::cos(0.45 * t1) + 0.5 * std::sin(0.45 * t1), 1e-8);
    }
  }
}

TEST(Solve, InvalidInputIsRefusedWithOneClearError) {
  VdForce f = [](const Vd& q, Vd& a) { a = q; };
  const SecondOrderProblem bad_sizes(f, Vd{1.0, 2.0}, Vd{1.0}, 0.0, 1.0);
  EXPECT_THROW(solve(bad_sizes, "VV", {.steps = 10}), invalid_input);
  const SecondOrderProblem nan_state(f, Vd{NAN}, Vd{1.0}, 0.0, 1.0);
  EXPECT_THROW(solve(nan_state, "VV", {.steps = 10}), invalid_input);
  const SecondOrderProblem inf_span(f, Vd{1.0}, Vd{1.0}, 0.0, INFINITY);
  EXPECT_THROW(solve(inf_span, "VV", {.steps = 10}), invalid_input);
  const auto prob = kepler(0.5, 0.0, 1.0);
  EXPECT_THROW(solve(prob, "VV"), invalid_input);             // no step size
  EXPECT_THROW(solve(prob, "DP12-adaptive"), invalid_input);  // no tolerance
  EXPECT_THROW(solve(prob, "VV", {.steps = 10, .t_eval = {0.5, 0.2}}), invalid_input);
  EXPECT_THROW(solve(prob, "VV", {.steps = 10, .t_eval = {2.0}}), invalid_input);
  // Every one of these is a nystrom::error too.
  EXPECT_THROW(solve(prob, "VV"), nystrom::error);
  // An adaptive method through the fixed-step factory is refused, never run with fixed steps.
  EXPECT_THROW(make_integrator<V2>(resolve_method("DP12-adaptive"), KeplerForce{}), invalid_input);
  EXPECT_THROW(make_integrator<V2>(resolve_method("M12-adaptive"), KeplerForce{}), invalid_input);
}

TEST(Solve, AdaptiveEnginesTakeSeparateAbsoluteAndRelativeTolerances) {
  // An oscillator of amplitude 1e6 (q = A cos t, v = -A sin t): an absolute tolerance bounds the
  // absolute error, a relative one the error relative to A, and each error follows its tolerance. With
  // one tolerance (atol 0 or equal to rtol) the scale is rtol (1 + |y|), bitwise the same either way.
  const double amp = 1e6, t1 = 10;
  VdForce f = [](const Vd& q, Vd& a) { a[0] = -q[0]; };
  const SecondOrderProblem prob(f, Vd{amp}, Vd{0.0}, 0.0, t1);
  auto err = [&](const SolveOptions& o, const std::string& m) {
    const auto sol = solve(prob, m, o);
    return std::hypot(sol.q_final[0] - amp * std::cos(t1), sol.v_final[0] + amp * std::sin(t1));
  };
  for (const std::string m : {"DP12-adaptive", "M10-adaptive"}) {
    SCOPED_TRACE(m);
    const double abs_loose = err({.rtol = 0, .atol = 1e-3}, m), abs_tight = err({.rtol = 0, .atol = 1e-6}, m);
    const double rel_loose = err({.rtol = 1e-8, .atol = 1e-300}, m);
    const double rel_tight = err({.rtol = 1e-11, .atol = 1e-300}, m);
    EXPECT_LT(abs_loose, 100 * 1e-3);
    EXPECT_LT(abs_tight, 100 * 1e-6);
    EXPECT_LT(rel_loose, 100 * 1e-8 * amp);
    EXPECT_LT(rel_tight, 100 * 1e-11 * amp);
    // A factor 1000 in either tolerance moves the error by more than 30 (order p: 1000^(p/(p+1))).
    EXPECT_GT(abs_loose, 30 * abs_tight);
    EXPECT_GT(rel_loose, 30 * rel_tight);
    // The relative tolerance 1e-6 alone allows errors of about 1e-6 A, far above the absolute 1e-6.
    EXPECT_GT(err({.rtol = 1e-6, .atol = 1e-300}, m), 1e4 * abs_tight);
    const auto one = solve(prob, m, {.rtol = 1e-9}), both = solve(prob, m, {.rtol = 1e-9, .atol = 1e-9});
    EXPECT_EQ(one.q_final[0], both.q_final[0]);
    EXPECT_EQ(one.v_final[0], both.v_final[0]);
    EXPECT_EQ(one.force_evals, both.force_evals);
    for (const SolveOptions& bad :
         {SolveOptions{.rtol = -1e-9}, SolveOptions{.rtol = 1e-9, .atol = -1}, SolveOptions{.rtol = NAN},
          SolveOptions{.rtol = 1e-9, .atol = NAN}, SolveOptions{.rtol = 0, .atol = 0}})
      EXPECT_THROW(solve(prob, m, bad), invalid_input);
  }
}

TEST(Solve, GbsTakesItsSequenceAndColumnsFromTheSpecification) {
  // GBS is data: "GBS:SEQUENCE:COLUMNS". Every sequence reaches the orbit; they differ in cost, and fewer
  // columns cap the order (order 2 x columns) and so need more steps.
  const KeplerProblem<double> kp(0.5);
  const double t1 = 2.5;
  const auto prob = kepler(0.5, 0.0, t1);
  const auto ex = kp.exact(t1);
  long harmonic_evals = 0;
  for (const std::string spec : {"GBS", "GBS:romberg", "GBS:bulirsch", "GBS:harmonic:4", "gbs:Bulirsch:8"}) {
    SCOPED_TRACE(spec);
    const auto sol = solve(prob, spec, {.rtol = 1e-11});
    EXPECT_LT(pos_err(sol.q_final, ex), 1e-8);
    if (spec == "GBS") harmonic_evals = sol.force_evals;
    if (spec == "GBS:romberg" || spec == "GBS:bulirsch") {
      EXPECT_NE(sol.force_evals, harmonic_evals);
    }
  }
  const auto four = solve(prob, "GBS:harmonic:4", {.rtol = 1e-11}), twelve = solve(prob, "GBS", {.rtol = 1e-11});
  EXPECT_GT(four.accepted, twelve.accepted);
  EXPECT_EQ(resolve_solve_method("GBS:bulirsch:10").info.order, 20);
  EXPECT_EQ(resolve_solve_method("GBS:bulirsch:10").info.name, "GBS:bulirsch:10");
  EXPECT_EQ(resolve_solve_method("gbs:harmonic:12").info.name, "GBS");  // the defaults have the short name
  EXPECT_EQ(resolve_solve_method("GBS").info.order, 24);
  for (const std::string bad : {"GBS:fibonacci", "GBS:harmonic:2", "GBS:harmonic:21", "GBS:harmonic:x",
                                "GBS:", "GBS:romberg:", "GBS:harmonic:100000000000000000000"})
    EXPECT_THROW(resolve_solve_method(bad), invalid_input) << bad;
  // listed after the catalog, as `nystrom methods` and nystrom.methods() show it
  EXPECT_EQ(listed_methods().back().info.name, "GBS");
  EXPECT_EQ(listed_methods().size(), catalog().size() + 1);
}

TEST(Solve, StepControlOptionsAreFlatAndRefusedWhereTheyDoNotApply) {
  const auto prob = kepler(0.5, 0.0, 2.5);
  // h_max bounds the adaptive step: at least span / h_max steps
  const auto free = solve(prob, "DP12-adaptive", {.rtol = 1e-8});
  const auto capped = solve(prob, "DP12-adaptive", {.rtol = 1e-8, .h_max = 0.01});
  EXPECT_LT(free.accepted, 100);
  EXPECT_GE(capped.accepted, 250);
  // h0 is the first step of an adaptive method and of GBS: a given first step changes the run (and its cost)
  const auto gbs = solve(prob, "GBS", {.rtol = 1e-10}), gbs_h0 = solve(prob, "GBS", {.rtol = 1e-10, .h0 = 0.01});
  EXPECT_NE(gbs.force_evals, gbs_h0.force_evals);
  const auto dp_h0 = solve(prob, "DP12-adaptive", {.rtol = 1e-8, .h0 = 1e-4});
  EXPECT_NE(dp_h0.force_evals, free.force_evals);
  // a smaller safety factor takes more, smaller steps
  EXPECT_GT(solve(prob, "M10-adaptive", {.rtol = 1e-8, .safety = 0.5}).accepted,
            solve(prob, "M10-adaptive", {.rtol = 1e-8}).accepted);
  // options of a controller the method does not have are refused, not ignored
  EXPECT_THROW(solve(prob, "M8", {.steps = 100, .safety = 0.5}), invalid_input);
  EXPECT_THROW(solve(prob, "M8", {.steps = 100, .h0 = 0.1}), invalid_input);
  EXPECT_THROW(solve(prob, "GBS", {.rtol = 1e-10, .h_max = 0.1}), invalid_input);
  EXPECT_THROW(solve(prob, "GBS", {.rtol = 1e-10, .predictive = false}), invalid_input);
  EXPECT_THROW(solve(prob, "DP12-adaptive", {.rtol = 1e-8, .h0 = -1}), invalid_input);
  EXPECT_THROW(solve(prob, "DP12-adaptive", {.rtol = 1e-8, .safety = 1.5}), invalid_input);
  EXPECT_THROW(solve(prob, "DP12-adaptive", {.rtol = 1e-8, .fac_max = 0.5}), invalid_input);
  // the calibrated tolerance (tolerance proportionality) works to a tighter tolerance than tol above 1e-15: plain
  // control (exponent 1) takes fewer steps (ten orbits at 1e-6: 25x looser); the method's own exponent and anchor
  // given explicitly are the same run
  const auto orbits = kepler(0.5, 0.0, 20 * std::numbers::pi);
  const auto calibrated = solve(orbits, "DP12-adaptive", {.rtol = 1e-6});
  const auto plain = solve(orbits, "DP12-adaptive", {.rtol = 1e-6, .tolerance_exponent = 1});
  EXPECT_LT(static_cast<double>(plain.accepted), 0.9 * static_cast<double>(calibrated.accepted));
  const auto same =
      solve(orbits, "DP12-adaptive", {.rtol = 1e-6, .tolerance_exponent = 11.0 / 13.0, .tolerance_anchor = 1e-15});
  EXPECT_EQ(same.accepted, calibrated.accepted);
  EXPECT_EQ(same.q_final, calibrated.q_final);
  EXPECT_THROW(solve(prob, "M8", {.steps = 100, .tolerance_exponent = 1}), invalid_input);
  EXPECT_THROW(solve(prob, "GBS", {.rtol = 1e-10, .tolerance_anchor = 1e-12}), invalid_input);
  EXPECT_THROW(solve(prob, "DP12-adaptive", {.rtol = 1e-8, .tolerance_exponent = 0.2}), invalid_input);
  EXPECT_THROW(solve(prob, "DP12-adaptive", {.rtol = 1e-8, .tolerance_anchor = -1}), invalid_input);
}

TEST(Solve, AForceReturningNaNIsReportedWithTheTime) {
  // a = NaN once q passes 0.5: the adaptive controllers must stop with an error, not loop.
  VdForce f = [](const Vd& q, Vd& a) { a[0] = q[0] > 0.5 ? NAN : 1.0; };
  const SecondOrderProblem prob(f, Vd{0.0}, Vd{0.0}, 0.0, 2.0);
  for (const std::string m : {"DP12-adaptive", "M10-adaptive"}) {
    SCOPED_TRACE(m);
    try {
      solve(prob, m, {.rtol = 1e-10});
      ADD_FAILURE() << "no error";
    } catch (const step_size_underflow& e) {
      EXPECT_NE(std::string(e.what()).find("NaN"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("t = 1"), std::string::npos) << e.what();  // q = t^2/2 = 0.5 at t = 1
    }
  }
  try {
    solve(prob, "VV", {.steps = 100});
    ADD_FAILURE() << "no error";
  } catch (const nystrom::error& e) {
    EXPECT_NE(std::string(e.what()).find("NaN"), std::string::npos) << e.what();
  }
}

TEST(Solve, AFailedRunReturnsTheStatesItReachedWhenAsked) {
  // SolveOptions::partial_on_failure: the failures above end the run with status failed, the error's message
  // and the states saved before it: q = t^2/2 (a constant force, integrated exactly up to rounding) for t <= 1.
  VdForce f = [](const Vd& q, Vd& a) { a[0] = q[0] > 0.5 ? NAN : 1.0; };
  const SecondOrderProblem prob(f, Vd{0.0}, Vd{0.0}, 0.0, 2.0);
  for (const std::string m : {"DP12-adaptive", "VV"}) {
    SCOPED_TRACE(m);
    SolveOptions opt = m == "VV" ? SolveOptions{.steps = 100} : SolveOptions{.rtol = 1e-10};
    opt.partial_on_failure = true;
    const auto sol = solve(prob, m, opt);
    EXPECT_EQ(sol.status, SolveStatus::failed);
    EXPECT_NE(sol.message.find("NaN"), std::string::npos) << sol.message;
    ASSERT_GE(sol.t.size(), 2u);
    EXPECT_LE(sol.t.back(), 1.0 + 1e-12);
    EXPECT_GT(sol.t.back(), 0.9);  // VV: the step end 1.0 before the failing one; DP12: steps shrunk towards 1
    for (std::size_t i = 0; i < sol.t.size(); ++i) EXPECT_NEAR(sol.q[i][0], sol.t[i] * sol.t[i] / 2, 1e-12);
    EXPECT_EQ(sol.t_final, sol.t.back());
    EXPECT_EQ(sol.q_final, sol.q.back());
  }
}

TEST(Solve, AFailedRunCountsTheForcesItEvaluated) {
  // A force that counts its calls and returns NaN once q passes 0.5 (t = 1): every engine fails midway, and
  // the partial result carries the forces evaluated up to the failure, the method's and the outputs' (dense
  // output at every step end, or none) adding up to the calls the force received.
  long calls = 0;
  const auto nan_past_half = [](const Vd& q, Vd& a) { a[0] = q[0] > 0.5 ? NAN : 1.0; };
  const SecondOrderProblem prob(CountingForce<VdForce>{&calls, nan_past_half}, Vd{0.0}, Vd{0.0}, 0.0, 2.0);
  for (const std::string m : {"VV", "M8", "DP12-adaptive", "M10-adaptive", "GBS"}) {
    for (const bool dense : {false, true}) {
      SCOPED_TRACE(m + (dense ? " dense" : ""));
      SolveOptions opt = m.find("adaptive") != std::string::npos || m == "GBS" ? SolveOptions{.rtol = 1e-10}
                                                                               : SolveOptions{.steps = 100};
      opt.dense = dense;
      opt.max_steps = 2000;  // a failure either way: step size underflow or too many steps
      opt.partial_on_failure = true;
      calls = 0;
      const auto sol = solve(prob, m, opt);
      EXPECT_EQ(sol.status, SolveStatus::failed);
      EXPECT_GT(sol.force_evals, 0);
      EXPECT_EQ(sol.force_evals + sol.output_force_evals, calls);
      if (!dense) {
        EXPECT_EQ(sol.output_force_evals, 0);
      }
      EXPECT_GT(sol.accepted, 0);
      EXPECT_LE(sol.t_final, 1.0 + 1e-12);
    }
  }
  // Fixed steps with only the end as output time: q = t^2/2 passes 0.5 at t = 1 = 50 h, the run fails in the
  // 50th or 51st step (by rounding) and counts what the engine stepped by hand to there counts.
  calls = 0;
  const auto vv = solve(prob, "VV", {.steps = 100, .t_eval = {2.0}, .dense = false, .partial_on_failure = true});
  EXPECT_GE(vv.accepted, 49);
  EXPECT_LE(vv.accepted, 50);
  EXPECT_EQ(vv.force_evals, calls);
  long by_hand = 0;
  auto integ = make_integrator<Vd>(resolve_method("VV"), CountingForce<VdForce>{&by_hand, nan_past_half});
  State<Vd> s{{0.0}, {0.0}};
  for (long k = 0; k <= vv.accepted; ++k) integ.step(s, 0.02);
  EXPECT_FALSE(std::isfinite(s.q[0]) && std::isfinite(s.v[0]));
  EXPECT_EQ(vv.force_evals, by_hand);
}

TEST(Solve, StepsWithNothingToRecordAreTheEngineStepsBitwise) {
  // Output times only (no events, no dense output): solve() runs the steps between two outputs as bare engine
  // steps. The states are those of the engine stepped one step at a time by hand, bit for bit, forward and
  // backward, with a step count or a step size (whose last step is shorter), and the same as with the dense
  // output (which records every step end); output times inside a step are partial steps from its start.
  for (const std::string m : {"VV", "M8"}) {
    for (const int dir : {1, -1}) {
      for (const bool by_h : {false, true}) {
        SCOPED_TRACE(m + (dir > 0 ? " forward" : " backward") + (by_h ? " h" : " steps"));
        const double t1 = dir * 10.3;
        const auto prob = kepler(0.5, 0.0, t1);
        const long n = 400;
        const double h = by_h ? 10.3 / (n - 0.5) : 10.3 / n;  // by h: the last step is half as long
        auto end = [&](long j) { return j == n ? t1 : dir * (h * static_cast<double>(j)); };
        SolveOptions opt{.t_eval = {end(7), end(8), end(150), end(151) - dir * h / 3, end(399), t1}, .dense = false};
        if (by_h)
          opt.h = h;
        else
          opt.steps = n;
        long beats = 0;
        opt.on_step = [&](double) { ++beats; };
        opt.on_step_every = 64;
        const auto quiet = solve(prob, m, opt);
        opt.dense = true;
        const auto every_step = solve(prob, m, opt);
        EXPECT_EQ(beats, 2 * (n / 64));
        ASSERT_EQ(quiet.t.size(), opt.t_eval.size());
        EXPECT_EQ(quiet.t, every_step.t);
        EXPECT_EQ(quiet.q, every_step.q);
        EXPECT_EQ(quiet.v, every_step.v);
        EXPECT_EQ(quiet.accepted, n);
        EXPECT_EQ(quiet.force_evals, every_step.force_evals);
        // By hand: the engine on the time-reversed problem (q, -v), one step at a time.
        auto integ = make_integrator<V2>(resolve_method(m), KeplerForce{});
        State<V2> s{prob.q0, {dir * prob.v0[0], dir * prob.v0[1]}};
        std::vector<V2> qs;
        for (long k = 0; k < n; ++k) {
          integ.step(s, k == n - 1 && by_h ? 10.3 - h * (n - 1) : h);
          if (k + 1 == 7 || k + 1 == 8 || k + 1 == 150 || k + 1 == 399 || k + 1 == n) qs.push_back(s.q);
        }
        EXPECT_EQ(quiet.q[0], qs[0]);
        EXPECT_EQ(quiet.q[1], qs[1]);
        EXPECT_EQ(quiet.q[2], qs[2]);
        EXPECT_EQ(quiet.q[4], qs[3]);
        EXPECT_EQ(quiet.q[5], qs[4]);
        EXPECT_EQ(quiet.q_final, qs[4]);
        EXPECT_EQ(quiet.v_final[0], dir * s.v[0]);
        EXPECT_NEAR(quiet.q[3][0], every_step(quiet.t[3]).q[0], 0.0);  // a partial step, as sol(t)
      }
    }
  }
}

TEST(Solve, OnStepRunsEveryNthStepAndItsExceptionEndsTheRunThere) {
  long calls = 0;
  const auto s0 = KeplerProblem<double>(0.5).initial_state();
  const SecondOrderProblem prob(CountingForce<KeplerForce>{&calls}, s0.q, s0.v, 0.0, 100.0);
  struct Stop {};
  std::vector<double> seen;
  SolveOptions opt{.steps = 10000, .t_eval = {100.0}, .dense = false};
  opt.on_step_every = 1000;
  opt.on_step = [&](double t) {
    seen.push_back(t);
    if (seen.size() == 3) throw Stop{};
  };
  EXPECT_THROW(solve(prob, "VV", opt), Stop);
  ASSERT_EQ(seen.size(), 3u);
  EXPECT_DOUBLE_EQ(seen[2], 30.0);
  // The run stopped right there: the forces of 3000 steps of VV.
  long by_hand = 0;
  auto integ = make_integrator<V2>(resolve_method("VV"), CountingForce<KeplerForce>{&by_hand});
  State<V2> s = s0;
  for (long k = 0; k < 3000; ++k) integ.step(s, 0.01);
  EXPECT_EQ(calls, by_hand);
  opt.on_step_every = 0;
  EXPECT_THROW(solve(prob, "VV", opt), invalid_input);
}

namespace {

// How far the located time of a zero of g = r.v (a pericentre or apocentre of Kepler) may lie from the
// analytic time ts, given the method's accuracy there: the error of sol(ts) (dq in position, dv in
// velocity) shifts g by at most |v| dq + r dv, and g' = |v|^2 - 1/r, so the zero moves by at most that
// over |g'|; twice that, plus the rounding of the time (a few ulps of ts).
double apsis_time_bound(const Solution<V2>& sol, const KeplerProblem<double>& kp, double ts) {
  const auto ex = kp.exact(ts);
  const auto s = sol(ts);
  const double dq = std::hypot(s.q[0] - ex.q[0], s.q[1] - ex.q[1]);
  const double dv = std::hypot(s.v[0] - ex.v[0], s.v[1] - ex.v[1]);
  const double r = std::hypot(ex.q[0], ex.q[1]), v = std::hypot(ex.v[0], ex.v[1]);
  const double gdot = std::abs(v * v - 1 / r);
  return 2 * (v * dq + r * dv) / gdot + 8 * std::numeric_limits<double>::epsilon() * ts;
}

const std::vector<Event<V2>> apsides = {
    {.name = "pericentre",
     .g = [](double, const V2& q, const V2& v) { return q[0] * v[0] + q[1] * v[1]; },
     .direction = +1},
    {.name = "apocentre",
     .g = [](double, const V2& q, const V2& v) { return q[0] * v[0] + q[1] * v[1]; },
     .direction = -1},
};

}  // namespace

TEST(SolveEvents, KeplerApsidesAreTheAnalyticOnesToTheMethodsAccuracy) {
  // From the apocentre, r.v < 0 until the pericentre at t = pi (mod 2 pi), where it turns positive.
  // e = 0.9, to just before 6 pi (not ending on an apocentre, where g = 0).
  const KeplerProblem<double> kp(0.9);
  const auto prob = kepler(0.9, 0.0, 6 * pi - 0.5);
  struct Case {
    std::string method;
    SolveOptions opt;
    bool target;  // accurate enough for the times to 1e-12 relative
  };
  const std::vector<Case> cases = {{"DP12-adaptive", {.rtol = 1e-12, .dense = true}, true},
                                   {"M8", {.steps = 60000, .dense = true}, true},
                                   {"M14-adaptive", {.rtol = 1e-12, .dense = true}, true},
                                   {"GBS", {.rtol = 1e-12, .dense = true}, false},
                                   {"M6", {.steps = 6000, .dense = true}, false}};
  for (const auto& c : cases) {
    SCOPED_TRACE(c.method);
    const auto sol = solve(prob, c.method, c.opt, apsides);
    std::vector<double> peri, apo;
    for (const auto& e : sol.events) (e.name == "pericentre" ? peri : apo).push_back(e.t);
    ASSERT_EQ(peri.size(), 3u);
    ASSERT_EQ(apo.size(), 2u);  // 2 pi and 4 pi
    for (int i = 0; i < 3; ++i) {
      const double ts = (2 * i + 1) * pi, bound = apsis_time_bound(sol, kp, ts);
      EXPECT_NEAR(peri[i], ts, bound);
      if (c.target) {
        EXPECT_LE(std::abs(peri[i] - ts), 1e-12 * ts);
      }
      std::printf("%-14s pericentre %d: t/pi - %d = %9.2e (bound from the state error %.2e)\n", c.method.c_str(), i,
                  2 * i + 1, peri[i] / pi - (2 * i + 1), bound / pi);
    }
    for (int i = 0; i < 2; ++i) {
      const double ts = 2 * (i + 1) * pi;
      EXPECT_NEAR(apo[i], ts, apsis_time_bound(sol, kp, ts));
    }
  }
}

TEST(SolveEvents, AnEventCostsTwoForcesAndAboutOneStepOfTheMethodInBothDirections) {
  // The apsides of e = 0.9 over three orbits, forward from the apocentre and backward to near it: without
  // dense output an event costs the forces at the ends of its step (2), one partial step of the method
  // to the interpolant's estimate, and the force there (1); the times are the analytic ones to the
  // method's accuracy, as with the dense output (which evaluates the force at every step end).
  const KeplerProblem<double> kp(0.9);
  const double T = 6 * pi - 0.5;
  const auto ex = kp.exact(T);
  struct Case {
    std::string method;
    SolveOptions opt;
    long per_step;  // force evaluations of one step of the method (the partial step)
  };
  const std::vector<Case> cases = {
      {"KL8", {.steps = 20000}, 17}, {"M8", {.steps = 20000}, 10}, {"DP12-adaptive", {.rtol = 1e-12}, 17}};
  for (const int dir : {+1, -1}) {
    const auto prob = dir > 0 ? kepler(0.9, 0.0, T) : SecondOrderProblem(KeplerForce{}, ex.q, ex.v, T, 0.5);
    for (const auto& c : cases) {
      SCOPED_TRACE(c.method + (dir > 0 ? " forward" : " backward"));
      const auto sol = solve(prob, c.method, c.opt, apsides);
      SolveOptions dense_opt = c.opt;
      dense_opt.dense = true;
      const auto dense = solve(prob, c.method, dense_opt, apsides);
      ASSERT_EQ(sol.events.size(), 5u);
      ASSERT_EQ(dense.events.size(), 5u);
      const long per_event = 3 + c.per_step;
      EXPECT_LE(sol.output_force_evals, 5 * per_event);
      EXPECT_GE(sol.output_force_evals, 5 * 3);
      EXPECT_LE(per_event, 20);
      // Dense output: one force per step end and the start, plus a partial step and a force per event.
      EXPECT_LE(dense.output_force_evals, sol.accepted + 1 + 5 * (1 + c.per_step));
      for (std::size_t k = 0; k < 5; ++k) {
        const auto& e = sol.events[k];
        const int m = dir > 0 ? static_cast<int>(k) + 1 : 5 - static_cast<int>(k);  // t = m pi
        EXPECT_EQ(e.name, m % 2 == 1 ? "pericentre" : "apocentre");
        const double ts = m * pi;
        EXPECT_NEAR(e.t, ts, apsis_time_bound(dense, kp, ts));
        EXPECT_EQ(e.t, dense.events[k].t);  // the same location with or without the dense output
        // The event's state: on the orbit at its time (positions and velocities).
        const auto at = kp.exact(e.t);
        EXPECT_NEAR(e.q[0], at.q[0], 1e-9);
        EXPECT_NEAR(e.q[1], at.q[1], 1e-9);
        EXPECT_NEAR(e.v[0], at.v[0], 1e-8);
        EXPECT_NEAR(e.v[1], at.v[1], 1e-8);
        // g = r.v vanishes there to the rounding of the time (|g'| <= |v|^2 + 1/r < 30).
        EXPECT_LE(std::abs(e.q[0] * e.v[0] + e.q[1] * e.v[1]), 30 * 8e-16 * ts);
      }
      std::printf("%-14s %s: %ld output forces for 5 events (%ld steps)\n", c.method.c_str(),
                  dir > 0 ? "forward " : "backward", sol.output_force_evals, sol.accepted);
    }
  }
}

// The zero finder of the event locator (the Illinois variant of regula falsi) on g(t) = t^3 - 1/8 over the
// bracket (0, 2), in either order: a first point at the zero costs one evaluation of g, a first point near it fewer
// than the bracket alone, and a first point at an end of the bracket is not used; each ends within a few units
// of rounding of the zero 1/2.
TEST(SolveEvents, TheZeroFinderStartsFromItsFirstPoint) {
  int calls = 0;
  const auto g = [&](double t) {
    ++calls;
    return t * t * t - 0.125;
  };
  const double eps = std::numeric_limits<double>::epsilon();
  auto zero = [&](bool reversed, double first) {
    calls = 0;
    return reversed ? solve_detail::illinois(g, 2.0, 0.0, 7.875, -0.125, first)
                    : solve_detail::illinois(g, 0.0, 2.0, -0.125, 7.875, first);
  };
  for (const bool reversed : {false, true}) {
    SCOPED_TRACE(reversed ? "bracket (2, 0)" : "bracket (0, 2)");
    EXPECT_EQ(zero(reversed, 0.5), 0.5);
    EXPECT_EQ(calls, 1);
    EXPECT_NEAR(zero(reversed, reversed ? 2.0 : 0.0), 0.5, 4 * eps);
    const int from_bracket = calls;
    EXPECT_NEAR(zero(reversed, 0.501), 0.5, 4 * eps);
    const int from_near = calls;
    EXPECT_LT(from_near, from_bracket);
    EXPECT_GE(from_near, 2);
    EXPECT_LE(from_bracket, 20);  // superlinear convergence, far below the cap of 100 evaluations
  }
}

TEST(SolveEvents, TerminalEventEndsTheRunThere) {
  const KeplerProblem<double> kp(0.9);
  const auto prob = kepler(0.9, 0.0, 20.0);
  const std::vector<Event<V2>> ev = {apsides[0]};
  std::vector<Event<V2>> terminal = ev;
  terminal[0].terminal = true;
  const auto sol = solve(prob, "DP12-adaptive", {.rtol = 1e-13, .dense = true}, terminal);
  EXPECT_EQ(sol.status, SolveStatus::terminated_by_event);
  ASSERT_EQ(sol.events.size(), 1u);
  // The same run without the terminal flag takes the same steps up to there and finds the same time.
  const auto full = solve(prob, "DP12-adaptive", {.rtol = 1e-13, .dense = true}, ev);
  ASSERT_GE(full.events.size(), 1u);
  EXPECT_EQ(full.events[0].t, sol.t_final);
  EXPECT_NEAR(sol.t_final, pi, apsis_time_bound(full, kp, pi));
  // The final state is the event's, and the dense output ends there.
  EXPECT_EQ(sol.q_final, sol.events[0].q);
  EXPECT_EQ(sol.dense.times().back(), sol.t_final);
  EXPECT_LE(sol.t.back(), sol.t_final);
  // The pericentre of e = 0.9 lies at (-(1 - e), 0), reached at speed |v| = 4.36: within the state
  // error of the method there plus |v| times the time error.
  const auto ex = kp.exact(pi);
  const auto s = full(pi);
  const double dq = std::hypot(s.q[0] - ex.q[0], s.q[1] - ex.q[1]) + 4.4 * std::abs(sol.t_final - pi);
  EXPECT_NEAR(sol.q_final[0], -0.1, 2 * dq + 1e-15);
  EXPECT_NEAR(sol.q_final[1], 0.0, 2 * dq + 1e-15);
}

TEST(SolveEvents, HenonHeilesPoincareSectionLiesOnTheSectionAndTheEnergySurface) {
  // H = (px^2 + py^2)/2 + (x^2 + y^2)/2 + x^2 y - y^3/3 at E = 1/8; section x = 0, px > 0.
  VdForce f = [](const Vd& q, Vd& a) {
    a[0] = -q[0] - 2 * q[0] * q[1];
    a[1] = -q[1] - q[0] * q[0] + q[1] * q[1];
  };
  auto energy = [](const Vd& q, const Vd& p) {
    return (p[0] * p[0] + p[1] * p[1]) / 2 + (q[0] * q[0] + q[1] * q[1]) / 2 + q[0] * q[0] * q[1] -
           q[1] * q[1] * q[1] / 3;
  };
  const double E = 0.125, y0 = 0.1, py0 = 0.2;
  const double px0 = std::sqrt(2 * E - py0 * py0 - y0 * y0 + 2 * y0 * y0 * y0 / 3);
  const SecondOrderProblem prob(f, Vd{0.0, y0}, Vd{px0, py0}, 0.0, 200.0);
  const std::vector<Event<Vd>> ev = {
      {.name = "x=0", .g = [](double, const Vd& q, const Vd&) { return q[0]; }, .direction = +1}};
  const double eps = std::numeric_limits<double>::epsilon();
  // M8 at h = 0.1 and h = 0.2: energy errors of about 5e-13 and 1e-10 at the step ends, well above
  // rounding. A section point is a state of the dense output, so its energy error is bounded by the
  // method's: within 10x of the largest at the step ends.
  for (const long steps : {2000L, 1000L}) {
    SCOPED_TRACE(steps);
    const auto sol = solve(prob, "M8", {.steps = steps}, ev);
    double de_ends = 0;
    for (std::size_t k = 0; k < sol.t.size(); ++k)
      de_ends = std::max(de_ends, std::abs(energy(sol.q[k], sol.v[k]) - E));
    EXPECT_GT(de_ends, 100 * eps);
    ASSERT_GT(sol.events.size(), 20u);
    double de_section = 0;
    for (const auto& e : sol.events) {
      // On the section to the rounding of the located time: |x| <= |px| * (a few ulps of t).
      EXPECT_LE(std::abs(e.q[0]), 8 * eps * e.t * std::abs(e.v[0]) + eps) << e.t;
      EXPECT_GT(e.v[0], 0.0);
      de_section = std::max(de_section, std::abs(energy(e.q, e.v) - E));
    }
    EXPECT_LE(de_section, 10 * de_ends);
    // Each section point: the forces at its step's two ends, one M8 step (10 forces) and one force at the
    // interpolant's estimate; nothing else is evaluated for output.
    EXPECT_LE(sol.output_force_evals, 13 * static_cast<long>(sol.events.size()));
    std::printf(
        "Henon-Heiles M8, %ld steps: %zu section points, energy error %.2e (step ends %.2e), %ld output "
        "forces\n",
        steps, sol.events.size(), de_section, de_ends, sol.output_force_evals);
  }
}

TEST(SolveCheckpoint, RestartIsBitwiseTheUninterruptedRun) {
  const auto prob = kepler(0.7, 0.0, 30.0);
  struct Case {
    std::string method;
    SolveOptions opt;
  };
  std::vector<Case> cases = {
      {"M8", {.steps = 3000}},                                   // compensated summation (double's default)
      {"KL8", {.h = 0.011}},       {"Aprime", {.steps = 2000}},  // first same as last: the reused force
      {"DOP853", {.rtol = 1e-11}}, {"DP12-adaptive", {.rtol = 1e-11}}, {"M12-adaptive", {.rtol = 1e-11}},
      {"GBS", {.rtol = 1e-11}}};
  for (auto& c : cases) {
    SCOPED_TRACE(c.method);
    const auto def = resolve_solve_method(c.method);
    const auto plain = solve(prob, def, c.opt);
    c.opt.checkpoint_at = 12.3;
    c.opt.checkpoint_problem = "kepler e=0.7";
    std::string text;
    c.opt.on_checkpoint = [&](const std::string& s) { text = s; };
    const auto first = solve(prob, def, c.opt);
    ASSERT_TRUE(first.checkpoint.has_value());
    EXPECT_GE(first.checkpoint->t, 12.3);
    EXPECT_EQ(to_text(*first.checkpoint), text);
    // Taking the checkpoint changes nothing.
    EXPECT_EQ(first.q_final, plain.q_final);
    EXPECT_EQ(first.v_final, plain.v_final);
    EXPECT_EQ(first.force_evals, plain.force_evals);
    // Restart from the text: bitwise the same end.
    const auto cp = checkpoint_from_text<double>(text);
    const auto second = resume(prob, def, cp, c.opt);
    EXPECT_EQ(second.q_final, plain.q_final);
    EXPECT_EQ(second.v_final, plain.v_final);
    EXPECT_EQ(second.accepted, plain.accepted);
    EXPECT_NEAR(static_cast<double>(second.force_evals), static_cast<double>(plain.force_evals), 1.0);
    // Another method or problem is refused.
    EXPECT_THROW(resume(prob, resolve_method("M6"), cp, c.opt), invalid_input);
    SolveOptions other = c.opt;
    other.checkpoint_problem = "kepler e=0.5";
    EXPECT_THROW(resume(prob, def, cp, other), invalid_input);
    // Output times from the checkpoint's time on: the same states; one before it is refused (the resumed run
    // has no state there).
    SolveOptions timed = c.opt;
    timed.t_eval = {cp.t, 20.0, 30.0};
    const auto third = resume(prob, def, cp, timed);
    ASSERT_EQ(third.q.size(), 3u);
    EXPECT_EQ(third.t[0], cp.t);
    EXPECT_EQ(third.q[0], (V2{cp.state[0], cp.state[1]}));
    EXPECT_EQ(third.q[2], plain.q_final);
    EXPECT_EQ(third.q_final, plain.q_final);
    timed.t_eval = {12.0, 20.0};
    try {
      resume(prob, def, cp, timed);
      ADD_FAILURE() << "an output time before the checkpoint was accepted";
    } catch (const invalid_input& e) {
      EXPECT_NE(std::string(e.what()).find("output time 12 lies before the checkpoint's time"), std::string::npos)
          << e.what();
    }
  }
  EXPECT_THROW(checkpoint_from_text<double>("nystrom-checkpoint 99\n"), invalid_input);
  EXPECT_THROW(checkpoint_from_text<double>("garbage"), invalid_input);
}

// A checkpoint whose state has one number too few or too many for the problem is refused with one line, for a
// real method (q, v) and for a complex one (q, v as real and imaginary parts: a value missing from the last pair).
TEST(SolveCheckpoint, AStateOfTheWrongSizeIsRefused) {
  const auto prob = kepler(0.7, 0.0, 3.0);
  for (const std::string method : {"M8", "Chambers"}) {
    SCOPED_TRACE(method);
    const auto def = resolve_solve_method(method);
    SolveOptions opt{.steps = 300};
    opt.checkpoint_at = 1.0;
    opt.checkpoint_problem = "kepler e=0.7";
    const auto first = solve(prob, def, opt);
    ASSERT_TRUE(first.checkpoint.has_value());
    const std::size_t values = method == "M8" ? 4 : 8;
    ASSERT_EQ(first.checkpoint->state.size(), values);
    EXPECT_EQ(resume(prob, def, *first.checkpoint, opt).q_final, solve(prob, def, {.steps = 300}).q_final);
    for (const int change : {-1, 1, -2}) {
      auto cp = *first.checkpoint;
      if (change > 0)
        cp.state.push_back(0.5);
      else
        cp.state.resize(cp.state.size() - static_cast<std::size_t>(-change));
      try {
        resume(prob, def, cp, opt);
        ADD_FAILURE() << "a state of " << cp.state.size() << " numbers was accepted";
      } catch (const invalid_input& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("the state has the wrong size"), std::string::npos) << what;
        EXPECT_EQ(what.find('\n'), std::string::npos) << what;
      }
    }
  }
}
