// Langevin dynamics (include/nystrom/stochastic/): splitting strings, the counter-based noise, the exact
// Ornstein-Uhlenbeck + harmonic process at a finite time and at equilibrium, the closed-form stationary
// variances of BAOAB and OBABO, their extrapolation, the double well against quadrature of the Boltzmann density,
// and bitwise reproducibility over threads and partitions of the paths.
#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <span>
#include <string>
#include <vector>

#include "nystrom/stochastic/langevin.hpp"
#include "nystrom/stochastic/potentials.hpp"
#include "support/double_well.hpp"

namespace st = nystrom::stochastic;

namespace {

// Harmonic oscillator a = -w^2 q with the observables q, v, q^2, v^2, q v.
struct Harmonic {
  double w2 = 1;
  void operator()(std::span<const double> q, std::span<double> a) const { a[0] = -w2 * q[0]; }
};
struct LinearMoments {
  void operator()(std::span<const double> q, std::span<const double> v, std::span<double> out) const {
    out[0] = q[0];
    out[1] = v[0];
    out[2] = q[0] * q[0];
    out[3] = v[0] * v[0];
    out[4] = q[0] * v[0];
  }
};
using HarmonicProblem = st::LangevinProblem<Harmonic, LinearMoments>;

HarmonicProblem harmonic(double w, double gamma, double kT, double t_end, double q0 = 1, double v0 = 0) {
  return {Harmonic{w * w}, LinearMoments{}, {"q", "v", "q2", "v2", "qv"}, {q0}, {v0}, gamma, kT, 1.0, t_end};
}

const st::ObservableResult& find(const st::LangevinResult& r, const std::string& name) {
  for (const auto& o : r.observables)
    if (o.name == name) return o;
  throw std::runtime_error("no observable " + name);
}

// Agreement with a prediction within z standard errors (plus an allowance for a known bias bound).
void expect_near_stat(const st::Estimate& e, double expected, double z, double allowance, const std::string& what) {
  EXPECT_LE(std::abs(e.value - expected), z * e.stderr_ + allowance)
      << what << ": " << e.value << " +- " << e.stderr_ << " against " << expected;
  EXPECT_GT(e.stderr_, 0) << what;
}

using test_support::chin_coefficients;

}  // namespace

TEST(LangevinSplitting, LettersAndWeights) {
  const auto baoab = st::parse_langevin_splitting("BAOAB");
  ASSERT_EQ(baoab.stages.size(), 5u);
  EXPECT_EQ(baoab.stages[0].flow, st::Flow::kick);
  EXPECT_DOUBLE_EQ(baoab.stages[0].fraction, 0.5);
  EXPECT_DOUBLE_EQ(baoab.stages[1].fraction, 0.5);
  EXPECT_EQ(baoab.stages[2].flow, st::Flow::ou);
  EXPECT_DOUBLE_EQ(baoab.stages[2].fraction, 1.0);
  EXPECT_TRUE(baoab.symmetric);
  EXPECT_EQ(baoab.ou_stages, 1);
  const auto obabo = st::parse_langevin_splitting("OBABO");
  EXPECT_DOUBLE_EQ(obabo.stages[0].fraction, 0.5);
  EXPECT_DOUBLE_EQ(obabo.stages[2].fraction, 1.0);  // the one A takes the whole step
  EXPECT_EQ(obabo.ou_stages, 2);
  EXPECT_EQ(st::parse_langevin_splitting("VRORV").name, "BAOAB");  // OpenMM's letters
  EXPECT_FALSE(st::parse_langevin_splitting("BAO").symmetric);
}

TEST(LangevinSplitting, BadStringsAreRefusedWithOneLine) {
  const std::vector<std::string> bad_strings{"",    "BAXAB", "baoab",  "BAAB",
                                             "AOA", "BOB",   "BAO AB", std::string(65, 'O')};
  for (const std::string& bad : bad_strings) {
    try {
      st::parse_langevin_splitting(bad);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const nystrom::invalid_input& e) {
      const std::string msg = e.what();
      EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
      EXPECT_FALSE(msg.empty());
    }
  }
}

TEST(LangevinSplitting, ExtrapolationNeedsASymmetricSplitting) {
  const auto p = harmonic(1, 1, 1, 1);
  st::LangevinOptions o;
  o.method = "BAO";
  o.h = 0.1;
  o.paths = 10;
  EXPECT_EQ(st::langevin(p, o).order, 1);  // a splitting that is not symmetric has weak order 1
  o.extrapolate = {1, 2};
  EXPECT_THROW(st::langevin(p, o), nystrom::invalid_input);
  o.method = "ABOBA";
  EXPECT_EQ(st::langevin(p, o).order, 4);
  o.extrapolate = {1};
  EXPECT_EQ(st::langevin(p, o).order, 2);
}

TEST(LangevinNoise, CounterBasedNormals) {
  const st::PathNormals a(7, 3), b(7, 3), other(7, 4);
  std::array<double, 6> x{}, y{}, z{};
  a.fill(11, x);
  b.fill(11, y);
  other.fill(11, z);
  EXPECT_EQ(std::memcmp(x.data(), y.data(), sizeof x), 0);  // a pure function of (seed, path, step, index)
  EXPECT_NE(x[0], z[0]);
  // the first five of six are those of a fill of five: the index, not the buffer, decides
  std::array<double, 5> w{};
  a.fill(11, w);
  for (std::size_t i = 0; i < w.size(); ++i) EXPECT_EQ(w[i], x[i]);
  // standard normal moments over 2e5 numbers
  double s = 0, s2 = 0, s4 = 0;
  const long n = 50000;
  std::array<double, 4> u{};
  for (long i = 0; i < n; ++i) {
    a.fill(static_cast<std::uint64_t>(i), u);
    for (double v : u) s += v, s2 += v * v, s4 += v * v * v * v;
  }
  const double m = 4.0 * n;
  EXPECT_NEAR(s / m, 0, 5 / std::sqrt(m));
  EXPECT_NEAR(s2 / m, 1, 5 * std::sqrt(2 / m));
  EXPECT_NEAR(s4 / m, 3, 5 * std::sqrt(96 / m));
}

// The exact process: X = (q, v), dX = M X dt + (0, sqrt(2 gamma kT)) dW, M = [[0, 1], [-w^2, -gamma]]. With
// beta = sqrt(w^2 - gamma^2 / 4): e^{Mt} = e^{-gamma t / 2} (cos(beta t) I + sin(beta t) / beta (M + gamma / 2 I)),
// the mean is e^{Mt} X0 and, since the stationary covariance S = diag(kT / w^2, kT) solves the Lyapunov equation,
// the covariance is S - e^{Mt} S e^{Mt}^T.
TEST(Langevin, HarmonicMeanAndCovarianceAtAFiniteTime) {
  const double w = 1.5, gamma = 1, kT = 0.7, t = 1, q0 = 1, v0 = -0.5;
  const double beta = std::sqrt(w * w - gamma * gamma / 4);
  const double f = std::exp(-gamma * t / 2), cs = std::cos(beta * t), sn = std::sin(beta * t) / beta;
  const double E[2][2] = {{f * (cs + sn * gamma / 2), f * sn}, {-f * sn * w * w, f * (cs - sn * gamma / 2)}};
  const double mq = E[0][0] * q0 + E[0][1] * v0, mv = E[1][0] * q0 + E[1][1] * v0;
  const double S[2] = {kT / (w * w), kT};
  const double cqq = S[0] - (E[0][0] * E[0][0] * S[0] + E[0][1] * E[0][1] * S[1]);
  const double cvv = S[1] - (E[1][0] * E[1][0] * S[0] + E[1][1] * E[1][1] * S[1]);
  const double cqv = -(E[0][0] * E[1][0] * S[0] + E[0][1] * E[1][1] * S[1]);
  for (const char* method : {"BAOAB", "OBABO", "ABOBA"}) {
    st::LangevinOptions o;
    o.method = method;
    o.h = 0.02;  // weak error O(h^2), a few 1e-4, below the statistical error
    o.paths = 8000;
    o.threads = 2;
    const auto r = st::langevin(harmonic(w, gamma, kT, t, q0, v0), o);
    const std::string m = method;
    expect_near_stat(find(r, "q").final, mq, 4.5, 1e-3, m + " E[q]");
    expect_near_stat(find(r, "v").final, mv, 4.5, 1e-3, m + " E[v]");
    expect_near_stat(find(r, "q2").final, cqq + mq * mq, 4.5, 1e-3, m + " E[q^2]");
    expect_near_stat(find(r, "v2").final, cvv + mv * mv, 4.5, 1e-3, m + " E[v^2]");
    expect_near_stat(find(r, "qv").final, cqv + mq * mv, 4.5, 1e-3, m + " E[qv]");
  }
}

// The mean of a linear scheme is deterministic: BAOAB's E[x_N] = (B A O A B)^N x0 with the O flow's mean
// diag(1, e^{-gamma h}) and B = [[1, 0], [-w^2 h / 2, 1]], A = [[1, h / 2], [0, 1]]. At h = 0.5 its bias in E[v_T]
// (0.071) is several standard errors; the two-term extrapolation removes the h^2 term (bias 2e-4), and each member
// run agrees with its own closed form.
TEST(Langevin, ExtrapolatedExpectationAtAFiniteTime) {
  const double w = 1.5, gamma = 1, kT = 0.7, t = 2, q0 = 1, v0 = -0.5, h = 0.5;
  using M2 = std::array<double, 4>;  // row-major 2x2
  const auto mul = [](const M2& a, const M2& b) {
    return M2{a[0] * b[0] + a[1] * b[2], a[0] * b[1] + a[1] * b[3], a[2] * b[0] + a[3] * b[2],
              a[2] * b[1] + a[3] * b[3]};
  };
  const auto scheme_mean = [&](double step, long n) {
    const M2 B{1, 0, -w * w * step / 2, 1}, A{1, step / 2, 0, 1}, O{1, 0, 0, std::exp(-gamma * step)};
    const M2 m = mul(B, mul(A, mul(O, mul(A, B))));
    M2 p{1, 0, 0, 1};
    for (long i = 0; i < n; ++i) p = mul(m, p);
    return std::array<double, 2>{p[0] * q0 + p[1] * v0, p[2] * q0 + p[3] * v0};
  };
  const double beta = std::sqrt(w * w - gamma * gamma / 4);
  const double f = std::exp(-gamma * t / 2), cs = std::cos(beta * t), sn = std::sin(beta * t) / beta;
  const double exact_v = -f * sn * w * w * q0 + f * (cs - sn * gamma / 2) * v0;
  const double exact_q = f * (cs + sn * gamma / 2) * q0 + f * sn * v0;
  st::LangevinOptions o;
  o.h = h;
  o.paths = 6000;
  o.threads = 2;
  o.extrapolate = {1, 2};
  const auto r = st::langevin(harmonic(w, gamma, kT, t, q0, v0), o);
  const auto m1 = scheme_mean(h, 4), m2 = scheme_mean(h / 2, 8);
  expect_near_stat(find(r, "q").member_final[0], m1[0], 4.5, 0, "E[q] at h");
  expect_near_stat(find(r, "v").member_final[0], m1[1], 4.5, 0, "E[v] at h");
  expect_near_stat(find(r, "v").member_final[1], m2[1], 4.5, 0, "E[v] at h/2");
  EXPECT_GT(std::abs(find(r, "v").member_final[0].value - exact_v), 4 * find(r, "v").member_final[0].stderr_);
  expect_near_stat(find(r, "q").final, exact_q, 4.5, 1e-3, "extrapolated E[q]");
  expect_near_stat(find(r, "v").final, exact_v, 4.5, 1e-3, "extrapolated E[v]");
}

// Stationary variances at the end of a step of the harmonic oscillator, independent of gamma: BAOAB samples q
// exactly, <q^2> = kT / w^2, and <v^2> = kT (1 - h^2 w^2 / 4); OBABO samples v exactly, <v^2> = kT, and
// <q^2> = kT / (w^2 (1 - h^2 w^2 / 4)) (B. Leimkuhler, C. Matthews, AMRX 2013; both follow from the Lyapunov
// equation Sigma = M Sigma M^T + N N^T of the scheme's linear map).
TEST(Langevin, HarmonicStationaryVariancesOfBaoabAndObabo) {
  const double w = 2, kT = 0.5, h = 0.5, x = h * h * w * w / 4;  // x = 1/4
  st::LangevinOptions o;
  o.h = h;
  o.paths = 400;
  o.threads = 2;
  const auto p = harmonic(w, 1, kT, 200);
  o.method = "BAOAB";
  const auto b = st::langevin(p, o);
  expect_near_stat(find(b, "q2").average, kT / (w * w), 4.5, 0, "BAOAB <q^2>");
  expect_near_stat(find(b, "v2").average, kT * (1 - x), 4.5, 0, "BAOAB <v^2>");
  EXPECT_GT(std::abs(find(b, "v2").average.value - kT), 10 * find(b, "v2").average.stderr_);  // the bias is seen
  o.method = "OBABO";
  const auto ob = st::langevin(p, o);
  expect_near_stat(find(ob, "q2").average, kT / (w * w * (1 - x)), 4.5, 0, "OBABO <q^2>");
  expect_near_stat(find(ob, "v2").average, kT, 4.5, 0, "OBABO <v^2>");
  EXPECT_GT(std::abs(find(ob, "q2").average.value - kT / (w * w)), 10 * find(ob, "q2").average.stderr_);
}

// Extrapolation of the closed-form biases: OBABO's <q^2>(h) = kT / (w^2 (1 - h^2 w^2 / 4)) has every even power
// of h; the n-term combination leaves sum_i c_i <q^2>(h / k_i) - kT / w^2, O(h^{2n}). BAOAB's <v^2> has the h^2
// term only: the two-term combination is exact. The combination of coupled runs keeps about the statistical
// error of one run, not sqrt(sum c_i^2) (2.3 for 1,2,3) times it.
TEST(Langevin, ExtrapolatedStationaryAveragesOfTheHarmonicOscillator) {
  const double w = 1, kT = 1, h = 1;
  const auto exact_q2 = [&](double step) { return kT / (w * w * (1 - step * step * w * w / 4)); };
  const auto p = harmonic(w, 1, kT, 100);
  st::LangevinOptions o;
  o.method = "OBABO";
  o.h = h;
  o.paths = 1000;
  o.threads = 2;
  double previous_bias = 1e300;
  for (const std::vector<long>& seq : {std::vector<long>{1}, {1, 2}, {1, 2, 3}}) {
    o.extrapolate = seq;
    const auto r = st::langevin(p, o);
    const std::vector<double> k(seq.begin(), seq.end());
    const auto c = chin_coefficients(k);
    double predicted = 0;
    for (std::size_t i = 0; i < k.size(); ++i) {
      predicted += c[i] * exact_q2(h / k[i]);
      EXPECT_NEAR(r.coefficients[i], c[i], 1e-14);
    }
    const auto& q2 = find(r, "q2");
    expect_near_stat(q2.average, predicted, 4.5, 0, "OBABO <q^2> extrapolated with " + std::to_string(seq.size()));
    const double bias = std::abs(predicted - kT / (w * w));
    EXPECT_LT(bias, previous_bias / 10);  // 0.33, 0.022, 0.00064: orders 2, 4, 6
    previous_bias = bias;
    if (seq.size() == 3) {
      EXPECT_LT(q2.average.stderr_, 1.5 * q2.member_average[0].stderr_);
    }
  }
  o.method = "BAOAB";
  o.extrapolate = {1, 2};
  const auto r = st::langevin(p, o);
  expect_near_stat(find(r, "v2").average, kT, 4.5, 0, "BAOAB <v^2> extrapolated");
  expect_near_stat(find(r, "v2").member_average[0], kT * (1 - h * h * w * w / 4), 4.5, 0, "BAOAB <v^2> at h");
}

// Double well U = (q^2 - 1)^2 at kT = 0.5: the extrapolated BAOAB average of q^2 and q^4 against Simpson's rule
// for the Boltzmann density exp(-U / kT) on [-4, 4].
TEST(Langevin, DoubleWellAgainstTheBoltzmannDensity) {
  const double kT = 0.5;
  const auto [m2, m4] = test_support::double_well_moments(kT);
  st::LangevinOptions o;
  o.h = 0.1;
  o.paths = 500;
  o.extrapolate = {1, 2, 3};
  o.threads = 2;
  const auto r = st::langevin(st::builtin_problem_1d("double-well", 1, kT, 60), o);
  expect_near_stat(find(r, "q2").average, m2, 4.5, 0, "<q^2>");
  expect_near_stat(find(r, "q4").average, m4, 4.5, 0, "<q^4>");
  expect_near_stat(find(r, "v2").average, kT, 4.5, 0, "<v^2>");
}

// Observed weak order in the double well U = (q^2 - 1)^2 (kT = 0.5, gamma = 1, from q = 1, v = 0): the mean energy
// averaged over t in [2, 4], from BAOAB at h = 0.25, 0.125, 0.0625 and 0.03125 on coupled paths (each path's noise
// summed for the coarser steps), so that the differences between step sizes have small standard errors. The
// differences D(h) = E[h] - E[h/2] of a weak order-2 scheme shrink 4x per halving: from D(h/2) and D(h/4) the
// observed order is 2 within 3 standard errors (about 0.15). The two-term extrapolation (4 E[h/2] - E[h]) / 3 removes
// the h^2 term: its change from h/2 to h/4 is zero within 3 standard errors, and that standard error is below a
// tenth of BAOAB's own change D(h/2).
TEST(Langevin, DoubleWellMeanEnergyHasWeakOrderTwoAndItsExtrapolationRemovesTheH2Term) {
  const auto prob = st::builtin_problem_1d("double-well", 1, 0.5, 4);
  st::LangevinOptions o;
  o.h = 0.25;
  o.extrapolate = {1, 2, 4, 8};
  const auto plan = st::detail::make_plan(prob, o);
  const std::size_t nk = 4, nobs = prob.observable_names.size();
  std::size_t j = nobs;
  for (std::size_t i = 0; i < nobs; ++i)
    if (prob.observable_names[i] == "energy") j = i;
  ASSERT_LT(j, nobs);
  std::vector<double> finals(nk * nobs), averages(nk * nobs), noise(static_cast<std::size_t>(plan.slots)), obs(nobs);
  std::vector<st::detail::Walker> walkers(nk);
  // per path: BAOAB's D(h), D(h/2), D(h/4) and the change of the extrapolation from h/2 to h/4
  st::RunningStats d1, d2, d3, dx;
  const long paths = 40000;
  for (long p = 0; p < paths; ++p) {
    st::detail::run_path(prob, plan, 1, p, std::span<double>(finals), std::span<double>(averages), noise, walkers, obs);
    const double* e = &averages[j * nk];  // h, h/2, h/4, h/8
    d1.add(e[0] - e[1]);
    d2.add(e[1] - e[2]);
    d3.add(e[2] - e[3]);
    dx.add((4 * e[2] - e[1]) / 3 - (4 * e[3] - e[2]) / 3);
  }
  const auto a = d1.estimate(), b = d2.estimate(), c = d3.estimate(), x = dx.estimate();
  const double order = std::log2(b.value / c.value);
  const double order_err = std::hypot(b.stderr_ / b.value, c.stderr_ / c.value) / std::log(2.0);
  std::printf(
      "[ weak order ] D(h) %.3e +- %.1e, D(h/2) %.3e +- %.1e, D(h/4) %.3e +- %.1e: order %.2f +- %.2f "
      "(%.2f from h); the extrapolation's change %.1e +- %.1e\n",
      a.value, a.stderr_, b.value, b.stderr_, c.value, c.stderr_, order, order_err, std::log2(a.value / b.value),
      x.value, x.stderr_);
  EXPECT_LT(order_err, 0.25);
  EXPECT_NEAR(order, 2.0, 3 * order_err);
  EXPECT_GT(std::abs(b.value), 10 * b.stderr_);
  EXPECT_LT(std::abs(x.value), 3 * x.stderr_);
  EXPECT_LT(x.stderr_, 0.1 * std::abs(b.value));
}

TEST(Langevin, BitwiseTheSameForAnyThreadCountAndPartition) {
  const auto p = st::builtin_problem_1d("double-well", 1, 0.5, 5);
  st::LangevinOptions o;
  o.h = 0.05;
  o.paths = 300;
  o.extrapolate = {1, 2, 3};
  std::vector<st::LangevinResult> runs;
  for (int threads : {1, 2, 4}) {
    o.threads = threads;
    runs.push_back(st::langevin(p, o));
  }
  // a partition at chunk boundaries, merged in path order
  o.threads = 3;
  auto part = st::run_langevin_paths(p, o, 0, 2 * st::chunk_paths);
  part.merge(st::run_langevin_paths(p, o, 2 * st::chunk_paths, o.paths - 2 * st::chunk_paths));
  runs.push_back(st::finish_langevin(p, o, part));
  for (const auto& r : runs) {
    EXPECT_EQ(r.force_evaluations, runs[0].force_evaluations);
    for (std::size_t j = 0; j < r.observables.size(); ++j) {
      const auto& a = r.observables[j];
      const auto& b = runs[0].observables[j];
      EXPECT_EQ(std::memcmp(&a.average, &b.average, sizeof a.average), 0) << a.name;
      EXPECT_EQ(std::memcmp(&a.final, &b.final, sizeof a.final), 0) << a.name;
    }
  }
  EXPECT_THROW(st::run_langevin_paths(p, o, 1, 10), nystrom::invalid_input);  // not at a chunk boundary
}

TEST(Langevin, ForceEvaluationsAreCounted) {
  // BAOAB and OBABO: one force per step plus the first; ABOBA: one per step (its force follows a drift).
  const auto p = harmonic(1, 1, 1, 2);
  st::LangevinOptions o;
  o.h = 0.1;
  o.paths = 7;
  o.extrapolate = {1, 3};
  for (const auto& [method, per_path] :
       {std::pair{"BAOAB", 20 + 1 + 60 + 1}, std::pair{"OBABO", 20 + 1 + 60 + 1}, std::pair{"ABOBA", 20 + 60}}) {
    o.method = method;
    EXPECT_EQ(st::langevin(p, o).force_evaluations, 7LL * per_path) << method;
  }
}

TEST(Langevin, BadInputIsRefused) {
  const auto p = harmonic(1, 1, 1, 1);
  st::LangevinOptions o;
  o.paths = 4;
  o.h = 0.3;  // 1 / 0.3 is not a whole number of steps
  EXPECT_THROW(st::langevin(p, o), nystrom::invalid_input);
  o.h = 0.1;
  o.extrapolate = {1, 1};
  EXPECT_THROW(st::langevin(p, o), nystrom::invalid_input);
  o.extrapolate = {1};
  auto q = p;
  q.gamma = -1;
  EXPECT_THROW(st::langevin(q, o), nystrom::invalid_input);
  q = p;
  q.v0 = {};
  EXPECT_THROW(st::langevin(q, o), nystrom::invalid_input);
  // beyond BAOAB's stability (h w < 2): the paths blow up, and the run says so instead of averaging infinities
  const auto unstable = harmonic(10, 0.01, 1, 100);
  o.h = 0.5;
  try {
    st::langevin(unstable, o);
    ADD_FAILURE() << "an unstable run gave a result";
  } catch (const nystrom::invalid_input& e) {
    EXPECT_NE(std::string(e.what()).find("stability"), std::string::npos) << e.what();
  }
  std::atomic<bool> stop{true};
  o.h = 0.1;
  o.stop = &stop;
  EXPECT_THROW(st::langevin(p, o), nystrom::error);
}
