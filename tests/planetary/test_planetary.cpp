// Planetary systems: the universal-variable Kepler drift against the analytic elliptic, parabolic and
// hyperbolic solutions; Jacobi coordinates; the Wisdom-Holman maps over them: the order of every map in the
// step, the eps h^2 structure of the errors (Laskar & Robutel 2001), bounded energy on the outer solar system.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include <gmpxx.h>

#include "nystrom/methods/blanes_et_al2013.hpp"
#include "nystrom/methods/wisdom_holman_touma1996.hpp"
#include "nystrom/planetary/kepler_drift.hpp"
#include "nystrom/planetary/system.hpp"
#include "nystrom/planetary/wisdom_holman.hpp"

using namespace nystrom::planetary;
using LD = long double;

namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
const LD kPi = 3.14159265358979323846264338327950288L;

template <class R>
R norm3(const Vec3<R>& a) {
  using std::sqrt;
  return sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
}

template <class A, class B>
double distance(const Vec3<A>& a, const Vec3<B>& b) {
  LD s = 0;
  for (int k = 0; k < 3; ++k) s += (LD(a[k]) - LD(b[k])) * (LD(a[k]) - LD(b[k]));
  return static_cast<double>(std::sqrt(s));
}

/// The planar elliptic orbit through (x, v) (z = 0) at time t, from its elements, in long double: a from the
/// energy, the eccentricity vector, the mean anomaly from the eccentric one, Kepler's equation by Newton.
void elliptic_analytic(LD mu, const Vec3<LD>& x0, const Vec3<LD>& v0, LD t, Vec3<LD>& x, Vec3<LD>& v) {
  const LD r = norm3(x0), v2 = v0[0] * v0[0] + v0[1] * v0[1];
  const LD a = 1 / (2 / r - v2 / mu);
  const LD rv = x0[0] * v0[0] + x0[1] * v0[1];
  const LD ex = ((v2 - mu / r) * x0[0] - rv * v0[0]) / mu, ey = ((v2 - mu / r) * x0[1] - rv * v0[1]) / mu;
  const LD e = std::sqrt(ex * ex + ey * ey), w = std::atan2(ey, ex);
  const LD sgn = x0[0] * v0[1] - x0[1] * v0[0] > 0 ? 1 : -1;
  const LD E0 = std::atan2(rv / std::sqrt(mu * a), 1 - r / a);  // e sin E, e cos E
  const LD n = std::sqrt(mu / (a * a * a));
  LD M = std::fmod(E0 - e * std::sin(E0) + n * t, 2 * kPi);
  LD E = M + e * std::sin(M);
  for (int i = 0; i < 60; ++i) E -= (E - e * std::sin(E) - M) / (1 - e * std::cos(E));
  const LD b = a * std::sqrt(1 - e * e), edot = n / (1 - e * std::cos(E));
  const LD X = a * (std::cos(E) - e), Y = sgn * b * std::sin(E);
  const LD VX = -a * std::sin(E) * edot, VY = sgn * b * std::cos(E) * edot;
  x = {X * std::cos(w) - Y * std::sin(w), X * std::sin(w) + Y * std::cos(w), 0};
  v = {VX * std::cos(w) - VY * std::sin(w), VX * std::sin(w) + VY * std::cos(w), 0};
}

/// A planar orbit of eccentricity e and pericentre distance q (mu = 1), at pericentre.
Vec3<double> pericentre_velocity(double e, double q) { return {0, std::sqrt((1 + e) / q), 0}; }

template <class R>
R kepler_energy(R mu, const Vec3<R>& x, const Vec3<R>& v) {
  return (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) / 2 - mu / norm3(x);
}

template <class R>
Vec3<R> cross(const Vec3<R>& a, const Vec3<R>& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

}  // namespace

// ---- the Kepler drift ---------------------------------------------------------------------------------------

TEST(KeplerDrift, StumpffFunctionsMatchTheirClosedForms) {
  for (double x : {-50.0, -3.0, -0.05, 1e-12, 0.05, 0.7, 3.0, 20.0, 39.0}) {
    const Stumpff<LD> c = stumpff<LD>(x);
    const LD s = std::sqrt(std::fabs(LD(x)));
    const LD c0 = x > 0 ? std::cos(s) : std::cosh(s);
    const LD c1 = x > 0 ? std::sin(s) / s : std::sinh(s) / s;
    // the quadruple-argument identities amplify the rounding of the series about 2-fold per quartering
    const double tol = 1e-15 * (1 + std::fabs(x));
    EXPECT_NEAR(static_cast<double>(c.c0), static_cast<double>(c0), tol * std::max(1.0, std::fabs(double(c0))));
    EXPECT_NEAR(static_cast<double>(c.c1), static_cast<double>(c1), tol * std::max(1.0, std::fabs(double(c1))));
    // x c2 = 1 - c0 and x c3 = 1 - c1 (checked where the differences do not cancel)
    if (std::fabs(x) > 0.5) {
      EXPECT_NEAR(static_cast<double>(x * c.c2), static_cast<double>(1 - c0), tol * std::fabs(double(1 - c0)));
      EXPECT_NEAR(static_cast<double>(x * c.c3), static_cast<double>(1 - c1), tol * std::fabs(double(1 - c1)));
    }
  }
  const Stumpff<double> z = stumpff(0.0);
  EXPECT_EQ(z.c0, 1.0);
  EXPECT_EQ(z.c1, 1.0);
  EXPECT_EQ(z.c2, 0.5);
  EXPECT_DOUBLE_EQ(z.c3, 1.0 / 6.0);
}

// In double, across the ranges where the series takes fewer terms (|x| small) and around the quartering threshold
// 0.1 (beyond it, the quadruple-argument identities amplify the rounding: the test above): against the series
// summed term by term in long double with every term down to 1e-30.
TEST(KeplerDrift, StumpffFunctionsInDoubleMatchTheSeries) {
  for (double x : {1e-9, -3e-7, 2e-5, -4e-4, 1e-3, -0.0123, 0.05, 0.0999, -0.1001, 0.12}) {
    LD ref[4] = {0, 0, 0, 0};
    for (int k = 0; k < 4; ++k) {
      LD term = 1;  // (-x)^j / (2j + k)!
      for (int f = 2; f <= k; ++f) term /= f;
      for (int j = 0; j < 40 && std::fabs(static_cast<double>(term)) > 1e-30; ++j) {
        ref[k] += term;
        term *= -LD(x) / ((2 * j + k + 1) * LD(2 * j + k + 2));
      }
    }
    const Stumpff<double> c = stumpff(x);
    const double got[4] = {c.c0, c.c1, c.c2, c.c3};
    for (int k = 0; k < 4; ++k)
      EXPECT_NEAR(got[k], static_cast<double>(ref[k]), 4 * kEps * std::fabs(static_cast<double>(ref[k])))
          << "x = " << x << " c" << k;
  }
}

// One drift across a million orbits: the only error is the rounding of the mean motion times the time,
// eps n t, which the analytic formula evaluated in double has too.
TEST(KeplerDrift, MatchesTheEllipticSolutionOverAMillionOrbits) {
  for (double e : {0.0167, 0.5, 0.9, 0.99}) {
    const Vec3<double> x0{1 - e, 0, 0}, v0 = pericentre_velocity(e, 1 - e);
    const double orbits = 1e6 + 0.3;  // a = 1, period 2 pi
    const double t = 2 * static_cast<double>(kPi) * orbits;
    Vec3<double> x = x0, v = v0;
    kepler_drift(1.0, t, x, v);
    Vec3<LD> xr, vr;
    elliptic_analytic(1, {x0[0], x0[1], 0}, {v0[0], v0[1], 0}, t, xr, vr);
    const double bound = 8 * kEps * (1 + 2 * static_cast<double>(kPi) * orbits) * (1 + e) / (1 - e);
    EXPECT_LT(distance(x, xr), bound) << "e = " << e;
    EXPECT_LT(distance(v, vr), bound * std::sqrt((1 + e) / (1 - e))) << "e = " << e;
  }
}

// Many short drifts (a Wisdom-Holman run): rounding accumulates like a random walk, not secularly.
TEST(KeplerDrift, ManyShortDriftsStayOnTheEllipse) {
  for (double e : {0.1, 0.9}) {
    const Vec3<double> x0{1 - e, 0, 0}, v0 = pericentre_velocity(e, 1 - e);
    const long orbits = 200, per_orbit = 100;
    const double h = 2 * static_cast<double>(kPi) / per_orbit + 1e-3;  // not commensurate with the period
    Vec3<double> x = x0, v = v0;
    for (long i = 0; i < orbits * per_orbit; ++i) kepler_drift(1.0, h, x, v);
    Vec3<LD> xr, vr;
    elliptic_analytic(1, {x0[0], x0[1], 0}, {v0[0], v0[1], 0}, LD(h) * (orbits * per_orbit), xr, vr);
    // Brouwer's law: the energy (so the mean motion) random-walks by eps per step, the phase error grows as
    // eps n t sqrt(steps); eccentric orbits amplify it by up to 1 / (1 - e)
    const double steps = static_cast<double>(orbits * per_orbit);
    const double bound = 2 * kEps * 2 * static_cast<double>(kPi) * orbits * std::sqrt(steps) / (1 - e);
    EXPECT_LT(distance(x, xr), bound) << "e = " << e;
    EXPECT_NEAR(kepler_energy(1.0, x, v), -0.5, 50 * kEps * orbits) << "e = " << e;
  }
}

// With carries, the drifts' increments are added by compensated summation and the carries move along the orbit:
// over 5000 drifts the rms position error over 8 realizations (pericentre distance scaled by 1 + r 2^-50) against
// the exact orbit falls 5-6x at e = 0.1 and 0.5 (measured 2.2e-13 against 1.3e-12 and 4.6e-13 against 2.8e-12) and
// stays as it was at e = 0.9 (8.4e-12 against 9.5e-12), where the solver's own error dominates; without carries
// the result is bitwise kepler_drift's.
TEST(KeplerDrift, CarriesCompensateTheIncrements) {
  const double h = 2 * static_cast<double>(kPi) / 100 + 1e-3;
  const long steps = 5000;
  for (double e : {0.1, 0.5, 0.9}) {
    double comp2 = 0, plain2 = 0;
    for (int r = 0; r < 8; ++r) {
      const Vec3<double> x0{(1 - e) * (1 + r * std::ldexp(1.0, -50)), 0, 0}, v0 = pericentre_velocity(e, 1 - e);
      Vec3<double> x = x0, v = v0, xp = x0, vp = v0, xs = x0, vs = v0, cx{}, cv{};
      auto mu = [](std::size_t) { return 1.0; };
      for (long i = 0; i < steps; ++i) {
        kepler_drift_many<double>(1, h, mu, x.data(), v.data(), cx.data(), cv.data());
        kepler_drift_many<double>(1, h, mu, xp.data(), vp.data());
        kepler_drift(1.0, h, xs, vs);
      }
      EXPECT_EQ(xp, xs);
      EXPECT_EQ(vp, vs);
      Vec3<LD> xr, vr;
      elliptic_analytic(1, {x0[0], x0[1], 0}, {v0[0], v0[1], 0}, LD(h) * steps, xr, vr);
      Vec3<LD> xc;
      for (int k = 0; k < 3; ++k) xc[k] = LD(x[k]) + cx[k];
      comp2 += distance(xc, xr) * distance(xc, xr);
      plain2 += distance(xp, xr) * distance(xp, xr);
    }
    const double comp = std::sqrt(comp2 / 8), plain = std::sqrt(plain2 / 8);
    std::cout << "[ carries  ] e = " << e << ": rms position error " << comp << " compensated, " << plain << " plain"
              << std::endl;
    EXPECT_LT(comp, e < 0.8 ? plain / 3 : 1.5 * plain) << "e = " << e;
  }
}

TEST(KeplerDrift, CompositionIsTheDriftOfTheSumAndTimeReversible) {
  for (double e : {0.3, 0.95, 1.0, 2.5}) {  // elliptic, parabolic, hyperbolic
    const Vec3<double> x0{1, 0.1, -0.05}, vq = pericentre_velocity(e, 1.0);
    const Vec3<double> v0{0.02, vq[1], 0.1};
    for (double h1 : {0.37, 5.0, -2.0}) {
      const double h2 = 1.91;
      Vec3<double> xa = x0, va = v0, xb = x0, vb = v0;
      kepler_drift(1.0, h1, xa, va);
      kepler_drift(1.0, h2, xa, va);
      kepler_drift(1.0, h1 + h2, xb, vb);
      const double scale = norm3(xb) + 1;
      EXPECT_LT(distance(xa, xb), 200 * kEps * scale) << "e = " << e << " h1 = " << h1;
      EXPECT_LT(distance(va, vb), 200 * kEps * (norm3(vb) + 1)) << "e = " << e << " h1 = " << h1;
      kepler_drift(1.0, -(h1 + h2), xb, vb);  // back to the start
      EXPECT_LT(distance(xb, x0), 200 * kEps * scale) << "e = " << e << " h1 = " << h1;
    }
  }
}

// Barker's equation: a parabola with pericentre q reaches D = tan(nu / 2) at t = sqrt(2 q^3 / mu) (D + D^3 / 3).
TEST(KeplerDrift, MatchesTheParabolicSolution) {
  const double q = 0.5;  // v = 2: the state is exactly parabolic in double
  const Vec3<double> x0{q, 0, 0}, v0{0, std::sqrt(2 / q), 0};
  for (double t : {0.01, 1.0, 30.0, 1e4}) {
    Vec3<double> x = x0, v = v0;
    kepler_drift(1.0, t, x, v);
    const LD tau = t / std::sqrt(LD(2) * q * q * q);
    const LD w = 1.5L * tau, root = std::sqrt(w * w + 1);
    const LD D = std::cbrt(w + root) - std::cbrt(root - w);
    const Vec3<LD> xr{q * (1 - D * D), 2 * q * D, 0};
    EXPECT_LT(distance(x, xr), 20 * kEps * norm3(xr)) << "t = " << t;
  }
}

// Nearly parabolic orbits (e = 1 -+ 1e-10) lose nothing: the double drift agrees with the long double one to
// rounding, and energy and angular momentum are kept to rounding.
TEST(KeplerDrift, NearlyParabolicOrbitsLoseNoAccuracy) {
  for (double e : {1 - 1e-10, 1 + 1e-10, 1 - 1e-6, 1.5, 10.0}) {
    const double q = 0.5;
    const Vec3<double> x0{q, 0, 0}, v0 = pericentre_velocity(e, q);
    for (double t : {0.1, 10.0, 1e3}) {
      Vec3<double> x = x0, v = v0;
      kepler_drift(1.0, t, x, v);
      Vec3<LD> xl{x0[0], x0[1], x0[2]}, vl{v0[0], v0[1], v0[2]};
      kepler_drift<LD>(1, t, xl, vl);
      EXPECT_LT(distance(x, xl), 50 * kEps * norm3(xl)) << "e = " << e << " t = " << t;
      EXPECT_LT(distance(v, vl), 50 * kEps * (norm3(vl) + 1)) << "e = " << e << " t = " << t;
      // to the rounding of the terms of each quantity
      const double e0 = kepler_energy(1.0, x0, v0), scale = norm3(v) * norm3(v) + 1 / norm3(x);
      EXPECT_NEAR(kepler_energy(1.0, x, v), e0, 20 * kEps * scale) << "e = " << e << " t = " << t;
      EXPECT_NEAR(cross(x, v)[2], cross(x0, v0)[2], 20 * kEps * norm3(x) * norm3(v)) << "e = " << e << " t = " << t;
    }
  }
}

TEST(KeplerDrift, LongDoubleMatchesTheEllipticSolutionToItsRounding) {
  const LD e = 0.6L, epsl = std::numeric_limits<LD>::epsilon();
  const Vec3<LD> x0{1 - e, 0, 0}, v0{0, std::sqrt((1 + e) / (1 - e)), 0};
  const LD t = 2 * kPi * 1000.25L;
  Vec3<LD> x = x0, v = v0, xr, vr;
  kepler_drift<LD>(1, t, x, v);
  elliptic_analytic(1, x0, v0, t, xr, vr);
  EXPECT_LT(distance(x, xr), static_cast<double>(16 * epsl * 2 * kPi * 1000 * 4));
}

TEST(KeplerDrift, RefusesACollisionOrbit) {
  Vec3<double> x{0, 0, 0}, v{1, 0, 0};
  EXPECT_THROW(kepler_drift(1.0, 1.0, x, v), std::invalid_argument);
}

TEST(KeplerDrift, NonFiniteInputIsRefusedWithItsReason) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  auto message = [](double mu, double dt, Vec3<double> x, Vec3<double> v) {
    try {
      kepler_drift(mu, dt, x, v);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(message(1.0, nan, {1, 0, 0}, {0, 1, 0}).find("drift time is not finite"), std::string::npos);
  EXPECT_NE(message(1.0, INFINITY, {1, 0, 0}, {0, 1, 0}).find("drift time is not finite"), std::string::npos);
  EXPECT_NE(message(nan, 1.0, {1, 0, 0}, {0, 1, 0}).find("gravitational parameter"), std::string::npos);
  EXPECT_NE(message(1.0, 1.0, {1, 0, 0}, {0, nan, 0}).find("velocity is not finite"), std::string::npos);
  EXPECT_EQ(message(1.0, 1.0, {1, 0, 0}, {0, 1, 0}), "accepted");
}

// The short-drift path (cubic guess, Halley steps moving the G-functions by the addition theorems) on the outer
// solar system's Jacobi orbits: taken for every drift at h = 25..400 days, and equal to the bracketed iteration
// (the general path, which evaluates the G-functions afresh at every iterate) to a few units of rounding.
TEST(KeplerDrift, ShortDriftPathAgreesWithTheBracketedIteration) {
  const PlanetarySystem<double> sys = outer_solar_system<double>();
  const std::vector<double> s0 = to_jacobi(sys);
  const std::vector<double> mu = jacobi_kepler_mu(sys.G, sys.mass);
  const std::size_t n = sys.size();
  for (double h : {25.0, -50.0, 200.0, 400.0}) {
    std::vector<double> s = s0;
    for (int step = 0; step < 200; ++step)
      for (std::size_t i = 1; i < n; ++i) {
        Vec3<double> xb{s[3 * i], s[3 * i + 1], s[3 * i + 2]},
            vb{s[3 * n + 3 * i], s[3 * n + 3 * i + 1], s[3 * n + 3 * i + 2]};
        const Vec3<double> x0 = xb, v0 = vb;
        detail::kepler_drift_bracketed(mu[i], h, xb, vb);
        bool done = false;
        detail::kepler_drift_short<double>(
            1, h, [&](std::size_t) { return mu[i]; }, &s[3 * i], &s[3 * n + 3 * i], &done);
        ASSERT_TRUE(done) << "h = " << h << " planet " << i << " step " << step;
        const Vec3<double> x{s[3 * i], s[3 * i + 1], s[3 * i + 2]},
            v{s[3 * n + 3 * i], s[3 * n + 3 * i + 1], s[3 * n + 3 * i + 2]};
        // the increments (f - 1) x0 + g v0 are exact to rounding in both: compare them with their size
        EXPECT_LT(distance(x, xb), 16 * kEps * (norm3(x0) + std::fabs(h) * norm3(v0))) << "h = " << h << " i = " << i;
        EXPECT_LT(distance(v, vb), 16 * kEps * norm3(v0)) << "h = " << h << " i = " << i;
      }
  }
}

namespace {

/// A mixture of orbits for the batched drift: elliptic (short and over many periods), nearly parabolic,
/// hyperbolic (a long drift far out), and ones the short-drift path declines.
struct Orbit {
  double mu;
  Vec3<double> x, v;
};
std::vector<Orbit> mixed_orbits() {
  std::vector<Orbit> o;
  for (double e : {0.0, 0.05, 0.3, 0.9, 1 - 1e-9, 1.0, 1.5, 10.0}) {
    const Vec3<double> v = pericentre_velocity(e, 0.7);
    o.push_back({1.0, {0.7, 0.01, -0.02}, {0.03, v[1], 0.05}});
    o.push_back({2.5, {-0.3, 0.9, 0.2}, {-v[1], 0.1, 0.02}});
  }
  return o;
}

}  // namespace

// Determinism: kepler_drift_many gives every orbit the bits kepler_drift gives it, whichever orbits share its
// batch and in whichever order, for short and long drifts (the short-drift path, the general path, both).
TEST(KeplerDrift, ManyOrbitsAtOnceGiveTheBitsOfEachAlone) {
  const std::vector<Orbit> orbits = mixed_orbits();
  for (double dt : {0.01, 0.3, -0.7, 40.0, 1e4}) {
    std::vector<Vec3<double>> xs, vs;  // one at a time
    for (const Orbit& o : orbits) {
      Vec3<double> x = o.x, v = o.v;
      kepler_drift(o.mu, dt, x, v);
      xs.push_back(x);
      vs.push_back(v);
    }
    for (int order = 0; order < 2; ++order) {  // as listed, then reversed (other batch neighbours)
      const std::size_t m = orbits.size();
      std::vector<double> x(3 * m), v(3 * m), mu(m);
      auto at = [&](std::size_t k) { return order == 0 ? k : m - 1 - k; };
      for (std::size_t k = 0; k < m; ++k) {
        mu[k] = orbits[at(k)].mu;
        for (int c = 0; c < 3; ++c) {
          x[3 * k + c] = orbits[at(k)].x[c];
          v[3 * k + c] = orbits[at(k)].v[c];
        }
      }
      kepler_drift_many<double>(
          m, dt, [&](std::size_t k) { return mu[k]; }, x.data(), v.data());
      for (std::size_t k = 0; k < m; ++k)
        for (int c = 0; c < 3; ++c) {
          EXPECT_EQ(x[3 * k + c], xs[at(k)][c]) << "dt = " << dt << " orbit " << at(k);
          EXPECT_EQ(v[3 * k + c], vs[at(k)][c]) << "dt = " << dt << " orbit " << at(k);
        }
    }
  }
}

// Short and long drifts of the mixed orbits against long double, through the batch: exact to rounding whichever
// path each orbit takes; dt = 0 leaves every bit unchanged; a collision orbit in a batch is refused.
TEST(KeplerDrift, ManyOrbitsAtOnceMatchLongDouble) {
  const std::vector<Orbit> orbits = mixed_orbits();
  const std::size_t m = orbits.size();
  for (double dt : {0.0, 1e-3, 0.5, -3.0, 200.0}) {
    std::vector<double> x(3 * m), v(3 * m);
    for (std::size_t k = 0; k < m; ++k)
      for (int c = 0; c < 3; ++c) {
        x[3 * k + c] = orbits[k].x[c];
        v[3 * k + c] = orbits[k].v[c];
      }
    kepler_drift_many<double>(
        m, dt, [&](std::size_t k) { return orbits[k].mu; }, x.data(), v.data());
    for (std::size_t k = 0; k < m; ++k) {
      const Vec3<double> xd{x[3 * k], x[3 * k + 1], x[3 * k + 2]}, vd{v[3 * k], v[3 * k + 1], v[3 * k + 2]};
      if (dt == 0) {
        EXPECT_EQ(xd, orbits[k].x);
        EXPECT_EQ(vd, orbits[k].v);
        continue;
      }
      Vec3<LD> xl{orbits[k].x[0], orbits[k].x[1], orbits[k].x[2]}, vl{orbits[k].v[0], orbits[k].v[1], orbits[k].v[2]};
      kepler_drift<LD>(orbits[k].mu, dt, xl, vl);
      // over many periods the rounding of the mean motion shifts the phase by about eps n dt
      const double bound = 100 * kEps * (1 + std::fabs(dt));
      EXPECT_LT(distance(xd, xl), bound * (norm3(xl) + 1)) << "dt = " << dt << " orbit " << k;
      EXPECT_LT(distance(vd, vl), bound * (norm3(vl) + 1)) << "dt = " << dt << " orbit " << k;
    }
  }
  std::vector<double> x = {1, 0, 0, 0, 0, 0}, v = {0, 1, 0, 1, 0, 0};
  EXPECT_THROW(kepler_drift_many<double>(
                   2, 0.1, [](std::size_t) { return 1.0; }, x.data(), v.data()),
               std::invalid_argument);
}

// Random orbits (positions in the unit cube, speeds over three decades, mu over two, |dt| from 1e-3 to 1e3, both
// signs; elliptic and hyperbolic): every drift converges and matches long double to rounding amplified by the
// drift's length. A bracketed iteration that takes an infinite F or r (a far guess on a hyperbola, where the
// G-functions overflow) for converged, or loosens its bracket on it, fails on about one in ten of such orbits.
TEST(KeplerDrift, RandomOrbitsConvergeAndMatchLongDouble) {
  std::mt19937_64 rng(12345);
  auto uniform = [&rng] { return static_cast<double>(rng() >> 11) * 0x1p-52 - 1; };  // in [-1, 1)
  for (int i = 0; i < 2000; ++i) {
    Vec3<double> x{uniform(), uniform(), uniform()}, v{uniform(), uniform(), uniform()};
    const double speed = std::pow(10.0, 1.5 * uniform()), mu = std::pow(10.0, uniform());
    const double dt = std::pow(10.0, 3 * uniform()) * (uniform() > 0 ? 1 : -1);
    for (double& c : v) c *= speed;
    const double beta = 2 * mu / norm3(x) - norm3(v) * norm3(v);
    Vec3<LD> xl{x[0], x[1], x[2]}, vl{v[0], v[1], v[2]};
    kepler_drift<LD>(mu, dt, xl, vl);
    ASSERT_NO_THROW(kepler_drift(mu, dt, x, v)) << "mu = " << mu << " dt = " << dt << " beta = " << beta;
    const double bound = 1e-11 * (1 + std::fabs(dt));
    EXPECT_LT(distance(x, xl), bound * norm3(xl)) << "mu = " << mu << " dt = " << dt << " beta = " << beta;
    EXPECT_LT(distance(v, vl), bound * norm3(vl)) << "mu = " << mu << " dt = " << dt << " beta = " << beta;
  }
}

// A drift after a kick that changed the orbit (as in a map: drift, kick, drift) is the drift of the new orbit:
// nothing of the previous orbit is reused. Against the analytic ellipse of the kicked state.
TEST(KeplerDrift, DriftAfterAKickFollowsTheNewOrbit) {
  Vec3<double> x{0.9, 0, 0}, v = pericentre_velocity(0.1, 0.9);
  kepler_drift(1.0, 0.4, x, v);
  for (int c = 0; c < 2; ++c) v[c] *= 1.2;  // the kick: a more eccentric ellipse (e about 0.6)
  const Vec3<double> x1 = x, v1 = v;
  kepler_drift(1.0, 0.4, x, v);
  Vec3<LD> xr, vr;
  elliptic_analytic(1, {x1[0], x1[1], 0}, {v1[0], v1[1], 0}, 0.4L, xr, vr);
  EXPECT_LT(distance(x, xr), 16 * kEps);
  EXPECT_LT(distance(v, vr), 16 * kEps * norm3(vr));
}

// ---- Jacobi coordinates ---------------------------------------------------------------------------------------

TEST(Jacobi, RoundTripAndDiagonalKineticEnergy) {
  const PlanetarySystem<double> sys = outer_solar_system<double>();
  const std::vector<double> s = to_jacobi(sys);
  std::vector<Vec3<double>> x, v;
  from_jacobi(sys.mass, s, x, v);
  for (std::size_t i = 0; i < sys.size(); ++i) {
    EXPECT_LT(distance(x[i], sys.x[i]), 1e-14 * 40);
    EXPECT_LT(distance(v[i], sys.v[i]), 1e-16 * 40);
  }
  // sum m v^2 = sum m' v'^2 with m'_0 the total mass and m'_i = m_i eta_{i-1} / eta_i
  const std::size_t n = sys.size();
  double inertial = 0, jacobi = 0, eta = sys.mass[0];
  for (std::size_t i = 0; i < n; ++i) inertial += sys.mass[i] * (norm3(sys.v[i]) * norm3(sys.v[i]));
  for (std::size_t i = 1; i < n; ++i) {
    const double next = eta + sys.mass[i];
    const Vec3<double> vj{s[3 * n + 3 * i], s[3 * n + 3 * i + 1], s[3 * n + 3 * i + 2]};
    jacobi += sys.mass[i] * eta / next * norm3(vj) * norm3(vj);
    eta = next;
  }
  const Vec3<double> vc{s[3 * n], s[3 * n + 1], s[3 * n + 2]};
  jacobi += eta * norm3(vc) * norm3(vc);
  EXPECT_NEAR(jacobi, inertial, 1e-14 * inertial);
}

// The direct methods' form of the system: the flat force is accelerations() bit for bit, the flat state round-trips,
// and the barycentric system keeps the relative motion, with its centre of mass at rest at the origin.
TEST(CartesianForm, FlatForceIsTheBodyForceBitwiseAndTheBarycentreIsAtRest) {
  const PlanetarySystem<double> sys = outer_solar_system<double>();
  std::vector<Vec3<double>> a, back;
  accelerations(sys.G, sys.mass, sys.x, a);
  const std::vector<double> q = flatten(sys.x);
  std::vector<double> fa(7, 1.0);  // resized and overwritten
  const CartesianForce<double> force(sys);
  force(q, fa);
  ASSERT_EQ(fa.size(), 3 * sys.size());
  for (std::size_t i = 0; i < sys.size(); ++i)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(fa[3 * i + k], a[i][k]) << i << ' ' << k;
  unflatten(q, back);
  EXPECT_EQ(back, sys.x);

  const PlanetarySystem<LD> b = barycentric(outer_solar_system<LD>());
  const PlanetarySystem<LD> h = outer_solar_system<LD>();
  LD m = 0;
  Vec3<LD> X{0, 0, 0}, P{0, 0, 0};
  for (std::size_t i = 0; i < b.size(); ++i) {
    m += b.mass[i];
    for (int k = 0; k < 3; ++k) {
      X[k] += b.mass[i] * b.x[i][k];
      P[k] += b.mass[i] * b.v[i][k];
      // relative positions and velocities are those of the data
      EXPECT_NEAR(static_cast<double>(b.x[i][k] - b.x[0][k]), static_cast<double>(h.x[i][k] - h.x[0][k]), 1e-17);
      EXPECT_NEAR(static_cast<double>(b.v[i][k] - b.v[0][k]), static_cast<double>(h.v[i][k] - h.v[0][k]), 1e-19);
    }
  }
  for (int k = 0; k < 3; ++k) {
    EXPECT_LT(std::fabs(static_cast<double>(X[k] / m)), 1e-17);
    EXPECT_LT(std::fabs(static_cast<double>(P[k] / m)), 1e-20);
  }
  // Hairer's barycentre itself moves: about 2.5 AU per thousand years
  LD p2 = 0;
  for (int k = 0; k < 3; ++k) {
    LD pk = 0;
    for (std::size_t i = 0; i < h.size(); ++i) pk += h.mass[i] * h.v[i][k];
    p2 += (pk / m) * (pk / m);
  }
  EXPECT_GT(static_cast<double>(std::sqrt(p2)) * 365250, 1.0);
}

// ---- Wisdom-Holman maps ---------------------------------------------------------------------------------------

namespace {

/// A star of mass 1 and two planets of masses eps and eps / 2 on nearly circular (e about 0.1), inclined,
/// non-resonant orbits (G = 1, inner period about 2 pi).
template <class R>
PlanetarySystem<R> two_planets(R eps) {
  PlanetarySystem<R> s;
  s.G = 1;
  s.mass = {1, eps, eps / 2};
  s.x = {Vec3<R>{0, 0, 0}, {1, 0, 0}, {0, R(1.7), R(0.05)}};
  s.v = {Vec3<R>{0, 0, 0}, {0, R(1.05), R(0.02)}, {R(-0.95) / std::sqrt(R(1.7)), 0, R(0.01)}};
  return s;
}

/// Positions of the planets after time T with a step T / n.
template <class R>
std::vector<Vec3<R>> planets_at(const PlanetarySystem<R>& s, const std::string& method, R T, long n) {
  return propagate(s, method, T / static_cast<R>(n), n).system.x;
}

template <class R>
double max_distance(const std::vector<Vec3<R>>& a, const std::vector<Vec3<R>>& b) {
  double d = 0;
  for (std::size_t i = 1; i < a.size(); ++i) d = std::max(d, distance(a[i], b[i]));
  return d;
}

/// Observed order from the differences of runs with n, 2n, 4n steps.
template <class R>
double observed_order(const PlanetarySystem<R>& s, const std::string& method, R T, long n) {
  const auto a = planets_at(s, method, T, n), b = planets_at(s, method, T, 2 * n), c = planets_at(s, method, T, 4 * n);
  return std::log2(max_distance(a, b) / max_distance(b, c));
}

// 17 time units: 2.7 inner orbits, so that no step of the tests is a simple fraction of the period (Wisdom-Holman
// maps have step-size resonances there).
constexpr double kT = 17.0;

}  // namespace

namespace {

/// The largest relative energy error over a run of n steps to time T (every step observed).
template <class R>
double energy_error_max(const PlanetarySystem<R>& s, const std::string& method, R T, long n) {
  const R e0 = energy(s.G, s.mass, s.x, s.v);
  double m = 0;
  std::vector<Vec3<R>> x, v;
  PropagateOptions<R> opt;
  opt.every = 1;
  opt.observer = [&](long, const std::vector<R>& st) {
    from_jacobi(s.mass, st, x, v);
    m = std::max(m, std::fabs(static_cast<double>(energy(s.G, s.mass, x, v) / e0 - 1)));
  };
  (void)propagate(s, method, T / static_cast<R>(n), n, opt);
  return m;
}

double energy_order(double eps, const std::string& method, long n) {
  const PlanetarySystem<LD> s = two_planets<LD>(eps);
  return std::log2(energy_error_max<LD>(s, method, kT, n) / energy_error_max<LD>(s, method, kT, 2 * n));
}

}  // namespace

// The energy error of a map is the size of its modified Hamiltonian's correction: for H = A + eps B, the
// Wisdom-Holman map's is eps h^2; SABA_n's and SBAB_n's eps h^{2n} + eps^2 h^2 (Laskar & Robutel 2001), so
// their slope is 2n for small eps and 2 once eps^2 h^2 dominates; the multi-product expansions over the map
// remove every h^2 ... h^{p-2} term, both orders in eps. Long double keeps the rounding floor below the
// smallest errors measured; the steps are in the asymptotic range (at least 60 per inner orbit for p >= 6).
TEST(WisdomHolman, OrderOfTheEnergyErrorInTheStepAndThePerturbation) {
  struct Case {
    std::string method;
    double eps;
    long n;
    double order;
  };
  for (const Case& c : std::vector<Case>{{"WH", 1e-3, 64, 2},
                                         {"SABA2", 1e-3, 64, 2},  // eps^2 h^2 dominates
                                         {"SBAB2", 1e-3, 64, 2},
                                         {"SABA2", 1e-7, 64, 4},  // eps h^4 dominates
                                         {"SBAB2", 1e-7, 64, 4},
                                         {"WH-M4", 1e-3, 64, 4},
                                         {"WH-FR", 1e-3, 64, 4},
                                         {"WH-M6", 1e-3, 128, 6},
                                         {"WH-M8", 1e-4, 40, 8},  // at 2n steps the error stays 1e3 above the rounding
                                         {"WH-mpe:1,2,3,4,6", 1e-5, 16, 10}})
    EXPECT_NEAR(energy_order(c.eps, c.method, c.n), c.order, 0.35) << c.method << " eps = " << c.eps;
}

// The Wisdom-Holman energy error is linear in the perturbation (eps h^2), and higher SABA_n gain orders at
// small eps: at eps = 1e-7 and 64 steps each n lowers the error.
TEST(WisdomHolman, EnergyErrorIsLinearInThePerturbation) {
  const double small = energy_error_max<LD>(two_planets<LD>(1e-7), "WH", kT, 128);
  const double large = energy_error_max<LD>(two_planets<LD>(1e-5), "WH", kT, 128);
  EXPECT_NEAR(large / small, 100.0, 5.0);
  const PlanetarySystem<LD> s = two_planets<LD>(1e-7);
  double previous = energy_error_max<LD>(s, "SABA1", kT, 64);
  for (const char* m : {"SABA2", "SABA3", "SABA4"}) {
    const double e = energy_error_max<LD>(s, m, kT, 64);
    EXPECT_LT(e, previous / 4) << m;
    previous = e;
  }
}

// The published correctors of different orders are solutions of one family of conditions: the odd moments
// sum_k r_k k^{2j+1} (methods/wisdom_holman_touma1996.hpp) that two orders both fix must agree, exactly. A digit
// changed in any table breaks an equality. The first moment is 1/48 for all: the corrector removes the h^2 [A,B]
// / 24 term of the map's modified Hamiltonian (alpha_1 beta_1 = 1/2 per unit of r).
TEST(SymplecticCorrector, PublishedOrdersShareTheirMoments) {
  auto moment = [](int order, int j) {
    const auto r = nystrom::methods::wh_corrector_rationals(order);
    mpq_class m = 0;
    for (std::size_t k = 1; k <= r.size(); ++k) {
      mpz_class p;
      mpz_pow_ui(p.get_mpz_t(), mpz_class(static_cast<unsigned long>(k)).get_mpz_t(), 2 * j + 1);
      m += r[k - 1] * mpq_class(p);
    }
    return m;
  };
  const std::vector<int>& orders = nystrom::methods::wh_corrector_orders();
  for (int n : orders) {
    EXPECT_EQ(moment(n, 0), mpq_class(1, 48)) << n;
    for (int j = 1; j < (n - 1) / 2; ++j) EXPECT_EQ(moment(n, j), moment(17, j)) << "order " << n << ", j = " << j;
  }
  EXPECT_THROW((void)nystrom::methods::wh_corrector_rationals(9), std::invalid_argument);
}

// The corrector of order n turns the map's eps h^2 energy error into eps h^{n+1} (eps^2 h^2 lies below it at
// eps = 1e-9 and these steps): the slopes in h are 2 (WH), 4, 6, 8 and 12, and at the same step every corrector
// gains over the map.
TEST(SymplecticCorrector, EnergyErrorOrderRisesWithTheCorrector) {
  const PlanetarySystem<LD> s = two_planets<LD>(1e-9);
  const long n = 32;
  const double wh = energy_error_max<LD>(s, "WH", kT, n);
  EXPECT_NEAR(std::log2(wh / energy_error_max<LD>(s, "WH", kT, 2 * n)), 2, 0.35);
  struct Case {
    const char* method;
    double order;
  };
  for (const Case& c : {Case{"WHC3", 4}, Case{"WHC5", 6}, Case{"WHC7", 8}}) {
    const double e = energy_error_max<LD>(s, c.method, kT, n);
    EXPECT_NEAR(std::log2(e / energy_error_max<LD>(s, c.method, kT, 2 * n)), c.order, 0.4) << c.method;
    EXPECT_LT(e, wh / 5) << c.method;
  }
  // order 11: slope 12 (10.6 measured at these steps, still approaching); order 17 reaches the eps^2 h^2 floor
  const double e11 = energy_error_max<LD>(s, "WHC11", kT, n);
  EXPECT_GT(std::log2(e11 / energy_error_max<LD>(s, "WHC11", kT, 2 * n)), 9.5);
  EXPECT_LT(energy_error_max<LD>(s, "WHC17", kT, n), e11);
  EXPECT_THROW((void)propagate(s, "WHC9", LD(0.1), 10), std::invalid_argument);
}

// Democratic heliocentric coordinates (Duncan, Levison & Lee 1998): the map is of second order, its
// multi-product expansion M8 of eighth order (slopes over a factor 4 in the step), and both conserve the total
// momentum to rounding (every flow keeps the barycentric velocities' momentum sum and the centre of mass's
// velocity; the expansion's linear combination keeps a linear invariant).
TEST(DemocraticHeliocentric, OrderOfTheMapAndOfItsExtrapolationAndMomentum) {
  auto slope4 = [](double eps, const std::string& method, long n) {
    const PlanetarySystem<LD> s = two_planets<LD>(eps);
    return std::log2(energy_error_max<LD>(s, method, kT, n) / energy_error_max<LD>(s, method, kT, 4 * n)) / 2;
  };
  EXPECT_NEAR(slope4(1e-3, "WHD", 32), 2, 0.2);
  EXPECT_NEAR(slope4(1e-4, "WHD-M8", 40), 8, 0.35);
  const PlanetarySystem<LD> s = two_planets<LD>(1e-3);
  for (const char* m : {"WHD", "WHD-M8"}) {
    const PropagateResult<LD> r = propagate(s, m, LD(0.1), 200);
    LD d = 0, p = 0;
    for (int k = 0; k < 3; ++k) {
      LD p0 = 0, p1 = 0;
      for (std::size_t i = 0; i < s.mass.size(); ++i) {
        p0 += s.mass[i] * s.v[i][k];
        p1 += s.mass[i] * r.system.v[i][k];
      }
      d += (p1 - p0) * (p1 - p0);
      p += p0 * p0;
    }
    EXPECT_LT(std::sqrt(d / p), 1e-16) << m;
    EXPECT_GT(distance(r.system.x[1], s.x[1]), 0.5) << m;  // it moved
  }
  // kicks that meet (a velocity-Verlet base) and complex coefficients are refused
  EXPECT_THROW((void)propagate(s, "WHD-VV", LD(0.1), 10), std::invalid_argument);
  EXPECT_THROW((void)propagate(s, "WHD-BC1", LD(0.1), 10), std::invalid_argument);
}

// Positions in double: the Wisdom-Holman map and its fourth-order extrapolation converge at their orders.
TEST(WisdomHolman, ObservedOrderOfThePositions) {
  const PlanetarySystem<double> s = two_planets<double>(1e-3);
  EXPECT_NEAR(observed_order<double>(s, "WH", kT, 64), 2, 0.35);
  EXPECT_NEAR(observed_order<double>(s, "WH-M4", kT, 64), 4, 0.35);
}

// The energy error of WH on the outer solar system over 10^4 years oscillates without drift.
TEST(WisdomHolman, BoundedEnergyOnTheOuterSolarSystem) {
  const PlanetarySystem<double> sys = outer_solar_system<double>();
  const double e0 = energy(sys.G, sys.mass, sys.x, sys.v);
  const double h = 100, years = 1e4;
  const long steps = static_cast<long>(years * 365.25 / h);
  double first = 0, second = 0;
  std::vector<Vec3<double>> x, v;
  PropagateOptions<double> opt;
  opt.every = 10;
  opt.observer = [&](long step, const std::vector<double>& s) {
    from_jacobi(sys.mass, s, x, v);
    const double de = std::fabs(energy(sys.G, sys.mass, x, v) / e0 - 1);
    (step <= steps / 2 ? first : second) = std::max(step <= steps / 2 ? first : second, de);
  };
  (void)propagate(sys, "WH", h, steps, opt);
  EXPECT_GT(first, 1e-9);          // WH at 100 days: an eps h^2 oscillation well above rounding ...
  EXPECT_LT(first, 1e-5);          // ... and small
  EXPECT_LT(second, 1.5 * first);  // no secular growth
}

TEST(PlanetarySystem, EveryBodyIsValidatedTheCentralOneToo) {
  // A bad mass, position or velocity is refused wherever it stands, body 0 (the central body) included.
  for (std::size_t body : {std::size_t(0), std::size_t(2)}) {
    SCOPED_TRACE(body);
    PlanetarySystem<double> sys = outer_solar_system<double>();
    EXPECT_NO_THROW(sys.validate());
    sys.mass[body] = 0;
    EXPECT_THROW(sys.validate(), std::invalid_argument);
    sys = outer_solar_system<double>();
    sys.x[body][1] = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THROW(sys.validate(), std::invalid_argument);
    sys = outer_solar_system<double>();
    sys.v[body][2] = std::numeric_limits<double>::infinity();
    EXPECT_THROW(sys.validate(), std::invalid_argument);
  }
}

// The observer is called where PropagateOptions says: never while `every` is 0 (the default), even when given;
// with every = k at step 0, every k steps and after the last step.
TEST(WisdomHolman, ObserverIsCalledEveryKStepsAndNotByDefault) {
  const PlanetarySystem<double> sys = two_planets<double>(1e-3);
  std::vector<long> seen;
  PropagateOptions<double> opt;
  opt.observer = [&](long step, const std::vector<double>&) { seen.push_back(step); };
  (void)propagate(sys, "WH", 0.1, 10, opt);
  EXPECT_TRUE(seen.empty());
  opt.every = 4;
  (void)propagate(sys, "WH", 0.1, 10, opt);
  EXPECT_EQ(seen, (std::vector<long>{0, 4, 8, 10}));
}

TEST(WisdomHolman, RefusesComplexAndUnknownMethods) {
  const PlanetarySystem<double> s = two_planets(1e-3);
  EXPECT_THROW((void)propagate(s, "WH-BC1", 0.1, 10), std::invalid_argument);
  EXPECT_THROW((void)propagate(s, "nonsense", 0.1, 10), std::invalid_argument);
  EXPECT_THROW((void)propagate(s, "WH-DP12-adaptive", 0.1, 10), std::invalid_argument);
  EXPECT_THROW((void)propagate(s, "WH", -0.1, 10), std::invalid_argument);
  PlanetarySystem<double> bad = s;
  bad.mass[1] = -1;
  EXPECT_THROW((void)propagate(bad, "WH", 0.1, 10), std::invalid_argument);
}

// A splitting over the Jacobi flows adds every drift's and kick's increment with compensated summation when asked
// (PropagateOptions::compensated; off by default): SABA(10,6,4) on the outer solar system at 150 days, whose
// truncation lies below its round-off there, over 1000 Jupiter periods; the rms of the relative energy error over
// four realizations (initial positions scaled by 1 + r 2^-50) falls by more than 2x (measured 1.1e-14 against
// 9.6e-14); the default is the plain map, bitwise.
TEST(WisdomHolman, CompensatedSplittingLowersTheRoundOff) {
  using nystrom::Compensation;
  const long steps = 29 * 1000;  // 29 steps of 150 days: 1.004 Jupiter periods
  auto rms = [&](Compensation c) {
    double sum = 0;
    for (int r = 0; r < 4; ++r) {
      PlanetarySystem<double> sys = outer_solar_system<double>();
      for (std::size_t i = 1; i < sys.size(); ++i)
        for (int k = 0; k < 3; ++k) sys.x[i][k] *= 1 + r * std::ldexp(1.0, -50);
      PlanetarySystem<LD> l = convert_system<LD>(sys);
      const LD e0 = energy(l.G, l.mass, l.x, l.v);
      PropagateOptions<double> opt;
      opt.compensated = c;
      const PropagateResult<double> res = propagate(sys, "SABA(10,6,4)", 150.0, steps, opt);
      for (std::size_t i = 0; i < sys.size(); ++i)
        for (int k = 0; k < 3; ++k) {
          l.x[i][k] = res.system.x[i][k];
          l.v[i][k] = res.system.v[i][k];
        }
      const double de = static_cast<double>(energy(l.G, l.mass, l.x, l.v) / e0 - 1);
      sum += de * de;
    }
    return std::sqrt(sum / 4);
  };
  const double comp = rms(Compensation::on), plain = rms(Compensation::off);
  EXPECT_EQ(rms(PropagateOptions<double>{}.compensated), plain);
  std::cout << "[ carries  ] SABA(10,6,4), 1000 periods: rms energy error " << comp << " compensated, " << plain
            << " plain" << std::endl;
  EXPECT_LT(comp, plain / 2);
  EXPECT_GT(plain, 1e-15);  // the plain map's round-off is what is measured
}

// The multi-product expansion over the planetary flows adds its combined increment with compensated summation
// (operators/flows.hpp): the carry lives from step to step and from one integrate() call to the next, so that
// n calls of one step give bitwise the result of one call of n steps; a state changed between calls starts a
// fresh carry (bitwise the result of a new integrator); without compensation the result differs by rounding only.
TEST(WisdomHolman, CompensatedExpansionKeepsItsCarryAcrossCalls) {
  using nystrom::Compensation;
  using Flows = JacobiFlows<double>;
  using Integrator = nystrom::operators::FlowIntegrator<Flows>;
  const PlanetarySystem<double> sys = two_planets<double>(1e-3);
  const auto fm = resolve_wh_method("WH-M6", 53, "double");
  const double h = kT / 64;
  const long n = 300;
  auto run = [&](Compensation c, long calls, std::vector<double> s) {
    Flows f(sys.G, sys.mass);
    Integrator integ(fm, c);
    for (long i = 0; i < calls; ++i) integ.integrate(f, s, h, n / calls);
    return s;
  };
  const std::vector<double> s0 = to_jacobi(sys);
  const std::vector<double> one = run(Compensation::automatic, 1, s0);
  EXPECT_EQ(run(Compensation::automatic, n, s0), one);
  const std::vector<double> plain = run(Compensation::off, 1, s0);
  EXPECT_NE(plain, one);
  // the two differ by the rounding of 300 steps, grown along the orbits (3e-13 measured)
  for (std::size_t i = 0; i < one.size(); ++i) EXPECT_NEAR(plain[i], one[i], 1e-11 * (1 + std::fabs(one[i])));

  // a state changed between calls: the carry of the previous run is dropped
  Flows f(sys.G, sys.mass);
  Integrator integ(fm, Compensation::automatic);
  std::vector<double> s = s0;
  integ.integrate(f, s, h, n);
  s = s0;
  integ.integrate(f, s, h, n);
  EXPECT_EQ(s, one);
}

// The methods of generalized order of Blanes, Casas, Farres, Laskar, Makazaga & Murua (2013), from their
// published decimals: each is a palindrome whose drifts and kicks sum to 1 (to the digits published).
TEST(GeneralizedOrder, PublishedCoefficientsAreConsistentAndSymmetric) {
  const nystrom::BigPrecision guard(256);
  const auto defs = nystrom::methods::blanes_et_al2013();
  ASSERT_EQ(defs.size(), 6u);
  for (const auto& def : defs) {
    SCOPED_TRACE(def.info.name);
    const auto sc = std::get<nystrom::SplittingScheme<nystrom::bigcomplex>>(def.build());
    nystrom::bigfloat a = 0, b = 0;
    const std::size_t m = sc.steps.size();
    for (std::size_t i = 0; i < m; ++i) {
      EXPECT_EQ(sc.steps[i].flow, i % 2 == 0 ? nystrom::Flow::drift : nystrom::Flow::kick);
      EXPECT_EQ(sc.steps[i].coef.re, sc.steps[m - 1 - i].coef.re);
      (sc.steps[i].flow == nystrom::Flow::drift ? a : b) += sc.steps[i].coef.re;
    }
    // 39 digits; 30 for the kick weights of SABA(8,6,4), which sum to 1 - 5.0e-31 as published
    const double tol = std::pow(10.0, 1 - def.info.published_digits);
    EXPECT_LT(static_cast<double>(abs(a - 1)), tol);
    EXPECT_LT(static_cast<double>(abs(b - 1)), tol);
    EXPECT_EQ(m, static_cast<std::size_t>(2 * def.info.stages + 1));
    // the name and its alias without parentheses resolve to the same method
    EXPECT_EQ(resolve_wh_method(def.info.aliases.at(0), 53, "double").info.name, def.info.name);
  }
}

// Their error structure, measured on the two-planet system (relative energy error, long double): at eps = 1e-7
// the eps h^s1 term dominates (slope 10 for the (10,...) methods, 8 for the (8,...) ones); at eps = 1e-3, the
// outer solar system's, every one has slope 4 in h, where SABA4 keeps the slope 2 of its eps^2 h^2 term, and an
// error at least 100 times below SABA4's; in that h^4 regime the error grows as eps^3 for the (s1,6,4) methods
// (their leading term there is eps^3 h^4) and as eps^2 for SABA(10,4) and SABAH(8,4,4) (eps^2 h^4).
TEST(GeneralizedOrder, ErrorTermsInThePerturbationAndTheStep) {
  struct Case {
    const char* method;
    double s1;
    long n;  // steps of the slope at eps = 1e-7 (asymptotic, above the rounding floor)
    double eps_power;
  };
  const PlanetarySystem<LD> small = two_planets<LD>(1e-7), jovian = two_planets<LD>(1e-3);
  const double saba4 = energy_error_max<LD>(jovian, "SABA4", kT, 128);
  EXPECT_NEAR(std::log2(energy_error_max<LD>(jovian, "SABA4", kT, 64) / saba4), 2, 0.2);
  for (const Case& c :
       {Case{"SABA(10,6,4)", 10, 16, 3}, Case{"SABA(8,6,4)", 8, 32, 3}, Case{"SABA(10,4)", 10, 16, 2},
        Case{"SABAH(8,4,4)", 8, 32, 2}, Case{"SABAH(8,6,4)", 8, 32, 3}, Case{"SABAH(10,6,4)", 10, 16, 3}}) {
    SCOPED_TRACE(c.method);
    EXPECT_NEAR(
        std::log2(energy_error_max<LD>(small, c.method, kT, c.n) / energy_error_max<LD>(small, c.method, kT, 2 * c.n)),
        c.s1, 0.7);
    const double e128 = energy_error_max<LD>(jovian, c.method, kT, 128);
    EXPECT_NEAR(std::log2(energy_error_max<LD>(jovian, c.method, kT, 64) / e128), 4, 0.25);
    EXPECT_LT(e128, saba4 / 100);
    const double lo = energy_error_max<LD>(two_planets<LD>(1.25e-4), c.method, kT, 128);
    const double hi = energy_error_max<LD>(two_planets<LD>(2.5e-4), c.method, kT, 128);
    EXPECT_NEAR(std::log2(hi / lo), c.eps_power, 0.4);
  }
}

// The total angular momentum sum m_i x_i cross v_i of two bodies with every component nonzero, computed by hand:
// 2 (1, 2, 3) x (4, 5, 6) = (-6, 12, -6) and 3 (-1, 1/2, 2) x (1/4, -2, 1) = (27/2, 9/2, 45/8).
TEST(PlanetarySystem, AngularMomentumOfTwoBodiesByHand) {
  const std::vector<double> mass = {2, 3};
  const std::vector<Vec3<double>> x = {{1, 2, 3}, {-1, 0.5, 2}}, v = {{4, 5, 6}, {0.25, -2, 1}};
  const Vec3<double> l = angular_momentum(mass, x, v);
  EXPECT_EQ(l[0], 7.5);
  EXPECT_EQ(l[1], 16.5);
  EXPECT_EQ(l[2], -0.375);
  const Vec3<double> one = angular_momentum(std::vector<double>{2}, x, v);
  EXPECT_EQ(one[0], -6);
  EXPECT_EQ(one[1], 12);
  EXPECT_EQ(one[2], -6);
}

// The short-drift path takes every orbit whose series terms are small, |u a2| + |u^2 a3| <= 1/4 with u = dt / r0
// (and |beta s^2| <= 2.5), however large a3 itself: at the pericentre of e = 0.9 (r0 = 0.1, a3 = -1.5) a drift of
// 1e-3 (u = 0.01, u^2 a3 = -1.5e-4) is solved there in either direction, as the bracketed iteration solves it;
// a drift of 0.2 (u = 2, u^2 a3 = -6) is declined and leaves the orbit as it was.
TEST(KeplerDrift, ShortDriftPathTakesEveryOrbitWhoseSeriesTermsAreSmall) {
  const double r0 = 0.1, mu = 1.0, vp = std::sqrt(mu * 1.9 / r0);  // e = 0.9 at its pericentre
  for (const Vec3<double>& vel : {Vec3<double>{0, vp, 0}, Vec3<double>{0.3, vp, 0.2}}) {
    for (const double dt : {1e-3, -1e-3, 2e-3}) {
      SCOPED_TRACE(dt);
      Vec3<double> x{r0, 0, 0}, v = vel, xb = x, vb = v;
      detail::kepler_drift_bracketed(mu, dt, xb, vb);
      bool done = false;
      detail::kepler_drift_short<double>(
          1, dt, [&](std::size_t) { return mu; }, x.data(), v.data(), &done);
      ASSERT_TRUE(done);
      EXPECT_LT(distance(x, xb), 16 * kEps * (r0 + std::fabs(dt) * norm3(vel)));
      EXPECT_LT(distance(v, vb), 16 * kEps * norm3(vel));
    }
    Vec3<double> x{r0, 0, 0}, v = vel;
    bool done = true;
    detail::kepler_drift_short<double>(
        1, 0.2, [&](std::size_t) { return mu; }, x.data(), v.data(), &done);
    EXPECT_FALSE(done);
    EXPECT_EQ(x, (Vec3<double>{r0, 0, 0}));
    EXPECT_EQ(v, vel);
  }
}
