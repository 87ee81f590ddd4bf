// Boost.Odeint's integrate_const runs nystrom methods through OdeintStepper.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <numbers>
#include <utility>

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
