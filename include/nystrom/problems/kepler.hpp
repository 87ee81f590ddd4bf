// The planar Kepler problem of Chin (2010), eqs (35)-(36), and its analytic solution.
//
//   a = -q / |q|^3,  q0 = (1+e, 0),  v0 = (0, sqrt((1-e)/(1+e))),  E = -1/2,  period 2 pi.
//
// The start is the apocentre on the +x axis and the motion is counter-clockwise; the pericentre
// lies on the -x axis, so the Laplace-Runge-Lenz vector is (-e, 0). The mean anomaly at time t is
// pi + t, and Kepler's equation M = E - e sin E is solved by Newton's method in the working type.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "nystrom/core/eft.hpp"
#include "nystrom/core/state.hpp"

namespace nystrom {

/// Force functor: works for any real or complex scalar (complex square root for complex q), on a
/// std::array<S, 2> or any container of two coordinates (std::vector<S>).
/// Real scalars form 1/r^3 by inv_r3 (core/scalar.hpp: S(1) / (r2 sqrt(r2)), so -inv_r3 is bitwise
/// S(-1) / (r2 r) in every correctly rounded type; double-double and quad-double have their own).
struct KeplerForce {
  template <class V, class S = typename V::value_type>
  void operator()(const V& q, V& a) const {
    const S r2 = q[0] * q[0] + q[1] * q[1];
    const S minv = [&] {
      if constexpr (is_complex_v<S>) {
        using std::sqrt;
        return S(-1) / (r2 * sqrt(r2));
      } else {
        return S(-inv_r3(r2));
      }
    }();
    a[0] = minv * q[0];
    a[1] = minv * q[1];
  }
};

/// The Kepler force with its own rounding error, for double and float: besides KeplerForce's force(q, a), the
/// compensated force(q, cq, a, alo) takes the position q + cq (cq its carry) and returns -(q + cq) / |q + cq|^3 as
/// a + alo, in double-word arithmetic from error-free transformations (core/eft.hpp; Dekker, Numer. Math. 18 (1971)
/// 224): relative error a few units of the working precision squared, where force(q, a) rounds at a few units of
/// it. The precise update of the adaptive RKN pairs and the compensated fixed-step splitting and multi-product runs use
/// it (engines/rkn.hpp, engines/splitting.hpp, engines/mpe.hpp; takes_carry_v).
struct CompensatedKeplerForce : KeplerForce {
  using KeplerForce::operator();
  template <class V, class S = typename V::value_type>
  requires std::is_floating_point_v<S>
  void operator()(const V& q, const V& cq, V& a, V& alo) const {
    using eft::fast_two_sum;
    using eft::two_prod;
    using eft::two_sum;
    // r^2 = |q + cq|^2 = r2 + r2l
    S e0, e1, e2;
    const S x2 = two_prod(q[0], q[0], e0), y2 = two_prod(q[1], q[1], e1);
    const S s = two_sum(x2, y2, e2);
    S r2l;
    const S r2 = fast_two_sum(s, (e0 + e1 + e2) + S(2) * (q[0] * cq[0] + q[1] * cq[1]), r2l);
    // m = 1 / r^3 = m0 + ml
    S ml;
    const S m0 = eft::dw_inv_r3(r2, r2l, ml);
    // a = -(q + cq) m
    for (std::size_t k = 0; k < 2; ++k) {
      S e;
      const S hi = two_prod(q[k], m0, e);
      S lo;
      a[k] = -fast_two_sum(hi, e + (q[k] * ml + cq[k] * m0), lo);
      alo[k] = -lo;
    }
  }
};

/// Kepler's equation M = E - e sin E, solved for E by Newton's method (starting at E = M + e sin M,
/// or pi for e > 0.8, which converges for all M and e < 1).
template <class T>
T eccentric_anomaly(const T& M, const T& e) {
  using std::abs;
  using std::acos;
  using std::cos;
  using std::floor;
  using std::sin;
  const T pi = acos(T(-1));
  // Reduce M to [-pi, pi].
  T m = M - T(2) * pi * floor((M + pi) / (T(2) * pi));
  T E = e > T(0.8) ? (m >= T(0) ? pi : -pi) : m + e * sin(m);
  for (int it = 0; it < 200; ++it) {
    const T f = E - e * sin(E) - m;
    const T d = f / (T(1) - e * cos(E));
    E -= d;
    if (abs(d) <= T(4) * epsilon_of<T>() * (T(1) + abs(E))) break;
  }
  return E + (M - m);
}

/// The Kepler problem at eccentricity e in scalar type T.
template <class T>
struct KeplerProblem {
  using vector_type = std::array<T, 2>;
  T e;

  explicit KeplerProblem(T ecc) : e(ecc) {
    if (!(ecc >= T(0)) || !(ecc < T(1))) throw std::invalid_argument("eccentricity must satisfy 0 <= e < 1");
  }

  KeplerForce force() const { return {}; }
  static T period() {
    using std::acos;
    return T(2) * acos(T(-1));
  }
  static T exact_energy() { return T(-1) / T(2); }

  State<vector_type> initial_state() const {
    using std::sqrt;
    return {{T(1) + e, T(0)}, {T(0), sqrt((T(1) - e) / (T(1) + e))}};
  }

  /// The analytic solution at time t.
  State<vector_type> exact(const T& t) const {
    using std::acos;
    using std::cos;
    using std::sin;
    using std::sqrt;
    const T pi = acos(T(-1));
    const T E = eccentric_anomaly<T>(pi + t, e);
    const T s = sqrt(T(1) - e * e);
    const T cE = cos(E), sE = sin(E);
    const T Edot = T(1) / (T(1) - e * cE);
    return {{e - cE, -s * sE}, {sE * Edot, -s * cE * Edot}};
  }
};

/// Energy |v|^2/2 - 1/|q|.
template <class T>
T kepler_energy(const State<std::array<T, 2>>& s) {
  using std::sqrt;
  return (s.v[0] * s.v[0] + s.v[1] * s.v[1]) / T(2) - T(1) / sqrt(s.q[0] * s.q[0] + s.q[1] * s.q[1]);
}

/// The Laplace-Runge-Lenz vector A = v x L - q/|q|, eq (37), in the plane.
template <class T>
std::array<T, 2> lrl_vector(const State<std::array<T, 2>>& s) {
  using std::sqrt;
  const T L = s.q[0] * s.v[1] - s.q[1] * s.v[0];
  const T r = sqrt(s.q[0] * s.q[0] + s.q[1] * s.q[1]);
  return {s.v[1] * L - s.q[0] / r, -s.v[0] * L - s.q[1] / r};
}

/// Signed angle from vector a to vector b, counter-clockwise positive, in (-pi, pi].
template <class T>
T signed_angle(const std::array<T, 2>& a, const std::array<T, 2>& b) {
  using std::atan2;
  return atan2(a[0] * b[1] - a[1] * b[0], a[0] * b[0] + a[1] * b[1]);
}

/// The harmonic oscillator q'' = -omega^2 q in d dimensions, with its exact solution.
struct HarmonicForce {
  double omega2 = 1.0;
  template <class V>
  void operator()(const V& q, V& a) const {
    using S = typename V::value_type;
    for (std::size_t i = 0; i < q.size(); ++i) a[i] = -S(omega2) * q[i];
  }
};

template <class T>
struct HarmonicProblem {
  using vector_type = std::array<T, 1>;
  HarmonicForce force() const { return {}; }
  State<vector_type> initial_state() const { return {{T(1)}, {T(0)}}; }
  State<vector_type> exact(const T& t) const {
    using std::cos;
    using std::sin;
    return {{cos(t)}, {-sin(t)}};
  }
  static T period() {
    using std::acos;
    return T(2) * acos(T(-1));
  }
};

}  // namespace nystrom
