// Exactly solvable flows for forces that depend on the velocity in a structured way, as operator flows
// (operators/flows.hpp): every real splitting and multi-product method of the catalog runs over them and keeps
// its order. In each family the "drift" A carries the whole velocity dependence and is solved exactly; the
// "kick" B is a force of the position alone (and, for DampedFlows, of the time), v <- v + h a(q).
//
//   RotatingFrameFlows  q'' = -2 Omega x v - Omega x (Omega x q) - grad U(q): a rotating frame. In the canonical
//                       variables p = v + Omega x q, H = |p|^2/2 - Omega.(q x p) + U(q). A = |p|^2/2 - Omega.(q x p)
//                       is free motion seen from the rotating frame: q(t) = R(-Omega t)(q + t p), p(t) =
//                       R(-Omega t) p, R(phi) the rotation by |phi| about phi. B = U(q) is the kick p <- p - h grad U,
//                       the same kick of v (q does not move). Symplectic; the Jacobi integral
//                       H = |v|^2/2 - |Omega x q|^2/2 + U(q) is conserved.
//   MagneticFlows       q'' = v x b + a(q), b = (charge/mass) B a uniform magnetic field, a(q) = (charge/mass) E(q)
//                       (or any force of the position). A is the gyration: v(t) = R(-b t) v, the position on the
//                       helix q(t) = q + n (n.v) t + v_perp sin(w t)/w - (n x v)(1 - cos(w t))/w, w = |b|, n = b/w.
//                       Symplectic in the canonical p = v + (b x q)/2; with a = -grad phi the energy
//                       |v|^2/2 + phi(q) is conserved.
//   DampedFlows         q'' = -gamma v + a(t, q): linear friction. A is q' = v, v' = -gamma v, t' = 1, exactly
//                       v(t) = e^{-gamma t} v, q(t) = q + v (1 - e^{-gamma t})/gamma; B is the kick v <- v + h a(t, q).
//                       The state carries the time (its last component). A splitting is conformally symplectic
//                       with the exact rate: the symplectic form shrinks by e^{-gamma h} per step, as the
//                       solution's does, since the drift coefficients sum to 1.
//
// In each family A is at most quadratic in the momenta and B a function of the positions (and time), so
// [B,[B,[A,B]]] = 0: the splittings designed for q'' = a(q) keep their order (OperatorStructure::rkn). Every
// flow is exact for a negative step too (DampedFlows then grows the velocity by e^{gamma |h|}, as the exact
// backward solution does), so methods with negative coefficients apply and both time directions work. Complex
// coefficients are refused: a real (q, v) has no complex time.
//
// The states are std::vector<R>: (q, v) with 3 components each for the rotating frame and the magnetic field
// (planar problems have z = 0), (q, v, t) with d components each and the time for friction.
#pragma once

#include <array>
#include <cmath>
#include <complex>
#include <cstddef>
#include <functional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace nystrom::velocity {

template <class R>
using Vec3 = std::array<R, 3>;

namespace detail {

template <class R>
Vec3<R> cross(const Vec3<R>& a, const Vec3<R>& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

template <class R>
R dot(const Vec3<R>& a, const Vec3<R>& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

template <class R>
R norm(const Vec3<R>& a) {
  using std::sqrt;
  return sqrt(dot(a, a));
}

template <class R>
Vec3<R> load(const std::vector<R>& s, std::size_t at) {
  return {s[at], s[at + 1], s[at + 2]};
}

template <class R>
void store(std::vector<R>& s, std::size_t at, const Vec3<R>& x) {
  s[at] = x[0];
  s[at + 1] = x[1];
  s[at + 2] = x[2];
}

/// The real part of a sub-step's coefficient; a complex one is an error.
template <class R>
R real_step(std::complex<R> z, const char* what) {
  if (z.imag() != 0)
    throw std::invalid_argument(std::string("a complex coefficient has no meaning for ") + what +
                                " of a real state (use a method with real coefficients)");
  return z.real();
}

/// x rotated about the unit axis n by the angle whose sine is s and whose 1 - cosine is omc (Rodrigues).
template <class R>
Vec3<R> rotate(const Vec3<R>& x, const Vec3<R>& n, R s, R omc) {
  const Vec3<R> nx = cross(n, x);
  const R nd = dot(n, x);
  Vec3<R> r;
  for (int i = 0; i < 3; ++i) r[i] = x[i] - omc * (x[i] - n[i] * nd) + s * nx[i];
  return r;
}

/// The vector operations every family shares (assign, scale, axpy over std::vector<R>).
template <class R>
struct VectorOps {
  using state_type = std::vector<R>;
  using real_type = R;
  void assign(state_type& d, const state_type& s) { d = s; }
  void scale(state_type& s, R r) {
    for (auto& x : s) x *= r;
  }
  void axpy(state_type& d, R r, const state_type& s) {
    if (d.size() != s.size()) d.assign(s.size(), R(0));
    for (std::size_t i = 0; i < s.size(); ++i) d[i] += r * s[i];
  }
};

}  // namespace detail

/// The gradient of a potential, or a force, of the position: out <- f(q) (3 components).
template <class R>
using Field3 = std::function<void(const Vec3<R>& q, Vec3<R>& out)>;

/// A rotating frame with angular velocity Omega and a potential U (its gradient), state (q, v), 6 components.
template <class R>
class RotatingFrameFlows : public detail::VectorOps<R> {
 public:
  using state_type = std::vector<R>;
  using real_type = R;

  RotatingFrameFlows(const Vec3<R>& omega, Field3<R> gradient) : omega_(omega), grad_(std::move(gradient)) {
    using std::isfinite;
    for (R x : omega_)
      if (!isfinite(x)) throw std::invalid_argument("the angular velocity must be finite");
    if (!grad_) throw std::invalid_argument("the rotating frame needs the gradient of its potential");
    w_ = detail::norm(omega_);
    if (w_ > 0)
      for (int i = 0; i < 3; ++i) axis_[i] = omega_[i] / w_;
  }

  const Vec3<R>& omega() const { return omega_; }

  /// Free motion seen from the rotating frame over the time t = z.
  void apply_a(state_type& s, std::complex<R> z) {
    using std::sin;
    const R t = detail::real_step(z, "the rotating-frame drift");
    const Vec3<R> q = detail::load(s, 0);
    const Vec3<R> oq = detail::cross(omega_, q);
    Vec3<R> p, x;
    for (int i = 0; i < 3; ++i) {
      p[i] = s[3 + i] + oq[i];
      x[i] = q[i] + t * p[i];
    }
    if (w_ > 0) {
      const R a = -w_ * t, sh = sin(a / 2);
      const R sn = sin(a), omc = 2 * sh * sh;
      x = detail::rotate(x, axis_, sn, omc);
      p = detail::rotate(p, axis_, sn, omc);
    }
    const Vec3<R> ox = detail::cross(omega_, x);
    for (int i = 0; i < 3; ++i) {
      s[i] = x[i];
      s[3 + i] = p[i] - ox[i];
    }
    ++drifts_;
  }

  /// The kick v <- v - z grad U(q).
  void apply_b(state_type& s, std::complex<R> z) {
    const R t = detail::real_step(z, "a kick");
    grad_(detail::load(s, 0), g_);
    for (int i = 0; i < 3; ++i) s[3 + i] -= t * g_[i];
    ++kicks_;
  }

  long drifts() const { return drifts_; }
  long kicks() const { return kicks_; }  // force evaluations: one per kick

 private:
  Vec3<R> omega_, axis_{};
  R w_ = 0;
  Field3<R> grad_;
  Vec3<R> g_{};
  long drifts_ = 0, kicks_ = 0;
};

/// A charged particle in a uniform magnetic field b = (charge/mass) B and a force a(q) of the position, state
/// (q, v), 6 components.
template <class R>
class MagneticFlows : public detail::VectorOps<R> {
 public:
  using state_type = std::vector<R>;
  using real_type = R;

  MagneticFlows(const Vec3<R>& b, Field3<R> force) : b_(b), force_(std::move(force)) {
    using std::isfinite;
    for (R x : b_)
      if (!isfinite(x)) throw std::invalid_argument("the magnetic field must be finite");
    w_ = detail::norm(b_);
    if (w_ > 0)
      for (int i = 0; i < 3; ++i) axis_[i] = b_[i] / w_;
  }

  const Vec3<R>& field() const { return b_; }

  /// The gyration over the time t = z: v turns by -|b| t about b, q moves on the helix.
  void apply_a(state_type& s, std::complex<R> z) {
    using std::sin;
    const R t = detail::real_step(z, "the gyration");
    Vec3<R> q = detail::load(s, 0);
    const Vec3<R> v = detail::load(s, 3);
    if (w_ == 0) {
      for (int i = 0; i < 3; ++i) q[i] += t * v[i];
      detail::store(s, 0, q);
      ++drifts_;
      return;
    }
    const R a = -w_ * t, sh = sin(a / 2);
    const R sn = sin(a), omc = 2 * sh * sh;  // sin(a), 1 - cos(a)
    const R par = detail::dot(axis_, v);
    const Vec3<R> nv = detail::cross(axis_, v);
    // q + n (n.v) t + v_perp sin(w t)/w - (n x v)(1 - cos(w t))/w, with sin(w t) = -sn, 1 - cos(w t) = omc
    for (int i = 0; i < 3; ++i) q[i] += axis_[i] * par * t + (-(v[i] - axis_[i] * par) * sn - nv[i] * omc) / w_;
    detail::store(s, 0, q);
    detail::store(s, 3, detail::rotate(v, axis_, sn, omc));
    ++drifts_;
  }

  /// The kick v <- v + z a(q) (no force: nothing).
  void apply_b(state_type& s, std::complex<R> z) {
    const R t = detail::real_step(z, "a kick");
    ++kicks_;
    if (!force_) return;
    force_(detail::load(s, 0), a_);
    for (int i = 0; i < 3; ++i) s[3 + i] += t * a_[i];
  }

  long drifts() const { return drifts_; }
  long kicks() const { return kicks_; }

 private:
  Vec3<R> b_, axis_{};
  R w_ = 0;
  Field3<R> force_;
  Vec3<R> a_{};
  long drifts_ = 0, kicks_ = 0;
};

/// A force of the time and the position in d dimensions: out <- a(t, q) (out has d components).
template <class R>
using TimeForce = std::function<void(R t, const std::vector<R>& q, std::vector<R>& out)>;

/// Linear friction -gamma v and a force a(t, q) in d dimensions, state (q, v, t), 2 d + 1 components.
template <class R>
class DampedFlows : public detail::VectorOps<R> {
 public:
  using state_type = std::vector<R>;
  using real_type = R;

  DampedFlows(std::size_t dims, R gamma, TimeForce<R> force) : d_(dims), gamma_(gamma), force_(std::move(force)) {
    using std::isfinite;
    if (d_ == 0) throw std::invalid_argument("the damped system needs at least one dimension");
    if (!isfinite(gamma_)) throw std::invalid_argument("the friction coefficient must be finite");
    q_.resize(d_);
    a_.resize(d_);
  }

  std::size_t dims() const { return d_; }
  R gamma() const { return gamma_; }

  /// q' = v, v' = -gamma v, t' = 1 over the time z.
  void apply_a(state_type& s, std::complex<R> z) {
    using std::exp;
    using std::expm1;
    const R t = detail::real_step(z, "the friction flow");
    const R x = -gamma_ * t;
    const R shrink = exp(x);
    const R travel = gamma_ == 0 ? t : -expm1(x) / gamma_;  // (1 - e^{-gamma t}) / gamma
    for (std::size_t i = 0; i < d_; ++i) {
      s[i] += travel * s[d_ + i];
      s[d_ + i] *= shrink;
    }
    s[2 * d_] += t;
    ++drifts_;
  }

  /// The kick v <- v + z a(t, q).
  void apply_b(state_type& s, std::complex<R> z) {
    const R t = detail::real_step(z, "a kick");
    ++kicks_;
    if (!force_) return;
    for (std::size_t i = 0; i < d_; ++i) q_[i] = s[i];
    force_(s[2 * d_], q_, a_);
    for (std::size_t i = 0; i < d_; ++i) s[d_ + i] += t * a_[i];
  }

  long drifts() const { return drifts_; }
  long kicks() const { return kicks_; }

 private:
  std::size_t d_;
  R gamma_;
  TimeForce<R> force_;
  std::vector<R> q_, a_;
  long drifts_ = 0, kicks_ = 0;
};

}  // namespace nystrom::velocity
