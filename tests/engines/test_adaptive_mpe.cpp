// The adaptive multi-product expansion (engines/adaptive_mpe.hpp): the embedded estimate has the
// order it claims, the error on Kepler follows the tolerance, the step shrinks at pericentre and steps
// are rejected there at e = 0.9, a high order at a tight tolerance does not aim below the
// estimate's round-off, force evaluations are counted exactly, the lockstep and sequential
// schedules give bitwise the same results, and bad input fails with std::invalid_argument (nystrom::invalid_input
// from the catalog).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iostream>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "nystrom/engines/adaptive_mpe.hpp"
#include "nystrom/methods/catalog.hpp"
#include "nystrom/planetary/system.hpp"
#include "nystrom/problems/counting_force.hpp"
#include "nystrom/problems/kepler.hpp"

using namespace nystrom;

namespace {

using V2 = std::array<double, 2>;
using VD = std::vector<double>;

using CountingKepler = CountingForce<KeplerForce>;

AdaptiveOptions with_tol(double tol) {
  AdaptiveOptions o;
  o.rtol = tol;
  return o;
}

double position_error(const State<V2>& s, double ecc, double t) {
  const KeplerProblem<long double> kp(static_cast<long double>(ecc));
  const auto ex = kp.exact(static_cast<long double>(t));
  return static_cast<double>(
      std::hypot(static_cast<long double>(s.q[0]) - ex.q[0], static_cast<long double>(s.q[1]) - ex.q[1]));
}

/// One period of Kepler e = 0.5 with the default controller at tolerance tol.
struct OnePeriod {
  double tol = 0, error = 0;
  long force_evals = 0, calls = 0;
};
OnePeriod one_period(const char* spec, double tol) {
  const double T = KeplerProblem<double>::period();
  OnePeriod r;
  r.tol = tol;
  auto ai = make_adaptive_mpe_integrator<V2>(resolve_method(spec), CountingKepler{&r.calls}, with_tol(tol));
  State<V2> s = KeplerProblem<double>(0.5).initial_state();
  r.force_evals = ai.integrate_to(s, 0.0, T).force_evals;
  r.error = position_error(s, 0.5, T);
  return r;
}

}  // namespace

// The exact coefficients: both combinations sum to 1, the error weights to 0, and the dropped product
// is the one of largest k.
TEST(AdaptiveMpe, CoefficientsOfThePair) {
  const auto ac = adaptive_mpe_coefficients({1, 2, 3, 4, 5});
  EXPECT_EQ(ac.dropped, 4u);
  mpq_class sh(0), sl(0), sd(0);
  for (const auto& c : ac.high.c) sh += c;
  for (const auto& c : ac.low.c) sl += c;
  for (const auto& c : ac.diff) sd += c;
  EXPECT_EQ(sh, 1);
  EXPECT_EQ(sl, 1);
  EXPECT_EQ(sd, 0);
  EXPECT_EQ(ac.low.order(), 8);
  EXPECT_EQ(ac.diff[4], ac.high.c[4]);
  EXPECT_EQ(adaptive_mpe_coefficients({3, 1, 2}).dropped, 0u);
}

// One trial step from the apocentre of e = 0.5: the estimate scales like h^(2n-1) and the propagated
// solution's local error like h^(2n+1) (M8: 7 and 9), observed over h, h/2, h/4.
TEST(AdaptiveMpe, EmbeddedEstimateHasItsOrder) {
  long calls = 0;
  auto ai = make_adaptive_mpe_integrator<V2>(resolve_method("M8-adaptive"), CountingKepler{&calls}, with_tol(1e-8));
  EXPECT_EQ(ai.error_order(), 6);
  EXPECT_EQ(ai.method_order(), 8);
  const KeplerProblem<double> kp(0.5);
  const State<V2> s0 = kp.initial_state();
  std::vector<double> est, loc;
  for (double h : {0.4, 0.2, 0.1}) {
    State<V2> inc, err;
    ai.trial_step(s0, h, inc, err);
    est.push_back(std::hypot(err.q[0], err.q[1]));
    State<V2> s1 = s0;
    for (int i = 0; i < 2; ++i) s1.q[i] += inc.q[i];
    loc.push_back(position_error(s1, 0.5, h));
  }
  for (int i = 0; i + 1 < 3; ++i) {
    const double pe = std::log2(est[i] / est[i + 1]);
    EXPECT_NEAR(pe, 7.0, 0.6) << "estimate order between h = " << 0.4 / (1 << i) << " and half";
  }
  // The local error at h = 0.1 is near rounding: use the two larger steps.
  EXPECT_NEAR(std::log2(loc[0] / loc[1]), 9.0, 0.8);
  EXPECT_LT(loc[1], 0.1 * est[1]);  // local extrapolation: the propagated solution is the better one
  EXPECT_EQ(calls, 3 * 10);         // sum k = 10 forces per trial (position Verlet base: no shared force)
}

// Kepler e = 0.5 over one period: the error follows the tolerance (bounded by a fixed multiple of it,
// and smaller at the tighter tolerance) and the work grows slowly.
TEST(AdaptiveMpe, KeplerErrorTracksTheTolerance) {
  const OnePeriod loose = one_period("M10-adaptive", 1e-8), tight = one_period("M10-adaptive", 1e-11);
  for (const OnePeriod* r : {&loose, &tight}) {
    EXPECT_EQ(r->force_evals, r->calls);
    EXPECT_LT(r->error, 100 * r->tol) << r->tol;
  }
  EXPECT_LT(tight.error, 1e-2 * loose.error);
  EXPECT_GT(tight.force_evals, loose.force_evals);
  EXPECT_LT(tight.force_evals, 4 * loose.force_evals);  // about tol^(-1/9): 2.2x for 1000x
}

// At high order and tight tolerance the default controller must not aim below the round-off of the
// estimate (sum |d_i| ~ 175 for M16 times the increments' rounding): M16-adaptive on Kepler e = 0.5,
// one period, tol 1e-11 -> 1e-13 should cost about 100^(1/15) = 1.36x the forces. Measured: 1.22x with
// the default safety 0.9; 3.7x with 0.7, which aims at err = 0.7^15 = 0.005 tol (and 37x for 1e-14).
TEST(AdaptiveMpe, HighOrderTightToleranceStaysAboveTheEstimatesRoundOff) {
  const OnePeriod loose = one_period("M16-adaptive", 1e-11), tight = one_period("M16-adaptive", 1e-13);
  for (const OnePeriod* r : {&loose, &tight}) EXPECT_LT(r->error, 100 * r->tol) << r->tol;
  EXPECT_GT(tight.force_evals, loose.force_evals);
  EXPECT_LT(tight.force_evals, 2 * loose.force_evals) << loose.force_evals << " -> " << tight.force_evals;
}

// Kepler e = 0.9: the step at pericentre is far smaller than at apocentre, the end time is hit
// exactly, and the force count is exact: sum k forces per attempted step plus the starting-step
// estimate. The standard controller rejects steps (the step grows on the way out and must shrink
// coming in); the predictive one (the default) follows that trend and rejects fewer.
TEST(AdaptiveMpe, PericentreShrinksTheStepAndRejects) {
  long rejected[2] = {0, 0};
  for (bool predictive : {false, true}) {
    SCOPED_TRACE(predictive ? "predictive" : "standard");
    long calls = 0;
    AdaptiveOptions opt = with_tol(1e-8);
    opt.predictive = predictive;
    auto ai = make_adaptive_mpe_integrator<V2>(resolve_method("M12-adaptive"), CountingKepler{&calls}, opt);
    State<V2> s = KeplerProblem<double>(0.9).initial_state();
    const double T = KeplerProblem<double>::period();
    double t_prev = 0, h_peri = INFINITY, h_apo = 0, t_last = -1;
    const AdaptiveStats st = ai.integrate_to(s, 0.0, 2 * T, [&](double t, const State<V2>& x) {
      const double r = std::hypot(x.q[0], x.q[1]);
      const double h = t - t_prev;
      if (t > 0 && t < 2 * T - 1e-9) {
        if (r < 0.2) h_peri = std::min(h_peri, h);
        if (r > 1.8) h_apo = std::max(h_apo, h);
      }
      t_prev = t;
      t_last = t;
    });
    EXPECT_EQ(t_last, 2 * T);
    EXPECT_LT(st.rejected, st.accepted);
    EXPECT_LT(h_peri, 0.05 * h_apo);
    EXPECT_EQ(st.force_evals, calls);
    EXPECT_EQ(st.force_evals, 21 * (st.accepted + st.rejected) + 2);
    EXPECT_LT(position_error(s, 0.9, 2 * T), 1e-5);
    rejected[predictive] = st.rejected;
  }
  EXPECT_GT(rejected[0], 0);
  EXPECT_LT(rejected[1], rejected[0]);
}

// Many short calls continue the run (step size and compensation carry kept) and land on each end time.
TEST(AdaptiveMpe, ContinuesAcrossCalls) {
  long calls = 0;
  auto ai = make_adaptive_mpe_integrator<V2>(resolve_method("M10-adaptive"), CountingKepler{&calls}, with_tol(1e-10));
  State<V2> s = KeplerProblem<double>(0.5).initial_state();
  const double T = KeplerProblem<double>::period();
  for (int i = 0; i < 10; ++i) ai.integrate_to(s, T * i / 10, T * (i + 1) / 10);
  EXPECT_LT(position_error(s, 0.5, T), 1e-8);
  EXPECT_EQ(ai.total().force_evals, calls);
}

// The schedules: lockstep (unrolled, std::array: trial_verlet, which issues the products by decreasing
// k), sequential, and the run-time lockstep of std::vector states give bitwise the same trajectory;
// with and without compensated summation, for a drift-first and a kick-first base, and for a sequence
// not in ascending order.
TEST(AdaptiveMpe, SchedulesAreBitwiseIdentical) {
  for (const char* spec : {"mpe-adaptive:1,2,3,5", "mpe-vv-adaptive:3,1,5,2"})
    for (Compensation comp : {Compensation::on, Compensation::off}) {
      SCOPED_TRACE(spec);
      auto run_array = [&](MpeSchedule sched) {
        long calls = 0;
        EngineOptions eo;
        eo.compensated = comp;
        eo.mpe_schedule = sched;
        auto ai = make_adaptive_mpe_integrator<V2>(resolve_method(spec), CountingKepler{&calls}, with_tol(1e-9), eo);
        EXPECT_EQ(ai.lockstep(), sched != MpeSchedule::sequential);
        State<V2> s = KeplerProblem<double>(0.9).initial_state();
        const AdaptiveStats st = ai.integrate_to(s, 0.0, 7.0);
        return std::pair(s, st.force_evals);
      };
      const auto [a, fa] = run_array(MpeSchedule::lockstep);
      const auto [b, fb] = run_array(MpeSchedule::sequential);
      EXPECT_EQ(fa, fb);
      for (int i = 0; i < 2; ++i) {
        EXPECT_EQ(a.q[i], b.q[i]);
        EXPECT_EQ(a.v[i], b.v[i]);
      }
      for (MpeSchedule sched : {MpeSchedule::lockstep, MpeSchedule::sequential}) {
        long calls = 0;
        EngineOptions eo;
        eo.compensated = comp;
        eo.mpe_schedule = sched;
        auto ai = make_adaptive_mpe_integrator<VD>(resolve_method(spec), CountingKepler{&calls}, with_tol(1e-9), eo);
        const auto s0 = KeplerProblem<double>(0.9).initial_state();
        State<VD> s{{s0.q[0], s0.q[1]}, {s0.v[0], s0.v[1]}};
        const AdaptiveStats st = ai.integrate_to(s, 0.0, 7.0);
        EXPECT_EQ(st.force_evals, fa);
        for (int i = 0; i < 2; ++i) {
          EXPECT_EQ(s.q[i], a.q[i]);
          EXPECT_EQ(s.v[i], a.v[i]);
        }
      }
    }
}

// std::array states of long double run the unrolled controller loop (as float and double do) in lockstep, and the
// run-time one in sequence and on std::vector: bitwise the same trajectory and force count, for fixed and controlled
// order, drift- and kick-first bases, with and without compensated summation.
namespace {
/// Kepler e = 0.9 from t = 0 to 7 at tolerance tol in the state type V and the given schedule; the end state, the
/// force evaluations, and whether the products were precise.
template <class V>
struct ScheduleRun {
  State<V> s;
  long force_evals = 0;
  bool precise = false;
};
template <class V>
ScheduleRun<V> schedule_run(const char* spec, Compensation comp, MpeSchedule sched, double tol) {
  using S = typename V::value_type;
  long calls = 0;
  EngineOptions eo;
  eo.compensated = comp;
  eo.mpe_schedule = sched;
  auto ai = make_adaptive_mpe_integrator<V>(resolve_method(spec), CountingKepler{&calls}, with_tol(tol), eo);
  const auto s0 = KeplerProblem<S>(S(0.9)).initial_state();
  ScheduleRun<V> r;
  r.s = State<V>{{s0.q[0], s0.q[1]}, {s0.v[0], s0.v[1]}};
  r.force_evals = ai.integrate_to(r.s, S(0), S(7)).force_evals;
  r.precise = ai.precise_products();
  EXPECT_EQ(r.force_evals, calls);
  return r;
}
template <class V>
std::pair<State<V>, long> long_double_run(const char* spec, Compensation comp, MpeSchedule sched) {
  const ScheduleRun<V> r = schedule_run<V>(spec, comp, sched, 1e-12);
  return {r.s, r.force_evals};
}
}  // namespace

TEST(AdaptiveMpe, LongDoubleArraysAgreeWithTheRunTimePathBitwise) {
  using VL = std::array<long double, 2>;
  using VLD = std::vector<long double>;
  for (const char* spec : {"M12-adaptive", "mpe-vv-adaptive:3,1,5,2", "MPE-adaptive"})
    for (Compensation comp : {Compensation::on, Compensation::off}) {
      SCOPED_TRACE(std::string(spec) + (comp == Compensation::on ? " compensated" : " plain"));
      const auto [a, fa] = long_double_run<VL>(spec, comp, MpeSchedule::lockstep);
      const auto [b, fb] = long_double_run<VL>(spec, comp, MpeSchedule::sequential);
      const auto [c, fc] = long_double_run<VLD>(spec, comp, MpeSchedule::lockstep);
      EXPECT_GT(fa, 1000);
      EXPECT_EQ(fa, fb);
      EXPECT_EQ(fa, fc);
      for (int i = 0; i < 2; ++i) {
        EXPECT_TRUE(a.q[i] == b.q[i] && a.v[i] == b.v[i]) << i;
        EXPECT_TRUE(a.q[i] == c.q[i] && a.v[i] == c.v[i]) << i;
      }
      // The run is long double's: it ends near the exact orbit, far below double's rounding.
      const auto ex = KeplerProblem<long double>(0.9L).exact(7.0L);
      EXPECT_LT(std::hypot(a.q[0] - ex.q[0], a.q[1] - ex.q[1]), 1e-9L);
    }
}

// Precise products (a compensated run in double at a tolerance near the rounding floor): the unrolled lockstep, the
// sequential schedule and std::vector states perform the same operations, bitwise the same trajectory and force count
// for fixed and controlled order, drift- and kick-first bases; a loose tolerance or a plain run keeps plain products.
TEST(AdaptiveMpe, PreciseProductsAreBitwiseTheSameOnEveryPath) {
  for (const char* spec : {"M12-adaptive", "mpe-vv-adaptive:3,1,5,2", "MPE-adaptive"}) {
    SCOPED_TRACE(spec);
    const auto a = schedule_run<V2>(spec, Compensation::automatic, MpeSchedule::lockstep, 1e-13);
    const auto b = schedule_run<V2>(spec, Compensation::automatic, MpeSchedule::sequential, 1e-13);
    const auto c = schedule_run<VD>(spec, Compensation::automatic, MpeSchedule::lockstep, 1e-13);
    EXPECT_TRUE(a.precise && b.precise && c.precise);
    EXPECT_GT(a.force_evals, 1000);
    EXPECT_EQ(a.force_evals, b.force_evals);
    EXPECT_EQ(a.force_evals, c.force_evals);
    for (int i = 0; i < 2; ++i) {
      EXPECT_TRUE(a.s.q[i] == b.s.q[i] && a.s.v[i] == b.s.v[i]) << i;
      EXPECT_TRUE(a.s.q[i] == c.s.q[i] && a.s.v[i] == c.s.v[i]) << i;
    }
    const auto ex = KeplerProblem<long double>(0.9L).exact(7.0L);
    EXPECT_LT(std::hypot(a.s.q[0] - ex.q[0], a.s.q[1] - ex.q[1]), 1e-11L);
    EXPECT_FALSE(schedule_run<V2>(spec, Compensation::automatic, MpeSchedule::lockstep, 1e-9).precise);
    EXPECT_FALSE(schedule_run<V2>(spec, Compensation::off, MpeSchedule::lockstep, 1e-13).precise);
  }
  // Not for types without an exact two-sum, nor where compensation is off by default (long double).
  EXPECT_FALSE(
      (schedule_run<std::array<long double, 2>>("M12-adaptive", Compensation::automatic, MpeSchedule::lockstep, 1e-13)
           .precise));
}

// Precise products lower the rounding floor of the multi-product expansion in double: M12-adaptive on Kepler over
// 100 periods at e = 0.3, 0.5 and 0.7 and 12 tolerances from 1e-13 to 3.2e-15 each (the decades double accepts),
// the median final position error is below 7e-12. Measured through the tool: 1.05e-11 with the products' rounding
// left in, 4.1e-12 precise, 1.3e-12 in long double (truncation alone at these steps). The median, not the rms: the
// rms is set by the few runs whose truncation error is largest.
TEST(AdaptiveMpe, PreciseProductsLowerTheRoundingFloor) {
  std::vector<double> errors;
  for (double ecc : {0.3, 0.5, 0.7})
    for (int i = 0; i < 12; ++i) {
      const double tol = std::pow(10.0, -13.0 - 1.5 * i / 11);
      const double T = 100 * KeplerProblem<double>::period();
      long calls = 0;
      auto ai = make_adaptive_mpe_integrator<V2>(resolve_method("M12-adaptive"), CountingKepler{&calls}, with_tol(tol));
      ASSERT_TRUE(ai.precise_products()) << tol;
      State<V2> s = KeplerProblem<double>(ecc).initial_state();
      ai.integrate_to(s, 0.0, T);
      errors.push_back(position_error(s, ecc, T));
    }
  std::sort(errors.begin(), errors.end());
  const double median = errors[errors.size() / 2];
  std::cout << "[ floor    ] M12-adaptive, Kepler e = 0.3, 0.5, 0.7, 100 periods, tol 1e-13..3.2e-15: median error "
            << median << ", largest " << errors.back() << "\n";
  EXPECT_LT(median, 7e-12);
}

// A base that starts with a kick (velocity Verlet) shares the force at q_0 among the products: one
// more force per accepted step (kept across a rejected one).
TEST(AdaptiveMpe, VelocityVerletBaseCountsTheSharedForce) {
  long calls = 0;
  auto ai = make_adaptive_mpe_integrator<V2>(resolve_method("mpe-vv-adaptive:1,2,3,4"), CountingKepler{&calls},
                                             with_tol(1e-9));
  State<V2> s = KeplerProblem<double>(0.5).initial_state();
  const double T = KeplerProblem<double>::period();
  const AdaptiveStats st = ai.integrate_to(s, 0.0, T);
  EXPECT_EQ(st.force_evals, calls);
  EXPECT_EQ(st.force_evals, 10 * (st.accepted + st.rejected) + st.accepted + 2);
  EXPECT_LT(position_error(s, 0.5, T), 1e-7);
}

TEST(AdaptiveMpe, BadInputThrows) {
  long calls = 0;
  const MethodDef def = resolve_method("M10-adaptive");
  EXPECT_TRUE(def.info.adaptive);
  EXPECT_EQ(def.info.order, 10);
  EXPECT_EQ(def.info.forces_per_step, 15);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (double tol : {0.0, -1e-8, nan, double(INFINITY), 1e-17})
    EXPECT_THROW(make_adaptive_mpe_integrator<V2>(def, CountingKepler{&calls}, with_tol(tol)), std::invalid_argument)
        << tol;
  for (const char* spec : {"mpe-adaptive:", "mpe-adaptive:1", "mpe-adaptive:1,1,2", "mpe-adaptive:0,1", "M2-adaptive",
                           "M7-adaptive", "mpe-vv-adaptive:x"})
    EXPECT_THROW(resolve_method(spec), invalid_input) << spec;
  EXPECT_THROW(adaptive_mpe_coefficients({}), std::invalid_argument);
  EXPECT_THROW(adaptive_mpe_coefficients({4}), std::invalid_argument);
  EXPECT_THROW(make_adaptive_mpe_integrator<V2>(resolve_method("DP12"), CountingKepler{&calls}, with_tol(1e-8)),
               std::invalid_argument);
  EngineOptions conc;
  conc.mpe_schedule = MpeSchedule::concurrent;
  EXPECT_THROW(make_adaptive_mpe_integrator<V2>(def, CountingKepler{&calls}, with_tol(1e-8), conc),
               std::invalid_argument);
  auto ai = make_adaptive_mpe_integrator<V2>(def, CountingKepler{&calls}, with_tol(1e-8));
  State<V2> s = KeplerProblem<double>(0.5).initial_state();
  EXPECT_THROW(ai.integrate_to(s, 1.0, 0.0), std::invalid_argument);
  EXPECT_THROW(ai.integrate_to(s, 0.0, nan), std::invalid_argument);
  State<V2> bad = s;
  bad.v[1] = nan;
  EXPECT_THROW(ai.integrate_to(bad, 0.0, 1.0), std::invalid_argument);
  // A tolerance that cannot be met near a collision: step-size underflow (a runtime_error).
  State<V2> radial{{1.0, 0.0}, {0.0, 0.0}};
  auto tight = make_adaptive_mpe_integrator<V2>(def, CountingKepler{&calls}, with_tol(1e-12));
  EXPECT_THROW(tight.integrate_to(radial, 0.0, 2.0), StepSizeUnderflow);
}

// ---- order control (MPE-adaptive) ---------------------------------------------------------------------

namespace {

struct OrderRun {
  State<V2> s;
  AdaptiveStats st;
  std::vector<long> hist;
  long calls = 0, early = 0;
  double error = 0;
};

OrderRun order_run(const char* spec, double ecc, double tol, double t1) {
  OrderRun r;
  auto ai = make_adaptive_mpe_integrator<V2>(resolve_method(spec), CountingKepler{&r.calls}, with_tol(tol));
  r.s = KeplerProblem<double>(ecc).initial_state();
  r.st = ai.integrate_to(r.s, 0.0, t1);
  r.hist = ai.order_histogram();
  r.early = ai.early_rejections();
  r.error = position_error(r.s, ecc, t1);
  return r;
}

// The mean order of the accepted steps.
double mean_order(const std::vector<long>& hist) {
  double n = 0, sum = 0;
  for (std::size_t p = 0; p < hist.size(); ++p) {
    n += static_cast<double>(hist[p]);
    sum += static_cast<double>(p * static_cast<std::size_t>(hist[p]));
  }
  return n > 0 ? sum / n : 0;
}

}  // namespace

// The catalog entry and its order cap: the metadata of the largest step (k = 1..8: 36 forces, order 16).
TEST(AdaptiveMpeOrderControl, CatalogEntry) {
  const MethodDef def = resolve_method("MPE-adaptive");
  EXPECT_TRUE(def.info.adaptive);
  EXPECT_EQ(def.info.family, "mpe");
  EXPECT_EQ(def.info.order, 16);
  EXPECT_EQ(def.info.stages, 36);
  EXPECT_EQ(def.info.forces_per_step, 36);
  EXPECT_FALSE(def.info.source.empty());
  const MethodDef capped = resolve_method("mpe-adaptive-max:10");
  EXPECT_EQ(capped.info.order, 10);
  EXPECT_EQ(capped.info.forces_per_step, 15);
  long calls = 0;
  auto ai = make_adaptive_mpe_integrator<V2>(capped, CountingKepler{&calls}, with_tol(1e-9));
  EXPECT_EQ(ai.max_products(), 5);
  EXPECT_EQ(ai.order_histogram().size(), 11u);
  for (const char* spec : {"MPE-adaptive-max:", "MPE-adaptive-max:2", "MPE-adaptive-max:7", "MPE-adaptive-max:18",
                           "MPE-adaptive-max:100", "MPE-adaptive-max:x", "MPE-adaptive-max:-4", "MPE-adaptive-max:1e1"})
    EXPECT_THROW(resolve_method(spec), invalid_input) << spec;
}

// Work per unit step: a loose tolerance makes the low orders' steps nearly as long as the high orders', so
// they win; a tight one favours the high orders (their step shrinks like tol^(1/(2n-1))). Kepler e = 0.5,
// one period: the mean order of the accepted steps rises with the tolerance's digits, the histogram counts
// every accepted step, and the error falls with the tolerance.
TEST(AdaptiveMpeOrderControl, OrderRisesAsTheToleranceTightens) {
  const double T = KeplerProblem<double>::period();
  std::vector<double> means, errors;
  for (double tol : {1e-5, 1e-9, 1e-12}) {
    const OrderRun r = order_run("MPE-adaptive", 0.5, tol, T);
    long sum = 0;
    for (long c : r.hist) sum += c;
    EXPECT_EQ(sum, r.st.accepted) << tol;
    EXPECT_EQ(r.hist[0] + r.hist[2], 0) << tol;  // the smallest order is 4 (two products)
    EXPECT_LT(r.error, 10 * tol) << tol;         // a global error from local errors below tol over ~20 steps
    means.push_back(mean_order(r.hist));
    errors.push_back(r.error);
    std::cout << "[ orders   ] tol " << tol << ": mean order " << means.back() << ", error " << r.error << ", "
              << r.st.accepted << " steps, " << r.st.rejected << " rejected (" << r.early << " early)" << std::endl;
  }
  EXPECT_LT(means[0], 12);  // 1e-5 is a controlled tolerance of 6.6e-7 (tolerance proportionality)
  EXPECT_GT(means[2], 13);
  EXPECT_GT(means[1], means[0] + 2);
  EXPECT_GE(means[2], means[1]);
  EXPECT_LT(errors[1], errors[0] * 1e-2);
  EXPECT_LT(errors[2], errors[1] * 1e-2);
}

// A loose tolerance on the outer solar system (Sun and five outer bodies, 100 Jupiter periods, tol 1e-6): order 4
// passes there, and a step taken with two products has no lower estimate to weigh against, so order control that
// took it stayed at order 4 for good (M4-adaptive's 21 172 steps, 75x the forces of M16-adaptive). The smallest
// target's three products always complete: the controller climbs to the high orders, and the run costs at most
// 1.5 times M16-adaptive's forces at the same tolerance (measured 1.0x).
TEST(AdaptiveMpeOrderControl, LooseToleranceDoesNotStayAtOrderFour) {
  const auto sys = planetary::outer_solar_system<double>();
  const planetary::CartesianForce<double> force(sys);
  const State<VD> s0{planetary::flatten(sys.x), planetary::flatten(sys.v)};
  const double span = 100 * 4332.59;  // days
  auto oc = make_adaptive_mpe_integrator<VD>(resolve_method("MPE-adaptive"), force, with_tol(1e-6));
  auto m16 = make_adaptive_mpe_integrator<VD>(resolve_method("M16-adaptive"), force, with_tol(1e-6));
  State<VD> a = s0, b = s0;
  const AdaptiveStats sa = oc.integrate_to(a, 0.0, span), sb = m16.integrate_to(b, 0.0, span);
  const std::vector<long>& hist = oc.order_histogram();
  std::cout << "[ orders   ] outer solar system, tol 1e-6: " << sa.accepted << " steps, " << sa.force_evals
            << " forces, mean order " << mean_order(hist) << " (M16-adaptive " << sb.accepted << " steps, "
            << sb.force_evals << " forces)" << std::endl;
  EXPECT_LT(static_cast<double>(sa.force_evals), 1.5 * static_cast<double>(sb.force_evals));
  EXPECT_GT(mean_order(hist), 12);
  EXPECT_LT(hist[4], sa.accepted / 10);
}

// Exact force counting with steps of several orders, steps stopped early after products 1..n-1 and rejected
// ones: the engine's count is the force's, over several calls that continue the run.
TEST(AdaptiveMpeOrderControl, CountsForcesExactly) {
  long calls = 0;
  auto ai = make_adaptive_mpe_integrator<V2>(resolve_method("MPE-adaptive"), CountingKepler{&calls}, with_tol(1e-10));
  State<V2> s = KeplerProblem<double>(0.9).initial_state();
  const double T = KeplerProblem<double>::period();
  long sum = 0;
  for (int i = 0; i < 4; ++i) sum += ai.integrate_to(s, T * i / 2, T * (i + 1) / 2).force_evals;
  EXPECT_EQ(sum, calls);
  EXPECT_EQ(ai.force_evals(), calls);
  EXPECT_EQ(ai.total().force_evals, calls);
  EXPECT_GT(ai.total().rejected, 0);  // e = 0.9: the pericentre rejects steps
  int orders = 0;
  for (long c : ai.order_histogram()) orders += c > 0;
  EXPECT_GE(orders, 2);
  EXPECT_LT(position_error(s, 0.9, 2 * T), 1e-7);
}

// With orders up to 4 only (two products, nothing to choose), the controller is the fixed-order one:
// MPE-adaptive-max:4 is bitwise M4-adaptive, force counts included.
TEST(AdaptiveMpeOrderControl, PinnedOrderIsTheFixedOrderEngine) {
  const double T = KeplerProblem<double>::period();
  const OrderRun a = order_run("MPE-adaptive-max:4", 0.9, 1e-7, T);
  long calls = 0;
  auto fixed = make_adaptive_mpe_integrator<V2>(resolve_method("M4-adaptive"), CountingKepler{&calls}, with_tol(1e-7));
  State<V2> s = KeplerProblem<double>(0.9).initial_state();
  const AdaptiveStats st = fixed.integrate_to(s, 0.0, T);
  EXPECT_EQ(a.st.accepted, st.accepted);
  EXPECT_EQ(a.st.rejected, st.rejected);
  EXPECT_EQ(a.st.force_evals, st.force_evals);
  EXPECT_EQ(a.hist[4], st.accepted);
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(a.s.q[i], s.q[i]);
    EXPECT_EQ(a.s.v[i], s.v[i]);
  }
}

// The unrolled path (std::array of double) and the run-time one (std::vector) take the
// same steps: bitwise the same trajectory, orders and force counts.
TEST(AdaptiveMpeOrderControl, StateTypesAgree) {
  const MethodDef def = resolve_method("MPE-adaptive");
  const OrderRun a = order_run("MPE-adaptive", 0.9, 1e-9, 7.0);
  long calls = 0;
  auto ai = make_adaptive_mpe_integrator<VD>(def, CountingKepler{&calls}, with_tol(1e-9));
  const auto s0 = KeplerProblem<double>(0.9).initial_state();
  State<VD> s{{s0.q[0], s0.q[1]}, {s0.v[0], s0.v[1]}};
  const AdaptiveStats st = ai.integrate_to(s, 0.0, 7.0);
  EXPECT_EQ(st.force_evals, a.st.force_evals);
  EXPECT_EQ(ai.order_histogram(), a.hist);
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(s.q[i], a.s.q[i]);
    EXPECT_EQ(s.v[i], a.s.v[i]);
  }
}

// The first step of an order-controlled run takes the number of products of ODEX's rule for the first order (HNW I,
// sec. II.9), floor(-0.6 log10(tol) + 1.5), between three and the largest: written out here per tolerance.
TEST(AdaptiveMpeOrderControl, FirstStepProductsFollowOdexsRule) {
  long calls = 0;
  const std::vector<std::pair<double, int>> rule = {{1e-3, 3},  {1e-5, 4},  {1e-7, 5}, {1e-8, 6},
                                                    {1e-10, 7}, {1e-12, 8}, {1e-14, 8}};
  for (const auto& [tol, n] : rule) {
    auto ai = make_adaptive_mpe_integrator<V2>(resolve_method("MPE-adaptive"), CountingKepler{&calls}, with_tol(tol));
    EXPECT_EQ(ai.initial_products(), n) << tol;
  }
  AdaptiveOptions abs_only;
  abs_only.rtol = 0;
  abs_only.atol = 1e-10;
  EXPECT_EQ(make_adaptive_mpe_integrator<V2>(resolve_method("MPE-adaptive"), CountingKepler{&calls}, abs_only)
                .initial_products(),
            7);
  EXPECT_EQ(
      make_adaptive_mpe_integrator<V2>(resolve_method("mpe-adaptive-max:10"), CountingKepler{&calls}, with_tol(1e-10))
          .initial_products(),
      5);
  EXPECT_EQ(make_adaptive_mpe_integrator<V2>(resolve_method("M10-adaptive"), CountingKepler{&calls}, with_tol(1e-10))
                .initial_products(),
            0);
}

// Order-control tables the engine cannot run are refused, for every number of products from two: a table of the
// wrong length, or with a coefficient that is not finite.
TEST(AdaptiveMpeOrderControl, MalformedTablesAreRefusedFromTwoProducts) {
  const std::vector<long> k = {1, 2, 3, 4};
  const AdaptiveMpeCoefficients ac = adaptive_mpe_coefficients(k);
  auto conv = [](const bigcomplex& x) { return to_scalar<double>(x); };
  const auto base = convert_scheme<double>(velocity_verlet_scheme(), conv);
  long calls = 0;
  auto make = [&](MpeOrderTables<double> orders) {
    return AdaptiveMpeIntegrator<V2, CountingKepler>(k, mpe_coefficients_as<double>(ac.high),
                                                     mpe_coefficients_as<double>(ac.error()), base,
                                                     CountingKepler{&calls}, with_tol(1e-8), {}, std::move(orders));
  };
  EXPECT_EQ(make(mpe_order_tables<double>(k)).max_products(), 4);
  for (std::size_t n = 2; n <= 4; ++n) {
    auto shorter = mpe_order_tables<double>(k);
    shorter.c[n].pop_back();
    EXPECT_THROW(make(shorter), std::invalid_argument) << n;
    auto longer = mpe_order_tables<double>(k);
    longer.d[n].push_back(0.0);
    EXPECT_THROW(make(longer), std::invalid_argument) << n;
    auto nan = mpe_order_tables<double>(k);
    nan.d[n][0] = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THROW(make(nan), std::invalid_argument) << n;
    auto inf = mpe_order_tables<double>(k);
    inf.c[n][n - 1] = std::numeric_limits<double>::infinity();
    EXPECT_THROW(make(inf), std::invalid_argument) << n;
  }
}

// One coefficient and one error weight per member of the sequence: either one too short, or both, is refused.
TEST(AdaptiveMpe, CoefficientsOfTheWrongLengthAreRefused) {
  const std::vector<long> k = {1, 2, 3};
  const AdaptiveMpeCoefficients ac = adaptive_mpe_coefficients(k);
  auto conv = [](const bigcomplex& x) { return to_scalar<double>(x); };
  const auto base = convert_scheme<double>(velocity_verlet_scheme(), conv);
  const std::vector<double> c = mpe_coefficients_as<double>(ac.high), d = mpe_coefficients_as<double>(ac.error());
  long calls = 0;
  auto make = [&](std::vector<double> cc, std::vector<double> dd) {
    return AdaptiveMpeIntegrator<V2, CountingKepler>(k, std::move(cc), std::move(dd), base, CountingKepler{&calls},
                                                     with_tol(1e-8));
  };
  EXPECT_EQ(make(c, d).sequence(), k);
  const std::vector<double> c_short(c.begin(), c.end() - 1), d_short(d.begin(), d.end() - 1);
  EXPECT_THROW(make(c_short, d), std::invalid_argument);
  EXPECT_THROW(make(c, d_short), std::invalid_argument);
  EXPECT_THROW(make(c_short, d_short), std::invalid_argument);
}
