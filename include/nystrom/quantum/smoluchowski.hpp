// The Smoluchowski (overdamped Fokker-Planck) equation
//   rho_t = D div(grad rho + beta rho grad U)
// on the periodic grid in 1-3 dimensions, as a thin layer on the split-operator flows. The symmetrising
// transformation rho = e^{-beta U/2} psi gives
//   psi_t = D lap psi - D W psi,   W = beta^2 |grad U|^2 / 4 - beta lap U / 2,
// and with tau = 2 D t this is psi_tau = -(T + W/2) psi, T = -lap/2: the imaginary-time Schrodinger flows
// (quantum/schrodinger.hpp) with the potential W/2, run without renormalisation (the density's mass, <e^{-beta
// U/2}|psi>, is what the equation conserves). Its ground state e^{-beta U/2} (eigenvalue 0) is the Boltzmann density;
// the relaxation rates are 2 D times the higher eigenvalues of T + W/2.
//
// Every flow of a diffusion must run forward: a sub-step with a coefficient whose real part is not positive
// multiplies the highest wave numbers by exp(|Re z| D h k_max^2) (S. A. Chin, Celest. Mech. Dyn. Astron. 106 (2010)
// 391, sec. I-II), so such methods are refused (operators::backward_sub_step). The multi-product expansions, Chin's
// forward 4A (its gradient term [B,[A,B]] = |grad W|^2 / 4 from the derivatives of W) and Gurkan's complex methods
// with positive real parts run; a complex method's density is the real part of e^{-beta U/2} psi.
//
// Derivatives: analytic for the built-in potentials (each a sum of one-axis terms u(x_j) with u', u'', u''' known);
// for a user's potential (a function sampled on the grid, or its values) central differences of order 8 on the
// grid, periodic across the box edge. Local differences, not spectral ones: a confining potential is not periodic
// on the box, and its spectral derivatives would ring over the whole box; the differences err only within four
// points of the edge, where e^{-beta U} vanishes.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "nystrom/core/error.hpp"
#include "nystrom/core/scalar.hpp"
#include "nystrom/operators/flow_methods.hpp"
#include "nystrom/quantum/diagnostics.hpp"
#include "nystrom/quantum/grid.hpp"
#include "nystrom/quantum/schrodinger.hpp"
#include "nystrom/quantum/solve.hpp"

namespace nystrom::quantum {

/// Built-in potentials of the Smoluchowski equation (docs/diffusion.md):
///   harmonic     |x|^2 / 2 (the Ornstein-Uhlenbeck process; exact Gaussian transition density)
///   double-well  (x_0^2 - 1)^2 + sum_{j>0} x_j^2 / 2 (barrier 1 between the wells at x_0 = -1, 1)
///   free         0 (free diffusion)
inline std::vector<std::string> smoluchowski_potential_names() { return {"harmonic", "double-well", "free"}; }

/// The default method: M8, the multi-product expansion of order 8, whose flows all run forward (as in imaginary
/// time, quantum::default_method).
inline std::string smoluchowski_default_method() { return "M8"; }

template <class R>
struct SmoluchowskiProblem {
  int dims = 1;
  int grid = 64;
  R box = 6;
  std::string potential = "double-well";  // smoluchowski_potential_names(), ignored when `user` or `values` is set
  PotentialFunction<R> user;              // a user potential U(x)
  /// U on the whole grid (row-major, last axis fastest, at x_i = -L/2 + i L/n); replaces `potential` and `user`.
  std::vector<R> values;
  R diffusion = 1;    // D
  R beta = 1;         // 1 / kT
  std::vector<R> x0;  // centre of the initial Gaussian density (missing components 0)
  R width = R(0.25);  // its standard deviation per axis
  /// The initial density on the whole grid (row-major, as `values`); replaces the Gaussian. Finite, not negative,
  /// not all zero; normalised to mass 1 on input.
  std::vector<R> initial;
  /// The number of lowest nonzero relaxation rates to compute (0: none), by imaginary-time projection over the same
  /// steps from e^{-beta U/2} times a fixed pseudo-random factor per point, each state kept orthogonal to the
  /// Boltzmann state e^{-beta U/2} and to the lower ones (Gram-Schmidt after every step).
  int rates = 0;
  FftOptions fft;
  /// Keep the final density and the Boltzmann density (SmoluchowskiResult::density, boltzmann).
  bool keep_density = false;
};

struct SmoluchowskiResult {
  std::string method;
  int order = 0;
  double dt = 0, time = 0;
  long steps = 0;
  double mass = 0;                     // integral of rho at the end (1 at the start)
  double mass_drift = 0;               // mass - 1
  double min_density = 0;              // the smallest value of rho on the grid (negative: positivity lost)
  double negative_mass = 0;            // integral of max(-rho, 0)
  double imaginary_part = 0;           // max |Im rho| / max |rho| (complex methods; 0 for real ones)
  std::vector<double> mean, variance;  // per axis, of rho / mass
  double boltzmann_distance = 0;       // integral |rho - rho_B|, rho_B = e^{-beta U} / Z on the grid
  double exact_error = std::numeric_limits<double>::quiet_NaN();  // integral |rho - rho_exact|, where known
  std::string exact_solution;                                     // "Ornstein-Uhlenbeck", "free diffusion" or ""
  std::vector<double> rates;                                      // the lowest nonzero relaxation rates, ascending
  std::vector<double> rate_residuals;  // 2 D ||(H - E) phi||: a rate of the grid operator lies within it
  double kramers_rate = std::numeric_limits<double>::quiet_NaN();  // double well: the high-barrier estimate
  long fft_count = 0;
  double seconds = 0;
  std::vector<double> density, boltzmann;  // when keep_density
};

namespace detail {

/// One axis of a built-in potential: u, u', u'', u''' at x.
struct AxisPotential {
  double u, d1, d2, d3;
};

template <class R>
AxisPotential builtin_axis(const std::string& name, int axis, R xr) {
  const double x = static_cast<double>(xr);
  if (name == "free") return {0, 0, 0, 0};
  if (name == "double-well" && axis == 0)
    return {(x * x - 1) * (x * x - 1), 4 * x * x * x - 4 * x, 12 * x * x - 4, 24 * x};
  return {x * x / 2, x, 1, 0};  // harmonic, and the other axes of the double well
}

/// Central difference of order 8 along `axis` of a field on the whole grid, periodic: the first derivative
/// (order 1) or the second (order 2).
template <class R>
std::vector<R> grid_derivative(const Grid<R>& g, const std::vector<R>& f, int axis, int derivative) {
  static constexpr double c1[5] = {0, 4.0 / 5, -1.0 / 5, 4.0 / 105, -1.0 / 280};
  static constexpr double c2[5] = {-205.0 / 72, 8.0 / 5, -1.0 / 5, 8.0 / 315, -1.0 / 560};
  std::size_t stride = 1;
  for (int a = g.dims - 1; a > axis; --a) stride *= static_cast<std::size_t>(g.n);
  const R dx = g.dx();
  std::vector<R> out(f.size());
  int idx[3] = {0, 0, 0};
  for (std::size_t i = 0; i < f.size(); ++i) {
    g.indices(i, idx);
    const std::size_t base = i - static_cast<std::size_t>(idx[axis]) * stride;
    auto at = [&](int m) { return f[base + static_cast<std::size_t>(((idx[axis] + m) % g.n + g.n) % g.n) * stride]; };
    R s = derivative == 2 ? static_cast<R>(c2[0]) * f[i] : R(0);
    for (int m = 1; m <= 4; ++m)
      s += derivative == 1 ? static_cast<R>(c1[m]) * (at(m) - at(-m)) : static_cast<R>(c2[m]) * (at(m) + at(-m));
    out[i] = derivative == 1 ? s / dx : s / (dx * dx);
  }
  return out;
}

/// U, W and |grad W|^2 on the whole grid.
template <class R>
struct SmoluchowskiFields {
  std::vector<R> u, w, grad_w2;
};

template <class R>
SmoluchowskiFields<R> smoluchowski_fields(const Grid<R>& g, const SmoluchowskiProblem<R>& p, bool gradient) {
  SmoluchowskiFields<R> f;
  const R beta = p.beta;
  if (p.values.empty() && !p.user) {
    f.u.resize(g.size());
    f.w.resize(g.size());
    f.grad_w2.resize(g.size());
    for_each_point(g, PointRange{}, [&](std::size_t i, const int* idx) {
      R u = 0, w = 0, gw2 = 0;
      for (int a = 0; a < g.dims; ++a) {
        const AxisPotential ax = builtin_axis(p.potential, a, g.coordinate(idx[a]));
        u += static_cast<R>(ax.u);
        const R d1 = static_cast<R>(ax.d1), d2 = static_cast<R>(ax.d2), d3 = static_cast<R>(ax.d3);
        w += beta * beta * d1 * d1 / 4 - beta * d2 / 2;
        const R dw = beta * beta * d1 * d2 / 2 - beta * d3 / 2;
        gw2 += dw * dw;
      }
      f.u[i] = u;
      f.w[i] = w;
      f.grad_w2[i] = gw2;
    });
    return f;
  }
  if (!p.values.empty()) {
    if (p.values.size() != g.size())
      throw std::invalid_argument("the potential has " + std::to_string(p.values.size()) + " values for " +
                                  std::to_string(g.size()) + " grid points");
    f.u = p.values;
    for (R x : f.u)
      if (!std::isfinite(static_cast<double>(x))) throw std::invalid_argument("the potential is not finite");
  } else {
    f.u = sample_potential(g, p.user);
  }
  f.w.assign(g.size(), R(0));
  for (int a = 0; a < g.dims; ++a) {
    const auto d1 = grid_derivative(g, f.u, a, 1), d2 = grid_derivative(g, f.u, a, 2);
    for (std::size_t i = 0; i < f.w.size(); ++i) f.w[i] += beta * beta * d1[i] * d1[i] / 4 - beta * d2[i] / 2;
  }
  if (gradient) {
    f.grad_w2.assign(g.size(), R(0));
    for (int a = 0; a < g.dims; ++a) {
      const auto dw = grid_derivative(g, f.w, a, 1);
      for (std::size_t i = 0; i < dw.size(); ++i) f.grad_w2[i] += dw[i] * dw[i];
    }
  }
  for (R x : f.w)
    if (!std::isfinite(static_cast<double>(x)))
      throw std::invalid_argument("beta^2 |grad U|^2 / 4 - beta lap U / 2 is not finite on the grid");
  return f;
}

/// The Smoluchowski flows: the imaginary-time Schrodinger flows of T + W/2 without renormalisation.
template <class R>
class SmoluchowskiFlows {
 public:
  using state_type = Field<R>;
  using real_type = R;
  explicit SmoluchowskiFlows(SchrodingerFlows<R>& f) : f_(f) {}
  void apply_a(state_type& s, std::complex<R> z) { f_.apply_a(s, z); }
  void apply_b(state_type& s, std::complex<R> z) { f_.apply_b(s, z); }
  void apply_b_gradient(state_type& s, std::complex<R> z, std::complex<R> w) { f_.apply_b_gradient(s, z, w); }
  void assign(state_type& d, const state_type& s) const { f_.assign(d, s); }
  void scale(state_type& s, R r) const { f_.scale(s, r); }
  void axpy(state_type& d, R r, const state_type& s) const { f_.axpy(d, r, s); }

 private:
  SchrodingerFlows<R>& f_;
};

/// The fraction of a field's squared norm in the outer quarter of the wave numbers of any axis (|m| >= 3n/8).
template <class R>
double spectral_tail(const SchrodingerFlows<R>& flows, const Field<R>& f) {
  Field<R> hat = f;
  flows.fft().forward(hat);
  const Grid<R>& g = flows.grid();
  double all = 0, tail = 0;
  for_each_point(g, PointRange{}, [&](std::size_t i, const int* idx) {
    const double w = static_cast<double>(std::norm(hat[i]));
    all += w;
    for (int a = 0; a < g.dims; ++a) {
      const int m = idx[a] < (g.n + 1) / 2 ? idx[a] : idx[a] - g.n;
      if (8 * std::abs(m) >= 3 * g.n) {
        tail += w;
        break;
      }
    }
  });
  return all > 0 ? tail / all : 0;
}

}  // namespace detail

/// The one-line refusal of a method with a backward sub-step.
inline std::string smoluchowski_backward_message(const std::string& method, const operators::BackwardSubStep& b) {
  const std::string where = b.gradient ? "gradient term" : b.flow == Flow::drift ? "diffusion flow" : "potential flow";
  return "'" + method + "' has a coefficient with a real part that is not positive (" +
         detail::coefficient_text(b.coefficient) + " in the " + where +
         "): a backward diffusion sub-step amplifies the highest wave numbers and the Smoluchowski equation diverges; "
         "use a forward method: " +
         operators::forward_alternatives(operators::OperatorStructure::rkn, true);
}

/// Propagates the problem's initial density by `steps` steps of size dt with `method` (empty: M8); the density's
/// mass, positivity, moments and distance to the Boltzmann density, the error against the exact solution where one is
/// known, and the lowest `rates` relaxation rates. Throws nystrom::invalid_input for a method with a backward
/// sub-step, std::invalid_argument for bad input, std::runtime_error when the density blows up or its mass drifts by
/// more than 1% (the step is too large for the method).
template <class R>
SmoluchowskiResult smoluchowski(const SmoluchowskiProblem<R>& p, const std::string& method_name, R dt, long steps) {
  const std::string method = method_name.empty() ? smoluchowski_default_method() : method_name;
  detail::check_positive_finite(static_cast<double>(dt), "dt");
  detail::check_positive_finite(static_cast<double>(p.diffusion), "the diffusion coefficient D");
  detail::check_positive_finite(static_cast<double>(p.beta), "beta");
  detail::check_positive_finite(static_cast<double>(p.width), "the initial width");
  if (steps < 0) throw std::invalid_argument("steps must not be negative");
  if (p.rates < 0 || p.rates > 100) throw std::invalid_argument("rates must be between 0 and 100");
  if (p.grid < 16)
    throw std::invalid_argument("the grid must have at least 16 points per axis, got " + std::to_string(p.grid));
  if (p.values.empty() && !p.user) {
    const auto names = smoluchowski_potential_names();
    if (std::find(names.begin(), names.end(), p.potential) == names.end()) {
      std::string known;
      for (const auto& n : names) known += (known.empty() ? "" : ", ") + n;
      throw std::invalid_argument("unknown potential '" + p.potential + "' (known: " + known +
                                  "; or give its values or a function)");
    }
  }
  if (!p.initial.empty() && (!p.x0.empty() || p.width != R(0.25)))
    throw std::invalid_argument("an initial density replaces the Gaussian: give no x0 or width with it");
  if (static_cast<int>(p.x0.size()) > p.dims)
    throw std::invalid_argument("x0 has " + std::to_string(p.x0.size()) + " components for " + std::to_string(p.dims) +
                                " dimension(s)");
  for (R x : p.x0)
    if (!std::isfinite(static_cast<double>(x))) throw std::invalid_argument("x0 must be finite");
  const Grid<R> grid(p.dims, p.grid, p.box);
  const operators::FlowMethod fm = operators::resolve_flow_method(method, operators::OperatorStructure::rkn,
                                                                  scalar_traits<R>::bits(), scalar_traits<R>::name());
  if (const auto b = operators::backward_sub_step(fm))
    throw invalid_input(smoluchowski_backward_message(fm.info.name, *b));
  const bool gradient = std::holds_alternative<operators::GradientSplitting>(fm.data);
  const detail::SmoluchowskiFields<R> fields = detail::smoluchowski_fields(grid, p, gradient);
  if (!p.initial.empty()) {
    if (p.initial.size() != grid.size())
      throw std::invalid_argument("the initial density has " + std::to_string(p.initial.size()) + " values for " +
                                  std::to_string(grid.size()) + " grid points");
    for (R x : p.initial)
      if (!std::isfinite(static_cast<double>(x)) || x < 0)
        throw std::invalid_argument("the initial density must be finite and not negative");
  }

  std::vector<R> v(fields.w.size());
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = fields.w[i] / 2;
  SchrodingerFlows<R> flows(grid, std::move(v), TimeKind::imaginary, R(0), p.fft);
  if (gradient) {
    std::vector<R> g2(fields.grad_w2.size());
    for (std::size_t i = 0; i < g2.size(); ++i) g2[i] = fields.grad_w2[i] / 4;  // |grad (W/2)|^2
    flows.set_gradient_term(std::move(g2));
  }
  detail::SmoluchowskiFlows<R> sflows(flows);
  operators::FlowIntegrator<detail::SmoluchowskiFlows<R>> integ(fm);
  operators::FlowIntegrator<SchrodingerFlows<R>> rate_integ(fm);

  // e^{-beta (U - U_min) / 2}: rho = half * psi; the Boltzmann density half^2 / Z
  const std::size_t n = grid.size();
  const R cell = grid.cell();
  const R umin = *std::min_element(fields.u.begin(), fields.u.end());
  std::vector<R> half(n), boltzmann(n);
  R z = 0;
  for (std::size_t i = 0; i < n; ++i) {
    half[i] = std::exp(-p.beta * (fields.u[i] - umin) / 2);
    z += half[i] * half[i] * cell;
  }
  for (std::size_t i = 0; i < n; ++i) boltzmann[i] = half[i] * half[i] / z;

  // the initial density, mass 1 on the grid
  std::vector<R> rho0(n);
  if (p.initial.empty()) {
    for_each_point(grid, PointRange{}, [&](std::size_t i, const int* idx) {
      R r2 = 0;
      for (int a = 0; a < grid.dims; ++a) {
        const R d = grid.coordinate(idx[a]) - detail::component(p.x0, a);
        r2 += d * d;
      }
      rho0[i] = std::exp(-r2 / (2 * p.width * p.width));
    });
  } else {
    rho0 = p.initial;
  }
  R mass0 = 0;
  for (R x : rho0) mass0 += x * cell;
  if (!(mass0 > 0) || !std::isfinite(static_cast<double>(mass0)))
    throw std::invalid_argument("the initial density is zero on the grid or too large to normalise");
  for (auto& x : rho0) x /= mass0;
  Field<R> psi(n);
  for (std::size_t i = 0; i < n; ++i) psi[i] = rho0[i] / half[i];
  for (const auto& x : psi)
    if (!std::isfinite(static_cast<double>(x.real())))
      throw std::invalid_argument(
          "the initial density times e^{beta U/2} overflows towards the edges of the box: "
          "use a narrower initial density, a smaller box or a smaller beta");
  {
    // e^{-beta U/2} must be resolved; where it does not vanish at the edges of the box (a confining potential in a box
    // too small), its periodic continuation has a kink
    Field<R> b(n);
    R edge = 0;
    for_each_point(grid, PointRange{}, [&](std::size_t i, const int* idx) {
      b[i] = half[i];
      for (int a = 0; a < grid.dims; ++a)
        if (idx[a] == 0) edge = std::max(edge, half[i]);
    });
    if (detail::spectral_tail(flows, b) > 1e-10)
      throw std::invalid_argument(
          edge > R(1e-6) ? "e^{-beta U/2}, the square root of the Boltzmann density, does not vanish at the edges of "
                           "the box and is not smooth across them: use a larger box (or a larger beta)"
                         : "the grid does not resolve e^{-beta U/2}, the square root of the Boltzmann density: use a "
                           "finer grid (or a smaller box, or a smaller beta)");
  }
  const double tail = detail::spectral_tail(flows, psi);
  if (tail > 1e-10) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.2g", tail);
    throw std::invalid_argument(std::string("the grid does not resolve rho0 e^{beta U/2} (a fraction ") + buf +
                                " of its norm in the highest wave numbers): the initial density must be smooth on the "
                                "grid and fall faster than e^{-beta U/2} towards the edges of the box; use a finer "
                                "grid, a smaller box or a narrower initial density");
  }

  const R dtau = 2 * p.diffusion * dt;
  SmoluchowskiResult r;
  r.method = fm.info.name;
  r.order = fm.info.order;
  r.dt = static_cast<double>(dt);
  r.steps = steps;
  r.time = static_cast<double>(dt) * static_cast<double>(steps);
  const auto t0 = std::chrono::steady_clock::now();
  integ.integrate(sflows, psi, dtau, steps);

  // the density and its diagnostics
  std::vector<R> rho(n);
  R mass = 0, neg = 0, dist = 0, rmax = 0, imax = 0;
  R rmin = std::numeric_limits<R>::infinity();
  std::vector<R> m1(static_cast<std::size_t>(grid.dims), R(0)), m2 = m1;
  for_each_point(grid, PointRange{}, [&](std::size_t i, const int* idx) {
    rho[i] = half[i] * psi[i].real();
    const R x = rho[i];
    mass += x * cell;
    if (x < 0) neg -= x * cell;
    rmin = std::min(rmin, x);
    rmax = std::max(rmax, std::abs(x));
    imax = std::max(imax, std::abs(half[i] * psi[i].imag()));
    dist += std::abs(x - boltzmann[i]) * cell;
    for (int a = 0; a < grid.dims; ++a) {
      const R c = grid.coordinate(idx[a]);
      m1[static_cast<std::size_t>(a)] += x * c * cell;
      m2[static_cast<std::size_t>(a)] += x * c * c * cell;
    }
  });
  r.mass = static_cast<double>(mass);
  r.mass_drift = r.mass - 1;
  if (!std::isfinite(r.mass) || !std::isfinite(static_cast<double>(dist)))
    throw std::runtime_error("the density blew up (its mass is not finite): '" + r.method +
                             "' is unstable for this problem and step; use a smaller step");
  if (std::abs(r.mass_drift) > 0.01) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "the mass of the density drifted from 1 to %.6g: '", r.mass);
    throw std::runtime_error(buf + r.method + "' is not accurate with this step on this problem; use a smaller step");
  }
  r.min_density = static_cast<double>(rmin);
  r.negative_mass = static_cast<double>(neg);
  r.imaginary_part = rmax > 0 ? static_cast<double>(imax / rmax) : 0;
  r.boltzmann_distance = static_cast<double>(dist);
  for (int a = 0; a < grid.dims; ++a) {
    const R mean = m1[static_cast<std::size_t>(a)] / mass;
    r.mean.push_back(static_cast<double>(mean));
    r.variance.push_back(static_cast<double>(m2[static_cast<std::size_t>(a)] / mass - mean * mean));
  }
  // exact solutions for a Gaussian start: the Ornstein-Uhlenbeck process (U = |x|^2 / 2: mean x0 e^{-D beta t},
  // variance s^2 e^{-2 D beta t} + (1 - e^{-2 D beta t}) / beta) and free diffusion (variance s^2 + 2 D t)
  if (p.initial.empty() && p.values.empty() && !p.user && (p.potential == "harmonic" || p.potential == "free")) {
    const R t = dt * static_cast<R>(steps);
    const bool ou = p.potential == "harmonic";
    const R decay = ou ? std::exp(-p.diffusion * p.beta * t) : R(1);
    const R var =
        ou ? p.width * p.width * decay * decay + (1 - decay * decay) / p.beta : p.width * p.width + 2 * p.diffusion * t;
    const R norm = std::pow(2 * std::numbers::pi_v<R> * var, -static_cast<R>(grid.dims) / 2);
    R err = 0;
    for_each_point(grid, PointRange{}, [&](std::size_t i, const int* idx) {
      R r2 = 0;
      for (int a = 0; a < grid.dims; ++a) {
        const R d = grid.coordinate(idx[a]) - detail::component(p.x0, a) * decay;
        r2 += d * d;
      }
      err += std::abs(rho[i] - norm * std::exp(-r2 / (2 * var))) * cell;
    });
    r.exact_error = static_cast<double>(err);
    r.exact_solution = ou ? "Ornstein-Uhlenbeck" : "free diffusion";
  }
  if (p.values.empty() && !p.user && p.potential == "double-well") {
    // Kramers' high-barrier rate k = D beta sqrt(U''(1) |U''(0)|) / (2 pi) e^{-beta dU}, dU = 1, for each direction;
    // the relaxation rate of the two wells' populations is 2k
    r.kramers_rate = 2 * static_cast<double>(p.diffusion * p.beta) * std::sqrt(32.0) / (2 * std::numbers::pi) *
                     std::exp(-static_cast<double>(p.beta));
  }

  // relaxation rates: imaginary-time projection of T + W/2, orthogonal to e^{-beta U/2} and the lower states
  if (p.rates > 0) {
    std::vector<Field<R>> lower;
    Field<R> ground(n);
    for (std::size_t i = 0; i < n; ++i) ground[i] = half[i];
    flows.renormalize(ground);
    lower.push_back(std::move(ground));
    for (int k = 1; k <= p.rates; ++k) {
      Field<R> phi(n);
      for (std::size_t i = 0; i < n; ++i)
        phi[i] = half[i] * static_cast<R>(1 + detail::unit_noise(i, static_cast<std::uint64_t>(k)) / 2);
      auto orthogonalise = [&] {
        for (const auto& l : lower) {
          const std::complex<R> c = overlap(flows, l, phi);
          for (std::size_t i = 0; i < n; ++i) phi[i] -= c * l[i];
        }
        flows.renormalize(phi);
      };
      orthogonalise();
      for (long i = 0; i < steps; ++i) {
        rate_integ.integrate(flows, phi, dtau, 1);
        orthogonalise();
      }
      const R e = observe(flows, phi).energy;
      // the residual ||(H - e) phi|| of the normalised phi: H = T + W/2 applied exactly (T in Fourier space)
      Field<R> hphi = phi;
      flows.fft().forward(hphi);
      for (std::size_t i = 0; i < n; ++i) hphi[i] *= flows.half_k2()[i] / static_cast<R>(n);
      flows.fft().backward(hphi);
      R res = 0;
      for (std::size_t i = 0; i < n; ++i) res += std::norm(hphi[i] + (flows.potential()[i] - e) * phi[i]);
      res = std::sqrt(res * cell);
      r.rates.push_back(static_cast<double>(2 * p.diffusion * e));
      r.rate_residuals.push_back(static_cast<double>(2 * p.diffusion * res));
      lower.push_back(std::move(phi));
    }
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.fft_count = flows.fft_count();
  if (p.keep_density) {
    for (R x : rho) r.density.push_back(static_cast<double>(x));
    for (R x : boltzmann) r.boltzmann.push_back(static_cast<double>(x));
  }
  return r;
}

}  // namespace nystrom::quantum
