// The quantum split-operator solver (include/nystrom/quantum) against hand-written FFTW loops.
//
//   BM_StepGeneric/BM_StepHand   one Strang (position-Verlet) step on a 3D 32^3 grid and one Forest-Ruth
//                                step, through the operator layer and as a hand-written FFTW loop with the
//                                same precomputed exponentials; target: generic / hand <= 1.10.
//   BM_GroundState               imaginary-time ground state of the 3D harmonic oscillator (32^3, box 16):
//                                the largest step (ladder h = 1.6 * 0.8^j) whose energy error is below 1e-10
//                                after tau = 12 from a displaced Gaussian; counters: FFTs, h, error.
//                                Target: M8 or better needs >= 10x fewer FFTs and >= 5x less time than the
//                                second-order split operator (PV).
#include <benchmark/benchmark.h>

#include <cmath>
#include <complex>
#include <cstdio>
#include <string>
#include <vector>

#include "nystrom/quantum/solve.hpp"

using namespace nystrom;
using namespace nystrom::quantum;

namespace {

constexpr int kGrid = 32;
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
  const long n = 20;
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
  const long n = 20;
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

void BM_GroundState(benchmark::State& st, const std::string& name) {
  QuantumProblem<double> p;
  p.dims = 3;
  p.grid = kGrid;
  p.box = kBox;
  p.time = TimeKind::imaginary;
  p.x0 = {0.5};
  const double tau = 12;  // the excited-state contamination 0.125 e^{-2 tau} = 5e-12 of the energy
  double h = 1.6;
  QuantumResult r;
  for (int j = 0; j < 40; ++j, h *= 0.8) {
    const long n = std::lround(tau / h);
    r = solve(p, name, tau / static_cast<double>(n), n);
    if (std::abs(r.energy - 1.5) < 1e-10) break;
  }
  const long n = std::lround(tau / h);
  const double error = std::abs(r.energy - 1.5);
  const long ffts = r.fft_count;
  for (auto _ : st) {
    const QuantumResult timed = solve(p, name, tau / static_cast<double>(n), n);
    benchmark::DoNotOptimize(timed.energy);
  }
  st.counters["ffts"] = static_cast<double>(ffts);
  st.counters["h"] = tau / static_cast<double>(n);
  st.counters["energy_error_e12"] = error * 1e12;  // in units of 1e-12
}

}  // namespace

BENCHMARK_CAPTURE(BM_StepGeneric, PV, std::string("PV"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_StepHand, PV, std::string("PV"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_StepGeneric, FR, std::string("FR"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_StepHand, FR, std::string("FR"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_GroundState, PV, std::string("PV"))->Unit(benchmark::kMillisecond)->Iterations(2);
BENCHMARK_CAPTURE(BM_GroundState, M8, std::string("M8"))->Unit(benchmark::kMillisecond)->Iterations(2);
BENCHMARK_CAPTURE(BM_GroundState, mpe_vv_1234, std::string("mpe-vv:1,2,3,4"))
    ->Unit(benchmark::kMillisecond)
    ->Iterations(2);
BENCHMARK_CAPTURE(BM_GroundState, M10, std::string("M10"))->Unit(benchmark::kMillisecond)->Iterations(2);
BENCHMARK_CAPTURE(BM_GroundState, BC1, std::string("BC1"))->Unit(benchmark::kMillisecond)->Iterations(2);

BENCHMARK_MAIN();
