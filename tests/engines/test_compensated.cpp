// Compensated summation of the position and velocity updates (EngineOptions::compensated).
//
// Kepler e = 0.5 over 1000 periods in double. The reference is the same method at the same step in
// long double (compensated) from the same double initial state, so the truncation error cancels and
// the difference is the round-off of the double run. Compensation must lower it by at least 10x for a
// splitting (FR), an MPE (M8) and an RKN tableau (M6-5F), and changes nothing else (force counts).
// The adaptive RKN pairs' precise update (engines/rkn.hpp): its error-free transformations are exact, and
// DP12-adaptive's round-off at the tightest tolerances stays below its truncation error.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <iostream>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "nystrom/core/eft.hpp"
#include "nystrom/core/extended.hpp"
#include "nystrom/engines/adaptive_mpe.hpp"
#include "nystrom/engines/adaptive_rkn.hpp"
#include "nystrom/nystrom.hpp"
#include "nystrom/problems/nbody.hpp"
#include "nystrom/problems/reference.hpp"
#include "nystrom/solve/checkpoint.hpp"
#include "nystrom/solve_inline.hpp"

using namespace nystrom;

namespace {

struct Outcome {
  double err = 0;  // |q_double - q_reference| at the end
  long evals = 0;
};

using V = std::array<double, 2>;
using VL = std::array<long double, 2>;

/// Final position of a double run against the long double reference (same method, same h).
Outcome roundoff_error(const std::string& spec, long steps_per_period, long periods, Compensation comp,
                       double* truncation = nullptr) {
  const MethodDef def = resolve_method(spec);
  const KeplerProblem<double> prob(0.5);
  const State<V> s0 = prob.initial_state();
  const double h = KeplerProblem<double>::period() / static_cast<double>(steps_per_period);
  const long n = steps_per_period * periods;

  EngineOptions opt;
  opt.compensated = comp;
  auto integ = make_integrator<V>(def, KeplerForce{}, opt);
  State<V> s = s0;
  integ.integrate(s, h, n);

  EngineOptions ref_opt;
  ref_opt.compensated = Compensation::on;
  auto ref = make_integrator<VL>(def, KeplerForce{}, ref_opt);
  State<VL> sl = convert_state<VL>(s0);
  ref.integrate(sl, static_cast<long double>(h), n);

  if (truncation) {
    const KeplerProblem<long double> pl(0.5L);
    const auto ex = pl.exact(static_cast<long double>(h) * static_cast<long double>(n));
    *truncation = static_cast<double>(std::hypot(sl.q[0] - ex.q[0], sl.q[1] - ex.q[1]));
  }
  Outcome o;
  o.err = std::hypot(static_cast<double>(static_cast<long double>(s.q[0]) - sl.q[0]),
                     static_cast<double>(static_cast<long double>(s.q[1]) - sl.q[1]));
  o.evals = integ.force_evals();
  return o;
}

/// Asserts a 10x gain; returns the truncation error of the reference.
double expect_gain(const std::string& spec, long steps_per_period, long periods) {
  double trunc = 0;
  const Outcome off = roundoff_error(spec, steps_per_period, periods, Compensation::off, &trunc);
  const Outcome on = roundoff_error(spec, steps_per_period, periods, Compensation::automatic);
  std::cout << spec << " at " << steps_per_period << " steps/period, " << periods
            << " periods: round-off error uncompensated " << off.err << ", compensated " << on.err << " (gain "
            << off.err / on.err << "); long double error against the analytic solution " << trunc << "\n";
  EXPECT_EQ(on.evals, off.evals) << spec;
  EXPECT_GT(off.err, 0) << spec;
  EXPECT_LT(on.err * 10, off.err) << spec;
  return trunc;
}

}  // namespace

TEST(Compensated, DefaultIsOnForFloatAndDoubleOnly) {
  static_assert(use_compensation<double>(Compensation::automatic));
  static_assert(use_compensation<float>(Compensation::automatic));
  static_assert(use_compensation<std::complex<double>>(Compensation::automatic));
  static_assert(!use_compensation<long double>(Compensation::automatic));
  static_assert(use_compensation<long double>(Compensation::on));
  static_assert(!use_compensation<double>(Compensation::off));
  SUCCEED();
}

TEST(Compensated, TwoSumCarriesTheExactError) {
  // 1 + 1e-17 a thousand times: plain summation stays at 1, the carry keeps 1e-14.
  double x = 1, c = 0, plain = 1;
  for (int i = 0; i < 1000; ++i) {
    compensated_add(x, c, 1e-17);
    plain += 1e-17;
  }
  EXPECT_EQ(plain, 1.0);
  EXPECT_NEAR((x - 1) + c, 1e-14, 1e-28);
  // The increment may be larger than the sum (positions cross zero): two-sum is exact for any order.
  double y = 1e-20, cy = 0;
  compensated_add(y, cy, 1.0);
  EXPECT_EQ(y, 1.0);
  EXPECT_EQ(cy, 1e-20);
}

// FR: truncation error large, but the reference has the same; the comparison is of round-off only.
TEST(Compensated, SplittingFR) { expect_gain("FR", 400, 1000); }
// M8 at 600 steps per period: truncation error (long double against the analytic solution) below
// the round-off error of the uncompensated double run.
TEST(Compensated, MpeM8) {
  const double trunc = expect_gain("M8", 600, 1000);
  EXPECT_LT(trunc, 1e-10);
}
// The multi-product expansion on the velocity-Verlet base, whose products start and end with a kick (the other
// branch of the products' last sub-step), at half the cost of M8 here.
TEST(Compensated, MpeOnTheVelocityVerletBase) { expect_gain("mpe-vv:1,2,3,4", 300, 1000); }
// RKN: one increment per step; the gain measured here is small (round-off of the stages dominates),
// compensation must at least not make it worse.
TEST(Compensated, RknM65F) {
  const Outcome off = roundoff_error("M6-5F", 200, 1000, Compensation::off);
  const Outcome on = roundoff_error("M6-5F", 200, 1000, Compensation::automatic);
  std::cout << "M6-5F at 200 steps/period, 1000 periods: round-off error uncompensated " << off.err << ", compensated "
            << on.err << "\n";
  EXPECT_LT(on.err, off.err);
}

TEST(Compensated, CarrySurvivesStepByStepCalls) {
  // integrate(s, h, 1) in a loop keeps the carry when the state is not moved in between.
  // An RKN tableau (no merging of sub-steps across calls): both runs must agree to the last bit.
  const MethodDef def = resolve_method("M6-5F");
  const KeplerProblem<double> prob(0.5);
  const double h = KeplerProblem<double>::period() / 200;
  auto a = make_integrator<V>(def, KeplerForce{});
  auto b = make_integrator<V>(def, KeplerForce{});
  State<V> sa = prob.initial_state(), sb = sa;
  a.integrate(sa, h, 4000);
  for (int i = 0; i < 4000; ++i) b.step(sb, h);
  EXPECT_EQ(sa.q[0], sb.q[0]);
  EXPECT_EQ(sa.q[1], sb.q[1]);
  EXPECT_EQ(sa.v[0], sb.v[0]);
  EXPECT_EQ(sa.v[1], sb.v[1]);
}

TEST(Compensated, ErrorFreeSumAndProductAreExact) {
  // s + e = a + b and p + e = a b exactly, checked in quadruple precision (113 bits hold the 106-bit product of
  // two doubles and every sum of two doubles within 2^50 of each other); float against double.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> mant(-1, 1);
  std::uniform_int_distribution<int> expo(-25, 25);
  for (int i = 0; i < 20000; ++i) {
    const double a = std::ldexp(mant(rng), expo(rng)), b = std::ldexp(mant(rng), expo(rng));
    double e;
    const double s = eft::two_sum(a, b, e);
    EXPECT_EQ(float128(s) + float128(e), float128(a) + float128(b)) << a << " + " << b;
    EXPECT_EQ(s, a + b);
    const double p = eft::two_prod(a, b, e);
    EXPECT_EQ(float128(p) + float128(e), float128(a) * float128(b)) << a << " * " << b;
    EXPECT_EQ(p, a * b);
    const float af = static_cast<float>(a), bf = static_cast<float>(b);
    float ef;
    const float pf = eft::two_prod(af, bf, ef);
    EXPECT_EQ(double(pf) + double(ef), double(af) * double(bf));
    const float sf = eft::two_sum(af, bf, ef);
    EXPECT_EQ(double(sf) + double(ef), double(af) + double(bf));
  }
}

namespace {

// The rms final position and velocity errors of an adaptive method on Kepler over 100 periods at the seven tolerances
// 10^(log_tol0 - k/8), k = 0..6, with the force F, against the exact orbit of the run's initial state; steps: the
// accepted steps at the tightest. The RKN pairs run under plain control (the controller works to tol itself: round-off
// against truncation at given tolerances, not the calibration of tolerance proportionality); the multi-product
// expansions under their calibration.
template <class T, class Force = KeplerForce>
ReferenceErrors floor_rms(const char* method, double ecc, double log_tol0, long* steps) {
  using VT = std::array<T, 2>;
  const KeplerProblem<T> kp(static_cast<T>(ecc));
  const MethodDef def = resolve_method(method);
  const bool mpe = def.info.family == "mpe";
  const T t_end = KeplerProblem<T>::period() * T(100);
  double sq = 0, sv = 0;
  for (int k = 0; k <= 6; ++k) {
    AdaptiveOptions opt;
    opt.rtol = std::pow(10.0, log_tol0 - k / 8.0);
    if (!mpe) opt.tolerance_exponent = 1;
    const State<VT> s0 = kp.initial_state();
    State<VT> s = s0;
    const AdaptiveStats st = mpe ? make_adaptive_mpe_integrator<VT>(def, Force{}, opt).integrate_to(s, T(0), t_end)
                                 : make_adaptive_integrator<VT>(def, Force{}, opt).integrate_to(s, T(0), t_end);
    const auto e = kepler_reference_errors(s0, s, t_end, 1);
    sq += e.position * e.position;
    sv += e.velocity * e.velocity;
    *steps = st.accepted;
  }
  ReferenceErrors out;
  out.position = std::sqrt(sq / 7);
  out.velocity = std::sqrt(sv / 7);
  return out;
}

// DP12-adaptive's rms final position error (floor_rms).
template <class T, class Force = KeplerForce>
double adaptive_floor_rms(double ecc, long* steps, double log_tol0 = -13.75) {
  return floor_rms<T, Force>("DP12-adaptive", ecc, log_tol0, steps).position;
}

}  // namespace

// At the tightest tolerances DP12-adaptive in double was 4x above its own truncation error (the same steps in
// long double, 4.0e-13 at e = 0.5 and 8.4e-13 at e = 0.9): rounded weights biasing every step, increments
// summed in double, stage positions rounded without their carry. The precise update keeps the round-off below
// the truncation: double within 2x long double, and at most 8e-13 (e = 0.5) and 1.6e-12 (e = 0.9), where the plain
// compensated update gave 1.6e-12 and 3.3e-12.
TEST(Compensated, AdaptiveRknRoundOffStaysBelowItsTruncation) {
  for (double ecc : {0.5, 0.9}) {
    long steps_d = 0, steps_l = 0;
    const double d = adaptive_floor_rms<double>(ecc, &steps_d);
    const double l = adaptive_floor_rms<long double>(ecc, &steps_l);
    std::cout << "e = " << ecc << ": rms position error, double " << d << ", long double " << l << " (" << steps_d
              << " and " << steps_l << " steps at the tightest tolerance)\n";
    EXPECT_LT(d, 2 * l) << ecc;
    EXPECT_LT(d, ecc < 0.7 ? 8e-13 : 1.6e-12) << ecc;
    EXPECT_NEAR(static_cast<double>(steps_d), static_cast<double>(steps_l), 0.01 * steps_l);
  }
}

// The compensated Kepler force returns -(q + cq) / |q + cq|^3 as a + alo to a few units of the working precision
// squared (against quadruple precision; float against double), over radii 1e-3 .. 1e3 and carries up to half an
// ulp, where the plain force rounds at units of the working precision; its plain form is KeplerForce's bitwise.
template <class S, class Ref>
void expect_compensated_kepler_force(double bound_in_eps2) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> angle(0, 6.283185307179586), log_r(-3, 3), frac(-0.5, 0.5);
  using VS = std::array<S, 2>;
  const double eps = static_cast<double>(std::numeric_limits<S>::epsilon());
  double worst = 0, worst_plain = 0;
  for (int k = 0; k < 20000; ++k) {
    const double r = std::pow(10.0, log_r(rng)), th = angle(rng);
    const VS q{static_cast<S>(r * std::cos(th)), static_cast<S>(r * std::sin(th))};
    VS cq{};
    for (int i = 0; i < 2; ++i) {
      const S ulp = std::nextafter(std::abs(q[i]), std::numeric_limits<S>::infinity()) - std::abs(q[i]);
      cq[i] = static_cast<S>(frac(rng)) * ulp;
    }
    VS a{}, alo{}, plain{}, via_base{};
    CompensatedKeplerForce{}(q, cq, a, alo);
    CompensatedKeplerForce{}(q, plain);
    KeplerForce{}(q, via_base);
    ASSERT_EQ(plain, via_base);
    const Ref x = Ref(q[0]) + Ref(cq[0]), y = Ref(q[1]) + Ref(cq[1]);
    const Ref r2 = x * x + y * y;
    using boost::multiprecision::abs;
    using boost::multiprecision::sqrt;
    using std::abs;
    using std::sqrt;
    const Ref m = Ref(1) / (r2 * sqrt(r2));
    const Ref norm = m * sqrt(r2);
    for (int i = 0; i < 2; ++i) {
      const Ref exact = -(i == 0 ? x : y) * m;
      worst = std::max(worst, static_cast<double>(abs(Ref(a[i]) + Ref(alo[i]) - exact) / norm));
      worst_plain = std::max(worst_plain, static_cast<double>(abs(Ref(plain[i]) - exact) / norm));
    }
  }
  std::cout << "compensated Kepler force: largest error " << worst / (eps * eps) << " eps^2; plain "
            << worst_plain / eps << " eps\n";
  EXPECT_LT(worst, bound_in_eps2 * eps * eps);
  EXPECT_GT(worst_plain, 0.5 * eps);  // the plain force does round at the working precision
}

TEST(Compensated, CompensatedKeplerForceIsAccurateToTwiceTheWorkingPrecision) {
  expect_compensated_kepler_force<double, float128>(16);
  expect_compensated_kepler_force<float, double>(16);
}

namespace {

SecondOrderProblem<V, CompensatedKeplerForce> compensated_kepler(double ecc, double t1) {
  const KeplerProblem<double> kp(ecc);
  const State<V> s0 = kp.initial_state();
  return SecondOrderProblem(CompensatedKeplerForce{}, s0.q, s0.v, 0.0, t1);
}

// The end of a backward run from the apocentre on the x axis, mirrored in the x axis: the forward orbit's end at
// the same |t|.
State<V> mirrored_in_x_axis(const State<V>& s) { return State<V>{{s.q[0], -s.q[1]}, {-s.v[0], s.v[1]}}; }

// The run of prob (span [0, t1]) with opt, and the same run checkpointed at 0.41 t1 and resumed: both end bitwise
// where the first does, with the same step count. Returns the uninterrupted run.
template <class F>
Solution<V> expect_restart_is_bitwise(const SecondOrderProblem<V, F>& prob, const MethodDef& def, SolveOptions opt,
                                      double t1) {
  const auto plain = solve(prob, def, opt);
  EXPECT_EQ(plain.status, SolveStatus::success);
  opt.checkpoint_at = 0.41 * t1;
  opt.checkpoint_problem = "kepler compensated";
  std::string text;
  opt.on_checkpoint = [&](const std::string& s) { text = s; };
  const auto first = solve(prob, def, opt);
  EXPECT_TRUE(first.checkpoint.has_value());
  EXPECT_EQ(first.q_final, plain.q_final);
  EXPECT_EQ(first.v_final, plain.v_final);
  const auto second = resume(prob, def, checkpoint_from_text<double>(text), opt);
  EXPECT_EQ(second.q_final, plain.q_final);
  EXPECT_EQ(second.v_final, plain.v_final);
  EXPECT_EQ(second.accepted, plain.accepted);
  EXPECT_EQ(second.rejected, plain.rejected);
  return plain;
}

}  // namespace

// With the compensated force the precise update of DP12-adaptive takes the force's rounding error, the exact
// weights, stage positions in double-word and a compensated velocity sum, and accepts tolerances down to eps/2.
// At tolerances 10^-15 .. 10^-15.75 (which the plain force refuses) the rms final position error on Kepler over 100
// periods falls to the order of the truncation (the same tolerances in long double), where the plain force stays at
// its floor at 10^-13.75 .. 10^-14.5.
TEST(Compensated, CompensatedForceTakesAdaptiveRknBelowThePlainForcesFloor) {
  for (double ecc : {0.5, 0.9}) {
    long steps_p = 0, steps_c = 0, steps_l = 0;
    const double plain = adaptive_floor_rms<double>(ecc, &steps_p);
    const double comp = adaptive_floor_rms<double, CompensatedKeplerForce>(ecc, &steps_c, -15.0);
    const double ld = adaptive_floor_rms<long double>(ecc, &steps_l, -15.0);
    std::cout << "e = " << ecc << ": rms position error, plain force " << plain << " (" << steps_p
              << " steps), compensated force " << comp << " (" << steps_c << "), long double " << ld << " (" << steps_l
              << ")\n";
    EXPECT_LT(comp, 0.4 * plain) << ecc;
    EXPECT_LT(comp, 1.2e-13) << ecc;
    EXPECT_NEAR(static_cast<double>(steps_c), static_cast<double>(steps_l), 0.01 * steps_l);
  }
  // The tolerance floor: eps/2 with the compensated force, 10 eps without.
  const MethodDef def = resolve_method("DP12-adaptive");
  AdaptiveOptions opt;
  opt.rtol = 1.2e-16;
  EXPECT_NO_THROW(make_adaptive_integrator<V>(def, CompensatedKeplerForce{}, opt));
  EXPECT_THROW(make_adaptive_integrator<V>(def, KeplerForce{}, opt), std::invalid_argument);
  opt.rtol = 1e-16;
  EXPECT_THROW(make_adaptive_integrator<V>(def, CompensatedKeplerForce{}, opt), std::invalid_argument);
  // Without compensated summation the force's low part has nowhere to go: the floor is 10 eps again.
  opt.rtol = 1.2e-16;
  EngineOptions off;
  off.compensated = Compensation::off;
  EXPECT_THROW(make_adaptive_integrator<V>(def, CompensatedKeplerForce{}, opt, off), std::invalid_argument);
}

// A run with the compensated force restarts from a checkpoint bitwise, forward and backward in time: the first
// stage after the restart evaluates the force at the state and its carry exactly as the step's last stage did.
TEST(Compensated, CompensatedForceRunRestartsBitwiseBothDirections) {
  const auto def = resolve_solve_method("DP12-adaptive");
  for (double t1 : {30.0, -30.0}) {
    SCOPED_TRACE(t1);
    SolveOptions opt;
    opt.rtol = 1e-15;
    const auto plain = expect_restart_is_bitwise(compensated_kepler(0.7, t1), def, opt, t1);
    // The force is counted like any other (16 stages, first same as last).
    EXPECT_GE(plain.force_evals, 15 * plain.accepted);
    // And it is the orbit: against the exact one of the run's initial state at |t1| = 30.
    const KeplerProblem<double> kp(0.7);
    const State<V> s0 = kp.initial_state();
    State<V> end{plain.q_final, plain.v_final};
    if (t1 < 0) end = mirrored_in_x_axis(end);
    EXPECT_LT(kepler_reference_errors(s0, end, 30.0, 1).position, 1e-12);
  }
}

// The adaptive multi-product expansion at a tolerance where its products are precise (their rounding carried in
// per-product carries, the increment a double-word into the run's carries) restarts from a checkpoint bitwise,
// forward and backward in time: the carries of a step do not outlive it except in the run's, which the checkpoint
// holds.
TEST(Compensated, PreciseProductsRunRestartsBitwiseBothDirections) {
  const auto def = resolve_solve_method("M12-adaptive");
  AdaptiveOptions aopt;
  aopt.rtol = 1e-13;
  ASSERT_TRUE(make_adaptive_mpe_integrator<V>(resolve_method("M12-adaptive"), KeplerForce{}, aopt).precise_products());
  const KeplerProblem<double> kp(0.7);
  const State<V> s0 = kp.initial_state();
  for (double t1 : {30.0, -30.0}) {
    SCOPED_TRACE(t1);
    SolveOptions opt;
    opt.rtol = aopt.rtol;
    const auto plain = expect_restart_is_bitwise(SecondOrderProblem(KeplerForce{}, s0.q, s0.v, 0.0, t1), def, opt, t1);
    EXPECT_GT(plain.accepted, 200);
    State<V> end{plain.q_final, plain.v_final};
    if (t1 < 0) end = mirrored_in_x_axis(end);
    EXPECT_LT(kepler_reference_errors(s0, end, 30.0, 1).position, 1e-12);
  }
}

// With the compensated force the products of the adaptive multi-product expansion run the base's drifts and kicks
// in double-word (trial_carried), their increments reach the run's carries as double-words, and the estimate's
// round-off floor falls with them: at tolerances 10^-13.75 .. 10^-14.5 the rms final position and velocity errors
// of M12-adaptive on Kepler over 100 periods fall to those of the same tolerances in long double (the truncation),
// with the same steps, where the plain force's products leave a random walk several times above it.
TEST(Compensated, CompensatedForceTakesAdaptiveMpeToItsTruncation) {
  for (double ecc : {0.5, 0.9}) {
    long steps_p = 0, steps_c = 0, steps_l = 0;
    const auto plain = floor_rms<double, KeplerForce>("M12-adaptive", ecc, -13.75, &steps_p);
    const auto comp = floor_rms<double, CompensatedKeplerForce>("M12-adaptive", ecc, -13.75, &steps_c);
    const auto ld = floor_rms<long double, KeplerForce>("M12-adaptive", ecc, -13.75, &steps_l);
    std::cout << "M12-adaptive e = " << ecc << ": rms position / velocity error, plain force " << plain.position
              << " / " << plain.velocity << " (" << steps_p << " steps), compensated force " << comp.position << " / "
              << comp.velocity << " (" << steps_c << "), long double " << ld.position << " / " << ld.velocity << " ("
              << steps_l << ")\n";
    EXPECT_LT(comp.position, 1.25 * ld.position) << ecc;
    EXPECT_LT(comp.velocity, 1.25 * ld.velocity) << ecc;
    EXPECT_LT(comp.position, 0.6 * plain.position) << ecc;
    EXPECT_NEAR(static_cast<double>(steps_c), static_cast<double>(steps_l), 0.02 * steps_l);
  }
}

// The compensated force's engine is chosen by the force's type: carried() with a compensated force in a
// compensated run, the tolerance then down to eps / 2; order control (MPE-adaptive) calls force(q, a) and refuses
// such a force in one line rather than ignore it.
TEST(Compensated, AdaptiveMpeTakesTheCompensatedForceWhereItCan) {
  const MethodDef def = resolve_method("M12-adaptive");
  AdaptiveOptions opt;
  opt.rtol = 1.2e-16;
  EXPECT_TRUE(make_adaptive_mpe_integrator<V>(def, CompensatedKeplerForce{}, opt).carried());
  EXPECT_THROW(make_adaptive_mpe_integrator<V>(def, KeplerForce{}, opt), std::invalid_argument);
  EngineOptions off;
  off.compensated = Compensation::off;
  EXPECT_THROW(make_adaptive_mpe_integrator<V>(def, CompensatedKeplerForce{}, opt, off), std::invalid_argument);
  opt.rtol = 1e-16;
  EXPECT_THROW(make_adaptive_mpe_integrator<V>(def, CompensatedKeplerForce{}, opt), std::invalid_argument);
  opt.rtol = 1e-12;
  EXPECT_FALSE(make_adaptive_mpe_integrator<V>(def, KeplerForce{}, opt).carried());
  EXPECT_FALSE(make_adaptive_mpe_integrator<V>(def, CompensatedKeplerForce{}, opt, off).carried());
  // Its products carry their rounding at every tolerance (precise_products), the plain force's only at the tightest.
  opt.rtol = 1e-8;
  EXPECT_TRUE(make_adaptive_mpe_integrator<V>(def, CompensatedKeplerForce{}, opt).precise_products());
  EXPECT_FALSE(make_adaptive_mpe_integrator<V>(def, KeplerForce{}, opt).precise_products());
  EXPECT_FALSE(make_adaptive_mpe_integrator<V>(def, CompensatedKeplerForce{}, opt, off).precise_products());
  try {
    make_adaptive_mpe_integrator<V>(resolve_method("MPE-adaptive"), CompensatedKeplerForce{}, opt);
    ADD_FAILURE() << "order control took a compensated force";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("order control"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

// A run of M12-adaptive with the compensated force restarts from a checkpoint bitwise, forward and backward in time,
// and ends on the orbit in position and velocity.
TEST(Compensated, AdaptiveMpeWithTheCompensatedForceRestartsBitwiseBothDirections) {
  const auto def = resolve_solve_method("M12-adaptive");
  const KeplerProblem<double> kp(0.7);
  const State<V> s0 = kp.initial_state();
  for (double t1 : {30.0, -30.0}) {
    SCOPED_TRACE(t1);
    SolveOptions opt;
    opt.rtol = 1e-15;
    const auto run = expect_restart_is_bitwise(compensated_kepler(0.7, t1), def, opt, t1);
    EXPECT_GT(run.accepted, 200);
    // 21 forces per step (6 products of 1..6 position-Verlet steps), the two of the starting step
    EXPECT_EQ(run.force_evals, 21 * (run.accepted + run.rejected) + 2);
    State<V> end{run.q_final, run.v_final};
    if (t1 < 0) end = mirrored_in_x_axis(end);
    const auto e = kepler_reference_errors(s0, end, 30.0, 1);
    EXPECT_LT(e.position, 1e-13);
    EXPECT_LT(e.velocity, 1e-13);
  }
}

namespace {

struct SplitErrors {
  double position = 0, velocity = 0;
};

// The final errors of a fixed-step run over 10 1/3 periods (the end away from the pericentre, where the exact
// position rounds to (1 - e, 0)) at spp steps per period, forward or backward, with the force F, against the exact
// orbit of the run's initial state; the backward run's end mirrored in the x axis is the forward orbit's.
template <class F>
SplitErrors fixed_step_errors(const std::string& method, double ecc, long spp, bool backward, long* evals = nullptr) {
  const KeplerProblem<double> kp(ecc);
  const State<V> s0 = kp.initial_state();
  const double h = KeplerProblem<double>::period() / static_cast<double>(spp);
  const long n = 10 * spp + spp / 3;
  auto integ = make_integrator<V>(resolve_method(method), F{});
  State<V> s = s0;
  integ.integrate(s, backward ? -h : h, n);
  if (evals) *evals = integ.force_evals();
  State<V> end = s;
  for (int i = 0; i < 2; ++i) {  // the carries belong to the result
    end.q[i] += integ.compensator().cq[i];
    end.v[i] += integ.compensator().cv[i];
  }
  if (backward) end = mirrored_in_x_axis(end);
  const auto e = kepler_reference_errors(s0, end, h, n);
  return {e.position, e.velocity};
}

}  // namespace

// With a compensated force a compensated splitting run adds exact products of the coefficients (and their rounding
// residuals) with v + cv and a + alo in double-word, and a multi-product step adds its products' increments as
// double-words: the plain force's rounding, which leaves 1e-15 to 4e-14 on Kepler (e = 0.5) over 10 periods at step
// counts whose truncation lies below 1e-16, is gone, and the final errors stay at a few units of the double result's
// rounding, forward and backward, positions and velocities, for the same force evaluations (SS10, KL8, M8). One
// call or several give the same bits (the cached force keeps its low part and the carry it was evaluated at).
TEST(Compensated, CompensatedForceTakesFixedStepMethodsToTheResultsRounding) {
  for (const char* method : {"SS10", "KL8", "M8"}) {
    for (bool backward : {false, true}) {
      SCOPED_TRACE(std::string(method) + (backward ? " backward" : " forward"));
      SplitErrors plain, comp;
      for (long spp : {951L, 1131L, 1345L}) {
        long ep = 0, ec = 0;
        const auto p = fixed_step_errors<KeplerForce>(method, 0.5, spp, backward, &ep);
        const auto q = fixed_step_errors<CompensatedKeplerForce>(method, 0.5, spp, backward, &ec);
        EXPECT_EQ(ec, ep);
        plain.position = std::max(plain.position, p.position);
        plain.velocity = std::max(plain.velocity, p.velocity);
        comp.position = std::max(comp.position, q.position);
        comp.velocity = std::max(comp.velocity, q.velocity);
      }
      std::cout << method << (backward ? " backward" : " forward")
                << ": largest final error over three step sizes, position / velocity, plain force " << plain.position
                << " / " << plain.velocity << ", compensated force " << comp.position << " / " << comp.velocity << "\n";
      EXPECT_LT(comp.position, 3e-16);
      EXPECT_LT(comp.velocity, 3e-16);
      EXPECT_LT(comp.position, 0.1 * plain.position);
      EXPECT_LT(comp.velocity, 0.1 * plain.velocity);
    }
  }
  // Split calls: bitwise one call.
  const KeplerProblem<double> kp(0.7);
  const double h = KeplerProblem<double>::period() / 500;
  for (const char* method : {"SS10", "KL8", "FR", "VV", "BR1", "M8", "mpe-vv:1,2,3"}) {
    auto one = make_integrator<V>(resolve_method(method), CompensatedKeplerForce{});
    auto parts = make_integrator<V>(resolve_method(method), CompensatedKeplerForce{});
    State<V> a = kp.initial_state(), b = a;
    one.integrate(a, h, 1000);
    parts.integrate(b, h, 377);
    parts.integrate(b, h, 1);
    parts.integrate(b, h, 622);
    EXPECT_EQ(a.q, b.q) << method;
    EXPECT_EQ(a.v, b.v) << method;
    EXPECT_EQ(one.compensator().cq, parts.compensator().cq) << method;
    EXPECT_EQ(one.force_evals(), parts.force_evals()) << method;
  }
}

// The compensated N-body force returns the accelerations of the positions q + cq as a + alo to a few units of the
// working precision squared (against quadruple precision), for 2 to 7 bodies with masses over three decades,
// coordinates over three decades, with and without softening, where the plain force rounds at units of it; its
// plain form is NBodyForce's bitwise.
TEST(Compensated, CompensatedNBodyForceIsAccurateToTwiceTheWorkingPrecision) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1, 1), log_m(-3, 0), frac(-0.5, 0.5);
  const double eps = std::numeric_limits<double>::epsilon();
  double worst = 0, worst_plain = 0;
  for (int trial = 0; trial < 600; ++trial) {
    const int n = 2 + trial % 6;
    std::vector<double> m(static_cast<std::size_t>(n));
    for (auto& x : m) x = std::pow(10.0, log_m(rng));
    const double eps2 = trial % 3 == 0 ? 1e-4 : 0.0;
    const CompensatedNBodyForce<double> f(m, eps2);
    const NBodyForce<double> base(m, eps2);
    std::vector<double> q(static_cast<std::size_t>(3 * n)), cq(q.size()), a, alo, plain, via_base;
    for (std::size_t i = 0; i < q.size(); ++i) {
      q[i] = u(rng) * std::pow(10.0, log_m(rng));
      cq[i] = frac(rng) * (std::nextafter(std::abs(q[i]), 1e300) - std::abs(q[i]));
    }
    f(q, cq, a, alo);
    f(q, plain);
    base(q, via_base);
    ASSERT_EQ(plain, via_base);
    auto at = [&](const std::vector<double>& x, const std::vector<double>& cx, int c, int i) {
      const auto k = static_cast<std::size_t>(c * n + i);
      return float128(x[k]) + float128(cx[k]);
    };
    for (int i = 0; i < n; ++i) {
      float128 exact[3] = {0, 0, 0}, norm = 0;
      for (int j = 0; j < n; ++j) {
        if (j == i) continue;
        float128 d[3], r2 = eps2;
        for (int c = 0; c < 3; ++c) {
          d[c] = at(q, cq, c, j) - at(q, cq, c, i);
          r2 += d[c] * d[c];
        }
        using boost::multiprecision::sqrt;
        const float128 w = float128(m[static_cast<std::size_t>(j)]) / (r2 * sqrt(r2));
        for (int c = 0; c < 3; ++c) exact[c] += w * d[c];
        norm += w * sqrt(r2 - eps2);
      }
      for (int c = 0; c < 3; ++c) {
        using boost::multiprecision::abs;
        const auto k = static_cast<std::size_t>(c * n + i);
        worst = std::max(worst, static_cast<double>(abs(float128(a[k]) + float128(alo[k]) - exact[c]) / norm));
        worst_plain = std::max(worst_plain, static_cast<double>(abs(float128(plain[k]) - exact[c]) / norm));
      }
    }
  }
  std::cout << "compensated N-body force: largest error " << worst / (eps * eps) << " eps^2 of sum m_j / r_ij^2; plain "
            << worst_plain / eps << " eps\n";
  EXPECT_LT(worst, 32 * eps * eps);
  EXPECT_GT(worst_plain, 0.5 * eps);
  // A state of the wrong size is refused, as by the plain force.
  const CompensatedNBodyForce<double> f({1.0, 1.0}, 0.0);
  std::vector<double> q(5), a, alo;
  EXPECT_THROW(f(q, q, a, alo), std::invalid_argument);
}

// The two-body problem as an N-body system (std::vector state, the inline path of solve()): with the compensated
// N-body force SS10 and M8 end within a few units of the double result's rounding of the exact relative orbit after
// 10 1/3 periods (e = 0.5), where the plain force leaves 1e-15 to 4e-14; the same force evaluations.
TEST(Compensated, CompensatedNBodyForceOnTheTwoBodyProblem) {
  using VV = std::vector<double>;
  const auto ps = two_body<double>(0.5);
  const auto rel = [](const VV& q, const VV& v) {
    return State<V>{{q[1] - q[0], q[3] - q[2]}, {v[1] - v[0], v[3] - v[2]}};
  };
  for (const char* method : {"SS10", "M8"}) {
    double worst = 0, worst_plain = 0;
    for (long spp : {951L, 1131L, 1345L}) {
      const double h = 2 * std::numbers::pi / static_cast<double>(spp);
      const long n = 10 * spp + spp / 3;
      SolveOptions opt;
      opt.steps = n;
      const NBodyForce<double> plain_force(ps.m, 0.0);
      const CompensatedNBodyForce<double> force(ps.m, 0.0);
      const auto p =
          solve(SecondOrderProblem(plain_force, ps.s.q, ps.s.v, 0.0, h * static_cast<double>(n)), method, opt);
      const auto c =
          solve_inline(SecondOrderProblem(force, ps.s.q, ps.s.v, 0.0, h * static_cast<double>(n)), method, opt);
      ASSERT_EQ(c.status, SolveStatus::success);
      EXPECT_EQ(c.force_evals, p.force_evals);
      const auto s0 = rel(ps.s.q, ps.s.v);
      worst_plain = std::max(worst_plain, kepler_reference_errors(s0, rel(p.q_final, p.v_final), h, n).position);
      const auto e = kepler_reference_errors(s0, rel(c.q_final, c.v_final), h, n);
      worst = std::max({worst, e.position, e.velocity});
    }
    std::cout << method << ": two-body relative orbit, largest final error " << worst << " (plain force " << worst_plain
              << ")\n";
    EXPECT_LT(worst, 3e-16) << method;
    EXPECT_LT(worst, 0.1 * worst_plain) << method;
  }
}

// A fixed-step run with the compensated force restarts from a checkpoint bitwise, forward and backward: the carries
// travel in the checkpoint, and the first force after the restart is evaluated at the state and its carry as the
// cached one was (SS10, M8, and VV, whose kicks reuse the cached force across steps).
TEST(Compensated, CompensatedForceFixedStepRunRestartsBitwise) {
  for (const char* method : {"SS10", "M8", "VV"}) {
    for (double t1 : {20.0, -20.0}) {
      SCOPED_TRACE(std::string(method) + " " + std::to_string(t1));
      SolveOptions opt;
      opt.steps = 3001;
      expect_restart_is_bitwise(compensated_kepler(0.7, t1), resolve_solve_method(method), opt, t1);
    }
  }
}
