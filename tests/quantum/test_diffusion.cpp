// The Smoluchowski equation (quantum/smoluchowski.hpp) against closed forms: the Ornstein-Uhlenbeck transition
// density and the observed order of the forward methods, the Boltzmann density as the stationary state of a double
// well, the lowest relaxation rate against an independent finite-difference eigenvalue of the Fokker-Planck
// operator; and the thermal propagators (quantum/thermal.hpp) against the primitive approximation's closed form for
// the harmonic oscillator and the exact Z(beta) = 1 / (2 sinh(beta / 2)), with the observed order in N of the
// extrapolated propagators.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "nystrom/core/error.hpp"
#include "nystrom/quantum/smoluchowski.hpp"
#include "nystrom/quantum/thermal.hpp"

using namespace nystrom;
using namespace nystrom::quantum;

namespace {

/// The Ornstein-Uhlenbeck problem: U = x^2/2, beta = 2, D = 0.5, a Gaussian of width 0.3 at x0 = 1.
SmoluchowskiProblem<double> ou_problem() {
  SmoluchowskiProblem<double> p;
  p.potential = "harmonic";
  p.grid = 128;
  p.box = 12;
  p.beta = 2;
  p.diffusion = 0.5;
  p.x0 = {1.0};
  p.width = 0.3;
  return p;
}

/// The double well (the default potential) on 64 points over a box of 6, from a Gaussian of width 0.2 in the left
/// well, the final density kept.
SmoluchowskiProblem<double> left_well_start() {
  SmoluchowskiProblem<double> p;
  p.grid = 64;
  p.box = 6;
  p.x0 = {-1.0};
  p.width = 0.2;
  p.keep_density = true;
  return p;
}

/// The slope log2(e(n) / e(2n)) of the last pair above the rounding floor, and the errors for the message.
double observed_order(const std::vector<double>& e, double floor, std::string& log) {
  double order = std::nan("");
  for (std::size_t i = 0; i + 1 < e.size(); ++i) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3e ", e[i]);
    log += buf;
    if (e[i + 1] > floor) order = std::log2(e[i] / e[i + 1]);
  }
  return order;
}

/// The k-th smallest eigenvalue (k = 0, 1, ...) of a symmetric tridiagonal matrix (diagonal a, off-diagonal b) by
/// bisection on the Sturm count: the number of negative pivots of the LDL^T factorisation of the matrix - x.
double tridiagonal_eigenvalue(const std::vector<double>& a, const std::vector<double>& b, std::size_t k) {
  auto count_below = [&](double x) {
    std::size_t neg = 0;
    double d = 1;
    for (std::size_t i = 0; i < a.size(); ++i) {
      d = a[i] - x - (i > 0 ? b[i - 1] * b[i - 1] / d : 0.0);
      if (d == 0) d = -1e-300;
      if (d < 0) ++neg;
    }
    return neg;
  };
  double lo = -1, hi = 1;
  for (std::size_t i = 0; i < a.size(); ++i) hi = std::max(hi, a[i] + 2 * std::abs(i < b.size() ? b[i] : 0.0) + 1);
  for (int it = 0; it < 200; ++it) {
    const double mid = (lo + hi) / 2;
    (count_below(mid) > k ? hi : lo) = mid;
  }
  return (lo + hi) / 2;
}

/// The lowest nonzero relaxation rate of rho_t = D (rho' + beta U' rho)' for the double well U = (x^2 - 1)^2 on
/// [-L/2, L/2] with reflecting ends, from the square-root approximation of the generator on m cells: jump rates
/// (D/dx^2) e^{-beta (U_j - U_i)/2} between neighbours (detailed balance with e^{-beta U}, second order in dx); its
/// symmetrised form is tridiagonal with off-diagonal -D/dx^2. Richardson's extrapolation of m and 2m cells.
double fokker_planck_rate(double beta, double d, double box) {
  auto rate = [&](int m) {
    const double dx = box / m;
    auto u = [](double x) { return (x * x - 1) * (x * x - 1); };
    std::vector<double> a(static_cast<std::size_t>(m), 0.0), b(static_cast<std::size_t>(m - 1), -d / (dx * dx));
    for (int i = 0; i < m; ++i) {
      const double x = -box / 2 + (i + 0.5) * dx;
      if (i > 0) a[i] += d / (dx * dx) * std::exp(-beta * (u(x - dx) - u(x)) / 2);
      if (i + 1 < m) a[i] += d / (dx * dx) * std::exp(-beta * (u(x + dx) - u(x)) / 2);
    }
    return tridiagonal_eigenvalue(a, b, 1);
  };
  const double coarse = rate(2000), fine = rate(4000);
  return (4 * fine - coarse) / 3;
}

}  // namespace

// The exact transition density of the Ornstein-Uhlenbeck process: a Gaussian of mean x0 e^{-D beta t} and variance
// s^2 e^{-2 D beta t} + (1 - e^{-2 D beta t}) / beta. Each forward method shows its order in the L1 error of the
// density and in the drift of the mass; the density stays positive.
TEST(Smoluchowski, OrnsteinUhlenbeckTransitionDensityAndObservedOrders) {
  const std::vector<std::pair<std::string, int>> methods = {{"PV", 2}, {"M4", 4},  {"M6", 6},
                                                            {"4A", 4}, {"BC1", 6}, {"AC1", 6}};
  // Gurkan's AC1 and BC1 are of order 5; on a real linear problem the leading error of a method whose complex
  // coefficients come in conjugate pairs is imaginary, so the real part of the density (what the solver returns)
  // is one order better (Gurkan sec. 5)
  for (const auto& [method, order] : methods) {
    std::vector<double> err, drift;
    for (long n = 4; n <= 128; n *= 2) {
      const auto r = smoluchowski(ou_problem(), method, 1.0 / static_cast<double>(n), n);
      EXPECT_EQ(r.exact_solution, "Ornstein-Uhlenbeck");
      err.push_back(r.exact_error);
      drift.push_back(std::abs(r.mass_drift));
      EXPECT_LT(r.negative_mass, 1e-12) << method;
      if (n == 128) {
        // the moments of the exact Gaussian at t = 1
        const double decay = std::exp(-1.0);
        const double tol = order == 2 ? 1e-5 : 1e-8;
        EXPECT_NEAR(r.mean[0], decay, tol) << method;
        EXPECT_NEAR(r.variance[0], 0.09 * decay * decay + (1 - decay * decay) / 2, tol) << method;
        EXPECT_LT(r.imaginary_part, 1e-12) << method;  // rounding of the transforms (and of the complex methods)
      }
    }
    std::string log, dlog;
    const double p = observed_order(err, 1e-12, log);
    std::printf("%-9s order %d observed %.2f (density L1), errors %s\n", method.c_str(), order, p, log.c_str());
    EXPECT_NEAR(p, order, 0.4) << method << " errors " << log;
    EXPECT_LT(err.back(), order == 2 ? 1e-4 : 1e-8) << method;
    const double pd = observed_order(drift, 1e-13, dlog);
    // the mass is <e^{-beta U/2}|psi>: a symmetric method conserves it to its order (the Gaussian's mass drift may
    // cancel to a higher order on the oscillator)
    EXPECT_GT(pd, order - 0.4) << method << " mass drifts " << dlog;
  }
}

// A method with a backward sub-step diverges on a diffusion: refused with one line that names the forward methods.
TEST(Smoluchowski, BackwardMethodsAreRefusedWithOneLine) {
  for (const std::string m : {"FR", "KL8", "Y6", "SS10", "mpe4:1,2,3"}) {
    try {
      smoluchowski(ou_problem(), m, 0.1, 10);
      ADD_FAILURE() << m << " was not refused";
    } catch (const invalid_input& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
      EXPECT_NE(what.find("not positive"), std::string::npos) << what;
      EXPECT_NE(what.find("M4..M16"), std::string::npos) << what;
      EXPECT_NE(what.find("4A"), std::string::npos) << what;
      EXPECT_NE(what.find("BC1"), std::string::npos) << what;
    }
  }
  EXPECT_EQ(smoluchowski(ou_problem(), "", 0.1, 1).method, "M8");
}

// From a Gaussian in the left well the density relaxes to the normalised Boltzmann density e^{-beta U} / Z of the
// double well, computed here from U; the mass stays 1.
TEST(Smoluchowski, DoubleWellRelaxesToTheBoltzmannDensity) {
  const SmoluchowskiProblem<double> p = left_well_start();
  // t = 40: e^{-lambda_1 t} ~ 1e-11. The mass drifts linearly in time with the method's ground-state shift, O(h^8)
  // with error constants as large as |grad W|^2 where the density lives (measured at t = 40: 5e-4 at h = 0.05,
  // 6e-6 at h = 0.025, 3e-8 at h = 0.01)
  const auto r = smoluchowski(p, "M8", 0.01, 4000);
  const Grid<double> g(1, 64, 6.0);
  std::vector<double> rb(64);
  double z = 0;
  for (int i = 0; i < 64; ++i) {
    const double x = g.coordinate(i);
    rb[i] = std::exp(-(x * x - 1) * (x * x - 1));
    z += rb[i] * g.dx();
  }
  double l1 = 0;
  for (int i = 0; i < 64; ++i) l1 += std::abs(r.density[i] - rb[i] / z) * g.dx();
  std::printf("L1 distance to the Boltzmann density %.3e, mass drift %.3e\n", l1, r.mass_drift);
  EXPECT_LT(l1, 1e-7);
  EXPECT_NEAR(r.boltzmann_distance, l1, 1e-12);
  EXPECT_LT(std::abs(r.mass_drift), 1e-7);
  EXPECT_NEAR(r.mean[0], 0.0, 1e-8);
  // at t = 1 it is still far from equilibrium: the left well holds most of the mass
  const auto early = smoluchowski(p, "M8", 0.01, 100);
  EXPECT_LT(early.mean[0], -0.4);
  EXPECT_GT(early.boltzmann_distance, 0.4);
}

// The lowest nonzero relaxation rate of the double well (the Kramers escape: twice the rate of each direction)
// against a finite-difference eigenvalue of the Fokker-Planck generator; the residual bound holds; Kramers'
// high-barrier formula approaches it as beta grows.
TEST(Smoluchowski, RelaxationRateOfTheDoubleWellAgainstFiniteDifferences) {
  double kramers_gap[2];
  int j = 0;
  for (const double beta : {3.0, 6.0}) {
    SmoluchowskiProblem<double> p;
    p.grid = 96;
    p.box = 5;
    p.beta = beta;
    p.diffusion = 0.7;
    p.rates = 2;
    p.width = beta > 3 ? 0.15 : 0.25;  // rho0 e^{beta U/2} must fall towards the edges of the box
    // the step: the rate's error is the square of the eigenvector's, which is O(h^8) with the large constants of a
    // steep W (measured at beta = 6: residual 1.1e-3 at h = 0.02, 1.6e-5 at h = 0.01, rate converged to 1e-11)
    const auto r = smoluchowski(p, "M8", 0.01, 400);
    const double fd = fokker_planck_rate(beta, 0.7, 5.0);
    std::printf("beta %.0f: rate %.12f, finite differences %.12f, residual %.2e, Kramers %.6f, second rate %.6f\n",
                beta, r.rates[0], fd, r.rate_residuals[0], r.kramers_rate, r.rates[1]);
    EXPECT_NEAR(r.rates[0], fd, 1e-8 * fd);
    EXPECT_LT(std::abs(r.rates[0] - fd), r.rate_residuals[0]);
    EXPECT_LT(r.rate_residuals[0], 1e-4);
    EXPECT_GT(r.rates[1], 10 * r.rates[0]);  // the gap: the wells' own relaxation is fast
    kramers_gap[j++] = std::abs(r.kramers_rate / r.rates[0] - 1);
  }
  EXPECT_LT(kramers_gap[1], kramers_gap[0]);
  EXPECT_LT(kramers_gap[1], 0.15);
}

// The rates of the 2D Ornstein-Uhlenbeck process are D beta (n_1 + n_2): D beta (twice), then 2 D beta.
TEST(Smoluchowski, RatesOfTheOrnsteinUhlenbeckProcessIn2D) {
  SmoluchowskiProblem<double> p;
  p.dims = 2;
  p.grid = 48;
  p.box = 16;
  p.potential = "harmonic";
  p.beta = 2;
  p.diffusion = 0.5;
  p.x0 = {0.5, 0.0};
  p.width = 0.7;
  p.rates = 3;
  const auto r = smoluchowski(p, "M6", 0.1, 200);
  ASSERT_EQ(r.rates.size(), 3u);
  EXPECT_NEAR(r.rates[0], 1.0, 1e-9);
  EXPECT_NEAR(r.rates[1], 1.0, 1e-9);
  EXPECT_NEAR(r.rates[2], 2.0, 1e-9);
  EXPECT_EQ(r.exact_solution, "Ornstein-Uhlenbeck");
  EXPECT_LT(r.exact_error, 1e-8);
}

// The 3D Ornstein-Uhlenbeck density: a Gaussian per axis, mean x0_j e^{-D beta t}, with 4A (gradient term in 3D).
TEST(Smoluchowski, OrnsteinUhlenbeckDensityIn3D) {
  SmoluchowskiProblem<double> p;
  p.dims = 3;
  p.grid = 40;
  p.box = 16;
  p.potential = "harmonic";
  p.beta = 2;
  p.diffusion = 0.5;
  p.x0 = {0.5, -0.25, 0.0};
  p.width = 0.7;
  const auto r = smoluchowski(p, "4A", 0.05, 20);
  EXPECT_EQ(r.exact_solution, "Ornstein-Uhlenbeck");
  EXPECT_LT(r.exact_error, 1e-6);
  EXPECT_NEAR(r.mean[0], 0.5 * std::exp(-1.0), 1e-7);
  EXPECT_NEAR(r.mean[1], -0.25 * std::exp(-1.0), 1e-7);
  EXPECT_NEAR(r.mean[2], 0.0, 1e-12);
  EXPECT_LT(std::abs(r.mass_drift), 1e-7);
}

// A user's potential given by its values (derivatives by differences on the grid) gives the built-in result.
TEST(Smoluchowski, PotentialValuesGiveTheBuiltInResult) {
  // differences of order 8 are exact for U (degree 4) and W (degree 6) away from the four points next to the edge,
  // where e^{-beta U} vanishes; 4A uses |grad W|^2 from them too
  for (const std::string method : {"M6", "4A"}) {
    SmoluchowskiProblem<double> p;
    p.grid = 96;
    p.box = 5;
    p.beta = 3;
    p.rates = 1;
    p.x0 = {-1.0};
    p.width = 0.12;
    const auto builtin = smoluchowski(p, method, 0.02, 100);
    const Grid<double> g(1, p.grid, p.box);
    for (int i = 0; i < p.grid; ++i) {
      const double x = g.coordinate(i);
      p.values.push_back((x * x - 1) * (x * x - 1));
    }
    const auto user = smoluchowski(p, method, 0.02, 100);
    EXPECT_NEAR(user.rates[0], builtin.rates[0], 1e-9 * builtin.rates[0]) << method;
    EXPECT_NEAR(user.mean[0], builtin.mean[0], 1e-9) << method;
    EXPECT_NEAR(user.variance[0], builtin.variance[0], 1e-9) << method;
    EXPECT_TRUE(std::isnan(user.kramers_rate));
  }
}

// The reported mass, mean and variance are those of the kept density, the moments per unit mass: at a step where
// the mass drifts measurably (so that dividing by the mass and multiplying by it differ), computed here from the
// density itself.
TEST(Smoluchowski, MomentsAreThoseOfTheKeptDensityPerUnitMass) {
  const SmoluchowskiProblem<double> p = left_well_start();
  const auto r = smoluchowski(p, "M8", 0.05, 200);
  ASSERT_EQ(r.density.size(), 64u);
  const Grid<double> g(1, 64, 6.0);
  double mass = 0, m1 = 0, m2 = 0;
  for (int i = 0; i < 64; ++i) {
    const double x = g.coordinate(i), w = r.density[static_cast<std::size_t>(i)] * g.dx();
    mass += w;
    m1 += x * w;
    m2 += x * x * w;
  }
  const double mean = m1 / mass, var = m2 / mass - mean * mean;
  std::printf("mass %.9f, mean %.9f, variance %.9f\n", mass, mean, var);
  ASSERT_GT(std::abs(mass - 1), 1e-6) << "the mass must drift for this test to tell the moments apart";
  EXPECT_NEAR(r.mass, mass, 1e-13);
  EXPECT_NEAR(r.mass_drift, mass - 1, 1e-13);
  ASSERT_EQ(r.mean.size(), 1u);
  ASSERT_EQ(r.variance.size(), 1u);
  EXPECT_NEAR(r.mean[0], mean, 1e-12);
  EXPECT_NEAR(r.variance[0], var, 1e-12);
}

TEST(Smoluchowski, BadInputIsRefused) {
  auto refused = [](auto change, const std::string& words) {
    SmoluchowskiProblem<double> p = ou_problem();
    change(p);
    try {
      smoluchowski(p, "M4", 0.1, 10);
      ADD_FAILURE() << "accepted; expected: " << words;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  refused([](auto& p) { p.diffusion = 0; }, "diffusion");
  refused([](auto& p) { p.beta = -1; }, "beta");
  refused([](auto& p) { p.potential = "morse"; }, "unknown potential");
  refused([](auto& p) { p.width = 3; }, "does not resolve");  // broader than e^{-beta U/2}: rho0 e^{beta U/2} grows
  refused([](auto& p) { p.grid = 8; }, "at least 16");
  refused([](auto& p) { p.box = 6; }, "larger box");  // e^{-x^2/2} is 0.011 at the edge
  refused([](auto& p) { p.initial.assign(128, -1.0); }, "initial");
  refused([](auto& p) { p.x0 = {1, 2}; }, "x0");
}

// The primitive approximation of the harmonic oscillator (omega = 1) is exactly the propagator of an oscillator
// with cosh(theta) = 1 + eps^2 / 2 per bead, eps = beta / N (match the Gaussian kernels: the off-diagonal
// coefficient 1/eps = 1/sinh(theta) gives sinh(theta/2) = eps/2, and the prefactors agree), so
//   Z_N = sum_n e^{-N theta (n + 1/2)} = 1 / (2 sinh(N theta / 2)),
//   E_N = -d ln Z_N / d beta = (1/2) coth(N theta / 2) / sqrt(1 + (beta / 2N)^2),
// tending to Z = 1 / (2 sinh(beta/2)), E = coth(beta/2) / 2.
TEST(Thermal, PrimitiveApproximationOfTheOscillatorInClosedForm) {
  ThermalProblem<double> p;
  p.beta = 2;
  p.beads = {1, 2, 4, 8, 16, 32};
  const auto r = thermal(p);
  for (const auto& row : r.rows) {
    const double eps = p.beta / static_cast<double>(row.beads),
                 half = static_cast<double>(row.beads) * std::asinh(eps / 2);
    const double z = 1 / (2 * std::sinh(half));
    const double e = 0.5 / std::tanh(half) / std::sqrt(1 + eps * eps / 4);
    EXPECT_NEAR(row.z_primitive / z, 1, 1e-12) << row.beads;
    EXPECT_NEAR(row.energy_primitive, e, 1e-11) << row.beads;
  }
  EXPECT_NEAR(r.z_exact * 2 * std::sinh(1.0), 1, 1e-12);
  EXPECT_NEAR(r.energy_exact, 0.5 / std::tanh(1.0), 1e-12);
  for (std::size_t n = 0; n < 5; ++n) EXPECT_NEAR(r.levels[n], static_cast<double>(n) + 0.5, 1e-11);
}

// The extrapolated propagators over {1,2} and {1,2,3} converge as N^-4 and N^-6 to the exact Z and energy, on the
// oscillator and on the double well (against the grid Hamiltonian's eigenvalues).
TEST(Thermal, ExtrapolatedPropagatorsConvergeAtTheirOrder) {
  for (const std::string potential : {"harmonic", "double-well"}) {
    for (const std::vector<long>& seq : {std::vector<long>{1}, std::vector<long>{1, 2}, std::vector<long>{1, 2, 3}}) {
      ThermalProblem<double> p;
      p.potential = potential;
      p.box = potential == "harmonic" ? 20 : 8;
      p.beta = potential == "harmonic" ? 2 : 1;
      p.beads = {4, 8, 16, 32, 64};
      p.extrapolate = seq;
      const auto r = thermal(p);
      std::vector<double> ez, ee;
      for (const auto& row : r.rows) {
        ez.push_back(std::abs(row.z_extrapolated / r.z_exact - 1));
        ee.push_back(std::abs(row.energy_extrapolated - r.energy_exact));
      }
      std::string lz, le;
      const double pz = observed_order(ez, 1e-12, lz), pe = observed_order(ee, 1e-12, le);
      std::printf("%-11s k = %zu terms: Z order %.2f (%s), E order %.2f (%s)\n", potential.c_str(), seq.size(), pz,
                  lz.c_str(), pe, le.c_str());
      EXPECT_NEAR(pz, 2.0 * static_cast<double>(seq.size()), 0.3) << potential << " " << lz;
      EXPECT_NEAR(pe, 2.0 * static_cast<double>(seq.size()), 0.3) << potential << " " << le;
      EXPECT_EQ(r.order, 2 * static_cast<int>(seq.size()));
    }
  }
}

// The Jacobi eigenvalues behind the exact partition function are those of the second-difference matrix
// (2 - 2 cos(k pi / (n + 1))), at every scale of the matrix: the stopping test is relative to its norm.
TEST(Thermal, JacobiEigenvaluesAtEveryScale) {
  constexpr std::size_t n = 6;
  for (const double scale : {1e-20, 1.0, 1e20}) {
    quantum::detail::Matrix<double> m(n);
    for (std::size_t i = 0; i < n; ++i) {
      m(i, i) = 2 * scale;
      if (i + 1 < n) m(i, i + 1) = m(i + 1, i) = -scale;
    }
    const auto e = quantum::detail::symmetric_eigenvalues(m);
    ASSERT_EQ(e.size(), n);
    for (std::size_t k = 0; k < n; ++k) {
      const double exact = scale * (2 - 2 * std::cos(static_cast<double>(k + 1) * std::numbers::pi / (n + 1)));
      EXPECT_NEAR(e[k], exact, 1e-14 * scale) << "scale " << scale << ", eigenvalue " << k;
    }
  }
}

// The number of beads may be anything from 1 to 1000000 (both ends included); 0 and 1000001 are refused.
TEST(Thermal, BeadsFromOneToAMillion) {
  ThermalProblem<double> p;
  p.grid = 4;
  p.box = 4;
  p.beta = 1;
  p.beads = {1, 1000000};
  const auto r = thermal(p);
  ASSERT_EQ(r.rows.size(), 2u);
  EXPECT_GT(r.rows[1].z_primitive, 0);
  for (const long b : {0L, 1000001L, -5L}) {
    p.beads = {b};
    EXPECT_THROW(thermal(p), std::invalid_argument) << b;
  }
}

TEST(Thermal, BadInputIsRefused) {
  auto refused = [](auto change) {
    ThermalProblem<double> p;
    change(p);
    EXPECT_THROW(thermal(p), std::invalid_argument);
  };
  refused([](auto& p) { p.beta = 0; });
  refused([](auto& p) { p.grid = 1024; });
  refused([](auto& p) { p.beads = {}; });
  refused([](auto& p) { p.beads = {0}; });
  refused([](auto& p) { p.extrapolate = {1, 1}; });
  refused([](auto& p) { p.potential = "nope"; });
  refused([](auto& p) { p.values = {1.0, 2.0}; });
}
