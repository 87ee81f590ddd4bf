// A charged particle in an ideal Penning trap (velocity/solve.hpp: uniform B along z with wc = 1, the quadrupole
// E = kappa (x/2, y/2, -z), kappa = 0.02) over 1e4 gyrations: the exact gyration flow (velocity/flows.hpp) under
// the multi-product expansion of order 8 (M8: mpe 1,2,3,4 over drift-kick-drift, 10 force evaluations per step)
// against the Boris pusher (the baseline, below: one force evaluation per step, in its synchronised
// drift-kick-rotate-kick-drift form) at the same number of force evaluations.
//
// The phase error is measured on the exact solution's three modes: the final (x + i y, its derivative) and
// (z, z') are split into the modified cyclotron, magnetron and axial amplitudes, and the error is the largest
// |arg(numerical amplitude / exact amplitude)| of the three (radians). The table gives it for both and their
// ratio at several budgets of force evaluations per gyration; then Google Benchmark times one force evaluation's
// worth of each (ns per force evaluation; the ratio Boris / M8 in the same run).
//
//   bench_velocity                       (the default here: 3 repetitions)
#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <cstdio>
#include <string>
#include <vector>

#include "bench_common.hpp"
#include "nystrom/velocity/solve.hpp"

using namespace nystrom::velocity;

namespace {

constexpr double kWc = 1, kKappa = 0.02, kGyrations = 1e4;
const double kPi = std::acos(-1.0);

struct State {
  double q[3], v[3];
};

const State kStart{{1, 0, 0.5}, {0, 1, 0.1}};

void quadrupole(const double* q, double* a) {
  a[0] = kKappa * q[0] / 2;
  a[1] = kKappa * q[1] / 2;
  a[2] = -kKappa * q[2];
}

/// The Boris pusher, synchronised: half drift, half kick, the Boris rotation (angle 2 atan(wc h / 2)), half kick,
/// half drift. One force evaluation per step.
void boris(State& s, double h, long steps) {
  const double t = kWc * h / 2, f = 2 * t / (1 + t * t);  // b along z: t = (0, 0, wc h / 2)
  double a[3];
  for (long n = 0; n < steps; ++n) {
    for (int i = 0; i < 3; ++i) s.q[i] += h / 2 * s.v[i];
    quadrupole(s.q, a);
    for (int i = 0; i < 3; ++i) s.v[i] += h / 2 * a[i];
    // v' = v + v x t, v+ = v + v' x s (t, s along z)
    const double px = s.v[0] + s.v[1] * t, py = s.v[1] - s.v[0] * t;
    s.v[0] += py * f;
    s.v[1] -= px * f;
    for (int i = 0; i < 3; ++i) s.v[i] += h / 2 * a[i];
    for (int i = 0; i < 3; ++i) s.q[i] += h / 2 * s.v[i];
  }
}

/// The three modes' complex amplitudes of a state (the exact solution's decomposition, velocity/solve.hpp).
std::array<std::complex<long double>, 3> modes(const double* q, const double* v) {
  using C = std::complex<long double>;
  const long double wc = kWc, kappa = kKappa;
  const long double root = std::sqrt(wc * wc - 2 * kappa), wp = (wc + root) / 2, wm = (wc - root) / 2;
  const long double wz = std::sqrt(kappa);
  const C i(0, 1), u(q[0], q[1]), du(v[0], v[1]);
  const C a = (i * du - wm * u) / (wp - wm);
  return {a, u - a, C(q[2], -v[2] / wz)};
}

double phase_error(const State& s, const Vec3<long double>& qe, const Vec3<long double>& ve) {
  const double qd[3] = {double(qe[0]), double(qe[1]), double(qe[2])},
               vd[3] = {double(ve[0]), double(ve[1]), double(ve[2])};
  const auto num = modes(s.q, s.v), ex = modes(qd, vd);
  double e = 0;
  for (int k = 0; k < 3; ++k) e = std::max(e, static_cast<double>(std::abs(std::arg(num[k] / ex[k]))));
  return e;
}

MagneticProblem<double> trap() {
  return penning<double>(kWc, kKappa, {kStart.q[0], kStart.q[1], kStart.q[2]}, {kStart.v[0], kStart.v[1], kStart.v[2]});
}

void accuracy_table() {
  const double span = kGyrations * 2 * kPi / kWc;
  const auto exact = penning<long double>(kWc, kKappa, {1, 0, 0.5L}, {0, 1, 0.1L});
  Vec3<long double> qe = exact.q0, ve = exact.v0;
  exact.exact(static_cast<long double>(span), qe, ve);
  std::printf("Penning trap, wc = 1, kappa = 0.02, %.0f gyrations: phase error (radians) at equal force evaluations\n",
              kGyrations);
  std::printf("%12s %14s %14s %14s %12s\n", "evals/gyr", "Boris", "gyration M8", "ratio", "M8 evals");
  for (long per : {1000L, 2000L, 4000L}) {
    State b = kStart;
    const long nb = static_cast<long>(per * kGyrations);
    boris(b, span / static_cast<double>(nb), nb);
    const long nm = nb / 10;  // M8: 10 force evaluations per step
    const FlowResult r = solve(trap(), "M8", span / static_cast<double>(nm), nm);
    State m;
    for (int i = 0; i < 3; ++i) {
      m.q[i] = r.q[static_cast<std::size_t>(i)];
      m.v[i] = r.v[static_cast<std::size_t>(i)];
    }
    const double eb = phase_error(b, qe, ve), em = phase_error(m, qe, ve);
    std::printf("%12ld %14.3e %14.3e %14.3e %12ld\n", per, eb, em, eb / em, r.force_evals);
  }
  std::printf("\n");
}

constexpr long kBatch = 10000;  // force evaluations per timed iteration

void BM_Boris(benchmark::State& st) {
  State s = kStart;
  for (auto _ : st) {
    boris(s, 2 * kPi / 100, kBatch);
    benchmark::DoNotOptimize(s);
  }
}

void BM_GyrationM8(benchmark::State& st) {
  const auto p = trap();
  const auto fm = resolve_velocity_method("M8", 53, "double");
  MagneticFlows<double> flows(p.b, p.force);
  nystrom::operators::FlowIntegrator<MagneticFlows<double>> integ(fm);
  std::vector<double> s{1, 0, 0.5, 0, 1, 0.1};
  for (auto _ : st) {
    integ.integrate(flows, s, 2 * kPi / 10, kBatch / 10);
    benchmark::DoNotOptimize(s.data());
  }
}

BENCHMARK(BM_Boris)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_GyrationM8)->Unit(benchmark::kMicrosecond);

}  // namespace

int main(int argc, char** argv) {
  accuracy_table();
  std::vector<char*> args(argv, argv + argc);
  std::string reps = "--benchmark_repetitions=3";
  bool has_reps = false;
  for (int i = 1; i < argc; ++i) has_reps |= std::string(argv[i]).rfind("--benchmark_repetitions", 0) == 0;
  if (!has_reps) args.push_back(reps.data());
  int n = static_cast<int>(args.size());
  benchmark::Initialize(&n, args.data());
  nystrom::bench::MinTimeReporter rep(nystrom::bench::MinTimeReporter::Clock::cpu, static_cast<double>(kBatch), 1e9);
  benchmark::RunSpecifiedBenchmarks(&rep);
  const double* b = rep.best("BM_Boris");
  const double* m = rep.best("BM_GyrationM8");
  if (b && m)
    std::printf("\nns per force evaluation: Boris %.2f, gyration M8 %.2f (M8 / Boris %.2f)\n", *b, *m, *m / *b);
  return 0;
}
