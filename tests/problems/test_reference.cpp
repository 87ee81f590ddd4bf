// The reference solutions that errors are measured against (problems/reference.hpp): the exact orbit of the
// initial state as rounded to the working precision, in quad-double (or MPFR), at the exact end time.
#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include "nystrom/core/extended.hpp"
#include "nystrom/problems/kepler.hpp"
#include "nystrom/problems/reference.hpp"

namespace {

using namespace nystrom;
using Q = quad_double;
using V2 = std::array<double, 2>;

State<std::array<Q, 2>> to_qd(const State<V2>& s) { return {{Q(s.q[0]), Q(s.q[1])}, {Q(s.v[0]), Q(s.v[1])}}; }
State<V2> to_double(const State<std::array<Q, 2>>& s) {
  return {{as_double(s.q[0]), as_double(s.q[1])}, {as_double(s.v[0]), as_double(s.v[1])}};
}
double qd_dist(const std::array<Q, 2>& a, const std::array<Q, 2>& b) {
  return as_double(sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1])));
}

// The f and g propagation agrees with the analytic solution of Chin's orbit (Kepler's equation from the
// apocentre), both in quad-double, forwards and backwards, positions and velocities.
TEST(Reference, KeplerFlowIsTheAnalyticOrbitInQuadDouble) {
  for (const double e : {0.0, 0.3, 0.5, 0.9, 0.99}) {
    const KeplerProblem<Q> p{Q(e)};
    const auto s0 = p.initial_state();
    for (const double t : {0.1, 1.0, 3.0, 7.3, 100.0, 628.3, -2.5}) {
      const auto a = kepler_flow<Q>(s0.q, s0.v, Q(t));
      // the analytic solution at negative times: the orbit is periodic with period 2 pi
      const auto b = p.exact(t >= 0 ? Q(t) : Q(t) + Q(2) * acos(Q(-1)));
      EXPECT_LT(qd_dist(a.q, b.q), 1e-55) << e << " " << t;
      EXPECT_LT(qd_dist(a.v, b.v), 1e-55 / (1 - e)) << e << " " << t;
    }
    // from an arbitrary point of the orbit, forwards then backwards
    const auto mid = kepler_flow<Q>(s0.q, s0.v, Q(2.2));
    const auto fwd = kepler_flow<Q>(mid.q, mid.v, Q(31.7));
    const auto back = kepler_flow<Q>(fwd.q, fwd.v, Q(-31.7));
    EXPECT_LT(qd_dist(back.q, mid.q), 1e-55) << e;
    EXPECT_LT(qd_dist(back.v, mid.v), 1e-54) << e;
  }
  EXPECT_THROW(kepler_flow<Q>({Q(1), Q(0)}, {Q(0), Q(2)}, Q(1)), std::invalid_argument);  // unbound
}

// A perfect integrator (the exact orbit of the double start, rounded to double at the end) scores its final
// rounding against the new reference; the nominal orbit (1 + e, sqrt((1 - e)/(1 + e)) taken exactly) charges
// it the orbit of the unrounded start, about 1e-14 after 100 periods.
TEST(Reference, PerfectIntegratorScoresItsRounding) {
  for (const double e : {0.5, 0.9}) {
    const auto s0 = KeplerProblem<double>(e).initial_state();
    const double h = KeplerProblem<double>::period() / 1000;  // rounded: the end is not at an apsis
    const long n = 100 * 1000 + 137;
    const auto exact = kepler_flow<Q>(to_qd(s0).q, to_qd(s0).v, Q(h) * Q(n));
    const auto s = to_double(exact);
    const ReferenceErrors err = kepler_reference_errors(s0, s, h, n);
    EXPECT_LT(err.position, 1e-15) << e;
    EXPECT_LT(err.velocity, 1e-15 / (1 - e)) << e;
    EXPECT_LT(err.energy, 1e-15) << e;
    // the same state against the nominal orbit in long double
    const auto nominal = KeplerProblem<long double>(static_cast<long double>(e))
                             .exact(static_cast<long double>(h) * static_cast<long double>(n));
    const double old =
        std::hypot(static_cast<double>(s.q[0] - nominal.q[0]), static_cast<double>(s.q[1] - nominal.q[1]));
    EXPECT_GT(old, 5e-15) << e;
    // and an adaptive run's end time (h = t_end, n = 1), both directions of time
    for (const double t_end : {628.0, -628.0}) {
      const auto x = to_double(kepler_flow<Q>(to_qd(s0).q, to_qd(s0).v, Q(t_end)));
      EXPECT_LT(kepler_reference_errors(s0, x, t_end).position, 1e-15) << e << " " << t_end;
    }
  }
}

// Every working type enters exactly: a start in long double, float128, double-double or MPFR propagated to
// itself over zero time has no error at all, and one period of its own orbit is measured to far below its
// own rounding.
TEST(Reference, WorkingTypesEnterExactly) {
  const auto check = [](auto tag, double bound) {
    using T = decltype(tag);
    const KeplerProblem<T> p{T(0.9)};
    const auto s0 = p.initial_state();
    EXPECT_EQ(kepler_reference_errors(s0, s0, T(0)).position, 0.0) << scalar_traits<T>::name();
    // against the analytic solution evaluated in T itself: the difference is T's rounding
    const T t(5.5);
    const auto ex = p.exact(t);
    const double err = kepler_reference_errors(s0, ex, t).position;
    EXPECT_LT(err, bound) << scalar_traits<T>::name();
    EXPECT_GT(err, bound * 1e-6) << scalar_traits<T>::name();  // the reference is finer than T
  };
  check(1.0L, 1e-16);
  check(float128(1), 1e-31);
  check(double_double(1), 1e-29);
  {
    const MpfrPrecision scope(128);
    check(mpfr_real(1), 1e-35);
  }
}

// The harmonic oscillator's reference: cos t, -sin t of the rounded start in quad-double.
TEST(Reference, HarmonicScoresItsRounding) {
  const State<std::array<double, 1>> s0{{1.0}, {0.0}};
  const double h = 2 * std::acos(-1.0) / 1000;
  const long n = 10 * 1000 + 250;
  const Q t = Q(h) * Q(n);
  const State<std::array<double, 1>> s{{as_double(cos(t))}, {as_double(-sin(t))}};
  const auto err = harmonic_reference_errors(s0, s, h, n);
  EXPECT_LT(err.position, 1.2e-16);
  EXPECT_LT(err.velocity, 1.2e-16);
  // evaluated in double at the rounded end time, the "exact" solution is off by far more
  const double td = h * static_cast<double>(n);
  EXPECT_GT(harmonic_reference_errors(s0, State<std::array<double, 1>>{{std::cos(td)}, {-std::sin(td)}}, h, n).position,
            1e-15);
}

}  // namespace
