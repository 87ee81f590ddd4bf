// The exact flow of the two-body problem x'' = -mu x / |x|^3 over a time dt, in universal variables: one
// formulation for elliptic, parabolic and hyperbolic orbits, with no loss of accuracy near e = 1.
//
// With r0 = |x0|, eta0 = x0.v0, beta = 2 mu / r0 - |v0|^2 (mu / a; > 0 elliptic) and zeta0 = mu - beta r0,
// the universal anomaly s solves Kepler's equation
//   F(s) = r0 s + eta0 G2(s) + zeta0 G3(s) - dt = 0,   F'(s) = r(s) = r0 + eta0 G1 + zeta0 G2,
// with the G-functions G_k(s) = s^k c_k(beta s^2) and the Stumpff functions c_k(x) = sum_j (-x)^j / (2j+k)!.
// Then, with Lagrange's f and g,
//   x = x0 + (f - 1) x0 + g v0,  v = v0 + fdot x0 + (gdot - 1) v0,
//   f - 1 = -mu G2 / r0,  g = r0 G1 + eta0 G2,  fdot = -mu G1 / (r r0),  gdot - 1 = -mu G2 / r,
// written as increments so that many small drifts add little rounding (Wisdom & Hernandez, MNRAS 453 (2015)
// 3015; Rein & Tamayo, MNRAS 452 (2015) 376; Danby, Fundamentals of Celestial Mechanics, 2nd ed., 1988, ch. 6).
//
// The Stumpff functions: argument quartered until |x| <= 0.1, Taylor series to the working precision, then
// the quadruple-argument identities c0(4x) = 2 c0^2 - 1, c1(4x) = c0 c1, c2(4x) = c1^2 / 2,
// c3(4x) = (c2 + c0 c3) / 4. An elliptic drift longer than one period is first reduced modulo the period.
// Kepler's equation: Laguerre-Conway iteration (n = 5) from a second-order guess, kept inside a bracket of
// the root that shrinks with every evaluation (F is increasing: F' = r > 0), bisection when a step leaves it
// or fails to reduce |F| 64-fold (Laguerre steps reduce it far more near a root).
#pragma once

#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace nystrom::planetary {

template <class R>
using Vec3 = std::array<R, 3>;

template <class R>
struct Stumpff {
  R c0, c1, c2, c3;
};

/// Stumpff functions c0..c3 at x (see the top of this file).
template <class R>
Stumpff<R> stumpff(R x) {
  using std::abs;
  int quarterings = 0;
  while (abs(x) > R(0.1) && quarterings < 200) {
    x /= 4;
    ++quarterings;
  }
  // c2 = sum_j (-x)^j / (2j+2)!, c3 = sum_j (-x)^j / (2j+3)! by Horner's rule, with the inverse factorials and
  // the number of terms for |x| <= 0.1 at this precision computed once
  struct Table {
    std::array<R, 64> inv_fact{};
    int terms = 0;
    Table() {
      inv_fact[0] = 1;
      for (int k = 1; k < 64; ++k) inv_fact[k] = inv_fact[k - 1] / R(k);
      const R eps = std::numeric_limits<R>::epsilon();
      R bound = 1;
      while (terms < 29 && bound * inv_fact[2 * terms + 2] > eps / 16) {
        bound /= 10;
        ++terms;
      }
    }
  };
  static const Table table;
  R c2 = 0, c3 = 0;
  for (int j = table.terms; j >= 0; --j) {
    c2 = table.inv_fact[2 * j + 2] - x * c2;
    c3 = table.inv_fact[2 * j + 3] - x * c3;
  }
  R c1 = 1 - x * c3;
  R c0 = 1 - x * c2;
  for (; quarterings > 0; --quarterings) {
    c3 = (c2 + c0 * c3) / 4;
    c2 = c1 * c1 / 2;
    c1 = c0 * c1;
    c0 = 2 * c0 * c0 - 1;
  }
  return {c0, c1, c2, c3};
}

/// Advances (x, v) by dt along the Kepler orbit of gravitational parameter mu > 0. Throws
/// std::invalid_argument for a non-finite input or a collision orbit (x = 0), std::runtime_error when
/// Kepler's equation has no finite solution in this precision.
template <class R>
void kepler_drift(R mu, R dt, Vec3<R>& x, Vec3<R>& v) {
  using std::abs;
  using std::sqrt;
  if (dt == 0) return;
  const R r0 = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
  if (!(r0 > 0) || !std::isfinite(static_cast<double>(r0)))
    throw std::invalid_argument("Kepler drift: the distance to the central body must be positive and finite");
  const R eta0 = x[0] * v[0] + x[1] * v[1] + x[2] * v[2];
  const R v2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
  const R beta = 2 * mu / r0 - v2;
  const R zeta0 = mu - beta * r0;

  R t = dt;
  if (beta > 0) {  // elliptic: reduce modulo the period 2 pi mu / beta^{3/2}
    const R pi = R(3.14159265358979323846264338327950288L);
    const R period = 2 * pi * mu / (beta * sqrt(beta));
    if (abs(t) > period) t = std::fmod(t, period);
  }

  const R eps = std::numeric_limits<R>::epsilon();
  // bracket [lo, hi] of the root; F(0) = -t
  R lo = t > 0 ? R(0) : -std::numeric_limits<R>::infinity();
  R hi = t > 0 ? std::numeric_limits<R>::infinity() : R(0);
  // guess: the series s = t / r0 - eta0 t^2 / (2 r0^3) for short drifts, t beta / mu (mean over an orbit) for
  // long elliptic ones
  R s = t / r0 - eta0 * t * t / (2 * r0 * r0 * r0);
  if (beta > 0 && abs(t) * sqrt(beta * beta * beta) / mu > R(0.5)) s = t * beta / mu;
  if (!std::isfinite(static_cast<double>(s))) s = t / r0;

  R g1 = 0, g2 = 0, g3 = 0, r = r0;
  bool converged = false;
  R prev_abs_f = std::numeric_limits<R>::infinity();
  for (int it = 0; it < 200; ++it) {
    const R s2 = s * s;
    const Stumpff<R> c = stumpff(beta * s2);
    g1 = s * c.c1;
    g2 = s2 * c.c2;
    g3 = s2 * s * c.c3;
    const R g0 = c.c0;
    const R f = r0 * s + eta0 * g2 + zeta0 * g3 - t;
    r = r0 + eta0 * g1 + zeta0 * g2;
    const R fpp = eta0 * g0 + zeta0 * g1;
    if (converged) break;  // one evaluation at the converged s for the G-functions
    // F at the level of its own rounding: s is as good as this precision allows
    if (abs(f) <= 4 * eps * (abs(r0 * s) + abs(eta0 * g2) + abs(zeta0 * g3) + abs(t))) {
      converged = true;
      break;
    }
    if (f < 0)
      lo = s;
    else
      hi = s;
    // Laguerre-Conway step, n = 5
    const R n = 5;
    const R disc = abs((n - 1) * (n - 1) * r * r - n * (n - 1) * f * fpp);
    const R den = r + (r >= 0 ? sqrt(disc) : -sqrt(disc));
    R next = s - n * f / den;
    // bisection when the step leaves the bracket, or when |F| fell less than 64-fold (a guess far out on a hyperbolic
    // orbit, where F grows exponentially and Laguerre steps shrink s slowly)
    const bool slow = abs(f) > prev_abs_f / 64 && std::isfinite(static_cast<double>(hi - lo));
    prev_abs_f = abs(f);
    if (slow || !(next > lo && next < hi) || !std::isfinite(static_cast<double>(next))) {
      if (std::isfinite(static_cast<double>(lo)) && std::isfinite(static_cast<double>(hi)))
        next = lo + (hi - lo) / 2;
      else if (std::isfinite(static_cast<double>(hi)))  // t < 0, no lower bound yet
        next = hi - 2 * (abs(hi) + abs(t / r0) + 1);
      else
        next = lo + 2 * (abs(lo) + abs(t / r0) + 1);
    }
    const R ds = next - s;
    s = next;
    if (abs(ds) <= 4 * eps * abs(s) || next == lo || next == hi) converged = true;
  }
  if (!converged || !std::isfinite(static_cast<double>(r)) || !(r > 0))
    throw std::runtime_error("Kepler drift: Kepler's equation did not converge");

  const R fm1 = -mu * g2 / r0;
  const R g = r0 * g1 + eta0 * g2;
  const R fdot = -mu * g1 / (r * r0);
  const R gdm1 = -mu * g2 / r;
  const Vec3<R> x0 = x, v0 = v;
  for (int k = 0; k < 3; ++k) {
    x[k] = x0[k] + (fm1 * x0[k] + g * v0[k]);
    v[k] = v0[k] + (fdot * x0[k] + gdm1 * v0[k]);
  }
}

}  // namespace nystrom::planetary
