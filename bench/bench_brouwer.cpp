// Brouwer's law in double: the error of long Kepler runs (e = 0.5, up to 1e6 periods) whose truncation error lies
// below their round-off. Rounding errors that change the energy at random by about eps per step make the relative
// energy error a random walk, growing as t^(1/2); the mean motion follows the energy, so the phase, and with it the
// position, drifts as t^(3/2) (Brouwer, Astron. J. 56 (1951) 9). A linear energy drift (t^1) and a position error
// growing as t^2 mark a bias: weights rounded the same way at every step, an increment summed without its carry.
// Each run continues one integrator over the whole span, its state and carries kept between the output times
// (fixed steps: the span of each period cut into the same n steps, so that the time reached after m periods is m
// times the period exactly in the reference; adaptive: integrate_to the output times, which are step ends). At
// log-spaced numbers of periods the program prints the relative energy error and the position error against the
// exact orbit of the rounded initial state (problems/reference.hpp, in quad-double), and at the end the slopes of
// log error against log t fitted over the last three decades (Brouwer: 0.5 and 1.5). SS10 and KL8 run a second time
// with the compensated Kepler force (CompensatedKeplerForce: drifts and kicks in double-word with the force's
// rounding error, engines/splitting.hpp), whose rounding per step is about eps^2 instead of eps.
//
//   bench_brouwer [--periods N (1e6)] [--ecc E (0.5)] [--csv FILE] [--compensated-only]
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "brouwer_common.hpp"
#include "nystrom/engines/adaptive_rkn.hpp"
#include "nystrom/engines/integrator.hpp"
#include "nystrom/methods/catalog.hpp"
#include "nystrom/problems/kepler.hpp"
#include "nystrom/problems/reference.hpp"

namespace {

using namespace nystrom;
using V = std::array<double, 2>;

using Point = bench::BrouwerPoint;

struct Config {
  std::string method;
  long steps_per_period;  // 0: adaptive
  double tol;
  bool compensated = false;  // CompensatedKeplerForce: the force's rounding error in double-word
};

std::string fmt_tol(double tol) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2g", tol);
  return buf;
}

template <class Force>
std::vector<Point> run(const Config& c, double ecc, long periods, long& forces, double& seconds) {
  const KeplerProblem<double> kp(ecc);
  const State<V> s0 = kp.initial_state();
  const double period = KeplerProblem<double>::period();
  const MethodDef def = resolve_method(c.method);
  std::vector<Point> pts;
  State<V> s = s0;
  const auto w0 = std::chrono::steady_clock::now();
  long done = 0;
  auto record = [&](long m, const ReferenceErrors& e) {
    pts.push_back({static_cast<double>(m), e.energy, e.position});
  };
  const std::vector<long> outs = bench::brouwer_outputs(periods);  // 1, 2, 5, 10, ... periods
  if (c.steps_per_period > 0) {
    auto integ = make_integrator<V>(def, Force{});
    const double h = period / static_cast<double>(c.steps_per_period);
    for (long m : outs) {
      integ.integrate(s, h, (m - done) * c.steps_per_period);
      done = m;
      State<V> x = s;  // with the carries of compensated summation
      for (std::size_t i = 0; i < 2; ++i) {
        x.q[i] += integ.compensator().cq[i];
        x.v[i] += integ.compensator().cv[i];
      }
      record(m, kepler_reference_errors(s0, x, h, m * c.steps_per_period));
    }
    forces = integ.force_evals();
  } else {
    AdaptiveOptions opt;
    opt.rtol = c.tol;
    opt.max_steps = 4000000000L;  // a call may span 5e5 periods
    auto integ = make_adaptive_integrator<V>(def, Force{}, opt);
    double t = 0;
    forces = 0;
    for (long m : outs) {
      const double t1 = period * static_cast<double>(m);
      forces += integ.integrate_to(s, t, t1).force_evals;
      t = t1;
      record(m, kepler_reference_errors(s0, s, t1, 1));
    }
  }
  seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
  return pts;
}

}  // namespace

int main(int argc, char** argv) {
  long periods = 1000000;
  double ecc = 0.5;
  std::string csv;
  bool compensated_only = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--periods" && i + 1 < argc) {
      periods = std::atol(argv[++i]);
    } else if (a == "--ecc" && i + 1 < argc) {
      ecc = std::atof(argv[++i]);
    } else if (a == "--csv" && i + 1 < argc) {
      csv = argv[++i];
    } else if (a == "--compensated-only") {
      compensated_only = true;
    } else {
      std::fprintf(stderr, "usage: bench_brouwer [--periods N] [--ecc E] [--csv FILE] [--compensated-only]\n");
      return 2;
    }
  }
  if (periods < 1 || periods > 100000000 || !(ecc >= 0 && ecc < 1)) {
    std::fprintf(stderr, "bench_brouwer: --periods must lie in 1..1e8 and --ecc in [0, 1)\n");
    return 2;
  }
  std::vector<Config> configs = {{"SS10", 200, 0},
                                 {"KL8", 500, 0},
                                 {"DP12", 200, 0},
                                 {"DP12-adaptive", 0, 2.5e-15},
                                 {"DOP853-adaptive", 0, 3e-15},
                                 {"SS10", 200, 0, true},
                                 {"KL8", 500, 0, true}};
  if (compensated_only) std::erase_if(configs, [](const Config& c) { return !c.compensated; });
  std::ofstream out;
  if (!csv.empty()) {
    out.open(csv + ".tmp");
    out << "method,steps_per_period,tol,periods,energy_error,position_error\n";
  }
  std::printf(
      "Kepler e = %g, %ld periods, double, compensated summation (the default); the plain force, or the "
      "compensated one where marked\n",
      ecc, periods);
  for (const auto& c : configs) {
    long forces = 0;
    double seconds = 0;
    const auto pts = c.compensated ? run<CompensatedKeplerForce>(c, ecc, periods, forces, seconds)
                                   : run<KeplerForce>(c, ecc, periods, forces, seconds);
    const std::string label = c.method + (c.compensated ? " (compensated force)" : "");
    std::printf("\n%s %s: %ld forces, %.1f s\n  %10s %12s %12s\n", label.c_str(),
                c.steps_per_period > 0 ? (std::to_string(c.steps_per_period) + " steps/period").c_str()
                                       : ("tol " + fmt_tol(c.tol)).c_str(),
                forces, seconds, "periods", "energy", "position");
    std::fflush(stdout);
    for (const auto& p : pts) {
      std::printf("  %10.0f %12.3e %12.3e\n", p.periods, p.energy, p.position);
      if (out)
        out << label << ',' << c.steps_per_period << ',' << c.tol << ',' << p.periods << ',' << p.energy << ','
            << p.position << '\n';
    }
    const double from = std::max(1.0, static_cast<double>(periods) / 1000);
    std::printf("  slopes over the last three decades: energy %.2f, position %.2f (Brouwer: 0.5, 1.5)\n",
                bench::brouwer_slope(pts, from, true), bench::brouwer_slope(pts, from, false));
    std::fflush(stdout);
  }
  if (out) {
    out.close();
    std::rename((csv + ".tmp").c_str(), csv.c_str());
  }
}
