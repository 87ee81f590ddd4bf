// Bias against cost of Langevin averages with and without extrapolation (include/nystrom/stochastic/): the
// double well U = (q^2 - 1)^2 at kT = 0.5, gamma = 1, unit mass, from q0 = 1, v0 = 0; the time average of q^2
// over the second half of [0, T] (T = 240), averaged over paths, against Simpson's rule for the Boltzmann
// density exp(-U / kT) on [-4, 4] (0.8521361521783344). BAOAB alone and with the 2- and 3-term multi-product
// extrapolations (1,2 and 1,2,3), each at several steps h, every run spending about the same number of force
// evaluations (BUDGET).
//
// Cost. To quote a bias b one needs a standard error of b / 10, so the cost of reaching b is the force
// evaluations F of a run at a step whose bias is b, scaled to that standard error: F (se / (b / 10))^2. For
// BAOAB the bias is fitted, bias = C h^2 (weighted least squares over the points resolved at 10 standard
// errors), giving the step h_b = sqrt(b / |C|); its variance per unit of simulated time, V = se^2 F h (the
// same at every h), gives the cost V / (h_b (b / 10)^2). For an extrapolation the same scaling of each
// measured run gives the cost at that step IF its bias is below b: the program prints the measured bias (with
// its standard error) beside it, since a bias of 1e-4 cannot be resolved with the default budget. The coupled
// runs of an extrapolation drift apart over a long run in the double well, so the combination's standard error
// is larger than one run's (up to sqrt(sum c_i^2)); the scaling counts that.
// A plain program (no Google Benchmark harness: it times whole ensembles).
//
//   bench_langevin [BUDGET [THREADS]]     (default: 2e8 force evaluations per run, all cores)
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "nystrom/stochastic/potentials.hpp"

namespace st = nystrom::stochastic;

namespace {

constexpr double kExact = 0.8521361521783344;  // Simpson, 200001 points on [-4, 4] (scipy.integrate.simpson)
constexpr double kTarget = 1e-4;
constexpr double kTEnd = 240;  // a whole number of steps for every h below

struct Row {
  std::vector<long> seq;
  double h, value, stderr_, seconds;
  long paths;
  long long forces;
};

std::string text(const std::vector<long>& seq) {
  std::string s;
  for (long k : seq) s += (s.empty() ? "" : ",") + std::to_string(k);
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  const double budget = argc > 1 ? std::atof(argv[1]) : 2e8;
  const unsigned hw = std::thread::hardware_concurrency();
  const int threads = argc > 2 ? std::atoi(argv[2]) : static_cast<int>(hw == 0 ? 1 : hw);
  if (!(budget >= 1e5) || threads < 1) {
    std::fprintf(stderr, "usage: bench_langevin [BUDGET >= 1e5 [THREADS >= 1]]\n");
    return 2;
  }
  const auto problem = st::builtin_problem_1d("double-well", 1, 0.5, kTEnd);
  const std::vector<std::pair<std::vector<long>, std::vector<double>>> plan = {
      {{1}, {0.3, 0.25, 0.2}},
      {{1, 2}, {0.3, 0.25, 0.2}},
      {{1, 2, 3}, {0.3, 0.25, 0.2}},
  };
  std::printf(
      "double well, kT = 0.5, gamma = 1: <q^2> over [T/2, T], T = %g, exact %.10f; BAOAB; budget %.3g forces "
      "per run, %d threads\n",
      kTEnd, kExact, budget, threads);
  std::printf("%-8s %6s %8s %12s %12s %10s %11s %10s %8s\n", "extrap", "h", "paths", "forces", "<q^2>", "stderr",
              "bias", "bias/se", "seconds");
  std::vector<Row> rows;
  for (const auto& [seq, steps] : plan) {
    long sum = 0;
    for (long k : seq) sum += k;
    for (double h : steps) {
      st::LangevinOptions o;
      o.h = h;
      o.extrapolate = seq;
      o.threads = threads;
      o.paths = std::max(2L, std::lround(budget / (kTEnd / h * static_cast<double>(sum))));
      const auto t0 = std::chrono::steady_clock::now();
      st::LangevinResult r;
      try {
        r = st::langevin(problem, o);
      } catch (const nystrom::invalid_input& e) {
        std::printf("%-8s %6.3f unstable: %s\n", text(seq).c_str(), h, e.what());
        continue;
      }
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      const auto& q2 = r.observables[1].average;
      rows.push_back({seq, h, q2.value, q2.stderr_, s, o.paths, r.force_evaluations});
      std::printf("%-8s %6.3f %8ld %12lld %12.8f %10.2e %+11.2e %10.1f %8.1f\n", text(seq).c_str(), h, o.paths,
                  r.force_evaluations, q2.value, q2.stderr_, q2.value - kExact,
                  std::abs(q2.value - kExact) / q2.stderr_, s);
      for (std::size_t i = 1; i < seq.size(); ++i) {  // the coupled runs at h / k_i, BAOAB alone
        const auto& m = r.observables[1].member_average[i];
        std::printf("  member h/%ld = %.4f: %12.8f %10.2e %+11.2e %10.1f\n", seq[i], h / static_cast<double>(seq[i]),
                    m.value, m.stderr_, m.value - kExact, std::abs(m.value - kExact) / m.stderr_);
      }
      std::fflush(stdout);
    }
  }
  // BAOAB: bias = C h^2, weighted least squares over the points resolved at 10 standard errors
  double num = 0, den = 0;
  for (const auto& r : rows)
    if (r.seq.size() == 1 && std::abs(r.value - kExact) >= 10 * r.stderr_) {
      const double x = r.h * r.h, w = 1 / (r.stderr_ * r.stderr_);
      num += w * x * (r.value - kExact);
      den += w * x * x;
    }
  const double se_target = kTarget / 10;
  std::printf("\ncost of a bias of %.0e quoted with a standard error of %.0e (force evaluations):\n", kTarget,
              se_target);
  double baoab_cost = NAN;
  if (den > 0) {
    const double c = num / den, h = std::sqrt(kTarget / std::abs(c));
    double v = 0;
    int n = 0;
    for (const auto& r : rows)
      if (r.seq.size() == 1) v += r.stderr_ * r.stderr_ * static_cast<double>(r.forces) * r.h, ++n;
    v /= n;
    baoab_cost = v / (h * se_target * se_target);
    std::printf("  BAOAB   bias = %.4f h^2 (fit), h = %.4f; variance per unit time %.3f: %.3g\n", c, h, v, baoab_cost);
  } else {
    std::printf("  BAOAB   no bias resolved at 10 standard errors: raise BUDGET\n");
  }
  for (const auto& r : rows) {
    if (r.seq.size() == 1) continue;
    const double cost = static_cast<double>(r.forces) * (r.stderr_ / se_target) * (r.stderr_ / se_target);
    std::printf("  %-7s h = %.3f: %.3g (BAOAB / this %.2f) if its bias, measured %+.1e +- %.1e, is below %.0e\n",
                text(r.seq).c_str(), r.h, cost, baoab_cost / cost, r.value - kExact, r.stderr_, kTarget);
  }
  return 0;
}
