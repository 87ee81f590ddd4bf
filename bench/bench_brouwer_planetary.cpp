// Brouwer's law on Hairer's outer solar system in double, up to 1e6 Jupiter periods (1.19e7 years): the relative
// energy error should grow as t^(1/2) and Jupiter's position error as t^(3/2) once the truncation lies below the
// round-off, with no linear drift (Brouwer, Astron. J. 56 (1951) 9). Brouwer's law describes the spread of runs
// whose roundings differ: the program runs K realizations (bench/brouwer_planetary.hpp: the planets' initial
// positions scaled by 1 + r 2^-50) and reports the root mean square of each error over them; a single run's error
// wanders about that law. The system is moved to its centre-of-mass frame first (planetary::barycentric; Hairer's
// barycentre moves 2.5 AU per thousand years, which over 1e7 years would cost the direct method every digit of its
// position differences) and rounded to double; every run of a realization starts from that state, with its masses
// and G.
//
// Runs: SABA(10,6,4) (Blanes et al. 2013, the cheapest Wisdom-Holman map on this problem) at 150 days, where its
// truncation (long double: 3e-15 in energy over 1e5 years) lies below its round-off (1.5e-13), plain (the default)
// and with compensated summation of its drifts and kicks (PropagateOptions::compensated), and DP12-adaptive on the
// Cartesian equations at the tightest tolerance double accepts. The reference of each realization is the same
// map with the same steps in long double, from the same initial state: against it the map's position error is its
// round-off alone; for DP12-adaptive and IAS15 it is accurate to its truncation's phase error (about 2e-8 AU after
// 1e6 periods, from runs at 100 and 75 days), far below what they are measured at.
//
// Output times: every 29 steps of 150 days (4350 days, 1.004 Jupiter periods) times 1, 2, 5, 10, ...; the tables
// give the time in Jupiter periods (4332.59 days). The energy error is computed in long double, the position is
// Jupiter's relative to the Sun, in AU. Slopes of log error against log time are fitted over the last three decades.
//
//   bench_brouwer_planetary [--periods N (1e6)] [--realizations K (1)] [--csv FILE] [--reference-csv FILE]
//
// --reference-csv writes the reference positions (realization, time in days, x, y, z with 21 digits) for the IAS15
// driver in bench/rebound, which runs REBOUND's IAS15 from the same states to the same times.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <future>
#include <string>
#include <vector>

#include <mpfr.h>

#include "brouwer_common.hpp"
#include "brouwer_planetary.hpp"
#include "nystrom/engines/adaptive_rkn.hpp"
#include "nystrom/methods/catalog.hpp"
#include "nystrom/planetary/system.hpp"
#include "nystrom/planetary/wisdom_holman.hpp"

namespace {

using namespace nystrom;
using namespace nystrom::planetary;
using bench::brouwer_time;
using bench::kBrouwerMapStep;
using bench::kStepsPerOutput;
using LD = long double;

const std::string kMap = "SABA(10,6,4)";

struct Sample {
  LD energy = 0;
  Vec3<LD> jupiter{};  // relative to the Sun
};

template <class R>
Sample sample(const PlanetarySystem<LD>& sys, const std::vector<Vec3<R>>& x, const std::vector<Vec3<R>>& v) {
  std::vector<Vec3<LD>> xl(x.size()), vl(v.size());
  for (std::size_t i = 0; i < x.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      xl[i][k] = x[i][k];
      vl[i][k] = v[i][k];
    }
  Sample s;
  s.energy = energy(sys.G, sys.mass, xl, vl);
  for (int k = 0; k < 3; ++k) s.jupiter[k] = xl[1][k] - xl[0][k];
  return s;
}

/// The map over every output (output m after m * kStepsPerOutput steps).
template <class R>
std::vector<Sample> run_map(const PlanetarySystem<double>& start, const PlanetarySystem<LD>& sys_ld,
                            const std::vector<long>& outs, long& kicks, Compensation compensated = Compensation::off) {
  const PlanetarySystem<R> sys = convert_system<R>(start);
  std::vector<Sample> samples;
  std::vector<Vec3<R>> x, v;
  std::size_t next = 0;
  PropagateOptions<R> opt;
  opt.every = kStepsPerOutput;
  opt.compensated = compensated;
  opt.observer = [&](long step, const std::vector<R>& jacobi) {
    if (next < outs.size() && step == outs[next] * kStepsPerOutput) {
      from_jacobi(sys.mass, jacobi, x, v);
      samples.push_back(sample(sys_ld, x, v));
      ++next;
    }
  };
  const PropagateResult<R> r = propagate(sys, kMap, R(kBrouwerMapStep), outs.back() * kStepsPerOutput, opt);
  kicks = r.kicks;
  return samples;
}

std::vector<Sample> run_adaptive(const PlanetarySystem<double>& start, const PlanetarySystem<LD>& sys_ld,
                                 const std::string& method, double tol, const std::vector<long>& outs, long& forces) {
  AdaptiveOptions opt;
  opt.rtol = tol;
  opt.max_steps = 4000000000L;
  auto integ =
      make_adaptive_integrator<std::vector<double>>(resolve_method(method), CartesianForce<double>(start), opt);
  State<std::vector<double>> s{flatten(start.x), flatten(start.v)};
  std::vector<Sample> samples;
  std::vector<Vec3<double>> x, v;
  double t = 0;
  forces = 0;
  for (long m : outs) {
    const double t1 = brouwer_time(m);
    forces += integ.integrate_to(s, t, t1).force_evals;
    t = t1;
    unflatten(s.q, x);
    unflatten(s.v, v);
    samples.push_back(sample(sys_ld, x, v));
  }
  return samples;
}

double periods_at(long m) { return brouwer_time(m) / bench::kJupiterPeriod; }

}  // namespace

int main(int argc, char** argv) {
  long periods = 1000000;
  int realizations = 1;
  std::string csv, reference_csv;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--periods" && i + 1 < argc) {
      periods = std::atol(argv[++i]);
    } else if (a == "--realizations" && i + 1 < argc) {
      realizations = std::atoi(argv[++i]);
    } else if (a == "--csv" && i + 1 < argc) {
      csv = argv[++i];
    } else if (a == "--reference-csv" && i + 1 < argc) {
      reference_csv = argv[++i];
    } else {
      std::fprintf(stderr,
                   "usage: bench_brouwer_planetary [--periods N] [--realizations K] [--csv FILE] "
                   "[--reference-csv FILE]\n");
      return 2;
    }
  }
  if (periods < 1 || periods > 10000000 || realizations < 1 || realizations > 64) {
    std::fprintf(stderr, "bench_brouwer_planetary: --periods must lie in 1..1e7 and --realizations in 1..64\n");
    return 2;
  }
  const std::vector<long> outs = bench::brouwer_outputs(periods);
  std::printf(
      "Outer solar system (Hairer), barycentric, double; %ld Jupiter periods of %g days, %d realization(s); "
      "reference: %s at %g days in long double\n",
      periods, bench::kJupiterPeriod, realizations, kMap.c_str(), kBrouwerMapStep);
  std::fflush(stdout);

  struct Run {
    std::string label;
    long forces = 0;
    double seconds = 0;
    std::vector<double> energy2, position2;  // sums of squares over the realizations, per output
  };
  std::vector<Run> runs(3);
  runs[0].label = kMap + " at " + std::to_string(static_cast<int>(kBrouwerMapStep)) + " days";
  runs[1].label = "DP12-adaptive at tol 2.5e-15";
  runs[2].label = runs[0].label + ", compensated";
  std::vector<double> ref_energy2(outs.size(), 0.0);
  long ref_kicks = 0;
  std::ofstream rf;
  if (!reference_csv.empty()) {
    rf.open(reference_csv + ".tmp");
    rf << "realization,time,x,y,z\n";
  }
  for (int r = 0; r < realizations; ++r) {
    const PlanetarySystem<double> start = bench::brouwer_start(r);
    const PlanetarySystem<LD> sys_ld = convert_system<LD>(start);  // the same state, masses and G, exactly
    const LD e0 = energy(sys_ld.G, sys_ld.mass, sys_ld.x, sys_ld.v);
    // the reference runs in a second thread while the double runs go on
    std::future<std::vector<Sample>> reference = std::async(std::launch::async, [&] {
      // MPFR keeps per-thread caches (of constants such as pi) until the thread frees them (MPFR's manual).
      struct FreeMpfrCache {
        ~FreeMpfrCache() { mpfr_free_cache(); }
      } free_cache;
      return run_map<LD>(start, sys_ld, outs, ref_kicks);
    });
    std::vector<std::vector<Sample>> samples(runs.size());
    for (std::size_t j = 0; j < runs.size(); ++j) {
      long forces = 0;
      const auto w0 = std::chrono::steady_clock::now();
      if (j == 1)
        samples[j] = run_adaptive(start, sys_ld, "DP12-adaptive", 2.5e-15, outs, forces);
      else
        samples[j] = run_map<double>(start, sys_ld, outs, forces, j == 0 ? Compensation::off : Compensation::on);
      runs[j].seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
      runs[j].forces += forces;
    }
    const std::vector<Sample> ref = reference.get();
    for (std::size_t m = 0; m < outs.size(); ++m) {
      const double de = static_cast<double>(ref[m].energy / e0 - 1);
      ref_energy2[m] += de * de;
      if (rf) {
        char line[200];
        std::snprintf(line, sizeof line, "%d,%.1f,%.21Lg,%.21Lg,%.21Lg\n", r, brouwer_time(outs[m]), ref[m].jupiter[0],
                      ref[m].jupiter[1], ref[m].jupiter[2]);
        rf << line;
      }
    }
    for (std::size_t j = 0; j < runs.size(); ++j) {
      runs[j].energy2.resize(outs.size());
      runs[j].position2.resize(outs.size());
      for (std::size_t m = 0; m < outs.size(); ++m) {
        const double de = static_cast<double>(samples[j][m].energy / e0 - 1);
        LD d2 = 0;
        for (int k = 0; k < 3; ++k)
          d2 += (samples[j][m].jupiter[k] - ref[m].jupiter[k]) * (samples[j][m].jupiter[k] - ref[m].jupiter[k]);
        runs[j].energy2[m] += de * de;
        runs[j].position2[m] += static_cast<double>(d2);
      }
    }
    std::printf("realization %d done\n", r);
    std::fflush(stdout);
  }
  if (rf) {
    rf.close();
    std::rename((reference_csv + ".tmp").c_str(), reference_csv.c_str());
  }

  std::ofstream out;
  if (!csv.empty()) {
    out.open(csv + ".tmp");
    out << "method,realizations,periods,energy_error,position_error\n";
  }
  const double from = std::max(1.0, static_cast<double>(periods) / 1000);
  const double k = realizations;
  std::vector<bench::BrouwerPoint> ref_pts;
  for (std::size_t m = 0; m < outs.size(); ++m)
    ref_pts.push_back({periods_at(outs[m]), std::sqrt(ref_energy2[m] / k), 0});
  std::printf("\nreference (%ld kicks per realization): rms energy error %.3e at the end, slope %.2f\n", ref_kicks,
              ref_pts.back().energy, bench::brouwer_slope(ref_pts, from, true));
  for (const Run& r : runs) {
    std::printf("\n%s: %ld forces, %.1f s (all realizations); rms over %d realization(s)\n  %12s %12s %12s\n",
                r.label.c_str(), r.forces, r.seconds, realizations, "periods", "energy", "Jupiter (AU)");
    std::vector<bench::BrouwerPoint> pts;
    for (std::size_t m = 0; m < outs.size(); ++m) {
      pts.push_back({periods_at(outs[m]), std::sqrt(r.energy2[m] / k), std::sqrt(r.position2[m] / k)});
      const auto& p = pts.back();
      std::printf("  %12.1f %12.3e %12.3e\n", p.periods, p.energy, p.position);
      if (out)
        out << '"' << r.label << "\"," << realizations << ',' << p.periods << ',' << p.energy << ',' << p.position
            << '\n';
    }
    std::printf("  slopes over the last three decades: energy %.2f, position %.2f (Brouwer: 0.5, 1.5)\n",
                bench::brouwer_slope(pts, from, true), bench::brouwer_slope(pts, from, false));
    std::fflush(stdout);
  }
  if (out) {
    out.close();
    std::rename((csv + ".tmp").c_str(), csv.c_str());
  }
  return 0;
}
