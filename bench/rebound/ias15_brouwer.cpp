// REBOUND's IAS15 (Rein & Spiegel, MNRAS 446 (2015) 1424) on bench_brouwer_planetary's problem: Hairer's outer
// solar system in its centre-of-mass frame, rounded to double, from the same states (every realization in the
// reference file, bench/brouwer_planetary.hpp) to the same output times, with the same errors: the energy in long
// double, Jupiter's position relative to the Sun against the reference that bench_brouwer_planetary --reference-csv
// wrote, the root mean square of each over the realizations. IAS15 runs with its defaults (epsilon 1e-9, the PRS23 step
// criterion, exact finish times, plain gravity) as its users run it, or with REBOUND's compensated gravity.
// Not part of the build or of CI: bench/rebound/build.sh compiles it against a REBOUND source tree.
//
//   ias15_brouwer REFERENCE_CSV [--compensated-gravity] [--csv FILE]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#define restrict __restrict__
extern "C" {
#include "rebound.h"
extern const char* reb_version_str;  // exported, declared in REBOUND's internal header
}
#undef restrict

#include "brouwer_common.hpp"
#include "brouwer_planetary.hpp"
#include "nystrom/planetary/system.hpp"

namespace {

using namespace nystrom::planetary;
using LD = long double;
struct RefPoint {
  int realization;
  double time;
  LD x, y, z;
};

std::vector<RefPoint> read_reference(const std::string& path) {
  std::ifstream in(path);
  std::vector<RefPoint> pts;
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    std::istringstream ls(line);
    RefPoint p{};
    char c0 = 0, c1 = 0, c2 = 0, c3 = 0;
    if (ls >> p.realization >> c0 >> p.time >> c1 >> p.x >> c2 >> p.y >> c3 >> p.z) pts.push_back(p);
  }
  return pts;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: ias15_brouwer REFERENCE_CSV [--compensated-gravity] [--csv FILE]\n");
    return 2;
  }
  bool compensated = false;
  std::string csv;
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--compensated-gravity") {
      compensated = true;
    } else if (a == "--csv" && i + 1 < argc) {
      csv = argv[++i];
    } else {
      std::fprintf(stderr, "ias15_brouwer: unknown argument '%s'\n", a.c_str());
      return 2;
    }
  }
  const std::vector<RefPoint> ref = read_reference(argv[1]);
  if (ref.empty()) {
    std::fprintf(stderr, "ias15_brouwer: no reference points in '%s'\n", argv[1]);
    return 2;
  }
  int realizations = 0;
  for (const RefPoint& p : ref) realizations = std::max(realizations, p.realization + 1);
  const std::string label = std::string("IAS15") + (compensated ? " (compensated gravity)" : "");
  std::vector<double> energy2, position2, periods;
  unsigned long long steps = 0;
  const auto w0 = std::chrono::steady_clock::now();
  for (int rz = 0; rz < realizations; ++rz) {
    // the state of bench_brouwer_planetary's realization rz, and its long-double copy for the energy
    const PlanetarySystem<double> start = nystrom::bench::brouwer_start(rz);
    const PlanetarySystem<LD> sys = convert_system<LD>(start);
    const LD e0 = energy(sys.G, sys.mass, sys.x, sys.v);
    reb_simulation* r = reb_simulation_create();
    reb_simulation_set_integrator(r, "ias15");
    r->G = start.G;
    if (compensated) r->gravity = reb_simulation::REB_GRAVITY_COMPENSATED;
    for (std::size_t i = 0; i < start.size(); ++i) {
      reb_particle p{};
      p.m = start.mass[i];
      p.x = start.x[i][0];
      p.y = start.x[i][1];
      p.z = start.x[i][2];
      p.vx = start.v[i][0];
      p.vy = start.v[i][1];
      p.vz = start.v[i][2];
      reb_simulation_add(r, p);
    }
    std::vector<Vec3<LD>> x(start.size()), v(start.size());
    std::size_t m = 0;
    for (const RefPoint& p : ref) {
      if (p.realization != rz) continue;
      reb_simulation_integrate(r, p.time);
      if (r->t != p.time) {
        std::fprintf(stderr, "ias15_brouwer: IAS15 stopped at t = %.17g instead of %.17g\n", r->t, p.time);
        return 1;
      }
      for (std::size_t i = 0; i < start.size(); ++i) {
        const reb_particle& q = r->particles[i];
        x[i] = {q.x, q.y, q.z};
        v[i] = {q.vx, q.vy, q.vz};
      }
      const LD dx = x[1][0] - x[0][0] - p.x, dy = x[1][1] - x[0][1] - p.y, dz = x[1][2] - x[0][2] - p.z;
      const double de = static_cast<double>(energy(sys.G, sys.mass, x, v) / e0 - 1);
      if (m == energy2.size()) {
        energy2.push_back(0);
        position2.push_back(0);
        periods.push_back(p.time / nystrom::bench::kJupiterPeriod);
      }
      energy2[m] += de * de;
      position2[m] += static_cast<double>(dx * dx + dy * dy + dz * dz);
      ++m;
    }
    steps += r->steps_done;
    reb_simulation_free(r);
    std::fprintf(stderr, "realization %d done\n", rz);
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
  std::vector<nystrom::bench::BrouwerPoint> pts;
  for (std::size_t m = 0; m < periods.size(); ++m)
    pts.push_back({periods[m], std::sqrt(energy2[m] / realizations), std::sqrt(position2[m] / realizations)});
  std::printf("%s (REBOUND %s): %llu steps, %.1f s (all realizations); rms over %d realization(s)\n  %12s %12s %12s\n",
              label.c_str(), reb_version_str, steps, seconds, realizations, "periods", "energy", "Jupiter (AU)");
  std::ofstream out;
  if (!csv.empty()) {
    out.open(csv + ".tmp");
    out << "method,realizations,periods,energy_error,position_error\n";
  }
  for (const auto& p : pts) {
    std::printf("  %12.1f %12.3e %12.3e\n", p.periods, p.energy, p.position);
    if (out)
      out << '"' << label << "\"," << realizations << ',' << p.periods << ',' << p.energy << ',' << p.position << '\n';
  }
  const double from = std::max(1.0, pts.back().periods / 1000);
  std::printf("  slopes over the last three decades: energy %.2f, position %.2f (Brouwer: 0.5, 1.5)\n",
              nystrom::bench::brouwer_slope(pts, from, true), nystrom::bench::brouwer_slope(pts, from, false));
  if (out) {
    out.close();
    std::rename((csv + ".tmp").c_str(), csv.c_str());
  }
  return 0;
}
