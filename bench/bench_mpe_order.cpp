// Work-precision of the adaptive multi-product expansion with order control (MPE-adaptive) against the
// fixed-order adaptive ones (M8..M16-adaptive), engines/adaptive_mpe.hpp, on Kepler (Chin eqs 35-36) over 100
// periods in double: for tolerances 10^-5 down to 10^-14.75 (four per decade) each method integrates from the
// apocentre (best wall time of 3 runs); the final position error is taken against the exact solution in long
// double. The table gives, per target error (1e-6, 1e-9, 1e-12, 1e-13), the least time of a run of each method
// that reached it, and the ratio (best fixed-order time) / (MPE-adaptive time), all from the same run.
// A plain program (no Google Benchmark harness: it times whole integrations, not a kernel).
//
//   bench_mpe_order [ECC ...]     (default: 0.9 0.5)
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "nystrom/engines/adaptive_mpe.hpp"
#include "nystrom/methods/catalog.hpp"
#include "nystrom/problems/kepler.hpp"
#include "nystrom/problems/reference.hpp"

using namespace nystrom;

namespace {

using V = std::array<double, 2>;
constexpr long kPeriods = 100;
constexpr int kReps = 3;
const std::vector<std::string> kMethods = {"M8-adaptive",  "M10-adaptive", "M12-adaptive",
                                           "M14-adaptive", "M16-adaptive", "MPE-adaptive"};
const std::vector<double> kTargets = {1e-6, 1e-9, 1e-12, 1e-13};

void sweep(double ecc) {
  const KeplerProblem<double> prob(ecc);
  const double t_end = KeplerProblem<double>::period() * kPeriods;
  std::vector<std::vector<double>> best(kMethods.size(), std::vector<double>(kTargets.size(), INFINITY));
  for (int it = 0; it < 40; ++it) {
    const double tol = std::pow(10.0, -5.0 - 0.25 * it);
    for (std::size_t m = 0; m < kMethods.size(); ++m) {
      AdaptiveOptions opt;
      opt.rtol = tol;
      const MethodDef def = resolve_method(kMethods[m]);
      double seconds = INFINITY, err = 0;
      for (int rep = 0; rep < kReps; ++rep) {
        auto ai = make_adaptive_mpe_integrator<V>(def, KeplerForce{}, opt);
        auto s = prob.initial_state();
        const auto t0 = std::chrono::steady_clock::now();
        ai.integrate_to(s, 0.0, t_end);
        const auto t1 = std::chrono::steady_clock::now();
        seconds = std::min(seconds, std::chrono::duration<double>(t1 - t0).count());
        // against the exact orbit of the double start at t_end (problems/reference.hpp)
        err = kepler_reference_errors(prob.initial_state(), s, t_end).position;
      }
      for (std::size_t k = 0; k < kTargets.size(); ++k)
        if (err <= kTargets[k]) best[m][k] = std::min(best[m][k], seconds);
    }
  }
  std::printf("Kepler e = %g, %ld periods: least time (ms) to a final position error <= target\n%-22s", ecc, kPeriods,
              "method");
  for (double t : kTargets) std::printf(" %9.0e", t);
  std::printf("\n");
  for (std::size_t m = 0; m < kMethods.size(); ++m) {
    std::printf("%-22s", kMethods[m].c_str());
    for (double b : best[m]) std::printf(" %9.3f", b * 1e3);
    std::printf("\n");
  }
  std::printf("%-22s", "best fixed / MPE-adapt");
  for (std::size_t k = 0; k < kTargets.size(); ++k) {
    double fixed = INFINITY;
    for (std::size_t m = 0; m + 1 < kMethods.size(); ++m) fixed = std::min(fixed, best[m][k]);
    const double oc = best.back()[k];
    if (std::isfinite(fixed) && std::isfinite(oc))
      std::printf(" %9.2f", fixed / oc);
    else
      std::printf(" %9s", "-");
  }
  std::printf("\n\n");
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<double> eccs;
  for (int i = 1; i < argc; ++i) {
    char* end = nullptr;
    const double e = std::strtod(argv[i], &end);
    if (end == argv[i] || *end != '\0' || !(e >= 0 && e < 1)) {
      std::fprintf(stderr, "bench_mpe_order: error: eccentricity must be a number in [0, 1), got '%s'\n", argv[i]);
      return 2;
    }
    eccs.push_back(e);
  }
  if (eccs.empty()) eccs = {0.9, 0.5};
  for (double e : eccs) sweep(e);
  return 0;
}
