// Cost per force evaluation of the adaptive engines on Kepler (Chin eqs 35-36) in double and long double:
//
//   DP12-adaptive   the embedded RKN12(10) pair of Dormand, El-Mikkawy and Prince (17 stages, each waiting
//                   on the previous force), engines/adaptive_rkn.hpp
//   M12-adaptive    the adaptive multi-product expansion (products in lockstep), engines/adaptive_mpe.hpp
//   hand-VV         a hand-written velocity Verlet loop: one force per step on one dependency chain, the
//                   cost of a force evaluation that waits on the previous one (the baseline)
//
// One benchmark iteration integrates kPeriods periods at e = 0.5 or 0.9 from the apocentre at tolerance
// kTol (DP12 and M12) or with kVvSteps steps per period (hand-VV), the state and the step-size history
// reset every iteration; the force functor counts its calls, so ns/force = CPU time / force evaluations
// (rejected steps and the starting-step estimate included). The final table gives ns per force (minimum
// over repetitions, robust on a shared machine), the ratio to hand-VV in the same precision and the ratio
// of long double to double for each method.
// Targets: DP12-adaptive at most 12 ns per force in double; long double at most 4x double per force.
//
//   bench_adaptive --benchmark_repetitions=5     (the default here: 5 repetitions, 0.2 s each)
#include <benchmark/benchmark.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "bench_common.hpp"
#include "nystrom/engines/adaptive_mpe.hpp"
#include "nystrom/engines/adaptive_rkn.hpp"
#include "nystrom/methods/catalog.hpp"
#include "nystrom/problems/counting_force.hpp"
#include "nystrom/problems/kepler.hpp"

using namespace nystrom;

namespace {

constexpr double kTol = 1e-12;
constexpr int kPeriods = 2;
constexpr long kVvSteps = 2000;  // hand-VV: steps per period

/// The Kepler force, counting its calls (the counter is outside the functor: engines copy it).
using CountingKepler = CountingForce<KeplerForce>;

/// Velocity Verlet, FSAL, the half kicks of consecutive steps merged; returns the force evaluations.
template <class T>
long hand_vv(State<std::array<T, 2>>& s, T h, long n) {
  std::array<T, 2> a;
  KeplerForce{}(s.q, a);
  T x = s.q[0], y = s.q[1], vx = s.v[0] + h / 2 * a[0], vy = s.v[1] + h / 2 * a[1];
  for (long k = 0; k < n; ++k) {
    x += h * vx;
    y += h * vy;
    KeplerForce{}(std::array<T, 2>{x, y}, a);
    const T c = (k + 1 < n) ? h : h / 2;
    vx += c * a[0];
    vy += c * a[1];
  }
  s.q = {x, y};
  s.v = {vx, vy};
  return n + 1;
}

template <class T>
void bm_adaptive(benchmark::State& state, const std::string& method, double ecc) {
  using V = std::array<T, 2>;
  long calls = 0, forces = 0;
  AdaptiveOptions opt;
  opt.rtol = kTol;
  const KeplerProblem<T> prob{T(ecc)};
  const auto s0 = prob.initial_state();
  const T t1 = KeplerProblem<T>::period() * T(kPeriods);
  auto run = [&](auto& integ) {
    for (auto _ : state) {
      integ.reset();
      auto s = s0;
      calls = 0;
      integ.integrate_to(s, T(0), t1);
      forces += calls;
      benchmark::DoNotOptimize(s);
    }
  };
  if (method == "hand-VV") {
    const T h = KeplerProblem<T>::period() / T(kVvSteps);
    for (auto _ : state) {
      auto s = s0;
      forces += hand_vv<T>(s, h, kVvSteps * kPeriods);
      benchmark::DoNotOptimize(s);
    }
  } else if (method == "DP12-adaptive") {
    auto integ = make_adaptive_integrator<V>(resolve_method(method), CountingKepler{&calls}, opt);
    run(integ);
  } else {
    auto integ = make_adaptive_mpe_integrator<V>(resolve_method(method), CountingKepler{&calls}, opt);
    run(integ);
  }
  state.counters["forces"] = benchmark::Counter(static_cast<double>(forces), benchmark::Counter::kAvgIterations);
}

/// Console output plus, per benchmark, the minimum over repetitions of CPU ns per force evaluation.
class ForceReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const auto& r : runs) {
      if (r.run_type != Run::RT_Iteration || r.error_occurred || r.iterations == 0) continue;
      const auto f = r.counters.find("forces");
      if (f == r.counters.end() || !(f->second.value > 0)) continue;
      const double ns = r.cpu_accumulated_time * 1e9 / static_cast<double>(r.iterations) / f->second.value;
      const std::string name = r.run_name.function_name;
      auto it = best_.find(name);
      if (it == best_.end() || ns < it->second) best_[name] = ns;
    }
  }
  void summary() const {
    std::printf("\nKepler, %d periods, tol %.0e; minimum over repetitions of CPU ns per force evaluation\n", kPeriods,
                kTol);
    std::printf("%-28s %10s %10s %14s %10s %14s\n", "method / e", "double", "/ hand-VV", "long double", "/ hand-VV",
                "long / double");
    for (const char* m : {"hand-VV", "DP12-adaptive", "M12-adaptive"})
      for (const char* e : {"0.5", "0.9"}) {
        const std::string key = std::string(m) + "/" + e;
        const double* d = get(key + "/double");
        const double* l = get(key + "/long-double");
        const double* vd = get(std::string("hand-VV/") + e + "/double");
        const double* vl = get(std::string("hand-VV/") + e + "/long-double");
        if (!d || !l || !vd || !vl) continue;
        std::printf("%-28s %10.2f %10.2f %14.2f %10.2f %14.2f\n", key.c_str(), *d, *d / *vd, *l, *l / *vl, *l / *d);
      }
  }

 private:
  const double* get(const std::string& name) const {
    const auto it = best_.find(name);
    return it == best_.end() ? nullptr : &it->second;
  }
  std::map<std::string, double> best_;
};

}  // namespace

int main(int argc, char** argv) {
  for (const std::string m : {"hand-VV", "DP12-adaptive", "M12-adaptive"})
    for (const double e : {0.5, 0.9}) {
      const std::string base = m + "/" + (e == 0.5 ? "0.5" : "0.9");
      benchmark::RegisterBenchmark((base + "/double").c_str(), [m, e](benchmark::State& s) {
        bm_adaptive<double>(s, m, e);
      })->MinTime(0.2);
      benchmark::RegisterBenchmark((base + "/long-double").c_str(), [m, e](benchmark::State& s) {
        bm_adaptive<long double>(s, m, e);
      })->MinTime(0.2);
    }
  if (!bench::initialize({argv, argv + argc}, 5)) return 1;
  ForceReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  reporter.summary();
  benchmark::Shutdown();
  return 0;
}
