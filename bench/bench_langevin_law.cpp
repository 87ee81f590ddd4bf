// Exact stationary biases of BAOAB and its multi-product extrapolations in the double well, and the step and force
// evaluations per unit time each needs for a given bias: the scheme's law on a phase-space grid
// (stochastic/splitting_law.hpp), so the biases carry no statistical error. U = (q^2 - 1)^2, kT = 0.5, gamma = 1,
// unit mass; the biases of <q^2> and <q^4> against the Boltzmann averages by the same quadrature.
//
// For each h of a scan (0.40, 0.39, ..., 0.03) one law with the members h, h/2, h/3 gives BAOAB at h and the
// combinations 1,2 and 1,2,3. For a target bias b the program reports, per method, the largest h of the scan at
// which both biases are within b at that h and every smaller h of the scan, refined by bisection when the next
// larger h fails by its bias (not by the grid refusing the law: near BAOAB's stability bound on the quartic wall
// the density leaves any grid), and the force evaluations per unit of simulated time there, sum k_i / h (BAOAB
// reuses its last force). Below the scan BAOAB's step comes from its h^2 coefficient (Richardson from 0.05 and
// 0.025), and the law at that step (if h >= 0.005) is printed beside it. The statistical cost of a given standard error
// is not included: the coupled runs of an extrapolation have 1.35 (1,2) and 2.3 (1,2,3) times the variance of BAOAB's
// (bench_langevin). A plain program (no Google Benchmark harness).
//
//   bench_langevin_law [POINTS [CSV]]     (grid points per axis, odd, default 65; CSV: the scan's rows, one per
//                                          h and method: h,method,forces_per_time,bias_q2,bias_q4, for
//                                          bench/langevin_law_plot.py; written to a temporary file and renamed)
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "nystrom/methods/mpe_coefficients.hpp"
#include "nystrom/stochastic/potentials.hpp"
#include "nystrom/stochastic/splitting_law.hpp"

namespace st = nystrom::stochastic;

namespace {

struct Biases {
  double q2[3], q4[3];  // BAOAB, 1,2, 1,2,3
};

const char* const kNames[3] = {"BAOAB", "1,2", "1,2,3"};
// BAOAB reuses its last force: the combination of 1..n costs 1 + 2 + ... + n forces per step h.
const double kForcesPerStep[3] = {1, 1 + 2, 1 + 2 + 3};

// The biases from one law with the members h, h/2, .., h/members (the combinations beyond `members` are not set).
std::optional<Biases> biases(const st::Problem1D& p, double h, int points, int members = 3) {
  st::StationaryLawOptions o;
  o.h = h;
  o.extrapolate.clear();
  for (int k = 1; k <= members; ++k) o.extrapolate.push_back(k);
  o.grid.nq = o.grid.nv = points;
  st::StationaryLawResult r;
  try {
    r = st::stationary_law(p, o);
  } catch (const nystrom::error&) {
    return std::nullopt;
  }
  Biases b{};
  for (int n = 0; n < members; ++n) {
    // The combination of the members 1..n + 1 with the multi-product coefficients of that sequence.
    std::vector<long> seq;
    for (long k = 1; k <= n + 1; ++k) seq.push_back(k);
    const nystrom::MpeCoefficients c = nystrom::mpe_coefficients(seq);
    double a2 = 0, a4 = 0;
    for (int i = 0; i <= n; ++i) {
      a2 += c.c[static_cast<std::size_t>(i)].get_d() * r.members[i][1];
      a4 += c.c[static_cast<std::size_t>(i)].get_d() * r.members[i][2];
    }
    b.q2[n] = a2 - r.boltzmann[1];
    b.q4[n] = a4 - r.boltzmann[2];
  }
  return b;
}

bool within(const Biases& b, int n, double target) {
  return std::abs(b.q2[n]) <= target && std::abs(b.q4[n]) <= target;
}

}  // namespace

int main(int argc, char** argv) {
  const int points = argc > 1 ? std::atoi(argv[1]) : 65;
  if (points < 9 || points > 1025 || points % 2 == 0 || argc > 3) {
    std::fprintf(stderr, "usage: bench_langevin_law [POINTS: odd, 9..1025 [CSV]]\n");
    return 2;
  }
  const std::string csv = argc > 2 ? argv[2] : "";
  const auto p = st::builtin_problem_1d("double-well", 1, 0.5, 10);
  std::printf("double well, kT = 0.5, gamma = 1: exact stationary biases of <q^2> and <q^4> (grid %d x %d)\n", points,
              points);
  std::printf("%6s  %11s %11s  %11s %11s  %11s %11s\n", "h", "BAOAB q2", "q4", "1,2 q2", "q4", "1,2,3 q2", "q4");
  std::vector<std::pair<double, std::optional<Biases>>> scan;
  for (int i = 40; i >= 3; --i) {
    const double h = i / 100.0;
    const auto b = biases(p, h, points);
    scan.emplace_back(h, b);
    if (!b) {
      std::printf("%6.2f  refused: the density leaves the grid (unstable on the quartic wall)\n", h);
    } else {
      std::printf("%6.2f  %+11.3e %+11.3e  %+11.3e %+11.3e  %+11.3e %+11.3e\n", h, b->q2[0], b->q4[0], b->q2[1],
                  b->q4[1], b->q2[2], b->q4[2]);
    }
    std::fflush(stdout);
  }
  if (!csv.empty()) {
    const std::string tmp = csv + ".tmp";
    {
      std::ofstream out(tmp);
      out << "h,method,forces_per_time,bias_q2,bias_q4\n";
      out.precision(17);
      for (const auto& [h, b] : scan)
        if (b)
          for (int n = 0; n < 3; ++n)
            out << h << ",\"" << kNames[n] << "\"," << kForcesPerStep[n] / h << ',' << b->q2[n] << ',' << b->q4[n]
                << '\n';
      if (!out) {
        std::fprintf(stderr, "cannot write %s\n", tmp.c_str());
        return 1;
      }
    }
    if (std::rename(tmp.c_str(), csv.c_str()) != 0) {
      std::fprintf(stderr, "cannot rename %s to %s\n", tmp.c_str(), csv.c_str());
      return 1;
    }
  }
  // BAOAB's h^2 coefficient: Richardson from 0.05 and 0.025.
  const auto b05 = biases(p, 0.05, points, 1), b025 = biases(p, 0.025, points, 1);
  if (!b05 || !b025) {
    std::printf("the law at h = 0.05 or 0.025 was refused: use more points\n");
    return 1;
  }
  // bias(h) = C h^2 + D h^4 + ...: 16 bias(h / 2) - bias(h) = 3 C h^2 + O(h^6), h = 0.05
  const double c2 = (16 * b025->q2[0] - b05->q2[0]) / (3 * 0.05 * 0.05),
               c4 = (16 * b025->q4[0] - b05->q4[0]) / (3 * 0.05 * 0.05);
  std::printf("BAOAB: bias of <q^2> = %.5g h^2, of <q^4> = %.5g h^2 as h -> 0\n", c2, c4);

  std::printf("\nforce evaluations per unit time for a stationary bias within b (both <q^2> and <q^4>):\n");
  std::printf("%8s  %-7s %8s %12s %14s\n", "b", "method", "h", "forces/time", "BAOAB / this");
  for (const double target : {1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8}) {
    double baoab = NAN;
    for (int n = 0; n < 3; ++n) {
      // The largest h of the scan from which every smaller h is within the target.
      std::size_t first = scan.size();
      for (std::size_t i = scan.size(); i-- > 0;) {
        if (!scan[i].second || !within(*scan[i].second, n, target)) break;
        first = i;
      }
      double h = NAN;
      std::string how = "scan";
      if (first < scan.size()) {
        h = scan[first].first;
        if (first > 0 && scan[first - 1].second) {  // refine between h and the next larger h, which failed by bias
          double lo = h, hi = scan[first - 1].first;
          for (int it = 0; it < 8; ++it) {
            const double mid = 0.5 * (lo + hi);
            const auto b = biases(p, mid, points);
            (b && within(*b, n, target) ? lo : hi) = mid;
          }
          h = lo;
          how = "bisection";
        }
      } else if (n == 0) {
        h = std::sqrt(target / std::max(std::abs(c2), std::abs(c4)));
        const auto b = h >= 0.005 ? biases(p, h, points, 1) : std::nullopt;  // smaller: minutes of steps
        char checked[96];
        if (b)
          std::snprintf(checked, sizeof checked, "h^2 law; its law there: biases %+.3e, %+.3e", b->q2[0], b->q4[0]);
        how = b ? checked : "h^2 law";
      }
      if (std::isnan(h)) {
        std::printf("%8.0e  %-7s below the scan\n", target, kNames[n]);
        continue;
      }
      const double forces = kForcesPerStep[n] / h;
      if (n == 0) baoab = forces;
      std::printf("%8.0e  %-7s %8.4f %12.2f %14.2f   (%s)\n", target, kNames[n], h, forces, baoab / forces,
                  how.c_str());
      std::fflush(stdout);
    }
  }
  return 0;
}
