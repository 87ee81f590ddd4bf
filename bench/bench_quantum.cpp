// The quantum split-operator solver (include/nystrom/quantum) against hand-written FFTW loops, 3D 64^3 grid.
//
//   BM_StepGeneric/BM_StepHand   steps of Strang (position Verlet) and of Forest-Ruth through the operator
//                                layer and as a hand-written FFTW loop with the same precomputed exponentials
//                                and the same merging; target: generic / hand <= 1.10.
//   BM_GroundState               imaginary-time ground state of the 3D harmonic oscillator (64^3, box 16) from a
//                                displaced Gaussian, total time tau = 12: the largest step whose energy error
//                                is below 1e-10, found by a short search on the step count (below), then one
//                                timed solve at that step; counters: FFTs (the solver's fft_count), h, error.
//                                Target: M8 or better needs >= 10x fewer FFTs and >= 5x less time than the
//                                second-order split operator (PV).
//   BM_Threads                   M8 steps (real time) with FFTW plans on 1 and 2 threads (wall-clock time).
//
// Run (a few minutes): bench_quantum --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "nystrom/quantum/solve.hpp"

using namespace nystrom;
using namespace nystrom::quantum;

namespace {

constexpr int kGrid = 64;
constexpr double kBox = 16;

struct Setup {
  Grid<double> grid{3, kGrid, kBox};
  std::vector<double> v = sample_potential(grid, named_potential<double>("harmonic"));
};

operators::FlowMethod method(const std::string& name) {
  return operators::resolve_flow_method(name, operators::OperatorStructure::rkn, 53, "double");
}

void BM_StepGeneric(benchmark::State& st, const std::string& name) {
  Setup s;
  SchrodingerFlows<double> flows(s.grid, s.v, TimeKind::real);
  operators::FlowIntegrator<SchrodingerFlows<double>> integ(method(name));
  Field<double> psi = gaussian_packet<double>(s.grid, {1.0}, {0.5});
  const long n = 10;
  integ.integrate(flows, psi, 0.01, n);  // fills the flows' cache of exponentials, as the hand loop's tables
  flows.reset_fft_count();
  for (auto _ : st) {
    integ.integrate(flows, psi, 0.01, n);
    benchmark::DoNotOptimize(psi.data());
  }
  st.SetItemsProcessed(st.iterations() * n);  // steps
  st.counters["ffts_per_step"] = static_cast<double>(flows.fft_count()) / static_cast<double>(st.iterations() * n);
}

/// A hand-written split-operator loop: the scheme's sub-steps with the last merged into the first of the
/// next step, exponentials precomputed once, psi *= table written out, FFTW in place.
void BM_StepHand(benchmark::State& st, const std::string& name) {
  Setup s;
  const auto fm = method(name);
  const auto& sc = std::get<SplittingScheme<bigcomplex>>(fm.data);
  std::vector<std::pair<Flow, double>> steps;
  for (const auto& x : normalized(sc).steps) steps.push_back({x.flow, to_real<double>(x.coef.re)});
  const std::size_t size = s.grid.size();
  const double h = 0.01;
  FftPair<double> fft(s.grid.shape(), FftOptions{});
  std::vector<double> k2(size);
  int idx[3];
  for (std::size_t i = 0; i < size; ++i) {
    s.grid.indices(i, idx);
    double q = 0;
    for (int a = 0; a < 3; ++a) q += s.grid.wavenumber(idx[a]) * s.grid.wavenumber(idx[a]);
    k2[i] = q / 2;
  }
  auto table = [&](const std::vector<double>& w, double c, double extra) {
    Field<double> t(size);
    for (std::size_t i = 0; i < size; ++i) t[i] = extra * std::exp(std::complex<double>(0, -c * h * w[i]));
    return t;
  };
  // tables per sub-step: first, middle ones, merged last+first, last
  std::vector<Field<double>> tabs;
  auto tab_for = [&](Flow f, double c) {
    return f == Flow::drift ? table(k2, c, 1.0 / static_cast<double>(size)) : table(s.v, c, 1.0);
  };
  for (const auto& [f, c] : steps) tabs.push_back(tab_for(f, c));
  const Field<double> joined = tab_for(steps.front().first, steps.front().second + steps.back().second);
  auto mul = [size](Field<double>& psi, const Field<double>& t) {
    double* p = reinterpret_cast<double*>(psi.data());
    const double* q = reinterpret_cast<const double*>(t.data());
    for (std::size_t i = 0; i < size; ++i) {
      const double a = p[2 * i], b = p[2 * i + 1], c = q[2 * i], d = q[2 * i + 1];
      p[2 * i] = a * c - b * d;
      p[2 * i + 1] = a * d + b * c;
    }
  };
  auto apply = [&](Field<double>& psi, Flow f, const Field<double>& t) {
    if (f == Flow::drift) {
      fft.forward(psi);
      mul(psi, t);
      fft.backward(psi);
    } else {
      mul(psi, t);
    }
  };
  Field<double> psi = gaussian_packet<double>(s.grid, {1.0}, {0.5});
  const long n = 10;
  for (auto _ : st) {
    apply(psi, steps.front().first, tabs.front());
    for (long i = 0; i < n; ++i) {
      for (std::size_t j = 1; j + 1 < steps.size(); ++j) apply(psi, steps[j].first, tabs[j]);
      apply(psi, steps.back().first, i + 1 < n ? joined : tabs.back());
    }
    benchmark::DoNotOptimize(psi.data());
  }
  st.SetItemsProcessed(st.iterations() * n);
}

/// The ground-state energy error after tau = 12 in n steps (the excited-state contamination of the displaced
/// Gaussian, 0.125 e^{-2 tau} = 5e-12, is below the target), and the solver's result.
QuantumResult ground_state(const std::string& name, long n, int threads = 1) {
  QuantumProblem<double> p;
  p.dims = 3;
  p.grid = kGrid;
  p.box = kBox;
  p.time = TimeKind::imaginary;
  p.x0 = {0.5};
  p.fft.threads = threads;
  const double tau = 12;
  return solve(p, name, tau / static_cast<double>(n), n);
}

/// The smallest step count n (largest step h = 12 / n), to within 2%, whose energy error is below 1e-10: from
/// n = 6 (h = 2), each failure predicts the next n from the asymptotic error ~ h^{2p} of the Rayleigh quotient
/// (order p), then a bisection closes the bracket. It assumes the error falls monotonically with h near the
/// answer, as it does on this problem for every method benchmarked.
long fewest_steps(const std::string& name, int order) {
  const double target = 1e-10;
  auto error = [&](long n) {
    try {
      const QuantumResult r = ground_state(name, n);
      std::fprintf(stderr, "  %s: n = %ld, h = %.5g, energy error %.3g, %ld FFTs, %.2f s\n", name.c_str(), n, r.dt,
                   std::abs(r.energy - 1.5), r.fft_count, r.seconds);
      return std::abs(r.energy - 1.5);
    } catch (const std::runtime_error&) {  // blown up at too large a step
      return 1.0;
    }
  };
  long lo = 0, hi = 6;  // error(lo) > target (lo = 0: none yet), error(hi) < target once found
  for (double e = error(hi); !(e < target); e = error(hi)) {
    lo = hi;
    const double grow = std::pow(std::max(e, 1e-300) / target, 1.0 / (2.0 * order)) * 1.03;
    hi = std::clamp(static_cast<long>(std::ceil(static_cast<double>(hi) * grow)), hi + 1, 8 * hi);
  }
  while (hi - lo > std::max(1L, hi / 50)) {
    const long mid = (lo + hi) / 2;
    (error(mid) < target ? hi : lo) = mid;
  }
  return hi;
}

void BM_GroundState(benchmark::State& st, const std::string& name) {
  const long n = fewest_steps(name, method(name).info.order);
  QuantumResult r;
  for (auto _ : st) r = ground_state(name, n);  // r is read below
  st.counters["ffts"] = static_cast<double>(r.fft_count);
  st.counters["h"] = r.dt;
  st.counters["energy_error_e12"] = std::abs(r.energy - 1.5) * 1e12;  // in units of 1e-12
}

/// Real-time M8 steps with FFTW plans on `threads` threads (the pointwise products stay on one thread).
void BM_Threads(benchmark::State& st, int threads) {
  Setup s;
  FftOptions opt;
  opt.threads = threads;
  SchrodingerFlows<double> flows(s.grid, s.v, TimeKind::real, 0, opt);
  operators::FlowIntegrator<SchrodingerFlows<double>> integ(method("M8"));
  Field<double> psi = gaussian_packet<double>(s.grid, {1.0}, {0.5});
  const long n = 2;
  integ.integrate(flows, psi, 0.05, n);  // the cache of exponentials
  for (auto _ : st) {
    integ.integrate(flows, psi, 0.05, n);
    benchmark::DoNotOptimize(psi.data());
  }
  st.SetItemsProcessed(st.iterations() * n);
}

}  // namespace

BENCHMARK_CAPTURE(BM_StepGeneric, PV, std::string("PV"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_StepHand, PV, std::string("PV"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_StepGeneric, FR, std::string("FR"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_StepHand, FR, std::string("FR"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Threads, 1, 1)->Unit(benchmark::kMillisecond)->UseRealTime()->Repetitions(3);
BENCHMARK_CAPTURE(BM_Threads, 2, 2)->Unit(benchmark::kMillisecond)->UseRealTime()->Repetitions(3);
BENCHMARK_CAPTURE(BM_GroundState, PV, std::string("PV"))->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK_CAPTURE(BM_GroundState, M8, std::string("M8"))->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK_CAPTURE(BM_GroundState, mpe_vv_1234, std::string("mpe-vv:1,2,3,4"))
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);
BENCHMARK_CAPTURE(BM_GroundState, BC1, std::string("BC1"))->Unit(benchmark::kMillisecond)->Iterations(1);

BENCHMARK_MAIN();
