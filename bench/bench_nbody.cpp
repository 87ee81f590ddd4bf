// Direct-summation N-body force: nanoseconds per pair interaction per core, at N = 400, 10 000 and
// 100 000 (one force evaluation), single thread and all threads, for the library's kernels and, as the
// baseline measured in the same run, a plain scalar double loop (pair symmetry, one sqrt and one division
// per pair, vectorization disabled).
//
//   ns/pair/core = CPU time of the process (all threads) for one evaluation / (N (N - 1) / 2)
//
// i.e. core-seconds per pair, which stays meaningful on a shared, loaded machine; the wall-clock figure
// (wall time x threads / pairs) is printed beside it in the final table.
//
// A pair is an unordered pair {i, j}: both a_i and a_j receive its contribution (kernels that compute
// N(N-1) ordered interactions are charged per unordered pair too). At the end a table gives every
// kernel's figure and its ratio to the scalar baseline at the same N.
#include <benchmark/benchmark.h>

#include <cmath>
#include <complex>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "nystrom/problems/nbody.hpp"
#include "nystrom/problems/plummer.hpp"

using namespace nystrom;

namespace {

struct System {
  std::vector<double> m, q;
  double eps2 = 0;
};

const System& system_of(std::size_t n) {
  static std::map<std::size_t, System> cache;
  auto it = cache.find(n);
  if (it == cache.end()) {
    PlummerOptions opt;
    opt.exact_energy = n <= 20000;  // the O(N^2) energy rescaling is not needed for timing
    auto p = plummer_sphere<double>(n, 42, opt);
    System s{p.m, p.s.q, 1.0 / (double(n) * double(n))};
    it = cache.emplace(n, std::move(s)).first;
  }
  return it->second;
}

// The baseline: the textbook loop over pairs i < j, scalar (not vectorized: GCC's optimize attribute, which
// clang rejects, or clang's loop pragma).
#if defined(__GNUC__) && !defined(__clang__)
#define NYSTROM_BENCH_NO_VECTORIZE __attribute__((optimize("no-tree-vectorize"), noinline))
#else
#define NYSTROM_BENCH_NO_VECTORIZE __attribute__((noinline))
#endif
NYSTROM_BENCH_NO_VECTORIZE void scalar_force(const System& s, std::vector<double>& a) {
  const std::size_t n = s.m.size();
  const double *x = s.q.data(), *y = x + n, *z = y + n, *m = s.m.data();
  a.assign(3 * n, 0.0);
  double *ax = a.data(), *ay = ax + n, *az = ay + n;
  for (std::size_t i = 0; i < n; ++i)
#ifdef __clang__
#pragma clang loop vectorize(disable) interleave(disable)
#endif
    for (std::size_t j = i + 1; j < n; ++j) {
      const double dx = x[j] - x[i], dy = y[j] - y[i], dz = z[j] - z[i];
      const double r2 = dx * dx + dy * dy + dz * dz + s.eps2;
      const double w = 1.0 / (r2 * std::sqrt(r2));
      ax[i] += m[j] * w * dx;
      ay[i] += m[j] * w * dy;
      az[i] += m[j] * w * dz;
      ax[j] -= m[i] * w * dx;
      ay[j] -= m[i] * w * dy;
      az[j] -= m[i] * w * dz;
    }
}

void set_counters(benchmark::State& st, std::size_t n, int threads) {
  st.counters["pairs"] = 0.5 * double(n) * double(n - 1);
  st.counters["threads"] = threads;
}

void BM_scalar_baseline(benchmark::State& st) {
  const auto& s = system_of(static_cast<std::size_t>(st.range(0)));
  std::vector<double> a;
  for (auto _ : st) {
    scalar_force(s, a);
    benchmark::DoNotOptimize(a.data());
  }
  set_counters(st, s.m.size(), 1);
}

template <NBodyKernel K, bool Complex>
void BM_force(benchmark::State& st) {
  const auto& s = system_of(static_cast<std::size_t>(st.range(0)));
  const int threads = static_cast<int>(st.range(1)) > 0 ? static_cast<int>(st.range(1)) : nbody_max_threads();
  if (K == NBodyKernel::simd && !nbody_simd_available()) {
    st.SkipWithError("no AVX-512 on this CPU");
    return;
  }
  NBodyForce<double> f(s.m, s.eps2);
  f.kernel = K;
  f.threads = threads;
  if constexpr (Complex) {
    std::vector<std::complex<double>> q(s.q.size()), a;
    for (std::size_t i = 0; i < q.size(); ++i) q[i] = {s.q[i], 1e-4 * std::sin(double(i))};
    f(q, a);
    for (auto _ : st) {
      f(q, a);
      benchmark::DoNotOptimize(a.data());
    }
  } else {
    std::vector<double> a;
    f(s.q, a);
    for (auto _ : st) {
      f(s.q, a);
      benchmark::DoNotOptimize(a.data());
    }
  }
  set_counters(st, s.m.size(), threads);
}

// N = 400, 10 000, 100 000 on one thread and (where there are more) on all threads.
void sizes_and_threads(benchmark::internal::Benchmark* b) {
  for (long n : {400L, 10000L, 100000L}) {
    b->Args({n, 1});
    if (nbody_max_threads() > 1) b->Args({n, 0});
  }
}

// One evaluation at N = 100 000 takes seconds: a single iteration there, a few at smaller N.
void config(benchmark::internal::Benchmark* b) { b->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime(); }

}  // namespace

BENCHMARK(BM_scalar_baseline)->Apply(config)->Arg(400)->Arg(10000);
BENCHMARK(BM_scalar_baseline)->Apply(config)->Arg(100000)->Iterations(1);
BENCHMARK(BM_force<NBodyKernel::simd, false>)->Name("simd_real")->Apply(config)->Apply(sizes_and_threads);
BENCHMARK(BM_force<NBodyKernel::generic, false>)->Name("generic_real")->Apply(config)->Args({400, 1})->Args({10000, 1});
// The generic kernel on complex positions (std::complex<double>, the portable path) at the small N only.
BENCHMARK(BM_force<NBodyKernel::generic, true>)->Name("generic_complex")->Apply(config)->Args({400, 1});
BENCHMARK(BM_force<NBodyKernel::simd, true>)
    ->Name("simd_complex")
    ->Apply(config)
    ->Args({400, 1})
    ->Args({10000, 1})
    ->Args({10000, 0});

namespace {

// Console output plus, at the end, each figure as a ratio to the scalar baseline at the same N.
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const auto& r : runs) {
      // Repetitions: each one is a row, the aggregates (mean, stddev, ...) are not; the baseline is the
      // fastest repetition.
      if (r.run_type != Run::RT_Iteration || r.error_occurred || r.iterations <= 0) continue;
      const auto p = r.counters.find("pairs"), t = r.counters.find("threads");
      if (p == r.counters.end() || t == r.counters.end()) continue;
      const std::string name = r.benchmark_name();
      const long n = std::stol(name.substr(name.find('/') + 1));
      const double it = static_cast<double>(r.iterations), pairs = p->second.value;
      const double cpu_ns = r.cpu_accumulated_time / it / pairs * 1e9;
      const double wall_ns = r.real_accumulated_time / it / pairs * 1e9 * t->second.value;
      rows_.push_back({name, n, cpu_ns, wall_ns});
      if (name.rfind("BM_scalar_baseline", 0) == 0 && (!base_.count(n) || cpu_ns < base_[n])) base_[n] = cpu_ns;
    }
  }
  void Finalize() override {
    ConsoleReporter::Finalize();
    std::printf("\n%-52s %14s %18s %16s\n", "kernel", "ns/pair/core", "speed-up vs scalar", "wall x threads");
    for (const auto& r : rows_) {
      const auto b = base_.find(r.n);
      if (b != base_.end())
        std::printf("%-52s %14.3f %17.2fx %16.3f\n", r.name.c_str(), r.ns, b->second / r.ns, r.wall);
      else
        std::printf("%-52s %14.3f %18s %16.3f\n", r.name.c_str(), r.ns, "-", r.wall);
    }
  }

 private:
  struct Row {
    std::string name;
    long n;
    double ns, wall;
  };
  std::vector<Row> rows_;
  std::map<long, double> base_;
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  RatioReporter rep;
  benchmark::RunSpecifiedBenchmarks(&rep);
  benchmark::Shutdown();
  return 0;
}
