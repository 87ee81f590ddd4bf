// The law of a Langevin splitting, computed on a phase-space grid (one degree of freedom) instead of sampled.
//
// A splitting (splitting.hpp) moves a path by three flows; it moves the density rho(q, v) of the paths by the
// same flows, each exactly:
//   A (drift by tau)   rho(q, v) <- rho(q - tau v, v)            a shift in q, by tau v on each row v
//   B (kick by tau)    rho(q, v) <- rho(q, v - tau a(q))         a shift in v, by tau a(q) on each column q
//   O (noise over tau) rho(q, .) <- the Ornstein-Uhlenbeck transition density applied in v:
//                      v' = c v + s xi, c = e^{-gamma tau}, s^2 = kT/m (1 - c^2)
// On a periodic grid of n (odd) points per axis the density is a trigonometric polynomial, and each flow is a
// kernel applied to the grid values: the shifts by the Dirichlet kernel D(x) = sin(n pi x / P) / (n sin(pi x / P))
// (P the period), the noise by (1/n) sum_k exp(-s^2 kappa_k^2 / 2) cos(kappa_k (v - c u)), the band-limited
// Gaussian transition kernel. Both conserve the mass exactly; for a density that is negligible at the edges and
// resolved by the grid, the error of each flow is exponentially small in the number of points. The stationary
// density of the scheme at a step h is then the fixed point of the step, reached by iterating it from the
// Boltzmann density, and its averages are the scheme's stationary averages without statistical error.
//
// This is the splitting applied to the Kramers (phase-space Fokker-Planck) equation itself: e^{h L} with
// L = L_A + L_B + L_O factorised as the string says. Its use here is to measure a scheme's bias exactly, and the
// bias of the multi-product combination of runs at h / k_i (langevin.hpp): for a symmetric splitting the errors
// are even in h and the n-term combination has weak order 2n.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <numbers>
#include <span>
#include <string>
#include <vector>

#include "nystrom/core/error.hpp"
#include "nystrom/stochastic/langevin.hpp"
#include "nystrom/stochastic/splitting.hpp"

namespace nystrom::stochastic {

/// A periodic phase-space grid: q in [q_min, q_max), v in [-v_max, v_max), nq and nv points (odd).
struct PhaseGrid {
  int nq = 0, nv = 0;           // 0: 65 points
  double q_min = 0, q_max = 0;  // both 0: where the Boltzmann density falls below e^{-40} of its maximum
  double v_max = 0;             // 0: sqrt(80 kT / m) (e^{-40})
};

struct StationaryLawOptions {
  std::string method = "BAOAB";
  double h = 0.05;
  std::vector<long> extrapolate = {1};  // k_1..k_n; {1}: the scheme alone
  PhaseGrid grid{};
  /// Stop once the estimated distance of every observable's average from its fixed point is below tol
  /// (absolute), or its change per step has reached the rounding level.
  double tol = 1e-14;
  long max_steps = 200000;  // per member
  /// Called after each member's law with (members done, members); may be empty.
  std::function<void(std::size_t done, std::size_t total)> progress{};
};

struct StationaryLawResult {
  std::string method;
  double h = 0;
  std::vector<long> extrapolate;
  std::vector<double> coefficients;  // c_i
  int order = 2;                     // weak order of the combination (2n)
  std::vector<std::string> observable_names;
  std::vector<double> averages;              // the combination sum_i c_i A_i, per observable
  std::vector<std::vector<double>> members;  // [i][j]: the stationary average of observable j at h / k_i
  std::vector<double> boltzmann;             // the exact (Boltzmann) averages by the same quadrature
  std::vector<long> steps;                   // steps of h / k_i iterated to the fixed point
  PhaseGrid grid;                            // the grid used
  /// Largest fraction (in norm) of a stationary density's discrete spectrum in the outer quarter of the wave
  /// numbers, over both axes and all members: how well the grid resolves it.
  double resolution = 0;
  /// Largest density on the grid's edges relative to its maximum, over the members.
  double edge = 0;
};

/// A stationary law whose density reaches this fraction of its maximum at the grid's edges, or has this fraction of
/// its spectrum in the outer quarter of the wave numbers, is refused.
inline constexpr double max_law_defect = 1e-5;

/// The most grid points per axis the tool and the Python module take (a step costs about 5 n^3 multiply-adds).
inline constexpr int max_front_end_grid_points = 257;

/// The tool's and the Python module's check of their grid points (named `name` in the message): odd, 9 to
/// max_front_end_grid_points; throws nystrom::invalid_input with one line otherwise.
inline void check_front_end_grid_points(int n, const std::string& name) {
  if (n < 9 || n > max_front_end_grid_points || n % 2 == 0)
    throw invalid_input(name + " must be odd, 9 to " + std::to_string(max_front_end_grid_points) + ", got " +
                        std::to_string(n));
}

namespace law_detail {

inline std::string sci(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1e", x);
  return buf;
}

inline std::string num(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}

inline constexpr double pi = std::numbers::pi;

// The band-limited periodic kernel of n (odd) points with period p, at x: (1/n) sum_{|k| <= (n-1)/2} g_k
// cos(2 pi k x / p), with g_0 = 1 and g_k = g[k - 1] (g empty: all 1, the Dirichlet kernel).
inline double cosine_sum(int n, double p, double x, const std::vector<double>& g) {
  double sum = 1;
  for (int k = 1; k <= (n - 1) / 2; ++k)
    sum += 2 * (g.empty() ? 1.0 : g[static_cast<std::size_t>(k) - 1]) * std::cos(2 * pi * k / p * x);
  return sum / n;
}

// The Dirichlet kernel of n (odd) points with period p, at x (its closed form away from the multiples of p).
inline double dirichlet(int n, double p, double x) {
  x -= p * std::nearbyint(x / p);
  if (std::abs(x) < 1e-9 * p) return cosine_sum(n, p, x, {});
  return std::sin(n * pi * x / p) / (n * std::sin(pi * x / p));
}

// A circulant shift by `shift` on n points of spacing d: y_i = sum_j w[n - 1 - i + j] x_j.
inline void shift_weights(int n, double d, double shift, double* w) {
  for (int t = 0; t < 2 * n - 1; ++t) w[t] = dirichlet(n, n * d, (n - 1 - t) * d - shift);
}

inline void apply_circulant(int n, const double* w, const double* x, double* y) {
  for (int i = 0; i < n; ++i) {
    const double* wi = w + (n - 1 - i);
    double sum = 0;
    for (int j = 0; j < n; ++j) sum += wi[j] * x[j];
    y[i] = sum;
  }
}

inline void apply_dense(int n, const double* m, const double* x, double* y) {
  for (int i = 0; i < n; ++i) {
    const double* mi = m + static_cast<std::size_t>(i) * n;
    double sum = 0;
    for (int j = 0; j < n; ++j) sum += mi[j] * x[j];
    y[i] = sum;
  }
}

inline void transpose(int rows, int cols, const std::vector<double>& a, std::vector<double>& b) {
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c)
      b[static_cast<std::size_t>(c) * rows + r] = a[static_cast<std::size_t>(r) * cols + c];
}

// Fraction (in norm) of the discrete spectrum of the rows of a (rows x n) in the outer quarter of the wave numbers.
inline double outer_spectrum(int rows, int n, const std::vector<double>& a) {
  double outer = 0, total = 0;
  const int kmax = (n - 1) / 2;
  std::vector<double> c(static_cast<std::size_t>(kmax + 1) * n), s(c.size());
  for (int k = 0; k <= kmax; ++k)
    for (int j = 0; j < n; ++j) {
      c[static_cast<std::size_t>(k) * n + j] = std::cos(2 * pi * k * j / n);
      s[static_cast<std::size_t>(k) * n + j] = std::sin(2 * pi * k * j / n);
    }
  for (int r = 0; r < rows; ++r) {
    const double* x = a.data() + static_cast<std::size_t>(r) * n;
    for (int k = 0; k <= kmax; ++k) {
      double re = 0, im = 0;
      for (int j = 0; j < n; ++j) {
        re += c[static_cast<std::size_t>(k) * n + j] * x[j];
        im += s[static_cast<std::size_t>(k) * n + j] * x[j];
      }
      const double p = (k == 0 ? 1 : 2) * (re * re + im * im);
      total += p;
      if (4 * k > 3 * kmax) outer += p;
    }
  }
  return total > 0 ? std::sqrt(outer / total) : 0;
}

// The acceleration a(q) of a one-dimensional problem at q.
template <class Acceleration>
double acceleration_at(const Acceleration& acc, double at) {
  std::array<double, 1> q{at}, a{};
  acc(std::span<const double>(q), std::span<double>(a));
  return a[0];
}

// The potential energy m * U(q) / m on the grid points, up to a constant, by integrating -m a(q) with 8-point
// Gauss-Legendre quadrature over each cell from the first point.
template <class Acceleration>
std::vector<double> potential_on(const Acceleration& acc, double mass, double q0, double dq, int n) {
  static constexpr std::array<double, 4> x = {0.1834346424956498, 0.5255324099163290, 0.7966664774136267,
                                              0.9602898564975363};
  static constexpr std::array<double, 4> w = {0.3626837833783620, 0.3137066458778873, 0.2223810344533745,
                                              0.1012285362903763};
  std::vector<double> u(static_cast<std::size_t>(n), 0.0);
  const auto force = [&](double at) { return acceleration_at(acc, at); };
  for (int j = 1; j < n; ++j) {
    const double mid = q0 + (j - 0.5) * dq, half = 0.5 * dq;
    double integral = 0;
    for (int k = 0; k < 4; ++k) integral += w[k] * (force(mid - half * x[k]) + force(mid + half * x[k]));
    u[static_cast<std::size_t>(j)] = u[static_cast<std::size_t>(j) - 1] - mass * half * integral;
  }
  return u;
}

// The q range where the Boltzmann density exceeds e^{-40} of its largest value, searched outward from q0 in
// steps of 1/64 (up to |q - q0| = 1e3); throws when the potential does not confine.
template <class Acceleration>
std::pair<double, double> confining_range(const Acceleration& acc, double mass, double kT, double q0) {
  const double step = 1.0 / 64, limit = 40;
  const int most = 64000;
  const auto force = [&](double at) { return acceleration_at(acc, at); };
  double ends[2];
  for (int dir = 0; dir < 2; ++dir) {
    const double sgn = dir == 0 ? 1.0 : -1.0;
    double u = 0, lowest = 0;
    int k = 1;
    for (; k <= most; ++k) {
      const double a0 = force(q0 + sgn * (k - 1) * step), a1 = force(q0 + sgn * (k - 0.5) * step),
                   a2 = force(q0 + sgn * k * step);
      u -= sgn * mass * step * (a0 + 4 * a1 + a2) / 6 / kT;
      if (!std::isfinite(u)) break;
      lowest = std::min(lowest, u);
      if (u - lowest > limit && a2 * sgn < 0) break;
    }
    if (k > most || !std::isfinite(u))
      throw invalid_input("the potential does not confine the Boltzmann density within 1000 of q0 " +
                          std::string("on one side: give the grid's q range"));
    ends[dir] = q0 + sgn * k * step;
  }
  return {ends[1], ends[0]};
}

}  // namespace law_detail

/// The stationary averages of a Langevin splitting at the steps h / k_i and their multi-product combination,
/// from the scheme's law on a phase-space grid (one degree of freedom). Throws nystrom::invalid_input with one line
/// for bad input, and nystrom::error when the iteration does not converge or the density is not resolved.
template <class Acceleration, class Observe>
StationaryLawResult stationary_law(const LangevinProblem<Acceleration, Observe>& problem,
                                   const StationaryLawOptions& o) {
  using law_detail::pi;
  const LangevinSplitting sp = parse_langevin_splitting(o.method);
  if (problem.q0.size() != 1 || problem.v0.size() != 1)
    throw invalid_input("the stationary law on a phase-space grid needs one degree of freedom (q0 and v0 of size 1)");
  if (!std::isfinite(problem.q0[0])) throw invalid_input("the initial state must be finite");
  if (!(o.h > 0) || !std::isfinite(o.h)) throw invalid_input("the step h must be positive and finite");
  if (!(problem.gamma > 0) || !std::isfinite(problem.gamma))
    throw invalid_input("a stationary law needs a positive, finite friction gamma");
  if (!(problem.kT > 0) || !std::isfinite(problem.kT))
    throw invalid_input("a stationary law needs a positive, finite temperature kT");
  if (!(problem.mass > 0) || !std::isfinite(problem.mass)) throw invalid_input("the mass must be positive and finite");
  if (problem.observable_names.empty()) throw invalid_input("a stationary law needs at least one observable");
  if (!(o.tol > 0) || !std::isfinite(o.tol)) throw invalid_input("the tolerance must be positive and finite");
  if (o.max_steps < 1) throw invalid_input("max_steps must be positive");
  check_extrapolation(sp, o.extrapolate);

  PhaseGrid g = o.grid;
  if (g.nq == 0) g.nq = 65;
  if (g.nv == 0) g.nv = 65;
  for (const int n : {g.nq, g.nv})
    if (n < 9 || n > 1025 || n % 2 == 0)
      throw invalid_input("the phase-space grid needs an odd 9..1025 points per axis");
  if (g.q_min == 0 && g.q_max == 0) {
    const auto [lo, hi] = law_detail::confining_range(problem.acceleration, problem.mass, problem.kT, problem.q0[0]);
    g.q_min = lo;
    g.q_max = hi;
  }
  if (g.v_max == 0) g.v_max = std::sqrt(80 * problem.kT / problem.mass);
  if (!(g.q_max > g.q_min) || !std::isfinite(g.q_min) || !std::isfinite(g.q_max) || !(g.v_max > 0) ||
      !std::isfinite(g.v_max))
    throw invalid_input("the phase-space grid needs q_min < q_max and v_max > 0, all finite");

  const int nq = g.nq, nv = g.nv;
  const std::size_t cells = static_cast<std::size_t>(nq) * nv;
  const double dq = (g.q_max - g.q_min) / nq, dv = 2 * g.v_max / nv;
  std::vector<double> qs(static_cast<std::size_t>(nq)), vs(static_cast<std::size_t>(nv));
  for (int j = 0; j < nq; ++j) qs[static_cast<std::size_t>(j)] = g.q_min + j * dq;
  for (int l = 0; l < nv; ++l) vs[static_cast<std::size_t>(l)] = -g.v_max + l * dv;

  // Forces, observables and the Boltzmann density on the grid (rows: v, columns: q).
  std::vector<double> acc(static_cast<std::size_t>(nq));
  for (int j = 0; j < nq; ++j) {
    acc[static_cast<std::size_t>(j)] =
        law_detail::acceleration_at(problem.acceleration, qs[static_cast<std::size_t>(j)]);
    if (!std::isfinite(acc[static_cast<std::size_t>(j)]))
      throw invalid_input("the acceleration is not finite on the phase-space grid");
  }
  const std::size_t nobs = problem.observable_names.size();
  std::vector<double> phi(nobs * cells);
  {
    std::array<double, 1> q{}, v{};
    std::vector<double> out(nobs);
    for (int l = 0; l < nv; ++l)
      for (int j = 0; j < nq; ++j) {
        q[0] = qs[static_cast<std::size_t>(j)];
        v[0] = vs[static_cast<std::size_t>(l)];
        problem.observe(std::span<const double>(q), std::span<const double>(v), std::span<double>(out));
        for (std::size_t b = 0; b < nobs; ++b) phi[b * cells + static_cast<std::size_t>(l) * nq + j] = out[b];
      }
  }
  const std::vector<double> u = law_detail::potential_on(problem.acceleration, problem.mass, g.q_min, dq, nq);
  const double umin = *std::min_element(u.begin(), u.end());
  std::vector<double> boltz(cells);
  for (int l = 0; l < nv; ++l)
    for (int j = 0; j < nq; ++j) {
      const double vv = vs[static_cast<std::size_t>(l)];
      boltz[static_cast<std::size_t>(l) * nq + j] =
          std::exp(-(u[static_cast<std::size_t>(j)] - umin + 0.5 * problem.mass * vv * vv) / problem.kT);
    }
  const auto averages = [&](const std::vector<double>& rho) {
    std::vector<double> out(nobs, 0.0);
    double mass = 0;
    for (std::size_t c = 0; c < cells; ++c) mass += rho[c];
    for (std::size_t b = 0; b < nobs; ++b) {
      double s = 0;
      const double* f = phi.data() + b * cells;
      for (std::size_t c = 0; c < cells; ++c) s += f[c] * rho[c];
      out[b] = s / mass;
    }
    return out;
  };

  // A density the grid does not hold: its edges or the outer quarter of its spectrum above max_law_defect.
  const auto refuse = [&](double edge, double resolution) {
    throw error("the stationary law of " + sp.name + " at h = " + law_detail::num(o.h) + " is not held by the " +
                std::to_string(nq) + " x " + std::to_string(nv) + " grid (" +
                (edge > max_law_defect ? "density at its edges " + law_detail::sci(edge)
                                       : "spectrum's outer quarter " + law_detail::sci(resolution)) +
                " of its size): use more points, a larger range, or a smaller step (the scheme may be unstable there)");
  };

  StationaryLawResult r;
  r.method = sp.name;
  r.h = o.h;
  r.extrapolate = o.extrapolate;
  r.order = weak_order(sp, o.extrapolate.size());
  {
    const MpeCoefficients m = mpe_coefficients(o.extrapolate);
    for (const auto& ci : m.c) r.coefficients.push_back(ci.get_d());
  }
  r.observable_names = problem.observable_names;
  r.boltzmann = averages(boltz);
  r.averages.assign(nobs, 0.0);

  std::vector<double> rho(cells), rhot(cells), tmp(std::max(nq, nv));
  for (std::size_t mi = 0; mi < o.extrapolate.size(); ++mi) {
    const double tau = o.h / static_cast<double>(o.extrapolate[mi]);
    // The kernel of each stage, one per distinct flow and sub-step (stages that repeat one share it): A: nv
    // shifts of 2 nq - 1 weights; B: nq shifts of 2 nv - 1; O: an nv x nv matrix.
    std::vector<std::vector<double>> kernels;
    std::vector<std::size_t> kernel_of(sp.stages.size());
    for (std::size_t i = 0; i < sp.stages.size(); ++i) {
      const Stage& st = sp.stages[i];
      std::size_t same = 0;
      while (same < i && (sp.stages[same].flow != st.flow || sp.stages[same].fraction != st.fraction)) ++same;
      if (same < i) {
        kernel_of[i] = kernel_of[same];
        continue;
      }
      kernel_of[i] = kernels.size();
      const double t = tau * st.fraction;
      std::vector<double> w;
      if (st.flow == Flow::drift) {
        w.resize(static_cast<std::size_t>(nv) * (2 * nq - 1));
        for (int l = 0; l < nv; ++l)
          law_detail::shift_weights(nq, dq, t * vs[static_cast<std::size_t>(l)],
                                    w.data() + static_cast<std::size_t>(l) * (2 * nq - 1));
      } else if (st.flow == Flow::kick) {
        w.resize(static_cast<std::size_t>(nq) * (2 * nv - 1));
        for (int j = 0; j < nq; ++j)
          law_detail::shift_weights(nv, dv, t * acc[static_cast<std::size_t>(j)],
                                    w.data() + static_cast<std::size_t>(j) * (2 * nv - 1));
      } else {
        const double c = std::exp(-problem.gamma * t), s2 = problem.kT / problem.mass * (1 - c * c);
        const double period = nv * dv;
        std::vector<double> g(static_cast<std::size_t>((nv - 1) / 2));
        for (std::size_t kk = 0; kk < g.size(); ++kk) {
          const double kappa = 2 * pi * static_cast<double>(kk + 1) / period;
          g[kk] = std::exp(-0.5 * s2 * kappa * kappa);
        }
        w.resize(static_cast<std::size_t>(nv) * nv);
        for (int l = 0; l < nv; ++l)
          for (int m = 0; m < nv; ++m)
            w[static_cast<std::size_t>(l) * nv + m] = law_detail::cosine_sum(
                nv, period, vs[static_cast<std::size_t>(l)] - c * vs[static_cast<std::size_t>(m)], g);
      }
      kernels.push_back(std::move(w));
    }
    // rho: rows v (nv x nq); rhot: rows q (nq x nv). `rows_q` says which one holds the density.
    rho = boltz;
    bool rows_q = false;
    const auto step = [&] {
      for (std::size_t i = 0; i < sp.stages.size(); ++i) {
        const Stage& st = sp.stages[i];
        const std::vector<double>& w = kernels[kernel_of[i]];
        if (st.flow == Flow::drift) {
          if (rows_q) {
            law_detail::transpose(nq, nv, rhot, rho);
            rows_q = false;
          }
          for (int l = 0; l < nv; ++l) {
            double* row = rho.data() + static_cast<std::size_t>(l) * nq;
            law_detail::apply_circulant(nq, w.data() + static_cast<std::size_t>(l) * (2 * nq - 1), row, tmp.data());
            std::copy_n(tmp.data(), nq, row);
          }
        } else {
          if (!rows_q) {
            law_detail::transpose(nv, nq, rho, rhot);
            rows_q = true;
          }
          for (int j = 0; j < nq; ++j) {
            double* col = rhot.data() + static_cast<std::size_t>(j) * nv;
            if (st.flow == Flow::kick)
              law_detail::apply_circulant(nv, w.data() + static_cast<std::size_t>(j) * (2 * nv - 1), col, tmp.data());
            else
              law_detail::apply_dense(nv, w.data(), col, tmp.data());
            std::copy_n(tmp.data(), nv, col);
          }
        }
      }
      if (rows_q) {
        law_detail::transpose(nq, nv, rhot, rho);
        rows_q = false;
      }
    };
    // The largest density on the grid's edges relative to its maximum.
    const auto edge_fraction = [&] {
      double top = 0, edge = 0;
      for (std::size_t c = 0; c < cells; ++c) top = std::max(top, std::abs(rho[c]));
      for (int l = 0; l < nv; ++l) {
        edge = std::max(edge, std::abs(rho[static_cast<std::size_t>(l) * nq]));
        edge = std::max(edge, std::abs(rho[static_cast<std::size_t>(l) * nq + nq - 1]));
      }
      for (int j = 0; j < nq; ++j) {
        edge = std::max(edge, std::abs(rho[static_cast<std::size_t>(j)]));
        edge = std::max(edge, std::abs(rho[static_cast<std::size_t>(nv - 1) * nq + j]));
      }
      return edge / top;
    };
    // Iterate to the fixed point: the remaining change is estimated from the geometric decay of the changes
    // over the last `span` steps. A density that reaches the grid's edges on the way is refused at once.
    constexpr int span = 10;
    std::vector<double> prev = averages(rho), cur;
    std::vector<double> changes;
    long n = 0;
    int quiet = 0;
    for (;;) {
      if (n >= o.max_steps)
        throw error("the stationary law of " + sp.name + " at h = " + law_detail::num(tau) + " did not converge in " +
                    std::to_string(o.max_steps) + " steps (the scheme may be unstable at this step)");
      step();
      ++n;
      if (n % 64 == 0) {
        const double edge = edge_fraction();
        if (edge > max_law_defect) refuse(edge, 0);
      }
      cur = averages(rho);
      double d = 0, size = 0;
      for (std::size_t b = 0; b < nobs; ++b) {
        if (!std::isfinite(cur[b]))
          throw error("the stationary law of " + sp.name + " at h = " + law_detail::num(tau) + " became non-finite");
        d = std::max(d, std::abs(cur[b] - prev[b]));
        size = std::max(size, std::abs(cur[b]));
      }
      changes.push_back(d);
      prev = cur;
      bool done = d == 0;
      if (!done && n > 2 * span) {
        // Converging (the changes shrink): the sum of the remaining changes is below tol. Not shrinking: done
        // only when the changes are the rounding of the step itself.
        const double before = changes[changes.size() - 1 - span];
        const double ratio = before > 0 ? std::pow(d / before, 1.0 / span) : 2.0;
        done = ratio < 1 ? d * ratio / (1 - ratio) < o.tol
                         : d <= 16 * std::numeric_limits<double>::epsilon() * std::max(size, 1.0);
      }
      quiet = done ? quiet + 1 : 0;
      if (quiet >= 3) break;
    }
    r.steps.push_back(n);
    r.members.push_back(cur);
    for (std::size_t b = 0; b < nobs; ++b) r.averages[b] += r.coefficients[mi] * cur[b];
    // How well the grid holds this density.
    r.edge = std::max(r.edge, edge_fraction());
    law_detail::transpose(nv, nq, rho, rhot);
    r.resolution =
        std::max({r.resolution, law_detail::outer_spectrum(nv, nq, rho), law_detail::outer_spectrum(nq, nv, rhot)});
    if (r.resolution > max_law_defect || r.edge > max_law_defect) refuse(r.edge, r.resolution);
    if (o.progress) o.progress(mi + 1, o.extrapolate.size());
  }
  r.grid = g;
  return r;
}

}  // namespace nystrom::stochastic
