// A planetary system: a central body and planets under their mutual gravitation, in any units (G is the
// user's; gauss_G gives astronomical units, days and solar masses), with Jacobi coordinates, energy and
// angular momentum, and Hairer's outer solar system as a built-in example.
//
// Jacobi coordinates (Wisdom & Holman, AJ 102 (1991) 1528): with the interior masses eta_i = m_0 + ... + m_i,
// the coordinate of planet i is its position relative to the centre of mass of bodies 0..i-1,
// x'_i = x_i - X_{i-1}, and x'_0 is the centre of mass of the whole system; velocities likewise. The Jacobi
// masses m'_i = m_i eta_{i-1} / eta_i make the kinetic energy diagonal, sum m_i v_i^2 = sum m'_i v'_i^2.
//
// The Jacobi state is one flat vector: the N positions x'_0..x'_{N-1} (3 components each), then the N
// velocities.
#pragma once

#include <array>
#include <cmath>
#include <complex>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "nystrom/planetary/kepler_drift.hpp"

namespace nystrom::planetary {

/// The gravitational constant in astronomical units, days and solar masses: Gauss's constant squared,
/// k^2 = 0.01720209895^2, as Hairer, Lubich & Wanner use it (GNI, 2nd ed., Springer 2006, sec. I.2.4).
inline constexpr double gauss_G = 2.95912208286e-4;

template <class R>
struct PlanetarySystem {
  R G = 1;
  std::vector<R> mass;        // mass[0]: the central body
  std::vector<Vec3<R>> x, v;  // positions and velocities in an inertial frame
  std::vector<std::string> names;

  std::size_t size() const { return mass.size(); }

  /// Throws std::invalid_argument unless G and the masses are positive, there is a central body and at
  /// least one planet, the arrays agree in size and every number is finite.
  void validate() const {
    auto finite = [](const R& a) { return std::isfinite(static_cast<double>(a)); };
    if (!(G > 0) || !finite(G)) throw std::invalid_argument("G must be positive and finite");
    if (mass.size() < 2) throw std::invalid_argument("a planetary system needs a central body and a planet");
    if (x.size() != mass.size() || v.size() != mass.size())
      throw std::invalid_argument("masses, positions and velocities differ in number");
    for (std::size_t i = 0; i < mass.size(); ++i) {
      if (!(mass[i] > 0) || !finite(mass[i])) throw std::invalid_argument("every mass must be positive and finite");
      for (int k = 0; k < 3; ++k)
        if (!finite(x[i][k]) || !finite(v[i][k]))
          throw std::invalid_argument("positions and velocities must be finite");
    }
  }
};

/// Gravitational parameters of the Kepler problems of the Jacobi coordinates: mu_i = G m_0 eta_i / eta_{i-1}
/// (mu_0 unused), so that H_Kepler = sum_i m'_i (v'_i^2 / 2 - mu_i / r'_i) (Wisdom & Holman 1991).
template <class R>
std::vector<R> jacobi_kepler_mu(R G, const std::vector<R>& mass) {
  std::vector<R> mu(mass.size(), R(0));
  R eta = mass[0];
  for (std::size_t i = 1; i < mass.size(); ++i) {
    const R next = eta + mass[i];
    mu[i] = G * mass[0] * next / eta;
    eta = next;
  }
  return mu;
}

namespace detail {

/// Jacobi vectors of N inertial vectors (positions, velocities or accelerations; the same linear map).
template <class R, class In, class Out>
void inertial_to_jacobi(const std::vector<R>& mass, std::size_t n, In in, Out out) {
  R eta = mass[0];
  Vec3<R> com = in(0);  // eta-weighted sum of bodies 0..i-1, divided by eta
  for (std::size_t i = 1; i < n; ++i) {
    const Vec3<R> xi = in(i);
    Vec3<R> j;
    for (int k = 0; k < 3; ++k) j[k] = xi[k] - com[k];
    out(i, j);
    const R next = eta + mass[i];
    for (int k = 0; k < 3; ++k) com[k] += mass[i] / next * j[k];
    eta = next;
  }
  out(0, com);
}

/// The interior masses eta_i = m_0 + ... + m_i.
template <class R>
std::vector<R> interior_masses(const std::vector<R>& mass) {
  std::vector<R> eta(mass.size());
  eta[0] = mass[0];
  for (std::size_t i = 1; i < mass.size(); ++i) eta[i] = eta[i - 1] + mass[i];
  return eta;
}

/// The inverse map: inertial vectors from Jacobi ones, with the interior masses eta given (no allocation).
template <class R, class In, class Out>
void jacobi_to_inertial(const std::vector<R>& mass, const std::vector<R>& eta, std::size_t n, In in, Out out) {
  Vec3<R> com = in(0);  // centre of mass of bodies 0..i
  for (std::size_t i = n - 1; i >= 1; --i) {
    const Vec3<R> j = in(i);
    for (int k = 0; k < 3; ++k) com[k] -= mass[i] / eta[i] * j[k];
    Vec3<R> xi;
    for (int k = 0; k < 3; ++k) xi[k] = com[k] + j[k];
    out(i, xi);
  }
  out(0, com);
}

/// The inverse map: inertial vectors from Jacobi ones.
template <class R, class In, class Out>
void jacobi_to_inertial(const std::vector<R>& mass, std::size_t n, In in, Out out) {
  jacobi_to_inertial<R>(mass, interior_masses(mass), n, in, out);
}

/// The time of a planetary flow's sub-step: its coefficient times h must be real (what names the flow).
template <class R>
R real_step(std::complex<R> z, const char* what) {
  if (z.imag() != 0)
    throw std::invalid_argument(std::string(what) +
                                " takes a real time: methods with complex coefficients do not apply");
  return z.real();
}

/// The drift of both Wisdom-Holman splittings over a state s (x of n bodies, then v; 3 components each): body 0
/// (the centre of mass, or the barycentre) moves freely, body i >= 1 follows its Kepler orbit of parameter mu(i).
/// With carries (laid out as s), every increment is added with compensated summation.
template <class R, class Mu>
void kepler_drift_bodies(std::vector<R>& s, std::size_t n, R dt, Mu mu, R* carry = nullptr) {
  R* x = s.data();
  R* v = s.data() + 3 * n;
  for (int k = 0; k < 3; ++k)
    add_increment(x[k], carry ? dt * v[k] + dt * carry[3 * n + k] : dt * v[k], carry ? carry + k : nullptr);
  kepler_drift_many<R>(
      n - 1, dt, [&](std::size_t k) { return mu(k + 1); }, x + 3, v + 3, carry ? carry + 3 : nullptr,
      carry ? carry + 3 * n + 3 : nullptr);
}

}  // namespace detail

/// The flat Jacobi state of a system (see the top of this file).
template <class R>
std::vector<R> to_jacobi(const PlanetarySystem<R>& sys) {
  const std::size_t n = sys.size();
  std::vector<R> s(6 * n);
  for (std::size_t part = 0; part < 2; ++part) {
    const auto& src = part == 0 ? sys.x : sys.v;
    R* dst = s.data() + 3 * n * part;
    detail::inertial_to_jacobi<R>(
        sys.mass, n, [&](std::size_t i) { return src[i]; },
        [&](std::size_t i, const Vec3<R>& j) {
          for (int k = 0; k < 3; ++k) dst[3 * i + k] = j[k];
        });
  }
  return s;
}

/// Inertial positions and velocities of a Jacobi state.
template <class R>
void from_jacobi(const std::vector<R>& mass, const std::vector<R>& s, std::vector<Vec3<R>>& x,
                 std::vector<Vec3<R>>& v) {
  const std::size_t n = mass.size();
  x.resize(n);
  v.resize(n);
  for (std::size_t part = 0; part < 2; ++part) {
    auto& dst = part == 0 ? x : v;
    const R* src = s.data() + 3 * n * part;
    detail::jacobi_to_inertial<R>(
        mass, n,
        [&](std::size_t i) {
          return Vec3<R>{src[3 * i], src[3 * i + 1], src[3 * i + 2]};
        },
        [&](std::size_t i, const Vec3<R>& xi) { dst[i] = xi; });
  }
}

/// Total energy sum m v^2 / 2 - sum_{i<j} G m_i m_j / r_ij.
template <class R>
R energy(R G, const std::vector<R>& mass, const std::vector<Vec3<R>>& x, const std::vector<Vec3<R>>& v) {
  using std::sqrt;
  R kin = 0, pot = 0;
  for (std::size_t i = 0; i < mass.size(); ++i) {
    kin += mass[i] * (v[i][0] * v[i][0] + v[i][1] * v[i][1] + v[i][2] * v[i][2]) / 2;
    for (std::size_t j = i + 1; j < mass.size(); ++j) {
      const R dx = x[j][0] - x[i][0], dy = x[j][1] - x[i][1], dz = x[j][2] - x[i][2];
      pot -= G * mass[i] * mass[j] / sqrt(dx * dx + dy * dy + dz * dz);
    }
  }
  return kin + pot;
}

/// Total angular momentum sum m x cross v.
template <class R>
Vec3<R> angular_momentum(const std::vector<R>& mass, const std::vector<Vec3<R>>& x, const std::vector<Vec3<R>>& v) {
  Vec3<R> l{0, 0, 0};
  for (std::size_t i = 0; i < mass.size(); ++i) {
    l[0] += mass[i] * (x[i][1] * v[i][2] - x[i][2] * v[i][1]);
    l[1] += mass[i] * (x[i][2] * v[i][0] - x[i][0] * v[i][2]);
    l[2] += mass[i] * (x[i][0] * v[i][1] - x[i][1] * v[i][0]);
  }
  return l;
}

/// Newtonian accelerations a_i = sum_{j != i} G m_j (x_j - x_i) / r_ij^3.
template <class R>
void accelerations(R G, const std::vector<R>& mass, const std::vector<Vec3<R>>& x, std::vector<Vec3<R>>& a) {
  using std::sqrt;
  const std::size_t n = mass.size();
  a.assign(n, Vec3<R>{0, 0, 0});
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j) {
      const Vec3<R> d{x[j][0] - x[i][0], x[j][1] - x[i][1], x[j][2] - x[i][2]};
      const R r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
      const R inv3 = G / (r2 * sqrt(r2));
      for (int k = 0; k < 3; ++k) {
        a[i][k] += mass[j] * inv3 * d[k];
        a[j][k] -= mass[i] * inv3 * d[k];
      }
    }
}

/// The same accelerations on the flat Cartesian state of the catalog's direct methods (body i at 3i, 3i + 1,
/// 3i + 2): the same operations in the same order as accelerations(), so bitwise the same values.
template <class R>
void flat_accelerations(R G, const std::vector<R>& mass, const std::vector<R>& q, std::vector<R>& a) {
  using std::sqrt;
  const std::size_t n = mass.size();
  a.assign(3 * n, R(0));
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j) {
      const R d[3] = {q[3 * j] - q[3 * i], q[3 * j + 1] - q[3 * i + 1], q[3 * j + 2] - q[3 * i + 2]};
      const R r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
      const R inv3 = G / (r2 * sqrt(r2));
      for (int k = 0; k < 3; ++k) {
        a[3 * i + k] += mass[j] * inv3 * d[k];
        a[3 * j + k] -= mass[i] * inv3 * d[k];
      }
    }
}

/// A system's Newtonian force as a force functor of solve() and the integrators, on the flat state (flatten()).
/// It keeps no scratch space, so concurrent calls (the products of a multi-product expansion) are safe.
template <class R>
struct CartesianForce {
  R G;
  std::vector<R> mass;
  explicit CartesianForce(const PlanetarySystem<R>& s) : G(s.G), mass(s.mass) {}
  void operator()(const std::vector<R>& q, std::vector<R>& a) const { flat_accelerations(G, mass, q, a); }
};

/// Positions or velocities body by body as one flat vector, and back.
template <class R>
std::vector<R> flatten(const std::vector<Vec3<R>>& x) {
  std::vector<R> f(3 * x.size());
  for (std::size_t i = 0; i < x.size(); ++i)
    for (int k = 0; k < 3; ++k) f[3 * i + k] = x[i][k];
  return f;
}

template <class R>
void unflatten(const std::vector<R>& f, std::vector<Vec3<R>>& x) {
  x.resize(f.size() / 3);
  for (std::size_t i = 0; i < x.size(); ++i)
    for (int k = 0; k < 3; ++k) x[i][k] = f[3 * i + k];
}

/// The system in another real type (G, masses, positions and velocities converted one by one): a run in long double
/// from the very state a double run starts from, or back.
template <class To, class From>
PlanetarySystem<To> convert_system(const PlanetarySystem<From>& s) {
  PlanetarySystem<To> t;
  t.G = static_cast<To>(s.G);
  t.names = s.names;
  for (std::size_t i = 0; i < s.size(); ++i) {
    t.mass.push_back(static_cast<To>(s.mass[i]));
    t.x.push_back({static_cast<To>(s.x[i][0]), static_cast<To>(s.x[i][1]), static_cast<To>(s.x[i][2])});
    t.v.push_back({static_cast<To>(s.v[i][0]), static_cast<To>(s.v[i][1]), static_cast<To>(s.v[i][2])});
  }
  return t;
}

/// The position and the velocity of the centre of mass.
template <class R>
std::pair<Vec3<R>, Vec3<R>> centre_of_mass(const PlanetarySystem<R>& sys) {
  R m = 0;
  Vec3<R> X{0, 0, 0}, V{0, 0, 0};
  for (std::size_t i = 0; i < sys.size(); ++i) {
    m += sys.mass[i];
    for (int k = 0; k < 3; ++k) {
      X[k] += sys.mass[i] * sys.x[i][k];
      V[k] += sys.mass[i] * sys.v[i][k];
    }
  }
  for (int k = 0; k < 3; ++k) {
    X[k] /= m;
    V[k] /= m;
  }
  return {X, V};
}

/// The system in its centre-of-mass frame: the barycentre at rest at the origin. Long runs of a system whose
/// barycentre moves (Hairer's data below: about 2.5 AU per thousand years) need it in a direct method, whose
/// positions would otherwise grow with time and lose their digits in every difference x_j - x_i.
template <class R>
PlanetarySystem<R> barycentric(const PlanetarySystem<R>& sys) {
  const auto [X, V] = centre_of_mass(sys);
  PlanetarySystem<R> b = sys;
  for (std::size_t i = 0; i < sys.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      b.x[i][k] -= X[k];
      b.v[i][k] -= V[k];
    }
  return b;
}

/// Hairer's outer solar system (Hairer, Lubich & Wanner, Geometric Numerical Integration, 2nd ed., Springer
/// 2006, sec. I.2.4, Table 2.2): the Sun with the inner planets, Jupiter, Saturn, Uranus, Neptune and Pluto
/// in astronomical units, days and solar masses, G = gauss_G; heliocentric positions and velocities at the
/// initial epoch, used as inertial initial data.
template <class R>
PlanetarySystem<R> outer_solar_system() {
  PlanetarySystem<R> s;
  s.G = R(gauss_G);
  s.names = {"Sun", "Jupiter", "Saturn", "Uranus", "Neptune", "Pluto"};
  s.mass = {R(1.00000597682L),      R(0.000954786104043L),  R(0.000285583733151L),
            R(0.0000437273164546L), R(0.0000517759138449L), R(1) / R(1.3e8L)};
  s.x = {Vec3<R>{0, 0, 0},
         {R(-3.5023653L), R(-3.8169847L), R(-1.5507963L)},
         {R(9.0755314L), R(-3.0458353L), R(-1.6483708L)},
         {R(8.3101420L), R(-16.2901086L), R(-7.2521278L)},
         {R(11.4707666L), R(-25.7294829L), R(-10.8169456L)},
         {R(-15.5387357L), R(-25.2225594L), R(-3.1902382L)}};
  s.v = {Vec3<R>{0, 0, 0},
         {R(0.00565429L), R(-0.00412490L), R(-0.00190589L)},
         {R(0.00168318L), R(0.00483525L), R(0.00192462L)},
         {R(0.00354178L), R(0.00137102L), R(0.00055029L)},
         {R(0.00288930L), R(0.00114527L), R(0.00039677L)},
         {R(0.00276725L), R(-0.00170702L), R(-0.00136504L)}};
  return s;
}

}  // namespace nystrom::planetary
