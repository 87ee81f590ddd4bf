// One problem type per family of velocity-dependent forces with an exactly solvable flow (velocity/flows.hpp),
// and one solve() for each: a rotating frame (RotatingFrameProblem), a charged particle in a uniform magnetic
// field (MagneticProblem), linear friction (DampedProblem). Any real splitting or multi-product method of the
// catalog runs on them with fixed steps (operators/flow_methods.hpp); a negative dt integrates backward in time.
//
// Built-in instances (builtin_problem(); the CLI's `nystrom flows` and Python's nystrom.flows run them):
//   arenstorf  the restricted three-body problem in the rotating frame (Arenstorf's periodic orbit, initial
//              state and period from Hairer, Norsett & Wanner, Solving ODEs I, 2nd ed., Springer 1993, II.0);
//   helix      uniform B along z and a uniform E: the exact helix with the E x B drift;
//   penning    an ideal Penning trap: uniform B along z, the quadrupole E = kappa (x/2, y/2, -z) (exact solution
//              in closed form: the modified cyclotron, magnetron and axial motions);
//   damped     the damped driven oscillator q'' = -gamma q' - omega0^2 q + F cos(Omega t) (exact solution).
#pragma once

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <complex>
#include <cstddef>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "nystrom/core/error.hpp"
#include "nystrom/core/scalar.hpp"
#include "nystrom/operators/flow_methods.hpp"
#include "nystrom/velocity/flows.hpp"

namespace nystrom::velocity {

/// q'' = -2 Omega x v - Omega x (Omega x q) - grad U(q).
template <class R>
struct RotatingFrameProblem {
  Vec3<R> omega{0, 0, 1};
  Vec3<R> q0{}, v0{};  // v0: the velocity in the rotating frame
  Field3<R> gradient;  // grad U
  /// U itself (optional): the Jacobi integral |v|^2/2 - |Omega x q|^2/2 + U(q) is then reported.
  std::function<R(const Vec3<R>&)> potential;
  R period = 0;  // of a periodic orbit, when known (> 0): FlowResult::periods
};

/// q'' = v x b + a(q), b = (charge/mass) B uniform.
template <class R>
struct MagneticProblem {
  Vec3<R> b{0, 0, 1};
  Vec3<R> q0{}, v0{};
  Field3<R> force;  // a(q) = (charge/mass) E(q); empty: none
  /// phi with a = -grad phi (optional): the energy |v|^2/2 + phi(q) is then reported.
  std::function<R(const Vec3<R>&)> potential;
  /// The exact solution (optional): exact(t, q, v) sets q(t), v(t); FlowResult::position_error etc.
  std::function<void(R t, Vec3<R>& q, Vec3<R>& v)> exact;
};

/// q'' = -gamma v + a(t, q) in d = q0.size() dimensions, from the time t0.
template <class R>
struct DampedProblem {
  R gamma = 0;
  std::vector<R> q0, v0;
  R t0 = 0;
  TimeForce<R> force;  // empty: none
  /// The exact solution (optional): exact(t, q, v) sets q(t), v(t) (d components each).
  std::function<void(R t, std::vector<R>& q, std::vector<R>& v)> exact;
};

/// The state at one time.
struct FlowSample {
  double time = 0;
  std::vector<double> q, v;
  double invariant = std::numeric_limits<double>::quiet_NaN();
};

struct FlowResult {
  std::string method;
  int order = 0;
  bool symplectic = false;  // the method's map (conformally symplectic for friction): a splitting, not an MPE
  double dt = 0, time = 0;  // time: the end time
  long steps = 0;
  std::vector<double> q, v;  // at the end
  long force_evals = 0;      // kicks (one evaluation of the force each)
  long flows = 0;            // applications of the exact flow A
  /// The conserved quantity (Jacobi integral, energy), when the problem has one: at the start, at the end, and
  /// the largest |I - I(0)| over the samples and the end; invariant_name says which ("" and NaN: none).
  std::string invariant_name;
  double invariant0 = std::numeric_limits<double>::quiet_NaN();
  double invariant = std::numeric_limits<double>::quiet_NaN();
  double invariant_error = std::numeric_limits<double>::quiet_NaN();
  /// Against the exact solution, when the problem has one: max-norm of q - q_exact and of v - v_exact.
  double position_error = std::numeric_limits<double>::quiet_NaN();
  double velocity_error = std::numeric_limits<double>::quiet_NaN();
  /// Periodic orbits (RotatingFrameProblem::period): |q(t) - q0| (Euclidean) and t / period.
  double return_error = std::numeric_limits<double>::quiet_NaN();
  double periods = std::numeric_limits<double>::quiet_NaN();
  double seconds = 0;
  std::vector<FlowSample> samples;  // samples + 1 states evenly spaced from the start, when asked for
};

/// The method solve() runs when none is named: Kahan-Li's symplectic composition of order 8.
inline std::string default_method() { return "KL8"; }

/// Resolves a method for these flows: the catalog's real splittings and multi-product expansions; a method
/// that does not apply is refused with one line (nystrom::invalid_input).
inline operators::FlowMethod resolve_velocity_method(const std::string& name, long bits, const std::string& type) {
  const std::string spec = name.empty() ? default_method() : name;
  const std::string others =
      "use a real splitting or multi-product method of the catalog (e.g. KL8, SS10, M8, VV, FR; `nystrom methods`)";
  operators::FlowMethod m;
  try {
    m = operators::resolve_flow_method(spec, operators::OperatorStructure::rkn, bits, type);
  } catch (const std::invalid_argument& e) {
    throw invalid_input(std::string(e.what()) + "; " + others);
  }
  if (m.info.complex)
    throw invalid_input("'" + m.info.name +
                        "' has complex coefficients: the exact flows of a real (q, v) have no complex time; " + others);
  if (std::holds_alternative<operators::GradientSplitting>(m.data))
    throw invalid_input("'" + m.info.name + "' needs the gradient term [B,[A,B]] of a Schrodinger potential; " +
                        others);
  return m;
}

namespace detail {

inline void check_step(double dt, long steps, long samples) {
  if (!std::isfinite(dt) || dt == 0) throw invalid_input("dt must be finite and not zero (negative: backward)");
  if (steps < 0) throw invalid_input("steps must not be negative");
  if (samples < 0) throw invalid_input("samples must not be negative");
}

template <class R>
void check_finite(const Vec3<R>& x, const char* what) {
  using std::isfinite;
  for (R c : x)
    if (!isfinite(c)) throw invalid_input(std::string(what) + " must be finite");
}

template <class R>
std::vector<double> to_double(const R* x, std::size_t n) {
  std::vector<double> r(n);
  for (std::size_t i = 0; i < n; ++i) r[i] = static_cast<double>(x[i]);
  return r;
}

/// The loop every family shares: `steps` steps of dt in `samples` pieces, recording the state (q, v the first
/// 2 d components), the invariant and the errors.
template <class F>
FlowResult run(F& flows, const operators::FlowMethod& fm, std::vector<typename F::real_type> s, std::size_t d,
               typename F::real_type dt, long steps, long samples, double t0,
               const std::function<double(const std::vector<typename F::real_type>&)>& invariant,
               const std::string& invariant_name) {
  operators::FlowIntegrator<F> integ(fm);
  FlowResult r;
  r.method = fm.info.name;
  r.order = fm.info.order;
  r.symplectic = fm.info.symplectic && !integ.is_mpe();
  r.dt = static_cast<double>(dt);
  r.steps = steps;
  r.invariant_name = invariant ? invariant_name : "";
  double worst = 0;
  auto record = [&](long done) {
    FlowSample smp;
    smp.time = t0 + static_cast<double>(dt) * static_cast<double>(done);
    smp.q = to_double(s.data(), d);
    smp.v = to_double(s.data() + d, d);
    if (invariant) {
      smp.invariant = invariant(s);
      if (done == 0) r.invariant0 = smp.invariant;
      worst = std::max(worst, std::abs(smp.invariant - r.invariant0));
      if (!std::isfinite(smp.invariant)) worst = smp.invariant;
    }
    return smp;
  };
  const auto start = std::chrono::steady_clock::now();
  FlowSample first = record(0);
  if (samples > 0) r.samples.push_back(first);
  long done = 0;
  const long pieces = samples > 0 ? samples : 1;
  for (long i = 1; i <= pieces; ++i) {
    const long target = steps * i / pieces;
    integ.integrate(flows, s, dt, target - done);
    done = target;
    if (samples > 0) r.samples.push_back(record(done));
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const FlowSample last = record(done);
  r.time = last.time;
  r.q = last.q;
  r.v = last.v;
  r.invariant = last.invariant;
  if (invariant) r.invariant_error = worst;
  r.force_evals = flows.kicks();
  r.flows = flows.drifts();
  for (double x : r.q)
    if (!std::isfinite(x)) throw std::runtime_error("the solution blew up: use a smaller step");
  for (double x : r.v)
    if (!std::isfinite(x)) throw std::runtime_error("the solution blew up: use a smaller step");
  return r;
}

template <class Q, class V>
void set_errors(FlowResult& r, const Q& q, const V& v) {
  r.position_error = r.velocity_error = 0;
  for (std::size_t i = 0; i < r.q.size(); ++i) {
    r.position_error = std::max(r.position_error, std::abs(r.q[i] - static_cast<double>(q[i])));
    r.velocity_error = std::max(r.velocity_error, std::abs(r.v[i] - static_cast<double>(v[i])));
  }
}

}  // namespace detail

/// `steps` steps of dt (negative: backward in time) with `method` (empty: default_method()); `samples` > 0
/// records samples + 1 evenly spaced states. Throws nystrom::invalid_input for bad input or a method that does
/// not apply, std::runtime_error when the solution blows up.
template <class R>
FlowResult solve(const RotatingFrameProblem<R>& p, const std::string& method, R dt, long steps, long samples = 0) {
  detail::check_step(static_cast<double>(dt), steps, samples);
  detail::check_finite(p.omega, "the angular velocity");
  detail::check_finite(p.q0, "q0");
  detail::check_finite(p.v0, "v0");
  if (!p.gradient) throw invalid_input("the rotating frame needs the gradient of its potential");
  const auto fm = resolve_velocity_method(method, scalar_traits<R>::bits(), scalar_traits<R>::name());
  RotatingFrameFlows<R> flows(p.omega, p.gradient);
  std::vector<R> s(6);
  for (int i = 0; i < 3; ++i) {
    s[i] = p.q0[i];
    s[3 + i] = p.v0[i];
  }
  std::function<double(const std::vector<R>&)> inv;
  if (p.potential)
    inv = [&](const std::vector<R>& x) {
      const Vec3<R> q = velocity::detail::load(x, 0), v = velocity::detail::load(x, 3);
      const Vec3<R> oq = velocity::detail::cross(p.omega, q);
      return static_cast<double>(velocity::detail::dot(v, v) / 2 - velocity::detail::dot(oq, oq) / 2 + p.potential(q));
    };
  FlowResult r = detail::run(flows, fm, std::move(s), 3, dt, steps, samples, 0.0, inv, "Jacobi integral");
  if (p.period > 0) {
    double d2 = 0;
    for (int i = 0; i < 3; ++i) d2 += (r.q[i] - static_cast<double>(p.q0[i])) * (r.q[i] - static_cast<double>(p.q0[i]));
    r.return_error = std::sqrt(d2);
    r.periods = r.time / static_cast<double>(p.period);
  }
  return r;
}

template <class R>
FlowResult solve(const MagneticProblem<R>& p, const std::string& method, R dt, long steps, long samples = 0) {
  detail::check_step(static_cast<double>(dt), steps, samples);
  detail::check_finite(p.b, "the magnetic field");
  detail::check_finite(p.q0, "q0");
  detail::check_finite(p.v0, "v0");
  const auto fm = resolve_velocity_method(method, scalar_traits<R>::bits(), scalar_traits<R>::name());
  MagneticFlows<R> flows(p.b, p.force);
  std::vector<R> s(6);
  for (int i = 0; i < 3; ++i) {
    s[i] = p.q0[i];
    s[3 + i] = p.v0[i];
  }
  std::function<double(const std::vector<R>&)> inv;
  if (p.potential)
    inv = [&](const std::vector<R>& x) {
      const Vec3<R> q = velocity::detail::load(x, 0), v = velocity::detail::load(x, 3);
      return static_cast<double>(velocity::detail::dot(v, v) / 2 + p.potential(q));
    };
  FlowResult r = detail::run(flows, fm, std::move(s), 3, dt, steps, samples, 0.0, inv, "energy");
  if (p.exact) {
    Vec3<R> q = p.q0, v = p.v0;
    p.exact(dt * static_cast<R>(steps), q, v);
    detail::set_errors(r, q, v);
  }
  return r;
}

template <class R>
FlowResult solve(const DampedProblem<R>& p, const std::string& method, R dt, long steps, long samples = 0) {
  using std::isfinite;
  detail::check_step(static_cast<double>(dt), steps, samples);
  const std::size_t d = p.q0.size();
  if (d == 0) throw invalid_input("q0 must have at least one component");
  if (p.v0.size() != d)
    throw invalid_input("v0 has " + std::to_string(p.v0.size()) + " components for " + std::to_string(d) +
                        " positions");
  for (const auto* x : {&p.q0, &p.v0})
    for (R c : *x)
      if (!isfinite(c)) throw invalid_input("q0 and v0 must be finite");
  if (!isfinite(p.gamma) || !isfinite(p.t0)) throw invalid_input("gamma and t0 must be finite");
  const auto fm = resolve_velocity_method(method, scalar_traits<R>::bits(), scalar_traits<R>::name());
  DampedFlows<R> flows(d, p.gamma, p.force);
  std::vector<R> s(2 * d + 1);
  for (std::size_t i = 0; i < d; ++i) {
    s[i] = p.q0[i];
    s[d + i] = p.v0[i];
  }
  s[2 * d] = p.t0;
  FlowResult r = detail::run(flows, fm, std::move(s), d, dt, steps, samples, static_cast<double>(p.t0), {}, "");
  if (p.exact) {
    std::vector<R> q = p.q0, v = p.v0;
    p.exact(p.t0 + dt * static_cast<R>(steps), q, v);
    detail::set_errors(r, q, v);
  }
  return r;
}

// ---- the built-in problems ----------------------------------------------------------------------------

/// Arenstorf's orbit: the Moon (mass fraction mu) at (1 - mu, 0), the Earth at (-mu, 0), the frame turning once
/// per unit time about z. HNW I's initial state and period (mu = 0.012277471).
template <class R>
RotatingFrameProblem<R> arenstorf(R mu = R(0.012277471L)) {
  using std::sqrt;
  if (!std::isfinite(static_cast<double>(mu)) || !(mu > 0) || !(mu < 1))
    throw invalid_input("mu must lie between 0 and 1");
  RotatingFrameProblem<R> p;
  p.omega = {0, 0, 1};
  p.q0 = {R(0.994L), 0, 0};
  p.v0 = {0, R(-2.00158510637908252240537862224L), 0};
  p.period = R(17.0652165601579625588917206249L);
  const R m1 = 1 - mu;
  p.gradient = [mu, m1](const Vec3<R>& q, Vec3<R>& g) {
    const R x1 = q[0] + mu, x2 = q[0] - m1, y = q[1], z = q[2];
    const R r1s = x1 * x1 + y * y + z * z, r2s = x2 * x2 + y * y + z * z;
    const R d1 = m1 / (r1s * sqrt(r1s)), d2 = mu / (r2s * sqrt(r2s));
    g = {d1 * x1 + d2 * x2, (d1 + d2) * y, (d1 + d2) * z};
  };
  p.potential = [mu, m1](const Vec3<R>& q) {
    const R x1 = q[0] + mu, x2 = q[0] - m1;
    return -m1 / sqrt(x1 * x1 + q[1] * q[1] + q[2] * q[2]) - mu / sqrt(x2 * x2 + q[1] * q[1] + q[2] * q[2]);
  };
  return p;
}

/// Uniform b and a uniform force e (both per unit mass and charge): the exact helix with the drift
/// e x b / |b|^2 and the acceleration along b.
template <class R>
MagneticProblem<R> helix(const Vec3<R>& b, const Vec3<R>& e, const Vec3<R>& q0, const Vec3<R>& v0) {
  MagneticProblem<R> p;
  p.b = b;
  p.q0 = q0;
  p.v0 = v0;
  p.force = [e](const Vec3<R>&, Vec3<R>& a) { a = e; };
  p.potential = [e](const Vec3<R>& q) { return -velocity::detail::dot(e, q); };
  p.exact = [b, e](R t, Vec3<R>& q, Vec3<R>& v) {
    // u = v - v_d with v_d = e x b / |b|^2 gyrates and accelerates along b by e_par
    const R bb = velocity::detail::dot(b, b);
    Vec3<R> vd{}, epar = e;
    if (bb > 0) {
      const Vec3<R> exb = velocity::detail::cross(e, b);
      const R eb = velocity::detail::dot(e, b);
      for (int i = 0; i < 3; ++i) {
        vd[i] = exb[i] / bb;
        epar[i] = eb * b[i] / bb;
      }
    }
    std::vector<R> s(6);
    for (int i = 0; i < 3; ++i) {
      s[i] = q[i];
      s[3 + i] = v[i] - vd[i];
    }
    MagneticFlows<R> g(b, {});
    g.apply_a(s, std::complex<R>(t));
    for (int i = 0; i < 3; ++i) {
      q[i] = s[i] + vd[i] * t + epar[i] * t * t / 2;
      v[i] = s[3 + i] + vd[i] + epar[i] * t;
    }
  };
  return p;
}

/// An ideal Penning trap: b = (0, 0, wc), the quadrupole force kappa (x/2, y/2, -z) (kappa = wz^2, the axial
/// frequency squared; confining when wc^2 > 2 kappa). Exact: z = z0 cos(wz t) + vz0 sin(wz t)/wz, and
/// x + i y = A e^{-i w+ t} + B e^{-i w- t}, w+- = (wc +- sqrt(wc^2 - 2 kappa))/2.
template <class R>
MagneticProblem<R> penning(R wc, R kappa, const Vec3<R>& q0, const Vec3<R>& v0) {
  using std::sqrt;
  if (!std::isfinite(static_cast<double>(wc)) || !std::isfinite(static_cast<double>(kappa)) || !(kappa > 0) ||
      !(wc * wc > 2 * kappa))
    throw invalid_input("a Penning trap needs kappa > 0 and wc^2 > 2 kappa (a confining trap)");
  MagneticProblem<R> p;
  p.b = {0, 0, wc};
  p.q0 = q0;
  p.v0 = v0;
  p.force = [kappa](const Vec3<R>& q, Vec3<R>& a) { a = {kappa * q[0] / 2, kappa * q[1] / 2, -kappa * q[2]}; };
  p.potential = [kappa](const Vec3<R>& q) { return kappa * (q[2] * q[2] - (q[0] * q[0] + q[1] * q[1]) / 2) / 2; };
  p.exact = [wc, kappa](R t, Vec3<R>& q, Vec3<R>& v) {
    using std::cos;
    using std::sin;
    using C = std::complex<R>;
    const R root = sqrt(wc * wc - 2 * kappa), wp = (wc + root) / 2, wm = (wc - root) / 2, wz = sqrt(kappa);
    const C i(0, 1), u0(q[0], q[1]), du0(v[0], v[1]);
    const C a = (i * du0 - wm * u0) / (wp - wm), bcoef = u0 - a;
    const C ep = std::exp(-i * wp * t), em = std::exp(-i * wm * t);
    const C u = a * ep + bcoef * em, du = -i * wp * a * ep - i * wm * bcoef * em;
    const R z = q[2] * cos(wz * t) + v[2] * sin(wz * t) / wz, vz = -q[2] * wz * sin(wz * t) + v[2] * cos(wz * t);
    q = {u.real(), u.imag(), z};
    v = {du.real(), du.imag(), vz};
  };
  return p;
}

/// The damped driven oscillator q'' = -gamma q' - w0^2 q + f cos(wd t), one dimension, from t = 0; exact
/// (under-, critically and over-damped; resonance without friction excluded).
template <class R>
DampedProblem<R> damped_oscillator(R gamma, R w0, R f, R wd, R q0, R v0) {
  for (R x : {gamma, w0, f, wd, q0, v0})
    if (!std::isfinite(static_cast<double>(x))) throw invalid_input("the oscillator's parameters must be finite");
  if (!(w0 > 0)) throw invalid_input("omega0 must be positive");
  if (f != 0 && gamma == 0 && wd * wd == w0 * w0)
    throw invalid_input("a driven oscillator without friction at resonance has no bounded solution to compare with");
  DampedProblem<R> p;
  p.gamma = gamma;
  p.q0 = {q0};
  p.v0 = {v0};
  p.force = [w0, f, wd](R t, const std::vector<R>& q, std::vector<R>& a) {
    using std::cos;
    a[0] = -w0 * w0 * q[0] + f * cos(wd * t);
  };
  p.exact = [gamma, w0, f, wd](R t, std::vector<R>& q, std::vector<R>& v) {
    using C = std::complex<R>;
    // particular: Re(Z e^{i wd t}), Z = f / (w0^2 - wd^2 + i gamma wd)
    const C i(0, 1);
    const C zc = f / (C(w0 * w0 - wd * wd, gamma * wd));
    const C e0 = zc, de0 = i * wd * zc;
    // homogeneous: roots l = -gamma/2 +- sqrt(gamma^2/4 - w0^2) (complex), c1 e^{l1 t} + c2 e^{l2 t}
    const R qh0 = q[0] - e0.real(), vh0 = v[0] - de0.real();
    const C disc = std::sqrt(C(gamma * gamma / 4 - w0 * w0, 0));
    C qh, vh;
    if (std::abs(disc) == 0) {  // critical: (c1 + c2 t) e^{-gamma t / 2}
      const R l = -gamma / 2, c1 = qh0, c2 = vh0 - l * qh0;
      const R e = std::exp(l * t);
      qh = (c1 + c2 * t) * e;
      vh = (c2 + l * (c1 + c2 * t)) * e;
    } else {
      const C l1 = -gamma / 2 + disc, l2 = -gamma / 2 - disc;
      const C c1 = (vh0 - l2 * qh0) / (l1 - l2), c2 = qh0 - c1;
      const C e1 = std::exp(l1 * t), e2 = std::exp(l2 * t);
      qh = c1 * e1 + c2 * e2;
      vh = l1 * c1 * e1 + l2 * c2 * e2;
    }
    const C ep = zc * std::exp(i * wd * t);
    q[0] = qh.real() + ep.real();
    v[0] = vh.real() + (i * wd * ep).real();
  };
  return p;
}

/// A built-in problem by name with its parameters, and the span and step: what the CLI (`nystrom flows`) and
/// Python (nystrom.flows) take, with the same defaults. The span is `periods` periods of the problem (negative:
/// backward in time): Arenstorf's period, the gyration period 2 pi / |b| (helix, penning), 2 pi / omega0
/// (damped); each period takes `steps_per_period` steps.
struct BuiltinSetup {
  std::string problem = "arenstorf";  // arenstorf, helix, penning, damped
  std::string method;                 // empty: default_method()
  double periods = 1;
  long steps_per_period = 0;  // 0: default_steps_per_period(problem)
  long samples = 0;
  double mu = 0.012277471;  // arenstorf: the Moon's mass fraction
  std::vector<double> b;    // helix, penning: (charge/mass) B; empty: (0, 0, 1)
  std::vector<double> e;    // helix: the uniform (charge/mass) E; empty: (0.1, 0, 0.05)
  double kappa = 0.02;      // penning: the quadrupole's strength (axial frequency squared)
  double gamma = 0.1, omega0 = 1, drive = 0.5, drive_frequency = 0.7;  // damped
  std::vector<double> q0, v0;  // empty: the problem's own (components as the problem's dimension)
};

inline const std::vector<std::string>& builtin_names() {
  static const std::vector<std::string> names{"arenstorf", "helix", "penning", "damped"};
  return names;
}

/// Steps per period when none is given: Arenstorf 20000 (KL8: return error 3e-9 after one period),
/// helix and penning 32, damped 64.
inline long default_steps_per_period(const std::string& problem) {
  if (problem == "arenstorf") return 20000;
  if (problem == "damped") return 64;
  return 32;
}

namespace detail {

template <class R>
Vec3<R> vec3(const std::vector<double>& x, const Vec3<R>& fallback, const std::string& what) {
  if (x.empty()) return fallback;
  if (x.size() != 3) throw invalid_input(what + " needs 3 components, got " + std::to_string(x.size()));
  for (double c : x)
    if (!std::isfinite(c)) throw invalid_input(what + " must be finite");
  return {static_cast<R>(x[0]), static_cast<R>(x[1]), static_cast<R>(x[2])};
}

}  // namespace detail

/// Runs a built-in problem (BuiltinSetup) in the working type R. Throws nystrom::invalid_input for bad input.
template <class R>
FlowResult solve_builtin(const BuiltinSetup& o) {
  using std::sqrt;
  if (!std::isfinite(o.periods) || o.periods == 0) throw invalid_input("periods must be finite and not zero");
  if (o.steps_per_period < 0) throw invalid_input("steps per period must not be negative");
  if (o.samples < 0) throw invalid_input("samples must not be negative");
  const long per = o.steps_per_period > 0 ? o.steps_per_period : default_steps_per_period(o.problem);
  const double nsteps = std::ceil(std::abs(o.periods) * static_cast<double>(per) - 1e-9);
  if (!(nsteps >= 1) || nsteps > 1e12) throw invalid_input("the span and steps per period give no step or too many");
  const long steps = static_cast<long>(nsteps);
  auto step_for = [&](R period) { return period * static_cast<R>(o.periods) / static_cast<R>(steps); };
  if (o.problem == "arenstorf") {
    auto p = arenstorf<R>(static_cast<R>(o.mu));
    p.q0 = detail::vec3<R>(o.q0, p.q0, "q0");
    p.v0 = detail::vec3<R>(o.v0, p.v0, "v0");
    return solve(p, o.method, step_for(p.period), steps, o.samples);
  }
  if (o.problem == "helix" || o.problem == "penning") {
    const Vec3<R> b = detail::vec3<R>(o.b, Vec3<R>{0, 0, 1}, "b");
    const R w = velocity::detail::norm(b);
    if (!(w > 0)) throw invalid_input("b must not be zero (the period is that of the gyration)");
    const R period = 2 * static_cast<R>(3.14159265358979323846264338327950288L) / w;
    const Vec3<R> q0 = detail::vec3<R>(o.q0, Vec3<R>{1, 0, o.problem == "penning" ? R(0.5) : R(0)}, "q0");
    const Vec3<R> v0 = detail::vec3<R>(o.v0, Vec3<R>{0, 1, R(0.1)}, "v0");
    if (o.problem == "helix") {
      const Vec3<R> e = detail::vec3<R>(o.e, Vec3<R>{R(0.1), 0, R(0.05)}, "e");
      return solve(helix<R>(b, e, q0, v0), o.method, step_for(period), steps, o.samples);
    }
    if (b[0] != 0 || b[1] != 0) throw invalid_input("the Penning trap's b lies along z: give b as 0,0,wc");
    if (!std::isfinite(o.kappa)) throw invalid_input("kappa must be finite");
    return solve(penning<R>(b[2], static_cast<R>(o.kappa), q0, v0), o.method, step_for(period), steps, o.samples);
  }
  if (o.problem == "damped") {
    if (!std::isfinite(o.omega0) || !(o.omega0 > 0)) throw invalid_input("omega0 must be positive and finite");
    auto scalar = [](const std::vector<double>& x, double fallback, const char* what) {
      if (x.empty()) return fallback;
      if (x.size() != 1) throw invalid_input(std::string(what) + " of the damped oscillator has one component");
      return x[0];
    };
    const auto p = damped_oscillator<R>(static_cast<R>(o.gamma), static_cast<R>(o.omega0), static_cast<R>(o.drive),
                                        static_cast<R>(o.drive_frequency), static_cast<R>(scalar(o.q0, 1, "q0")),
                                        static_cast<R>(scalar(o.v0, 0, "v0")));
    const R period = 2 * static_cast<R>(3.14159265358979323846264338327950288L) / static_cast<R>(o.omega0);
    return solve(p, o.method, step_for(period), steps, o.samples);
  }
  std::string names;
  for (const auto& n : builtin_names()) names += (names.empty() ? "" : ", ") + n;
  throw invalid_input("unknown problem '" + o.problem + "' (built in: " + names + ")");
}

}  // namespace nystrom::velocity
