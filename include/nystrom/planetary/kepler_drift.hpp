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
// The Stumpff functions: argument quartered until |x| <= 0.1, Taylor series with as many terms as |x| needs at
// the working precision (even and odd terms in two chains), then the quadruple-argument identities
// c0(4x) = 2 c0^2 - 1, c1(4x) = c0 c1, c2(4x) = c1^2 / 2, c3(4x) = (c2 + c0 c3) / 4.
//
// Kepler's equation, two paths. The short-drift path (a Wisdom-Holman map's drifts): the cubic series of s(dt),
//   s = u - (eta0 / (2 r0)) u^2 + (eta0^2 / (2 r0^2) - zeta0 / (6 r0)) u^3,  u = dt / r0,
// exact on a circle (s = u) and otherwise to O(e (n dt)^4), one Stumpff evaluation there, then at most three
// Halley steps, each moving the G-functions by the addition theorems
//   G0(s+d) = G0 G0(d) - beta G1 G1(d),  G1(s+d) = G1 G0(d) + G0 G1(d),
//   G2(s+d) = G2 + G2(d) + G1 G1(d) - beta G2 G2(d),  G3(s+d) = G3 + G3(d) + G1 G2(d) + G2 G1(d)
// (G(d) by a two- or three-term series, |d| <= |s| / 64) instead of evaluating them anew. It is taken when the
// series' terms are small, |beta s^2| <= 2.5 (less than a quarter of an ellipse) and F at the last iterate is at the
// level of its own rounding, the acceptance test of the general path; otherwise the general path runs from the
// start: an elliptic drift longer than one period reduced modulo the period, Laguerre-Conway iteration (n = 5)
// from the quadratic series (or the mean motion for long elliptic drifts), kept inside a bracket of the root that
// shrinks with every evaluation (F is increasing: F' = r > 0), bisection when a step leaves it or fails to reduce
// |F| 64-fold (Laguerre steps reduce it far more near a root), the G-functions evaluated afresh at every iterate;
// where they overflow (a far guess on a hyperbola) the bracket shrinks on the side of s and the search goes on.
// No state is kept between drifts: the path and the result depend on the arguments only, and kepler_drift_many
// gives every orbit the bits kepler_drift gives it (tests/planetary/test_planetary.cpp).
//
// Compensated summation (kepler_drift_many with carries cx, cv): the increments (f - 1) x + g v and
// fdot x + (gdot - 1) v are added with an exact two-sum, x + (dx + cx), whose rounding error becomes the new carry,
// as the engines add their steps (core/state.hpp): the state's rounding then no longer accumulates over the drifts of
// a long run (docs/performance.md, "Long runs"). The orbit is solved from the rounded x, v; the carries are moved
// along it by the same f and g (to first order: the f and g of the exact state differ in their last bits).
//
// Cost (bench/bench_planetary.cpp, outer solar system's Jacobi orbits, h = 50..400 days, GCC 12 -O3): the short
// path takes every drift there, with one Stumpff evaluation where the general path needs two or three and no
// square root in its steps; kepler_drift_many runs it on up to eight orbits in lockstep, so that their
// arithmetic (a chain of dependent operations per orbit) overlaps: see docs/planetary.md for the measured times.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <stdexcept>

#include "nystrom/core/eft.hpp"

namespace nystrom::planetary {

template <class R>
using Vec3 = std::array<R, 3>;

template <class R>
struct Stumpff {
  R c0, c1, c2, c3;
};

namespace detail {

/// x += d, with the carry c of compensated summation when c is given (c == nullptr: plainly).
template <class R>
inline void add_increment(R& x, R d, R* c) {
  if (c == nullptr) {
    x = x + d;
    return;
  }
  R e;
  x = eft::two_sum(x, d + *c, e);
  *c = e;
}

/// One component of Lagrange's update, x = x0 + (f - 1) x0 + g v0 and v = v0 + fdot x0 + (gdot - 1) v0, plainly
/// (cx == nullptr) or with compensated summation: the carries ride along the orbit to first order (the increments
/// of x0 + cx, v0 + cv) and the sums' rounding errors become the new carries.
template <class R>
inline void lagrange_update(R& x, R& v, R x0, R v0, R fm1, R g, R fdot, R gdm1, R* cx, R* cv) {
  if (cx == nullptr) {
    x = x0 + (fm1 * x0 + g * v0);
    v = v0 + (fdot * x0 + gdm1 * v0);
    return;
  }
  const R c = *cx, w = *cv;
  x = eft::two_sum(x0, (fm1 * x0 + g * v0) + ((fm1 * c + g * w) + c), *cx);
  v = eft::two_sum(v0, (fdot * x0 + gdm1 * v0) + ((fdot * c + gdm1 * w) + w), *cv);
}

/// Inverse factorials, and for every number of series terms the largest |x| it serves to the working precision.
template <class R>
struct StumpffTable {
  static constexpr int kMaxTerms = 30;
  std::array<R, 2 * kMaxTerms + 4> inv_fact{};
  std::array<double, kMaxTerms> reach{};  // terms 0..j of the series serve |x| <= reach[j]
  int terms = 0;                          // the terms 0..terms serve |x| <= 0.1

  StumpffTable() {
    inv_fact[0] = 1;
    for (std::size_t k = 1; k < inv_fact.size(); ++k) inv_fact[k] = inv_fact[k - 1] / R(static_cast<int>(k));
    // the first omitted term of c2 (the larger relative to the leading term), x^{j+1} / (2j+4)!, at most
    // eps / 32 of c2(0) = 1/2
    const double eps = static_cast<double>(std::numeric_limits<R>::epsilon());
    for (int j = 0; j < kMaxTerms; ++j) {
      const double next = static_cast<double>(inv_fact[2 * j + 4]);
      reach[j] = std::pow(eps / 64 / next, 1.0 / (j + 1)) / 2;
    }
    while (terms < kMaxTerms - 1 && reach[terms] < 0.1) ++terms;
  }
  static const StumpffTable& get() {
    static const StumpffTable table;
    return table;
  }
};

/// c0..c3 at |x| <= 0.1 by their series, with the terms |x| needs.
template <class R>
Stumpff<R> stumpff_series(const StumpffTable<R>& table, R x) {
  using std::abs;
  const double ax = static_cast<double>(abs(x));
  int n = 0;
  while (n < table.terms && ax > table.reach[n]) ++n;
  // c2 = E2(x^2) - x O2(x^2) (even and odd terms), likewise c3: two chains of half the length
  const R x2 = x * x;
  R e2 = 0, o2 = 0, e3 = 0, o3 = 0;
  for (int j = n - n % 2; j >= 0; j -= 2) {
    e2 = table.inv_fact[2 * j + 2] + x2 * e2;
    e3 = table.inv_fact[2 * j + 3] + x2 * e3;
  }
  for (int j = n - 1 + n % 2; j >= 1; j -= 2) {
    o2 = table.inv_fact[2 * j + 2] + x2 * o2;
    o3 = table.inv_fact[2 * j + 3] + x2 * o3;
  }
  const R c2 = e2 - x * o2, c3 = e3 - x * o3;
  return {1 - x * c2, 1 - x * c3, c2, c3};
}

}  // namespace detail

/// Stumpff functions c0..c3 at x (see the top of this file).
template <class R>
Stumpff<R> stumpff(R x) {
  using std::abs;
  int quarterings = 0;
  while (abs(x) > R(0.1) && quarterings < 200) {
    x /= 4;
    ++quarterings;
  }
  auto [c0, c1, c2, c3] = detail::stumpff_series(detail::StumpffTable<R>::get(), x);
  for (; quarterings > 0; --quarterings) {
    c3 = (c2 + c0 * c3) / 4;
    c2 = c1 * c1 / 2;
    c1 = c0 * c1;
    c0 = 2 * c0 * c0 - 1;
  }
  return {c0, c1, c2, c3};
}

namespace detail {

/// The drift of one orbit by the bracketed Laguerre-Conway iteration (any orbit, any dt; see the top of this file).
template <class R>
void kepler_drift_bracketed(R mu, R dt, Vec3<R>& x, Vec3<R>& v, R* cx = nullptr, R* cv = nullptr) {
  using std::abs;
  using std::sqrt;
  if (dt == 0) return;
  if (!std::isfinite(static_cast<double>(dt)))
    throw std::invalid_argument("Kepler drift: the drift time is not finite");
  if (!(mu > 0) || !std::isfinite(static_cast<double>(mu)))
    throw std::invalid_argument("Kepler drift: the gravitational parameter must be positive and finite");
  for (int c = 0; c < 3; ++c)
    if (!std::isfinite(static_cast<double>(v[c])))
      throw std::invalid_argument("Kepler drift: the velocity is not finite");
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
    // (and F, r representable: G-functions that overflow make the bound infinite)
    if (std::isfinite(static_cast<double>(f)) && std::isfinite(static_cast<double>(r)) &&
        abs(f) <= 4 * eps * (abs(r0 * s) + abs(eta0 * g2) + abs(zeta0 * g3) + abs(t))) {
      converged = true;
      break;
    }
    // the bracket only shrinks; F too large to represent (a far guess on a hyperbolic orbit, where the G-functions
    // grow exponentially) is beyond the root on the side of s: F(s) -> +-inf as s -> +-inf
    if (f < 0 || (!std::isfinite(static_cast<double>(f)) && s < 0))
      lo = std::max(lo, s);
    else
      hi = std::min(hi, s);
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
    lagrange_update(x[k], v[k], x0[k], v0[k], fm1, g, fdot, gdm1, cx ? cx + k : nullptr, cv ? cv + k : nullptr);
  }
}

/// Orbits the short-drift path takes at once.
inline constexpr std::size_t kKeplerBatch = 8;

/// The short-drift path (top of this file) for count <= kKeplerBatch orbits at once, orbit k of parameter
/// mu(k) at x + 3k, v + 3k. The orbits it solves to rounding are advanced and marked done[k]; the others are
/// left as they were. Each orbit's arithmetic depends on its own data only.
template <class R, class Mu>
void kepler_drift_short(std::size_t count, R dt, Mu mu, R* x, R* v, bool* done, R* cx = nullptr, R* cv = nullptr) {
  using std::abs;
  using std::sqrt;
  const StumpffTable<R>& table = StumpffTable<R>::get();
  const R eps = std::numeric_limits<R>::epsilon();
  std::array<R, kKeplerBatch> r0, inv_r0, eta0, beta, zeta0, s, g0, g1, g2, g3, f, r;
  std::array<bool, kKeplerBatch> ok;
  for (std::size_t k = 0; k < count; ++k) {  // the orbit and the cubic guess
    const R* xk = x + 3 * k;
    const R* vk = v + 3 * k;
    const R m = mu(k);
    r0[k] = sqrt(xk[0] * xk[0] + xk[1] * xk[1] + xk[2] * xk[2]);
    inv_r0[k] = 1 / r0[k];
    eta0[k] = xk[0] * vk[0] + xk[1] * vk[1] + xk[2] * vk[2];
    beta[k] = 2 * m * inv_r0[k] - (vk[0] * vk[0] + vk[1] * vk[1] + vk[2] * vk[2]);
    zeta0[k] = m - beta[k] * r0[k];
    const R u = dt * inv_r0[k];
    const R a2 = -eta0[k] * inv_r0[k] / 2, a3 = (eta0[k] * eta0[k] * inv_r0[k] / 2 - zeta0[k] / 6) * inv_r0[k];
    s[k] = u * (1 + u * (a2 + u * a3));
    // the series where its terms are small, over less than a quarter of an ellipse (no reduction modulo the
    // period); false for a non-finite or collision orbit
    ok[k] = abs(u * a2) + abs(u * u * a3) <= R(0.25) && abs(beta[k] * s[k] * s[k]) <= R(2.5) && r0[k] > 0;
  }
  for (std::size_t k = 0; k < count; ++k) {  // the G-functions at the guess
    const R s2 = s[k] * s[k];
    const Stumpff<R> c = stumpff(ok[k] ? beta[k] * s2 : R(0));
    g0[k] = c.c0;
    g1[k] = s[k] * c.c1;
    g2[k] = s2 * c.c2;
    g3[k] = s2 * s[k] * c.c3;
  }
  for (std::size_t k = 0; k < count; ++k) {  // at most three steps of Halley's method
    f[k] = r0[k] * s[k] + eta0[k] * g2[k] + zeta0[k] * g3[k] - dt;
    r[k] = r0[k] + eta0[k] * g1[k] + zeta0[k] * g2[k];
    bool converged = false;
    for (int step = 0; step < 3 && ok[k] && !converged; ++step) {
      const R fpp = eta0[k] * g0[k] + zeta0[k] * g1[k];
      const R ds = -2 * f[k] * r[k] / (2 * r[k] * r[k] - f[k] * fpp);
      // the G-functions at s + ds by the addition theorems, |beta ds^2| <= 2.5 / 64^2
      ok[k] = abs(ds) <= abs(s[k]) / 64;
      const Stumpff<R> d = stumpff_series(table, ok[k] ? beta[k] * ds * ds : R(0));
      const R d1 = ds * d.c1, d2 = ds * ds * d.c2, d3 = ds * ds * ds * d.c3;
      const R n0 = g0[k] * d.c0 - beta[k] * g1[k] * d1;
      const R n1 = g1[k] * d.c0 + g0[k] * d1;
      const R n2 = g2[k] + d2 + g1[k] * d1 - beta[k] * g2[k] * d2;
      const R n3 = g3[k] + d3 + g1[k] * d2 + g2[k] * d1;
      s[k] += ds;
      g0[k] = n0;
      g1[k] = n1;
      g2[k] = n2;
      g3[k] = n3;
      // Kepler's equation at the level of its own rounding (the test of the bracketed iteration)
      f[k] = r0[k] * s[k] + eta0[k] * g2[k] + zeta0[k] * g3[k] - dt;
      r[k] = r0[k] + eta0[k] * g1[k] + zeta0[k] * g2[k];
      converged = abs(f[k]) <= 4 * eps * (abs(r0[k] * s[k]) + abs(eta0[k] * g2[k]) + abs(zeta0[k] * g3[k]) + abs(dt));
    }
    ok[k] = ok[k] && converged && r[k] > 0 && std::isfinite(static_cast<double>(r[k]));
  }
  for (std::size_t k = 0; k < count; ++k) {  // Lagrange's f and g
    done[k] = ok[k];
    if (!ok[k]) continue;
    const R m = mu(k);
    const R inv_r = 1 / r[k];
    const R fm1 = -m * g2[k] * inv_r0[k];
    const R g = r0[k] * g1[k] + eta0[k] * g2[k];
    const R fdot = -m * g1[k] * inv_r * inv_r0[k];
    const R gdm1 = -m * g2[k] * inv_r;
    R* xk = x + 3 * k;
    R* vk = v + 3 * k;
    const Vec3<R> x0{xk[0], xk[1], xk[2]}, v0{vk[0], vk[1], vk[2]};
    for (int c = 0; c < 3; ++c) {
      lagrange_update(xk[c], vk[c], x0[c], v0[c], fm1, g, fdot, gdm1, cx ? cx + 3 * k + c : nullptr,
                      cv ? cv + 3 * k + c : nullptr);
    }
  }
}

}  // namespace detail

/// Advances (x, v) by dt along the Kepler orbit of gravitational parameter mu > 0. Throws
/// std::invalid_argument for a non-finite input or a collision orbit (x = 0), std::runtime_error when
/// Kepler's equation has no finite solution in this precision.
template <class R>
void kepler_drift(R mu, R dt, Vec3<R>& x, Vec3<R>& v) {
  if (dt == 0) return;
  bool done = false;
  detail::kepler_drift_short<R>(
      1, dt, [mu](std::size_t) { return mu; }, x.data(), v.data(), &done);
  if (!done) detail::kepler_drift_bracketed(mu, dt, x, v);
}

/// Advances `count` orbits by the same dt, orbit k of parameter mu(k) at x + 3k and v + 3k (3 components each):
/// the same result as kepler_drift on each, with the short-drift path run on several orbits together so that
/// their arithmetic overlaps. With carries cx, cv (laid out as x and v), the increments are added with compensated
/// summation (top of this file). Throws as kepler_drift does.
template <class R, class Mu>
void kepler_drift_many(std::size_t count, R dt, Mu mu, R* x, R* v, R* cx = nullptr, R* cv = nullptr) {
  if (dt == 0) return;
  for (std::size_t first = 0; first < count; first += detail::kKeplerBatch) {
    const std::size_t m = std::min(detail::kKeplerBatch, count - first);
    std::array<bool, detail::kKeplerBatch> done{};
    detail::kepler_drift_short<R>(
        m, dt, [&](std::size_t k) { return mu(first + k); }, x + 3 * first, v + 3 * first, done.data(),
        cx ? cx + 3 * first : nullptr, cv ? cv + 3 * first : nullptr);
    for (std::size_t k = 0; k < m; ++k)
      if (!done[k]) {
        const std::size_t i = first + k;
        Vec3<R> xi{x[3 * i], x[3 * i + 1], x[3 * i + 2]}, vi{v[3 * i], v[3 * i + 1], v[3 * i + 2]};
        detail::kepler_drift_bracketed(mu(i), dt, xi, vi, cx ? cx + 3 * i : nullptr, cv ? cv + 3 * i : nullptr);
        for (int c = 0; c < 3; ++c) {
          x[3 * i + c] = xi[c];
          v[3 * i + c] = vi[c];
        }
      }
  }
}

}  // namespace nystrom::planetary
