// Per-step cost of the fixed-step methods of `nystrom bench-peers` (src/experiments/peers.hpp): nystrom's
// VV, M4, M6, M6-5F, A6, M8, KL8, M10, SS10, M12, DP12 (compensated summation on, the default for
// double, and off for VV, M8 and DP12) and Boost.Odeint's velocity_verlet, symplectic_rkn_sb3a_mclachlan,
// symplectic_rkn_sb3a_m4_mclachlan and runge_kutta_fehlberg78, all with the same counting Kepler force.
//
// One iteration integrates one period of Kepler e = 0.5 at 1000 steps per period from the apocentre
// (steppers copied or built afresh, as in bench-peers). Counters: ns per step and ns per force
// evaluation (per force: the overhead of the engine around the force, which costs the same in both).
//
//   bench_peers --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include "experiments/peers.hpp"

namespace {

namespace np = nystrom::peers;

constexpr double kEcc = 0.5;
constexpr long kStepsPerPeriod = 1000;

void per_step(benchmark::State& st, np::MethodSpec m) {
  np::ForceCounter counter;
  const np::Run run = m.make(&counter)(static_cast<double>(kStepsPerPeriod));
  long steps = 0, forces = 0;
  for (auto _ : st) {
    counter.calls = 0;
    nystrom::State<np::Vec2> s;
    long n = 0;
    np::EndTime end;
    run(s, n, end);
    benchmark::DoNotOptimize(s);
    steps += n;
    forces += counter.calls;
  }
  st.counters["ns/step"] =
      benchmark::Counter(static_cast<double>(steps) * 1e-9, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  st.counters["ns/force"] =
      benchmark::Counter(static_cast<double>(forces) * 1e-9, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

const int registered = [] {
  for (auto& m : np::peer_methods(kEcc, 1))
    if (!m.adaptive) {
      const std::string name = m.library + "/" + m.label;
      benchmark::RegisterBenchmark(name.c_str(), per_step, m)->Unit(benchmark::kMicrosecond);
    }
  return 0;
}();

}  // namespace

BENCHMARK_MAIN();
