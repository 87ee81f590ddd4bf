// The Van der Pol oscillator as a first-order system (Hairer, Nørsett & Wanner I, sec. I.16; II, sec. IV.1):
//
//   y1' = y2,  y2' = mu (1 - y1^2) y2 - y1.
//
// Every solution but the origin tends to a limit cycle; for mu = 1 its period is 6.6632868593231301896996820305
// (the value used to check a first-order integrator's events and long runs).
#pragma once

namespace nystrom {

template <class T>
struct VanDerPol {
  T mu = T(1);
  /// The period of the limit cycle for mu = 1.
  static T period_mu1() { return T(6.6632868593231301896996820305L); }
  /// dy = f(y), on any container of two real coordinates.
  template <class V>
  void operator()(const V& y, V& dy) const {
    dy[0] = y[1];
    dy[1] = mu * (T(1) - y[0] * y[0]) * y[1] - y[0];
  }
};

}  // namespace nystrom
