// Boost.Odeint's integrate_const runs nystrom methods through OdeintStepper, with autonomous and
// time-dependent forces.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <numbers>
#include <utility>
#include <vector>

#include <boost/numeric/odeint.hpp>

#include "nystrom/problems/kepler.hpp"
#include "nystrom/solve/odeint.hpp"

using V2 = std::array<double, 2>;

TEST(Odeint, IntegrateConstRunsCatalogMethods) {
  namespace odeint = boost::numeric::odeint;
  const nystrom::KeplerProblem<double> kp(0.5);
  const auto s0 = kp.initial_state();
  const double t1 = 2.5, dt = 2.5 / 500;
  const auto ex = kp.exact(t1);
  for (const char* m : {"VV", "FR", "M8", "A6", "RKNb6"}) {
    SCOPED_TRACE(m);
    nystrom::OdeintStepper<V2> st(m);
    auto force = [](const V2& q, V2& a) { nystrom::KeplerForce{}(q, a); };
    long observed = 0;
    double t_last = -1;
    auto x = std::make_pair(s0.q, s0.v);
    const auto steps = odeint::integrate_const(st, force, x, 0.0, t1, dt, [&](const std::pair<V2, V2>&, double t) {
      ++observed;
      t_last = t;
    });
    EXPECT_EQ(steps, 500u);
    EXPECT_EQ(observed, 501);
    EXPECT_NEAR(t_last, t1, 1e-12);
    const double err = std::hypot(x.first[0] - ex.q[0], x.first[1] - ex.q[1]);
    EXPECT_LT(err, std::string(m) == "VV" ? 1e-3 : 1e-6);
    EXPECT_GT(st.force_evals(), 499);  // the copies odeint makes share the integrator
    // The same through a temporary pair of references, as with odeint's own symplectic steppers.
    V2 q = s0.q, p = s0.v;
    odeint::integrate_const(st, force, std::make_pair(std::ref(q), std::ref(p)), 0.0, t1, dt,
                            [](const auto&, double) {});
    EXPECT_EQ(q, x.first);
    EXPECT_EQ(p, x.second);
  }
  EXPECT_THROW(nystrom::OdeintStepper<V2>("DP12-adaptive"), nystrom::invalid_input);
}

TEST(Odeint, TimeDependentForceGetsTheTimeOfEachEvaluation) {
  // The driven oscillator q'' = -q + cos 2t from q(t0) = 1, p(t0) = 0: q + cos(2t)/3 oscillates
  // harmonically, so q(t) = p0 cos(t - t0) + dp0 sin(t - t0) - cos(2t)/3. A force that saw no time (or
  // the step's start time only) misses it by far more than the methods' errors.
  namespace odeint = boost::numeric::odeint;
  const double t0 = 0.7, t1 = 10.7, dt = 0.01;
  const double p0 = 1 + std::cos(2 * t0) / 3, dp0 = -2 * std::sin(2 * t0) / 3;
  const double exact = p0 * std::cos(t1 - t0) + dp0 * std::sin(t1 - t0) - std::cos(2 * t1) / 3;
  for (const char* m : {"VV", "FR", "M8", "RKNb6"}) {
    SCOPED_TRACE(m);
    const double bound = std::string(m) == "VV" ? 1e-4 : 1e-8;
    nystrom::OdeintStepper<std::array<double, 1>> st(m);
    double t_min = 1e300, t_max = -1e300;
    auto force = [&](const double& t, const std::array<double, 1>& q, std::array<double, 1>& a) {
      t_min = std::min(t_min, t);
      t_max = std::max(t_max, t);
      a[0] = -q[0] + std::cos(2 * t);
    };
    auto x = std::make_pair(std::array<double, 1>{1.0}, std::array<double, 1>{0.0});
    const auto steps = odeint::integrate_const(st, force, x, t0, t1, dt);
    EXPECT_EQ(steps, 1000u);
    EXPECT_NEAR(x.first[0], exact, bound);
    EXPECT_LT(t_min, t0 + dt);  // the force saw the times of the whole span
    EXPECT_GT(t_max, t1 - dt);
    // std::vector states too, and the same numbers
    nystrom::OdeintStepper<std::vector<double>> sv(m);
    auto fv = [](const double& t, const std::vector<double>& q, std::vector<double>& a) {
      a[0] = -q[0] + std::cos(2 * t);
    };
    auto y = std::make_pair(std::vector<double>{1.0}, std::vector<double>{0.0});
    odeint::integrate_const(sv, fv, y, t0, t1, dt);
    EXPECT_EQ(y.first[0], x.first[0]);
    EXPECT_EQ(y.second[0], x.second[0]);
  }
}
