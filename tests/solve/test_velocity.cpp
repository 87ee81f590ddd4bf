// Velocity-dependent forces a(t, q, v) through solve(): GBS on the first-order form (Gragg's modified
// midpoint), the multi-product expansion over that rule (fixed and adaptive) and the general RKN pairs (DOP853 in
// Nystrom form, Fine's 4(3) and 5(4)) against exact solutions (positions
// and velocities, both time directions), the Arenstorf orbit of Hairer-Nørsett-Wanner I, the compiled path against the
// inline one, dense output and events, the cost the controller decides, and the one-line refusal of every method that
// is not made for such forces.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "nystrom/engines/adaptive_mpe_coefficients.hpp"
#include "nystrom/engines/mpe_midpoint.hpp"
#include "nystrom/methods/catalog.hpp"
#include "nystrom/methods/method_data.hpp"
#include "nystrom/problems/arenstorf.hpp"
#include "nystrom/problems/damped_oscillator.hpp"
#include "nystrom/problems/van_der_pol.hpp"
#include "nystrom/solve/solve.hpp"

using namespace nystrom;
using Vd = std::vector<double>;

namespace {

const DampedOscillator<double> osc(2.0, 0.15, 0.7, 1.3);

// The largest error in position and in velocity against the exact solution at the end of the span.
void exact_errors(const Solution<Vd>& sol, double q0, double v0, double& eq, double& ev) {
  double qe = 0, ve = 0;
  osc.exact(q0, v0, sol.t_final, qe, ve);
  eq = std::abs(sol.q_final[0] - qe);
  ev = std::abs(sol.v_final[0] - ve);
}

double arenstorf_return_error(const std::string& method, double tol, long* evals = nullptr) {
  const double T = Arenstorf<double>::period();
  const SecondOrderProblem prob(ArenstorfForce{}, Vd{Arenstorf<double>::q0x(), 0.0}, Vd{0.0, Arenstorf<double>::v0y()},
                                0.0, T);
  const auto sol = solve(prob, method, {.rtol = tol});
  if (evals) *evals = sol.force_evals;
  return std::hypot(sol.q_final[0] - Arenstorf<double>::q0x(), sol.q_final[1]);
}

// The adaptive methods for y'' = f(t, y, y'): extrapolation, the general RKN pairs and the multi-product expansion
// of order 8 over the midpoint rule.
const char* const kVelocityPairs[] = {"GBS", "DOP853-adaptive", "Fine5-adaptive", "Fine4-adaptive",
                                      "mpe-midpoint-adaptive:1,2,3,4"};

}  // namespace

TEST(Velocity, DampedOscillatorMatchesExactSolutionForward) {
  for (const char* m : kVelocityPairs) {
    SCOPED_TRACE(m);
    const SecondOrderProblem prob(osc, Vd{1.0}, Vd{0.0}, 0.0, 10.0);
    for (double tol : {1e-6, 1e-9, 1e-12}) {
      const auto sol = solve(prob, m, {.rtol = tol});
      double eq = 0, ev = 0;
      exact_errors(sol, 1.0, 0.0, eq, ev);
      EXPECT_LT(eq, 50 * tol) << tol;
      EXPECT_LT(ev, 50 * tol) << tol;
      EXPECT_GT(sol.accepted, 0);
    }
  }
}

TEST(Velocity, DampedOscillatorBackwardReturnsToTheExactStart) {
  for (const char* m : kVelocityPairs) {
    SCOPED_TRACE(m);
    // From the exact state at t = 6 back to t = 0: the time-reversed problem (v -> -v) of a force that
    // depends on both t and v.
    double q6 = 0, v6 = 0;
    osc.exact(0.3, -0.5, 6.0, q6, v6);
    const SecondOrderProblem prob(osc, Vd{q6}, Vd{v6}, 6.0, 0.0);
    const auto sol = solve(prob, m, {.rtol = 1e-11});
    EXPECT_EQ(sol.t_final, 0.0);
    EXPECT_LT(std::abs(sol.q_final[0] - 0.3), 1e-8);
    EXPECT_LT(std::abs(sol.v_final[0] + 0.5), 1e-8);
  }
}

TEST(Velocity, AutonomousVelocityForceBothDirections) {
  for (const char* m : kVelocityPairs) {
    SCOPED_TRACE(m);
    // q'' = -q - 2 gamma q' without time: force(q, v, a). Forward to t = 4 and back with the result.
    const double g = 0.1;
    auto force = [g](const Vd& q, const Vd& v, Vd& a) { a[0] = -q[0] - 2 * g * v[0]; };
    const DampedOscillator<double> free_osc(1.0, g, 0.0, 1.0);
    const SecondOrderProblem fwd(force, Vd{1.0}, Vd{0.5}, 0.0, 4.0);
    const auto s1 = solve(fwd, m, {.rtol = 1e-12});
    double qe = 0, ve = 0;
    free_osc.exact(1.0, 0.5, 4.0, qe, ve);
    EXPECT_LT(std::abs(s1.q_final[0] - qe), 1e-10);
    EXPECT_LT(std::abs(s1.v_final[0] - ve), 1e-10);
    const SecondOrderProblem back(force, s1.q_final, s1.v_final, 4.0, 0.0);
    const auto s2 = solve(back, m, {.rtol = 1e-12});
    EXPECT_LT(std::abs(s2.q_final[0] - 1.0), 1e-10);
    EXPECT_LT(std::abs(s2.v_final[0] - 0.5), 1e-10);
  }
}

TEST(Velocity, ErrorFollowsTheTolerance) {
  for (const char* m : kVelocityPairs) {
    SCOPED_TRACE(m);
    // The error at the end shrinks with the tolerance: at least 100x from each tolerance to 1000x smaller.
    const SecondOrderProblem prob(osc, Vd{1.0}, Vd{0.0}, 0.0, 7.3);
    double last = 0;
    for (double tol : {1e-5, 1e-8, 1e-11}) {
      double eq = 0, ev = 0;
      exact_errors(solve(prob, m, {.rtol = tol}), 1.0, 0.0, eq, ev);
      const double e = std::max(eq, ev);
      if (last > 0) {
        EXPECT_LT(e, last / 100) << tol;
      }
      last = e;
    }
  }
}

TEST(Velocity, ArenstorfReturnsToItsStart) {
  for (const char* m : kVelocityPairs) {
    SCOPED_TRACE(m);
    // After one period of Hairer-Nørsett-Wanner's Arenstorf orbit the orbit closes to within what the
    // tolerance allows (the period and initial state are printed to 30 digits: the orbit itself closes to
    // about 1e-15).
    long e8 = 0, e12 = 0;
    const double r8 = arenstorf_return_error(m, 1e-8, &e8);
    const double r12 = arenstorf_return_error(m, 1e-12, &e12);
    EXPECT_LT(r8, 1e-4);
    EXPECT_LT(r12, 1e-8);
    EXPECT_LT(r12, r8 / 100);
    EXPECT_GT(e12, e8);
  }
}

TEST(Velocity, GbsCostOnArenstorfStaysInItsWindow) {
  // The controller's cost for one period at rtol 1e-10: force evaluations within 25% of the 3053 it spends
  // (66 accepted and 18 rejected steps; a regression of the order or step control moves it out).
  long evals = 0;
  arenstorf_return_error("GBS", 1e-10, &evals);
  EXPECT_GT(evals, 2300);
  EXPECT_LT(evals, 3800);
}

TEST(Velocity, CompiledPathIsBitwiseTheInlinePath) {
  for (const char* m : kVelocityPairs) {
    SCOPED_TRACE(m);
    const SecondOrderProblem prob(osc, Vd{1.0}, Vd{-0.2}, 0.0, 5.0);
    const SolveOptions opt{.rtol = 1e-10, .t_eval = {0.5, 2.5, 4.75}};
    const auto a = solve(prob, m, opt);
    const auto b = solve_inline(prob, m, opt);
    ASSERT_EQ(a.t.size(), b.t.size());
    for (std::size_t i = 0; i < a.t.size(); ++i) {
      EXPECT_EQ(std::memcmp(&a.q[i][0], &b.q[i][0], sizeof(double)), 0);
      EXPECT_EQ(std::memcmp(&a.v[i][0], &b.v[i][0], sizeof(double)), 0);
    }
    EXPECT_EQ(a.force_evals, b.force_evals);
  }
}

TEST(Velocity, InlinePathOnArrays) {
  for (const char* m : kVelocityPairs) {
    SCOPED_TRACE(m);
    using V2 = std::array<double, 2>;
    const SecondOrderProblem prob(ArenstorfForce{}, V2{Arenstorf<double>::q0x(), 0.0},
                                  V2{0.0, Arenstorf<double>::v0y()}, 0.0, Arenstorf<double>::period());
    const auto sol = solve_inline(prob, m, {.rtol = 1e-12});
    EXPECT_LT(std::hypot(sol.q_final[0] - Arenstorf<double>::q0x(), sol.q_final[1]), 1e-8);
  }
}

TEST(Velocity, DenseOutputAndEvents) {
  for (const char* m : kVelocityPairs) {
    SCOPED_TRACE(m);
    // sol(t) between the steps and the zeros of q located by an event, against the exact solution.
    const SecondOrderProblem prob(osc, Vd{1.0}, Vd{0.0}, 0.0, 6.0);
    std::vector<Event<Vd>> ev{{"q=0", [](double, const Vd& q, const Vd&) { return q[0]; }, 0, false}};
    SolveOptions opt{.rtol = 1e-11};
    opt.dense = true;
    const auto sol = solve(prob, m, opt, ev);
    for (double t : {0.37, 1.9, 3.14159, 5.5}) {
      const auto s = sol(t);
      double qe = 0, ve = 0;
      osc.exact(1.0, 0.0, t, qe, ve);
      EXPECT_LT(std::abs(s.q[0] - qe), 1e-8) << t;
      EXPECT_LT(std::abs(s.v[0] - ve), 1e-8) << t;
    }
    ASSERT_GE(sol.events.size(), 2u);
    for (const auto& e : sol.events) {
      double qe = 0, ve = 0;
      osc.exact(1.0, 0.0, e.t, qe, ve);
      EXPECT_LT(std::abs(qe), 1e-8) << e.t;  // q(t_event) = 0 for the exact solution
    }
  }
}

TEST(Velocity, MethodsNotForVelocityForcesAreRefusedWithOneLine) {
  const SecondOrderProblem prob(osc, Vd{1.0}, Vd{0.0}, 0.0, 1.0);
  const std::string expected =
      "method 'M8' does not support velocity-dependent forces a(t, q, v); methods that do: DOP853-adaptive, "
      "Fine4-adaptive, Fine5-adaptive, GBS, mpe-midpoint:K1,K2,..., "
      "mpe-midpoint-adaptive:K1,K2,...";
  EXPECT_EQ(velocity_refusal("M8"), expected);
  for (const char* m : {"M8", "VV", "DP12-adaptive", "M10-adaptive"}) {
    try {
      solve(prob, m, {.steps = 10, .rtol = 1e-8});
      ADD_FAILURE() << m << " was not refused";
    } catch (const invalid_input& e) {
      EXPECT_EQ(std::string(e.what()), velocity_refusal(resolve_method(m).info.name)) << m;
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
    }
  }
  // The catalog says which methods take such forces: the general RKN pairs, those with velocity coefficients.
  for (const auto& d : catalog()) {
    BigPrecision guard(128);
    const MethodData data = d.build();
    const auto* t = std::get_if<RknTableau<bigcomplex>>(&data);
    EXPECT_EQ(d.info.velocity, t != nullptr && t->general()) << d.info.name;
  }
  EXPECT_TRUE(gbs_method_def().info.velocity);
  EXPECT_EQ(velocity_methods(),
            (std::vector<std::string>{"DOP853-adaptive", "Fine4-adaptive", "Fine5-adaptive", "GBS",
                                      "mpe-midpoint:K1,K2,...", "mpe-midpoint-adaptive:K1,K2,..."}));
}

TEST(Velocity, TheForcesBoundsAreChecked) {
  auto wrong = [](double, const Vd&, const Vd&, Vd& a) { a = Vd(3, 0.0); };
  const SecondOrderProblem prob(wrong, Vd{1.0}, Vd{0.0}, 0.0, 1.0);
  EXPECT_THROW(solve(prob, "GBS", {.rtol = 1e-8}), invalid_input);
}

// ---- first-order systems y' = f(t, y) -------------------------------------------------------------------

TEST(FirstOrder, LinearSystemBothDirectionsWithDenseOutput) {
  for (const char* m : kVelocityPairs) {
    SCOPED_TRACE(m);
    // y' = (y2, -y1) + (0, cos t)... a forced rotation with exact solution y1 = cos t + t sin t / 2,
    // y2 = y1' = -sin t / 2 + t cos t / 2 (y1'' + y1 = cos t, y1(0) = 1, y1'(0) = 0).
    auto fun = [](double t, const Vd& y, Vd& dy) {
      dy[0] = y[1];
      dy[1] = -y[0] + std::cos(t);
    };
    auto y1 = [](double t) { return std::cos(t) + t * std::sin(t) / 2; };
    auto y2 = [](double t) { return -std::sin(t) / 2 + t * std::cos(t) / 2; };
    SolveOptions opt{.rtol = 1e-11};
    opt.dense = true;
    const auto sol = solve(FirstOrderProblem(fun, Vd{1.0, 0.0}, 0.0, 9.0), m, opt);
    EXPECT_EQ(sol.t_final, 9.0);
    EXPECT_LT(std::abs(sol.y_final[0] - y1(9.0)), 1e-9);
    EXPECT_LT(std::abs(sol.y_final[1] - y2(9.0)), 1e-9);
    for (double t : {0.3, 2.71, 5.0, 8.9}) {
      const Vd y = sol(t);
      EXPECT_LT(std::abs(y[0] - y1(t)), 1e-9) << t;
      EXPECT_LT(std::abs(y[1] - y2(t)), 1e-9) << t;
    }
    EXPECT_GT(sol.force_evals, 0);
    // Backward from t = 9 to 0.
    const auto back = solve(FirstOrderProblem(fun, Vd{y1(9.0), y2(9.0)}, 9.0, 0.0), m, {.rtol = 1e-11});
    EXPECT_EQ(back.t_final, 0.0);
    EXPECT_LT(std::abs(back.y_final[0] - 1.0), 1e-9);
    EXPECT_LT(std::abs(back.y_final[1]), 1e-9);
  }
}

TEST(FirstOrder, VanDerPolLimitCycleByEvents) {
  for (const char* m : kVelocityPairs) {
    SCOPED_TRACE(m);
    // The maxima of y1 (y2 = 0 falling) on the limit cycle of mu = 1 are one period apart.
    std::vector<FirstOrderEvent<Vd>> ev{{"max y1", [](double, const Vd& y) { return y[1]; }, -1, false}};
    const auto sol = solve(FirstOrderProblem(VanDerPol<double>{}, Vd{2.0, 0.0}, 0.0, 60.0), m, {.rtol = 1e-12}, ev);
    ASSERT_GE(sol.events.size(), 5u);
    const auto& e = sol.events;
    const double period = e[e.size() - 1].t - e[e.size() - 2].t;
    EXPECT_NEAR(period, VanDerPol<double>::period_mu1(), 1e-8);
    EXPECT_LT(std::abs(e.back().y[1]), 1e-9);  // located on y2 = 0
  }
}

TEST(FirstOrder, OtherMethodsAreRefusedWithOneLine) {
  auto fun = [](const Vd& y, Vd& dy) { dy[0] = -y[0]; };
  try {
    solve(FirstOrderProblem(fun, Vd{1.0}, 0.0, 1.0), "M8", {.steps = 10});
    ADD_FAILURE() << "not refused";
  } catch (const invalid_input& e) {
    EXPECT_EQ(std::string(e.what()),
              "method 'M8' does not integrate first-order systems y' = f(t, y); methods that do: DOP853-adaptive, "
              "Fine4-adaptive, Fine5-adaptive, GBS, mpe-midpoint:K1,K2,..., "
              "mpe-midpoint-adaptive:K1,K2,...");
  }
}

// ---- the multi-product expansion over Gragg's modified midpoint rule ----------------------------------------

namespace {

// The largest position or velocity error of mpe-midpoint:K with `steps` steps over [0, 4] (forward) or from
// the exact state at 4 back to 0 (backward), on the damped driven oscillator.
double midpoint_error(const std::string& spec, long steps, bool backward) {
  double q4 = 0, v4 = 0;
  osc.exact(1.0, 0.0, 4.0, q4, v4);
  const auto sol = backward ? solve(SecondOrderProblem(osc, Vd{q4}, Vd{v4}, 4.0, 0.0), spec, {.steps = steps})
                            : solve(SecondOrderProblem(osc, Vd{1.0}, Vd{0.0}, 0.0, 4.0), spec, {.steps = steps});
  const double qe = backward ? 1.0 : q4, ve = backward ? 0.0 : v4;
  return std::max(std::abs(sol.q_final[0] - qe), std::abs(sol.v_final[0] - ve));
}

}  // namespace

TEST(MidpointMpe, ObservedOrderOnTheVelocityDependentClassBothDirections) {
  struct Case {
    const char* spec;
    int order;
    long steps;
  };
  for (const Case& c : {Case{"mpe-midpoint:1", 2, 200}, Case{"mpe-midpoint:1,2", 4, 40},
                        Case{"mpe-midpoint:1,2,3", 6, 40}, Case{"mpe-midpoint:1,2,3,4", 8, 32}}) {
    EXPECT_EQ(resolve_solve_method(c.spec).info.order, c.order);
    for (bool backward : {false, true}) {
      const double e1 = midpoint_error(c.spec, c.steps, backward), e2 = midpoint_error(c.spec, 2 * c.steps, backward);
      const double p = std::log2(e1 / e2);
      EXPECT_GT(p, c.order - 0.3) << c.spec << (backward ? " backward" : " forward") << " e1 " << e1 << " e2 " << e2;
      EXPECT_LT(p, c.order + 0.7) << c.spec << (backward ? " backward" : " forward") << " e1 " << e1 << " e2 " << e2;
    }
  }
}

TEST(MidpointMpe, CostPerStepIsItsCatalogCount) {
  // 1 + sum (2 k_i - 1) force evaluations per step: 1 + 1 + 3 + 5 = 10 for 1,2,3.
  const auto def = resolve_solve_method("mpe-midpoint:1,2,3");
  EXPECT_EQ(def.info.forces_per_step, 10);
  EXPECT_TRUE(def.info.velocity);
  const auto sol = solve(SecondOrderProblem(osc, Vd{1.0}, Vd{0.0}, 0.0, 1.0), def, {.steps = 7});
  EXPECT_EQ(sol.force_evals, 70);
}

TEST(MidpointMpe, FirstOrderSystemAndRefusalForAccelerations) {
  // Van der Pol from the same start with the midpoint MPE of order 8 and with GBS agree.
  const FirstOrderProblem vdp(VanDerPol<double>{}, Vd{2.0, 0.0}, 0.0, 5.0);
  const auto a = solve(vdp, "mpe-midpoint:1,2,3,4", {.steps = 400});
  const auto b = solve(vdp, "GBS", {.rtol = 1e-13});
  EXPECT_LT(std::abs(a.y_final[0] - b.y_final[0]), 1e-9);
  EXPECT_LT(std::abs(a.y_final[1] - b.y_final[1]), 1e-9);
  // A force a(q) is refused with one line naming the method for it.
  auto harmonic = [](const Vd& q, Vd& acc) { acc[0] = -q[0]; };
  try {
    solve(SecondOrderProblem(harmonic, Vd{1.0}, Vd{0.0}, 0.0, 1.0), "mpe-midpoint:1,2", {.steps = 10});
    ADD_FAILURE() << "not refused";
  } catch (const invalid_input& e) {
    EXPECT_EQ(std::string(e.what()),
              "method 'mpe-midpoint:1,2' is for velocity-dependent forces and first-order systems; for a(t, q) run "
              "its multi-product expansion over Verlet, mpe:1,2");
  }
}

TEST(MidpointMpe, AdaptiveErrorEstimateHasOrderTwoNMinusOne) {
  // The estimate sum_i d_i (T_i - z0) of the products without the largest k is the local error of the method of
  // order 2n - 2: it shrinks like h^(2n - 1) (5 for 1,2,3, 7 for 1,2,3,4); the step itself is that of the fixed
  // method (bitwise).
  auto force = [](const Vd& q, const Vd& v, Vd& a) { a[0] = -std::sin(q[0]) - 0.3 * v[0] - 0.2 * v[0] * v[0] * v[0]; };
  for (const std::vector<long>& k : {std::vector<long>{1, 2, 3}, std::vector<long>{1, 2, 3, 4}}) {
    const AdaptiveMpeCoefficients ac = adaptive_mpe_coefficients(k);
    const auto c = mpe_coefficients_as<double>(ac.high), d = mpe_coefficients_as<double>(ac.error());
    double e[2];
    for (int j = 0; j < 2; ++j) {
      const double h = 0.2 / (1 << j);
      MidpointMpeIntegrator<Vd, decltype(force)> stepper(k, c, force, {}, d);
      State<Vd> s{Vd{1.2}, Vd{0.3}}, err;
      stepper.step_with_error(s, h, err);
      e[j] = std::hypot(err.q[0], err.v[0]);
      MidpointMpeIntegrator<Vd, decltype(force)> fixed(k, c, force);
      State<Vd> f{Vd{1.2}, Vd{0.3}};
      fixed.integrate(f, h, 1);
      EXPECT_EQ(f.q, s.q);
      EXPECT_EQ(f.v, s.v);
    }
    const double p = std::log2(e[0] / e[1]), expected = 2.0 * static_cast<double>(k.size()) - 1;
    EXPECT_NEAR(p, expected, 0.4) << k.size() << " products: " << e[0] << " " << e[1];
  }
}

TEST(MidpointMpe, AdaptiveCostIsExactAndItsOrderIsInTheCatalog) {
  // Two forces for the starting step, 1 + sum (2 k_i - 1) per attempt from a new state and sum (2 k_i - 1) for a
  // retry after a rejection (the start force is kept): 16 + 1 per accepted step for 1,2,3,4.
  const MethodDef def = resolve_solve_method("mpe-midpoint-adaptive:1,2,3,4");
  EXPECT_EQ(def.info.order, 8);
  EXPECT_TRUE(def.info.adaptive);
  EXPECT_TRUE(def.info.velocity);
  EXPECT_EQ(def.info.forces_per_step, 17);
  long total_rejected = 0;
  for (double tol : {1e-7, 1e-10, 1e-13}) {
    const SecondOrderProblem prob(ArenstorfForce{}, Vd{Arenstorf<double>::q0x(), 0.0},
                                  Vd{0.0, Arenstorf<double>::v0y()}, 0.0, Arenstorf<double>::period());
    const auto sol = solve(prob, def, {.rtol = tol});
    EXPECT_EQ(sol.force_evals, 2 + 16 * (sol.accepted + sol.rejected) + sol.accepted) << tol;
    total_rejected += sol.rejected;
  }
  EXPECT_GT(total_rejected, 0);  // the retry's saving was exercised
  // A single product has no estimate; a step count alone is refused; a force a(q) is sent to the adaptive MPE
  // over Verlet.
  EXPECT_THROW(resolve_solve_method("mpe-midpoint-adaptive:4"), invalid_input);
  const SecondOrderProblem pd(osc, Vd{1.0}, Vd{0.0}, 0.0, 1.0);
  EXPECT_THROW(solve(pd, def, {.steps = 10}), invalid_input);
  auto harmonic = [](const Vd& q, Vd& acc) { acc[0] = -q[0]; };
  try {
    solve(SecondOrderProblem(harmonic, Vd{1.0}, Vd{0.0}, 0.0, 1.0), "mpe-midpoint-adaptive:1,2,3", {.rtol = 1e-8});
    ADD_FAILURE() << "not refused";
  } catch (const invalid_input& e) {
    EXPECT_EQ(std::string(e.what()),
              "method 'mpe-midpoint-adaptive:1,2,3' is for velocity-dependent forces and first-order systems; for "
              "a(t, q) run its multi-product expansion over Verlet, mpe-adaptive:1,2,3");
  }
}

// ---- the general RKN pairs ----------------------------------------------------------------------------------

TEST(Velocity, GeneralPairsCostOnArenstorfFollowsTheirOrder) {
  // One period at rtol 1e-10: the higher the order, the fewer forces; the return error within what the
  // tolerance allows. Each step costs its catalog count, the first step size two more.
  long dop = 0, fine5 = 0, fine4 = 0;
  EXPECT_LT(arenstorf_return_error("DOP853-adaptive", 1e-10, &dop), 1e-6);
  EXPECT_LT(arenstorf_return_error("Fine5-adaptive", 1e-10, &fine5), 1e-6);
  EXPECT_LT(arenstorf_return_error("Fine4-adaptive", 1e-10, &fine4), 1e-6);
  std::printf("Arenstorf, rtol 1e-10: forces DOP853 %ld, Fine5 %ld, Fine4 %ld\n", dop, fine5, fine4);
  EXPECT_LT(2 * dop, fine5);
  EXPECT_LT(fine5, fine4);
  const SecondOrderProblem prob(ArenstorfForce{}, Vd{Arenstorf<double>::q0x(), 0.0}, Vd{0.0, Arenstorf<double>::v0y()},
                                0.0, Arenstorf<double>::period());
  const auto sol = solve(prob, "DOP853", {.rtol = 1e-10});
  EXPECT_EQ(sol.force_evals, 2 + 13 + (sol.accepted + sol.rejected - 1) * 12);
}

TEST(Velocity, GeneralPairsRefuseWhatTheyCannotDo) {
  // DOP853's coefficients are published to 28 digits: enough for double and long double, not for
  // double-double (106 bits; only splitting methods are refined). Fine's pairs are exact.
  const MethodDef dop = resolve_method("DOP853");
  EXPECT_NO_THROW(method_data_for(dop, 64, "long double"));
  try {
    method_data_for(dop, 106, "dd");
    ADD_FAILURE() << "not refused";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("published with 28 digits, too few for dd"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(method_data_for(resolve_method("Fine5-adaptive"), 212, "qd"));
  // A pair runs with a tolerance: a step count alone is refused.
  const SecondOrderProblem pd(osc, Vd{1.0}, Vd{0.0}, 0.0, 1.0);
  EXPECT_THROW(solve(pd, "DOP853-adaptive", {.steps = 10}), invalid_input);
}

TEST(Velocity, AdaptivePairsRestartFromACheckpointBitwise) {
  // A time- and velocity-dependent force, forward and backward: the run resumed from the checkpoint's text ends
  // bitwise where the uninterrupted one does (one force more at most: the reused first force is not in the text).
  for (const char* m : {"DOP853-adaptive", "Fine5-adaptive", "mpe-midpoint-adaptive:1,2,3"})
    for (const double t1 : {9.0, -9.0}) {
      SCOPED_TRACE(std::string(m) + (t1 > 0 ? " forward" : " backward"));
      const SecondOrderProblem prob(osc, Vd{1.0}, Vd{-0.4}, 0.0, t1);
      SolveOptions opt{.rtol = 1e-10};
      const auto plain = solve(prob, m, opt);
      opt.checkpoint_at = t1 / 3;
      opt.checkpoint_problem = "damped";
      std::string text;
      opt.on_checkpoint = [&](const std::string& s) { text = s; };
      const auto first = solve(prob, m, opt);
      ASSERT_TRUE(first.checkpoint.has_value());
      EXPECT_EQ(first.q_final, plain.q_final);
      const auto second = resume(prob, resolve_solve_method(m), checkpoint_from_text<double>(text), opt);
      EXPECT_EQ(second.q_final, plain.q_final);
      EXPECT_EQ(second.v_final, plain.v_final);
      EXPECT_EQ(second.accepted, plain.accepted);
      EXPECT_NEAR(static_cast<double>(second.force_evals), static_cast<double>(plain.force_evals), 1.0);
    }
}
