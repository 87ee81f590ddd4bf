// The damped driven harmonic oscillator and its exact solution:
//
//   q'' + 2 gamma q' + omega0^2 q = F cos(omega t),  0 < gamma < omega0 (under-damped),
//
// q(t) = A cos(omega t) + B sin(omega t) + e^{-gamma t} (C1 cos(wd t) + C2 sin(wd t)), wd = sqrt(omega0^2 -
// gamma^2), with the steady state A = F (omega0^2 - omega^2) / D, B = 2 F gamma omega / D, D = (omega0^2 -
// omega^2)^2 + (2 gamma omega)^2, and C1, C2 from q(0), q'(0). The force is a(t, q, v) in one coordinate
// (force(t, q, v, a) on any container; each coordinate is an independent copy of the oscillator).
#pragma once

#include <cmath>
#include <stdexcept>

#include "nystrom/core/state.hpp"

namespace nystrom {

template <class T>
struct DampedOscillator {
  T omega0, gamma, F, omega;

  DampedOscillator(T omega0_, T gamma_, T F_, T omega_) : omega0(omega0_), gamma(gamma_), F(F_), omega(omega_) {
    if (!(gamma > T(0)) || !(gamma < omega0)) throw std::invalid_argument("damped oscillator: need 0 < gamma < omega0");
  }

  /// a = F cos(omega t) - 2 gamma v - omega0^2 q, for every coordinate.
  template <class V>
  void operator()(const T& t, const V& q, const V& v, V& a) const {
    using std::cos;
    const T drive = F * cos(omega * t);
    for (std::size_t i = 0; i < q.size(); ++i) a[i] = drive - T(2) * gamma * v[i] - omega0 * omega0 * q[i];
  }

  /// The exact position and velocity at time t of the solution with q(0) = q0, q'(0) = v0.
  void exact(const T& q0, const T& v0, const T& t, T& q, T& v) const {
    using std::cos;
    using std::exp;
    using std::sin;
    using std::sqrt;
    const T w2 = omega0 * omega0 - omega * omega, g2w = T(2) * gamma * omega;
    const T D = w2 * w2 + g2w * g2w;
    const T A = F * w2 / D, B = F * g2w / D;
    const T wd = sqrt(omega0 * omega0 - gamma * gamma);
    const T C1 = q0 - A;
    const T C2 = (v0 - B * omega + gamma * C1) / wd;
    const T e = exp(-gamma * t), c = cos(wd * t), s = sin(wd * t);
    q = A * cos(omega * t) + B * sin(omega * t) + e * (C1 * c + C2 * s);
    v = -A * omega * sin(omega * t) + B * omega * cos(omega * t) +
        e * (-gamma * (C1 * c + C2 * s) + wd * (-C1 * s + C2 * c));
  }
};

}  // namespace nystrom
