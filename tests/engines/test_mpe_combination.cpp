// Round-off of the multi-product combination at orders 8-16 in double (Chin's c_i grow like k^{2n}).
//
// Kepler e = 0.5, 100 periods; the reference is the same method at the same step in float128 from the
// same double initial state (truncation cancels): the difference is the round-off of the double run.
// Three ways to combine the products are measured:
//   naive        sum c_i T_i                                   (EngineOptions::mpe_naive_combination)
//   difference   T_ref + sum c_i (T_i - T_ref), uncompensated  (Compensation::off)
//   compensated  the difference form on increments T_i - s known to full precision (the default)
// The numbers are printed; the test asserts the ordering at the orders where the loss is large.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <iostream>
#include <string>

#include "nystrom/nystrom.hpp"

using namespace nystrom;

namespace {

using V = std::array<double, 2>;
using VQ = std::array<float128, 2>;

double roundoff(const std::string& spec, long steps_per_period, long periods, const EngineOptions& opt) {
  const MethodDef def = resolve_method(spec);
  const KeplerProblem<double> prob(0.5);
  const State<V> s0 = prob.initial_state();
  const double h = KeplerProblem<double>::period() / static_cast<double>(steps_per_period);
  const long n = steps_per_period * periods;
  auto integ = make_integrator<V>(def, KeplerForce{}, opt);
  State<V> s = s0;
  integ.integrate(s, h, n);
  auto ref = make_integrator<VQ>(def, KeplerForce{});
  State<VQ> sq = convert_state<VQ>(s0);
  ref.integrate(sq, float128(h), n);
  const float128 dx = float128(s.q[0]) - sq.q[0], dy = float128(s.q[1]) - sq.q[1];
  return static_cast<double>(sqrt(dx * dx + dy * dy));
}

struct Row {
  double naive, difference, compensated;
};

Row measure(const std::string& spec, long steps_per_period, long periods) {
  EngineOptions naive;
  naive.mpe_naive_combination = true;
  EngineOptions diff;
  diff.compensated = Compensation::off;
  const Row r{roundoff(spec, steps_per_period, periods, naive), roundoff(spec, steps_per_period, periods, diff),
              roundoff(spec, steps_per_period, periods, EngineOptions{})};
  std::cout << spec << " (" << steps_per_period << " steps/period, " << periods << " periods) round-off |dq|: naive "
            << r.naive << ", difference " << r.difference << ", compensated " << r.compensated << "  (naive/difference "
            << r.naive / r.difference << ", naive/compensated " << r.naive / r.compensated << ")\n";
  return r;
}

}  // namespace

TEST(MpeCombination, RoundoffAtOrders8To16) {
  // Measured (double, e = 0.5, 100 steps/period, 100 periods): naive/difference 19 to 750,
  // naive/compensated 260 to 2100. The margins below are several times smaller.
  for (const char* m : {"M8", "M10", "M12", "M14", "M16"}) {
    const Row r = measure(m, 100, 100);
    EXPECT_LT(r.difference * 5, r.naive) << m;
    EXPECT_LT(r.compensated * 20, r.naive) << m;
    EXPECT_LT(r.compensated, r.difference) << m;
  }
}
