// Cost per step of M8 (the {1,2,3,4} PV multi-product method, Chin eq 17; 10 forces per step) on
// Kepler (Chin eqs 35-36, e = 0.9) in every precision, relative to double in the same run:
//
//   double, long-double, float128 (libquadmath), dd and qd (libqd), mpfr:113 and mpfr:256 (MPFR
//   through Boost.Multiprecision)
//
// The engine is the same generic code in every case (make_integrator<std::array<T, 2>>); only the
// scalar type differs. One benchmark iteration integrates a batch of kSteps steps from the apocentre
// (h = 2 pi / kSteps, one period per batch), the state reset every iteration.
// The baseline is double without compensated summation, like every wider type (the library's
// default compensates float and double only: EngineOptions::compensated); the default double,
// compensated, is listed as well ("double+comp").
//
// Before benchmarking, every precision's final state after one period is checked against double's
// (same method and step, so they must agree to double's rounding). After the run, a table gives the
// CPU time per step (minimum over repetitions, robust on a shared machine) and the ratio to double.
// Target: double-double at most 10x double per step. Double-double multiplication needs
// an exact product a*b = p + e: with hardware FMA (built with -march=native, CMake option
// NYSTROM_NATIVE) that is two instructions, without it Dekker's splitting (17 flops); the summary says
// which one this build uses. In dd and qd the force's 1/r^3 comes from inv_r3 (core/extended.hpp: a
// double seed and one correction, no libqd square root or division), and dd's products are forced
// inline (the out-of-line calls cost a fifth of a step). Measured (minimum over 5 repetitions, two
// runs, default build): dd 8.0-9.6x double; 14.8x with libqd's own square root, division and
// out-of-line products.
//
//   bench_precision --benchmark_repetitions=5     (the default here: 5 repetitions, 0.2 s each)
#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "bench_common.hpp"
#include "nystrom/core/precision.hpp"
#include "nystrom/engines/integrator.hpp"
#include "nystrom/methods/catalog.hpp"
#include "nystrom/problems/kepler.hpp"

using namespace nystrom;

namespace {

constexpr double kEcc = 0.9;
constexpr long kSteps = 2000;  // per batch: one period at h = 2 pi / 2000
const char* const kMethod = "M8";

const std::vector<std::string>& precisions() {
  static const std::vector<std::string> p{"double", "double+comp", "long-double", "float128",
                                          "dd",     "qd",          "mpfr:113",    "mpfr:256"};
  return p;
}

/// One period of M8 in precision T from the apocentre; the final state in double.
template <class T>
std::array<double, 4> one_period() {
  auto integ = make_integrator<std::array<T, 2>>(resolve_method(kMethod), KeplerForce{});
  auto s = KeplerProblem<T>(T(kEcc)).initial_state();
  integ.integrate(s, KeplerProblem<T>::period() / T(kSteps), kSteps);
  return {as_double(s.q[0]), as_double(s.q[1]), as_double(s.v[0]), as_double(s.v[1])};
}

void bm_precision(benchmark::State& state, const std::string& precision) {
  const bool comp = precision == "double+comp";
  dispatch_precision(comp ? std::string("double") : precision, [&](auto tag) {
    using T = typename decltype(tag)::type;
    EngineOptions opt;
    opt.compensated = comp ? Compensation::on : Compensation::off;
    auto integ = make_integrator<std::array<T, 2>>(resolve_method(kMethod), KeplerForce{}, opt);
    const KeplerProblem<T> prob{T(kEcc)};
    const auto s0 = prob.initial_state();
    const T h = KeplerProblem<T>::period() / T(kSteps);
    for (auto _ : state) {
      auto s = s0;
      integ.integrate(s, h, kSteps);
      benchmark::DoNotOptimize(s);
    }
    state.SetItemsProcessed(state.iterations() * kSteps);
    return 0;
  });
}

bool check_agreement() {
  const auto ref = one_period<double>();
  bool ok = true;
  for (const auto& p : precisions()) {
    if (p == "double+comp") continue;
    const auto x = dispatch_precision(p, [](auto tag) { return one_period<typename decltype(tag)::type>(); });
    double diff = 0;
    for (int k = 0; k < 4; ++k) diff = std::max(diff, std::abs(x[k] - ref[k]));
    std::printf("check %-12s final state after one period vs double: max |difference| = %.2e\n", p.c_str(), diff);
    if (!(diff < 1e-9)) {
      std::fprintf(stderr, "error: %s does not reproduce double's one-period state\n", p.c_str());
      ok = false;
    }
  }
  return ok;
}

/// The summary: minimum CPU time per step of every benchmark (bench_common.hpp), ratios to double.
class SummaryReporter : public bench::MinTimeReporter {
 public:
  SummaryReporter() : MinTimeReporter(Clock::cpu, static_cast<double>(kSteps), 1e9) {}
  void summary() const {
    std::printf("\n%s on Kepler e = %.1f, %ld steps per batch; minimum over repetitions of CPU time per step\n",
                kMethod, kEcc, kSteps);
#ifdef __FMA__
    std::printf("built with hardware FMA: double-double products by fma\n");
#else
    std::printf("built without FMA: double-double products by Dekker's splitting (see NYSTROM_NATIVE)\n");
#endif
    const double* base = best("M8/double");
    std::printf("%-12s %12s %10s\n", "precision", "ns/step", "/ double");
    for (const auto& p : precisions()) {
      const double* t = best("M8/" + p);
      if (!t) continue;
      if (!base) {
        std::printf("%-12s %12.1f %10s\n", p.c_str(), *t, "-");
      } else {
        const double ratio = *t / *base;
        std::printf("%-12s %12.1f %10.2f%s\n", p.c_str(), *t, ratio,
                    p == "dd" && ratio > 10 ? "  (target for dd: <= 10)" : "");
      }
    }
  }
};

}  // namespace

int main(int argc, char** argv) {
  for (const auto& p : precisions())
    benchmark::RegisterBenchmark(("M8/" + p).c_str(), [p](benchmark::State& s) { bm_precision(s, p); })->MinTime(0.2);
  if (!bench::initialize({argv, argv + argc}, 5)) return 1;  // five repetitions unless told otherwise
  if (!check_agreement()) return 1;
  SummaryReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  reporter.summary();
  benchmark::Shutdown();
  return 0;
}
