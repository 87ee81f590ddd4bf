// Kepler problems for the tests of solve() and its dense output: the orbit of eccentricity e from its
// pericentre as a SecondOrderProblem, and the position error against the analytic orbit.
#pragma once

#include <array>
#include <cmath>

#include "nystrom/problems/kepler.hpp"
#include "nystrom/solve/solve.hpp"

namespace nystrom::test {

using V2 = std::array<double, 2>;

inline SecondOrderProblem<V2, KeplerForce> kepler(double e, double t0, double t1) {
  const auto s = KeplerProblem<double>(e).initial_state();
  return SecondOrderProblem(KeplerForce{}, s.q, s.v, t0, t1);
}

inline double pos_err(const V2& q, const State<V2>& ex) { return std::hypot(q[0] - ex.q[0], q[1] - ex.q[1]); }

}  // namespace nystrom::test
