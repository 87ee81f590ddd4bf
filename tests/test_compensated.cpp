// Compensated summation of the position and velocity updates (EngineOptions::compensated).
//
// Kepler e = 0.5 over 1000 periods in double. The reference is the same method at the same step in
// long double (compensated) from the same double initial state, so the truncation error cancels and
// the difference is the round-off of the double run. Compensation must lower it by at least 10x for a
// splitting (FR) and an MPE (M8), and change nothing else (force counts); for the RKN engine see below.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <complex>
#include <iostream>
#include <string>
#include <utility>
#include <variant>

#include "nystrom/nystrom.hpp"

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
// RKN, fixed steps: the loop carries the velocity's rounding into the increment but leaves the stage positions
// rounded at the size of q, and that rounding dominates here: compensation changes the error by no more than 2x.
TEST(Compensated, RknM65F) {
  const Outcome off = roundoff_error("M6-5F", 200, 1000, Compensation::off);
  const Outcome on = roundoff_error("M6-5F", 200, 1000, Compensation::automatic);
  std::cout << "M6-5F at 200 steps/period, 1000 periods: round-off error uncompensated " << off.err << ", compensated "
            << on.err << "\n";
  EXPECT_LT(on.err, 2 * off.err);
  EXPECT_LT(on.err, 2e-10);
}

// RKN, the step of the adaptive engine (RknStepper::step_with_error with carries): the carries also enter the stage
// positions and the increments are added by exact two-sums. On a linear force (the harmonic oscillator a = -q, whose
// evaluation is exact, so that all the round-off is the engine's own) that removes most of it: M6-5F and DP12 at a
// fixed step over 1000 periods against the same steps in long double, with carries against plain. (On Kepler the
// force's own rounding, which no summation removes, dominates at these step counts.)
namespace {
struct Linear {
  template <class W>
  void operator()(const W& q, W& a) const {
    for (std::size_t i = 0; i < q.size(); ++i) a[i] = -q[i];
  }
};
}  // namespace

TEST(Compensated, RknStepWithCarriesRemovesTheEngineRounding) {
  for (const auto& [name, spp] : {std::pair<const char*, long>{"M6-5F", 200}, {"DP12", 60}}) {
    const MethodDef def = resolve_method(name);
    const auto tableau = [&](auto tag) {
      using S = decltype(tag);
      const MethodData data = method_data_for(def, scalar_traits<S>::bits(), scalar_traits<S>::name());
      return convert_tableau<S>(std::get<RknTableau<bigcomplex>>(data),
                                [](const bigcomplex& x) { return to_scalar<S>(x); });
    };
    const double h = 2 * std::acos(-1.0) / static_cast<double>(spp);
    const long n = spp * 1000;
    RknStepper<V, Linear> plain(tableau(0.0), Linear{}), carried(tableau(0.0), Linear{});
    RknStepper<VL, Linear> ref(tableau(0.0L), Linear{});
    State<V> a{{0.6, -0.8}, {0.3, 0.7}}, b = a, err;
    State<VL> r = convert_state<VL>(a), errl;
    Compensator<V> cb;
    Compensator<VL> cr;
    cb.begin(b);
    cr.begin(r);
    for (long k = 0; k < n; ++k) {
      plain.step_with_error(a, h, err);
      carried.step_with_error(b, h, err, cb);
      ref.step_with_error(r, static_cast<long double>(h), errl, cr);
    }
    const auto dist = [&](const State<V>& x) {
      return std::hypot(static_cast<double>(static_cast<long double>(x.q[0]) - r.q[0]),
                        static_cast<double>(static_cast<long double>(x.q[1]) - r.q[1]));
    };
    std::cout << name << " at " << spp << " steps/period, 1000 periods, the adaptive engine's step on a linear force: "
              << "round-off error plain " << dist(a) << ", with carries " << dist(b) << "\n";
    EXPECT_LT(5 * dist(b), dist(a)) << name;
  }
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

// A uniform force a = (1, -2): every consistent RKN tableau integrates it exactly (q = q0 + v0 t + a t^2 / 2), but
// only if its weights satisfy sum B_i = 1 and sum b_i = 1/2 exactly; rounded to double they miss by an ulp or so.
// The engine's difference form (sum B_i f_i = f_1 + sum B_i (f_i - f_1)) holds them exactly: with h a power of two
// every number is exact, so each run, forwards and back, must land exactly, compensated or not.
TEST(Compensated, RknWeightsSumExactlyInDifferenceForm) {
  struct Uniform {
    void operator()(const V&, V& a) const { a = {1.0, -2.0}; }
  };
  const double h = 1.0 / 1024;
  const long n = 64 * 1024;  // t = 64
  for (const char* name : {"N4", "M4-RKN", "M6-5F", "A6", "Aprime", "DP10", "DP12"}) {
    for (const Compensation comp : {Compensation::automatic, Compensation::off}) {
      EngineOptions opt;
      opt.compensated = comp;
      auto integ = make_integrator<V>(resolve_method(name), Uniform{}, opt);
      State<V> s{{0.5, 0.25}, {0.0, 1.0}};
      integ.integrate(s, h, n);
      EXPECT_EQ(s.v[0], 64.0) << name;
      EXPECT_EQ(s.v[1], 1.0 - 128.0) << name;
      EXPECT_EQ(s.q[0], 0.5 + 2048.0) << name;
      EXPECT_EQ(s.q[1], 0.25 + 64.0 - 4096.0) << name;
      integ.integrate(s, -h, n);
      EXPECT_EQ(s.q[0], 0.5) << name;
      EXPECT_EQ(s.q[1], 0.25) << name;
      EXPECT_EQ(s.v[0], 0.0) << name;
      EXPECT_EQ(s.v[1], 1.0) << name;
    }
  }
}

// The exact update: x + c += hi + lo keeps every part of the increment (compensated_add loses the rounding of
// c + increment); the new x is the rounding of the exact sum.
TEST(Compensated, FoldedUpdateIsExact) {
  // 1 + 3e-17 (hi = 2e-17, lo = 1e-17 + carry) a thousand times: x + c = 1 + 3e-14 to the carry's rounding
  double x = 1, c = 0;
  for (int i = 0; i < 1000; ++i) compensated_add_folded(x, c, 2e-17, 1e-17 + c);
  EXPECT_NEAR((x - 1) + c, 3e-14, 1e-28);
  // increments larger than the value (positions cross zero)
  double y = 1e-20, cy = 0;
  compensated_add_folded(y, cy, 1.0, 3e-17 + cy);
  EXPECT_EQ(y, 1.0);
  EXPECT_NEAR(cy, 3e-17 + 1e-20, 1e-32);
}
