// Democratic heliocentric coordinates (M. J. Duncan, H. F. Levison and M. H. Lee, "A multiple time step
// symplectic algorithm for integrating close encounters", AJ 116 (1998) 2067): heliocentric positions
// Q_i = x_i - x_0 and barycentric velocities V_i = v_i - V_cm of the planets (i >= 1), the centre of mass
// (Q_0, V_0). With P_i = m_i V_i the Hamiltonian splits three ways,
//   H_Kepler      = sum_{i>=1} (P_i^2 / (2 m_i) - G m_0 m_i / |Q_i|)     (+ the free motion of the centre of mass),
//   H_interaction = -sum_{1<=i<j} G m_i m_j / |Q_i - Q_j|                 (a kick of the V_i),
//   H_Sun         = |sum_{i>=1} P_i|^2 / (2 m_0)                          (a jump: Q_i += dt sum_j P_j / m_0),
// The flows here are A = the Kepler drifts (mu = G m_0 for every planet) and B(dt) = jump(dt/2) kick(dt)
// jump(dt/2), a symmetric second-order approximation of the flow of H_interaction + H_Sun with B(-dt) =
// B(dt)^{-1}, so that e^{hA/2} B(h) e^{hA/2} is a symmetric second-order map of H (the DLL98 map with the
// Kepler drift outermost) and every symmetric composition or multi-product expansion of it reaches its order.
// B is not a one-parameter group (B(a) B(b) != B(a + b)): only methods whose kicks never meet (schemes that begin
// and end with a drift, over the position-Verlet base) apply; the jump and the interaction do not commute, so
// the order conditions of splittings designed for [B,[B,[A,B]]] = 0 do not hold either.
#pragma once

#include <complex>
#include <cstddef>
#include <stdexcept>
#include <utility>
#include <vector>

#include "nystrom/planetary/kepler_drift.hpp"
#include "nystrom/planetary/system.hpp"

namespace nystrom::planetary {

/// The flat democratic heliocentric state of a system: (Q_0, Q_1, ..., V_0, V_1, ...), Q_0 and V_0 the centre
/// of mass.
template <class R>
std::vector<R> to_democratic(const PlanetarySystem<R>& sys) {
  const std::size_t n = sys.size();
  R M = 0;
  Vec3<R> xc{0, 0, 0}, vc{0, 0, 0};
  for (std::size_t i = 0; i < n; ++i) {
    M += sys.mass[i];
    for (int k = 0; k < 3; ++k) {
      xc[k] += sys.mass[i] * sys.x[i][k];
      vc[k] += sys.mass[i] * sys.v[i][k];
    }
  }
  std::vector<R> s(6 * n);
  R* q = s.data();
  R* v = s.data() + 3 * n;
  for (int k = 0; k < 3; ++k) {
    q[k] = xc[k] / M;
    v[k] = vc[k] / M;
  }
  for (std::size_t i = 1; i < n; ++i)
    for (int k = 0; k < 3; ++k) {
      q[3 * i + k] = sys.x[i][k] - sys.x[0][k];
      v[3 * i + k] = sys.v[i][k] - v[k];
    }
  return s;
}

/// Inertial positions and velocities of a democratic heliocentric state.
template <class R>
void from_democratic(const std::vector<R>& mass, const std::vector<R>& s, std::vector<Vec3<R>>& x,
                     std::vector<Vec3<R>>& v) {
  const std::size_t n = mass.size();
  x.resize(n);
  v.resize(n);
  const R* q = s.data();
  const R* w = s.data() + 3 * n;
  R M = 0;
  for (R m : mass) M += m;
  Vec3<R> mq{0, 0, 0}, mw{0, 0, 0};
  for (std::size_t i = 1; i < n; ++i)
    for (int k = 0; k < 3; ++k) {
      mq[k] += mass[i] * q[3 * i + k];
      mw[k] += mass[i] * w[3 * i + k];
    }
  for (int k = 0; k < 3; ++k) {
    x[0][k] = q[k] - mq[k] / M;        // the centre of mass is x_0 + sum m_i Q_i / M
    v[0][k] = w[k] - mw[k] / mass[0];  // barycentric momenta sum to zero: m_0 (v_0 - V_0) = -sum m_i V_i
  }
  for (std::size_t i = 1; i < n; ++i)
    for (int k = 0; k < 3; ++k) {
      x[i][k] = x[0][k] + q[3 * i + k];
      v[i][k] = w[k] + w[3 * i + k];
    }
}

/// The Kepler drifts (A) and the jump-kick-jump (B) of a planetary system over its flat democratic heliocentric
/// state (see the top of this file).
template <class R>
class DemocraticHeliocentricFlows {
 public:
  using state_type = std::vector<R>;
  using real_type = R;

  DemocraticHeliocentricFlows(R G, std::vector<R> mass) : G_(G), mass_(std::move(mass)) {}

  long kepler_drifts() const { return drifts_; }
  long kicks() const { return kicks_; }

  void apply_a(state_type& s, std::complex<R> z) {
    const R mu = G_ * mass_[0];
    detail::kepler_drift_bodies(s, mass_.size(), detail::real_step(z, "a Kepler drift"),
                                [mu](std::size_t) { return mu; });
    ++drifts_;
  }

  void apply_b(state_type& s, std::complex<R> z) {
    using std::sqrt;
    const R dt = detail::real_step(z, "an interaction kick");
    const std::size_t n = mass_.size();
    R* q = s.data();
    R* v = s.data() + 3 * n;
    jump(q, v, n, dt / 2);
    for (std::size_t i = 1; i < n; ++i)
      for (std::size_t j = i + 1; j < n; ++j) {
        const R dx = q[3 * j] - q[3 * i], dy = q[3 * j + 1] - q[3 * i + 1], dz = q[3 * j + 2] - q[3 * i + 2];
        const R r2 = dx * dx + dy * dy + dz * dz;
        const R k = dt * G_ / (r2 * sqrt(r2));
        v[3 * i] += k * mass_[j] * dx;
        v[3 * i + 1] += k * mass_[j] * dy;
        v[3 * i + 2] += k * mass_[j] * dz;
        v[3 * j] -= k * mass_[i] * dx;
        v[3 * j + 1] -= k * mass_[i] * dy;
        v[3 * j + 2] -= k * mass_[i] * dz;
      }
    jump(q, v, n, dt / 2);
    ++kicks_;
  }

  void assign(state_type& d, const state_type& s) { d = s; }
  void scale(state_type& s, R r) {
    for (R& a : s) a *= r;
  }
  void axpy(state_type& d, R r, const state_type& s) {
    for (std::size_t i = 0; i < d.size(); ++i) d[i] += r * s[i];
  }

 private:
  /// The flow of H_Sun: every heliocentric position moves with the Sun's barycentric velocity, reversed.
  void jump(R* q, const R* v, std::size_t n, R dt) const {
    Vec3<R> p{0, 0, 0};
    for (std::size_t i = 1; i < n; ++i)
      for (int k = 0; k < 3; ++k) p[k] += mass_[i] * v[3 * i + k];
    for (std::size_t i = 1; i < n; ++i)
      for (int k = 0; k < 3; ++k) q[3 * i + k] += dt * p[k] / mass_[0];
  }

  R G_;
  std::vector<R> mass_;
  long drifts_ = 0, kicks_ = 0;
};

}  // namespace nystrom::planetary
