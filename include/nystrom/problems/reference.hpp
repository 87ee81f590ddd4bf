// Reference solutions that measure an integrator alone: the exact flow of the initial state as it was
// rounded to the working precision, evaluated in at least quad-double at the exact end time.
//
// A run in double starts from (1 + e, 0), (0, sqrt((1 - e)/(1 + e))) rounded to double, not from the
// nominal orbit of KeplerProblem::exact; the two orbits part by about 1e-16 relative in their elements,
// which grows to 1e-14 in position over 100 periods (the period differs). The analytic solution
// evaluated in double adds several ulps more. Both would be charged to the integrator. Here
//   * the initial state is taken as it is (every double, long double, float128 and double-double is
//     exactly a quad-double);
//   * the end time is the integrator's own: h n for n fixed steps of the (rounded) step h, computed in
//     the reference type, or the end of the span the adaptive engines land on exactly;
//   * the orbit of that state is propagated by the f and g functions of the eccentric-anomaly
//     difference (Danby, "Fundamentals of Celestial Mechanics", 2nd ed., 1988, sec. 6.8), Kepler's
//     equation solved by safeguarded Newton iteration, all in quad-double (about 62 digits), or in MPFR
//     at the working precision plus 64 bits (at least 256) for mpfr_real.
// The error of the reference is then below 1e-50: a result that is the exact solution rounded to double
// scores its own rounding, about 1e-16.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <type_traits>

#include "nystrom/core/extended.hpp"
#include "nystrom/core/state.hpp"

namespace nystrom {

namespace detail {

/// The type a reference for working type T is computed in: quad-double, or MPFR for MPFR runs.
template <class T>
using reference_scalar_t = std::conditional_t<std::is_same_v<T, mpfr_real>, mpfr_real, quad_double>;

/// A working value, exactly, in the reference type.
inline quad_double to_reference(double x) { return quad_double(x); }
inline quad_double to_reference(long double x) { return quad_double(x); }
inline quad_double to_reference(const double_double& x) { return quad_double(x.x[0], x.x[1], 0.0, 0.0); }
inline quad_double to_reference(const quad_double& x) { return x; }
inline quad_double to_reference(const float128& x) {
  // three doubles, each the nearest to what remains: exact for a 113-bit significand
  const __float128 v = x.backend().value();
  const double d0 = static_cast<double>(v);
  const __float128 r1 = v - d0;
  const double d1 = static_cast<double>(r1);
  const double d2 = static_cast<double>(r1 - d1);
  return quad_double(d0, d1, d2, 0.0);
}
inline mpfr_real to_reference(const mpfr_real& x) { return x; }  // keeps its precision (exact)

/// Runs fn() with the precision the reference of working type T is computed in: for MPFR, the working
/// precision plus 64 bits and at least 256 (MPFR values keep their own precision, so the working values
/// enter exactly and every operation is carried at the larger one).
template <class T, class Fn>
auto with_reference_precision(Fn&& fn) {
  if constexpr (std::is_same_v<T, mpfr_real>) {
    const MpfrPrecision scope(std::max<long>(MpfrPrecision::effective() + 64, 256));
    return fn();
  } else {
    return fn();
  }
}

}  // namespace detail

/// The exact Kepler flow (mu = 1) of the planar state (q0, v0) over time t, in real type R: the f and g
/// functions of the eccentric-anomaly difference x, which solves
///     n t = x - (1 - r0/a) sin x + (q0.v0 / sqrt(a)) (1 - cos x),   1/a = 2/r0 - |v0|^2,  n = a^(-3/2).
/// Throws std::invalid_argument for a state that is not on a bound orbit.
template <class R>
State<std::array<R, 2>> kepler_flow(const std::array<R, 2>& q0, const std::array<R, 2>& v0, const R& t) {
  using std::abs;
  using std::acos;
  using std::cos;
  using std::floor;
  using std::sin;
  using std::sqrt;
  const R r0 = sqrt(q0[0] * q0[0] + q0[1] * q0[1]);
  const R sigma = q0[0] * v0[0] + q0[1] * v0[1];
  const R alpha = R(2) / r0 - (v0[0] * v0[0] + v0[1] * v0[1]);  // 1/a
  if (!(alpha > R(0)) || !(r0 > R(0))) throw std::invalid_argument("kepler_flow: the state is not on a bound orbit");
  const R a = R(1) / alpha, sa = sqrt(a), n = alpha * sqrt(alpha);
  const R ec = R(1) - r0 * alpha;  // e cos E0
  const R es = sigma / sa;         // e sin E0
  const R pi = acos(R(-1)), two_pi = R(2) * pi;
  const R mean = n * t;
  const R k = floor((mean + pi) / two_pi);
  const R m = mean - k * two_pi;  // in [-pi, pi)
  // F(x) = x - e sin(x + E0) + e sin E0 - m is increasing (F' = r/a > 0) with its root in [m - 2, m + 2]
  R lo = m - R(2), hi = m + R(2), x = m;
  // Newton converges quadratically: one iteration after a step below sqrt(epsilon) reaches the rounding
  const R tiny = R(64) * epsilon_of<R>(), root = sqrt(epsilon_of<R>());
  bool last = false;
  for (int it = 0; it < 500; ++it) {
    const R sx = sin(x), cx = cos(x);
    const R f = x - ec * sx + es * (R(1) - cx) - m;
    if (f > R(0))
      hi = x;
    else
      lo = x;
    if (f == R(0)) break;
    const R d = f / (R(1) - ec * cx + es * sx);
    R next = x - d;
    if (!(next >= lo && next <= hi)) next = (lo + hi) / R(2);  // Newton left the bracket: bisect
    const R step = abs(next - x);
    x = next;
    if (last || step <= tiny * (R(1) + abs(x)) || hi - lo <= tiny) break;
    last = step <= root * (R(1) + abs(x));
  }
  const R c = cos(x), s = sin(x);
  const R r = a + (r0 - a) * c + sigma * sa * s;
  const R f = R(1) - a / r0 * (R(1) - c);
  const R g = (t - k * two_pi / n) - (x - s) / n;
  const R fdot = -sa * s / (r * r0);
  const R gdot = R(1) - a / r * (R(1) - c);
  return {{f * q0[0] + g * v0[0], f * q0[1] + g * v0[1]}, {fdot * q0[0] + gdot * v0[0], fdot * q0[1] + gdot * v0[1]}};
}

/// Errors of a final state against a reference, in double.
struct ReferenceErrors {
  double position = 0;  // |q - q_ref|
  double velocity = 0;  // |v - v_ref|
  double energy = 0;    // |E(s) - E(s0)| / |E(s0)| (Kepler: E = |v|^2/2 - 1/|q|; harmonic: (q^2 + v^2)/2)
};

/// The Kepler errors of final state s after n steps of size h from s0 (an adaptive run that ended on t_end:
/// h = t_end, n = 1), against the exact orbit of s0 at time h n, everything in the reference type.
template <class T>
ReferenceErrors kepler_reference_errors(const State<std::array<T, 2>>& s0, const State<std::array<T, 2>>& s, const T& h,
                                        long n = 1) {
  return detail::with_reference_precision<T>([&] {
    using R = detail::reference_scalar_t<T>;
    using std::abs;
    using std::sqrt;
    using detail::to_reference;
    const std::array<R, 2> q0{to_reference(s0.q[0]), to_reference(s0.q[1])};
    const std::array<R, 2> v0{to_reference(s0.v[0]), to_reference(s0.v[1])};
    const std::array<R, 2> q{to_reference(s.q[0]), to_reference(s.q[1])};
    const std::array<R, 2> v{to_reference(s.v[0]), to_reference(s.v[1])};
    const R t = to_reference(h) * R(n);
    const auto ex = kepler_flow<R>(q0, v0, t);
    const auto energy = [](const std::array<R, 2>& x, const std::array<R, 2>& u) {
      return (u[0] * u[0] + u[1] * u[1]) / R(2) - R(1) / sqrt(x[0] * x[0] + x[1] * x[1]);
    };
    const auto dist = [](const std::array<R, 2>& x, const std::array<R, 2>& y) {
      const R dx = x[0] - y[0], dy = x[1] - y[1];
      return as_double(sqrt(dx * dx + dy * dy));
    };
    const R e0 = energy(q0, v0);
    ReferenceErrors out;
    out.position = dist(q, ex.q);
    out.velocity = dist(v, ex.v);
    out.energy = as_double(abs((energy(q, v) - e0) / e0));
    return out;
  });
}

/// The harmonic oscillator q'' = -q (one dimension): errors of s after n steps of size h from s0 against
/// q0 cos t + v0 sin t in the reference type.
template <class T>
ReferenceErrors harmonic_reference_errors(const State<std::array<T, 1>>& s0, const State<std::array<T, 1>>& s,
                                          const T& h, long n = 1) {
  return detail::with_reference_precision<T>([&] {
    using R = detail::reference_scalar_t<T>;
    using detail::to_reference;
    using std::abs;
    using std::cos;
    using std::sin;
    const R q0 = to_reference(s0.q[0]), v0 = to_reference(s0.v[0]);
    const R q = to_reference(s.q[0]), v = to_reference(s.v[0]);
    const R t = to_reference(h) * R(n);
    const R c = cos(t), sn = sin(t);
    const R e0 = (q0 * q0 + v0 * v0) / R(2);
    ReferenceErrors out;
    out.position = as_double(abs(q - (q0 * c + v0 * sn)));
    out.velocity = as_double(abs(v - (v0 * c - q0 * sn)));
    out.energy = as_double(abs(((q * q + v * v) / R(2) - e0) / e0));
    return out;
  });
}

}  // namespace nystrom
