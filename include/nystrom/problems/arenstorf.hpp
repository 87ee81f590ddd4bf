// The Arenstorf orbit of the restricted three-body problem in the rotating frame (Hairer, Nørsett &
// Wanner, Solving Ordinary Differential Equations I, 2nd ed., Springer 1993, sec. II.0, eq. (0.1), with
// the initial values (0.2) and the period printed there):
//
//   y1'' = y1 + 2 y2' - mu' (y1 + mu) / D1 - mu (y1 - mu') / D2,
//   y2'' = y2 - 2 y1' - mu' y2 / D1 - mu y2 / D2,
//   D1 = ((y1 + mu)^2 + y2^2)^{3/2},  D2 = ((y1 - mu')^2 + y2^2)^{3/2},  mu = 0.012277471,  mu' = 1 - mu,
//   y(0) = (0.994, 0),  y'(0) = (0, -2.00158510637908252240537862224),
//   period T = 17.0652165601579625588917206249.
//
// The Coriolis terms make the force velocity-dependent: ArenstorfForce is force(q, v, a).
#pragma once

#include <cmath>

#include "nystrom/core/state.hpp"

namespace nystrom {

template <class T>
struct Arenstorf {
  static T mu() { return T(0.012277471); }
  static T period() { return T(17.0652165601579625588917206249L); }
  static T q0x() { return T(0.994); }
  static T v0y() { return T(-2.00158510637908252240537862224L); }
};

/// a = a(q, v) in the rotating frame, on any container of two real coordinates.
struct ArenstorfForce {
  template <class V>
  void operator()(const V& q, const V& v, V& a) const {
    using S = typename V::value_type;
    using std::sqrt;
    const S mu = Arenstorf<S>::mu(), mup = S(1) - mu;
    const S x1 = q[0] + mu, x2 = q[0] - mup, y = q[1];
    const S r1 = x1 * x1 + y * y, r2 = x2 * x2 + y * y;
    const S d1 = r1 * sqrt(r1), d2 = r2 * sqrt(r2);
    a[0] = q[0] + S(2) * v[1] - mup * x1 / d1 - mu * x2 / d2;
    a[1] = q[1] - S(2) * v[0] - mup * y / d1 - mu * y / d2;
  }
};

}  // namespace nystrom
