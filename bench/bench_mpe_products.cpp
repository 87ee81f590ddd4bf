// The n products T_2^{k_i}(h / k_i) of a multi-product step are independent (Chin, sec. II); for an
// expensive force the engine can run them concurrently (EngineOptions::mpe_schedule = concurrent, one
// OpenMP thread per product, each with its own copy of the force functor). This benchmark measures one
// M8 step ({1,2,3,4}: 10 forces) on a Plummer sphere of N = 10 000 particles (softening 1e-4), wall
// time per step, three ways in the same run:
//
//   sequential-1t   products one after the other, the force on 1 thread
//   sequential-Pt   products one after the other, the force on all threads (OpenMP over particles)
//   concurrent-Pt   products on all threads (the force of each product on its own thread)
//
// and prints the speedups of concurrent-Pt over the other two. All three give bitwise the same state
// (checked before timing; tests/engines/test_mpe_schedule.cpp asserts it). --quick: N = 2000.
//
//   bench_mpe_products [--benchmark_repetitions=3]
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "bench_common.hpp"
#include "nystrom/engines/integrator.hpp"
#include "nystrom/methods/catalog.hpp"
#include "nystrom/problems/nbody.hpp"
#include "nystrom/problems/plummer.hpp"

using namespace nystrom;

namespace {

std::size_t g_n = 10000;
constexpr double kEps2 = 1e-4;
constexpr double kStep = 1.0 / 256;

int all_threads() {
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}

const ParticleSet<double>& particles() {
  static const ParticleSet<double> p = [] {
    PlummerOptions opt;
    opt.exact_energy = false;  // timing only
    return plummer_sphere<double>(g_n, 42, opt);
  }();
  return p;
}

enum class Mode { seq1, seqP, concP };

const char* name_of(Mode m) {
  switch (m) {
    case Mode::seq1: return "sequential-1t";
    case Mode::seqP: return "sequential-Pt";
    default: return "concurrent-Pt";
  }
}

auto make(Mode mode) {
  NBodyForce<double> force(particles().m, kEps2);
  EngineOptions opt;
  opt.mpe_schedule = mode == Mode::concP ? MpeSchedule::concurrent : MpeSchedule::sequential;
  opt.mpe_threads = all_threads();
  force.threads = mode == Mode::seq1 ? 1 : all_threads();
  return make_integrator<std::vector<double>>(resolve_method("M8"), force, opt);
}

void bm_step(benchmark::State& state, Mode mode) {
  auto integ = make(mode);
  const State<std::vector<double>> s0 = particles().s;
  for (auto _ : state) {
    State<std::vector<double>> s = s0;
    integ.integrate(s, kStep, 1);
    benchmark::DoNotOptimize(s.q.data());
  }
}

bool check_identical() {
  std::vector<State<std::vector<double>>> out;
  for (Mode m : {Mode::seq1, Mode::seqP, Mode::concP}) {
    auto integ = make(m);
    State<std::vector<double>> s = particles().s;
    integ.integrate(s, kStep, 1);
    out.push_back(s);
  }
  const bool same = out[0].q == out[1].q && out[0].q == out[2].q && out[0].v == out[1].v && out[0].v == out[2].v;
  std::printf("the three schedules give %s states\n", same ? "bitwise identical" : "DIFFERENT");
  return same;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<char*> args;
  for (int i = 0; i < argc; ++i) {
    if (std::string(argv[i]) == "--quick")
      g_n = 2000;
    else
      args.push_back(argv[i]);
  }
  if (!bench::initialize(args, 3)) return 1;  // three repetitions unless told otherwise
  std::printf("M8 on a Plummer sphere, N = %zu, %d threads\n", g_n, all_threads());
  if (!check_identical()) return 1;
  for (Mode m : {Mode::seq1, Mode::seqP, Mode::concP})
    benchmark::RegisterBenchmark(name_of(m), [m](benchmark::State& s) { bm_step(s, m); })
        ->UseRealTime()
        ->Unit(benchmark::kMillisecond)
        ->MinTime(0.5);
  bench::MinTimeReporter reporter(bench::MinTimeReporter::Clock::real, 1, 1);  // seconds per step
  benchmark::RunSpecifiedBenchmarks(&reporter);
  const double* t1 = reporter.best("sequential-1t");
  const double* tp = reporter.best("sequential-Pt");
  const double* tc = reporter.best("concurrent-Pt");
  const double s1 = t1 ? *t1 : 0, sp = tp ? *tp : 0, cp = tc ? *tc : 0;
  if (s1 > 0 && sp > 0 && cp > 0) {
    std::printf("\nM8 step, N = %zu, wall time (minimum over repetitions):\n", g_n);
    std::printf("  sequential products, force on 1 thread:       %9.2f ms\n", s1 * 1e3);
    std::printf("  sequential products, force on %2d threads:     %9.2f ms\n", all_threads(), sp * 1e3);
    std::printf("  concurrent products on %2d threads:            %9.2f ms\n", all_threads(), cp * 1e3);
    std::printf("  speedup of concurrent over sequential (1 thread):  %.2fx\n", s1 / cp);
    std::printf("  speedup of concurrent over sequential (%d threads): %.2fx\n", all_threads(), sp / cp);
  }
  benchmark::Shutdown();
  return 0;
}
