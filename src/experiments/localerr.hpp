// The measurements of the Gürkan paper's section 5:
//
// run_localerr: follow the orbit with the Gragg-Bulirsch-Stoer reference (engines/gbs.hpp, tolerance 1e-14
//   by default, harmonic sequence, 12 columns); at every step of size h, advance each method under test one
//   step from the same GBS state, and collect the differences of its position components from GBS's
//   position at the end of the step. Report the quantiles 0.25 and 0.75 of those differences and their
//   difference, the interquartile range. Complex-coefficient methods run on the complexified state and drop
//   the imaginary parts after the step (the paper's choice). Problems:
//     twobody  two equal masses at eccentricity e (default 0.2) for 50 orbital periods; h is given in
//              orbital periods (the paper's Fig. 5.1 axis); the orbit lies in the x-y plane, so the x and
//              y components are collected (z differences are identically zero);
//     nbody    a Plummer sphere (default 400 particles, seed 42) or a particle file, softening
//              eps^2 = (1/N)^2, for 1 time unit by default; h in time units (Fig. 5.2); x, y, z collected.
//
// run_cputime: the cost of one step of each method on an N-body system (default 10 000 particles),
//   normalised to the leapfrog's in the same run (the paper's Table 5.1). Each method integrates one step
//   (which pays the initial force evaluation) and then `steps` steps whose time is measured, so the
//   first-same-as-last saving is counted as in a long run; the minimum over `repeats` is reported.
#pragma once

#include <chrono>
#include <cmath>
#include <complex>
#include <cstdint>
#include <ctime>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "nystrom/diagnostics/stats.hpp"
#include "nystrom/engines/gbs.hpp"
#include "nystrom/engines/integrator.hpp"
#include "nystrom/methods/catalog.hpp"
#include "nystrom/problems/nbody.hpp"
#include "nystrom/problems/plummer.hpp"

namespace nystrom {

/// The N-body system of an experiment.
struct NBodySetup {
  std::string problem = "nbody";  // nbody | twobody
  std::size_t n = 400;            // Plummer particles (nbody without a file)
  std::uint64_t seed = 42;
  std::string ic_file;  // particle file instead of a Plummer sphere
  double ecc = 0.2;     // twobody
  double eps2 = -1;     // < 0: (1/N)^2 for nbody, 0 for twobody
  int threads = 0;      // force threads (0: OpenMP default)
};

struct NBodyInstance {
  ParticleSet<double> particles;
  NBodyForce<double> force;
  double period = 0;  // twobody: 2 pi; nbody: 0
  std::string description;
};

inline NBodyInstance make_nbody_instance(const NBodySetup& s) {
  NBodyInstance r;
  if (s.problem == "twobody") {
    if (!s.ic_file.empty()) throw std::invalid_argument("--ic is for --problem nbody, not twobody");
    r.particles = two_body<double>(s.ecc);
    r.period = 2 * std::acos(-1.0);
  } else if (s.problem == "nbody") {
    if (!s.ic_file.empty()) {
      r.particles = load_particles<double>(s.ic_file);
    } else {
      if (s.n < 2 || s.n > 1000000) throw std::invalid_argument("--n must be between 2 and 1000000");
      r.particles = plummer_sphere<double>(s.n, s.seed);
    }
  } else {
    throw std::invalid_argument("unknown N-body problem '" + s.problem + "' (known: nbody, twobody)");
  }
  const double N = static_cast<double>(r.particles.size());
  double eps2 = s.eps2;
  if (!std::isfinite(eps2)) throw std::invalid_argument("softening must be finite");
  if (eps2 < 0) eps2 = s.problem == "twobody" ? 0.0 : 1.0 / (N * N);
  r.force = NBodyForce<double>(r.particles.m, eps2);
  r.force.threads = s.threads;
  r.description = s.problem == "twobody" ? "two-body, e = " + std::to_string(s.ecc)
                                         : std::to_string(r.particles.size()) + " bodies" +
                                               (s.ic_file.empty() ? " (Plummer, seed " + std::to_string(s.seed) + ")"
                                                                  : " (" + s.ic_file + ")");
  return r;
}

/// One method, real or complex, stepping real states (RealStateIntegrator converts for complex methods).
class NBodyMethodStepper {
 public:
  using V = std::vector<double>;
  NBodyMethodStepper(const MethodDef& def, const NBodyForce<double>& f)
      : info_(def.info), impl_(std::make_unique<RealStateIntegrator<V, NBodyForce<double>>>(def, f)) {}
  const MethodInfo& info() const { return info_; }
  /// n steps of size h, in place.
  void integrate(State<V>& s, double h, long n) { impl_->integrate(s, h, n); }
  long force_evals() const { return impl_->force_evals(); }

 private:
  MethodInfo info_;
  std::unique_ptr<RealStateIntegrator<V, NBodyForce<double>>> impl_;
};

struct LocalErrConfig {
  NBodySetup setup;
  double duration = -1;    // < 0: 50 periods (twobody) or 1 time unit (nbody); in periods for twobody
  std::vector<double> hs;  // step sizes (periods for twobody, time units for nbody)
  std::vector<std::string> methods;
  std::vector<MethodDef> method_defs;  // further methods given as data (after `methods`)
  double tol = 1e-14;                  // GBS rtol = atol
  int gbs_columns = 12;
  GbsSequence sequence = GbsSequence::harmonic;
};

struct LocalErrRow {
  std::string method;
  double h = 0;       // as given (periods or time units)
  double h_time = 0;  // in time units
  long steps = 0;
  long samples = 0;
  double q25 = 0, q75 = 0, iqr = 0;
};

struct LocalErrResult {
  std::string description, h_unit;
  std::vector<LocalErrRow> rows;
  long gbs_force_evals = 0;
  double seconds = 0;
};

/// See the top of the file. progress(done, total) is called after every reference step.
inline LocalErrResult run_localerr(const LocalErrConfig& cfg, const std::function<void(long, long)>& progress = {}) {
  if (cfg.hs.empty()) throw std::invalid_argument("no step sizes given");
  if (cfg.methods.empty() && cfg.method_defs.empty()) throw std::invalid_argument("no methods given");
  for (double h : cfg.hs)
    if (!(h > 0) || !std::isfinite(h)) throw std::invalid_argument("step sizes must be positive and finite");
  const NBodyInstance inst = make_nbody_instance(cfg.setup);
  const bool twobody = cfg.setup.problem == "twobody";
  const double unit = twobody ? inst.period : 1.0;
  const double duration = (cfg.duration < 0 ? (twobody ? 50.0 : 1.0) : cfg.duration) * unit;
  if (!(duration > 0) || !std::isfinite(duration)) throw std::invalid_argument("duration must be positive");
  std::vector<MethodDef> defs;
  for (const auto& m : cfg.methods) defs.push_back(resolve_method(m));
  for (const auto& d : cfg.method_defs) defs.push_back(d);
  GbsOptions go;
  go.rtol = go.atol = cfg.tol;
  go.max_columns = cfg.gbs_columns;
  go.sequence = cfg.sequence;
  long total = 0;
  std::vector<long> nsteps;
  for (double h : cfg.hs) {
    const double ht = h * unit;
    const double steps = duration / ht;  // checked before rounding: lround of a huge value is undefined
    if (!(steps <= 1e8)) throw std::invalid_argument("too many steps: h is too small for the duration");
    const long n = std::max(1L, std::lround(steps));
    nsteps.push_back(n);
    total += n;
  }
  const std::size_t N = inst.particles.size();
  const std::size_t comps = twobody ? 2 : 3;  // position components collected
  LocalErrResult res;
  res.description = inst.description;
  res.h_unit = twobody ? "orbital periods" : "time units";
  const auto t0 = std::chrono::steady_clock::now();
  long done = 0;
  for (std::size_t ih = 0; ih < cfg.hs.size(); ++ih) {
    const double ht = cfg.hs[ih] * unit;
    const long n = nsteps[ih];
    GbsIntegrator<std::vector<double>, NBodyForce<double>> gbs(inst.force, go);
    std::vector<std::unique_ptr<NBodyMethodStepper>> st;
    for (const auto& d : defs) st.push_back(std::make_unique<NBodyMethodStepper>(d, inst.force));
    std::vector<std::vector<double>> diffs(defs.size());
    for (auto& d : diffs) d.reserve(static_cast<std::size_t>(n) * comps * N);
    State<std::vector<double>> s = inst.particles.s, next, trial;
    for (long k = 0; k < n; ++k) {
      next = s;
      gbs.integrate_to(next, ht);
      for (std::size_t m = 0; m < st.size(); ++m) {
        trial = s;
        st[m]->integrate(trial, ht, 1);
        for (std::size_t i = 0; i < comps * N; ++i) diffs[m].push_back(trial.q[i] - next.q[i]);
      }
      s = next;
      ++done;
      if (progress) progress(done, total);
    }
    for (std::size_t m = 0; m < st.size(); ++m) {
      LocalErrRow r;
      r.method = defs[m].info.name;
      r.h = cfg.hs[ih];
      r.h_time = ht;
      r.steps = n;
      r.samples = static_cast<long>(diffs[m].size());
      r.q25 = quantile_inplace(diffs[m], 0.25);
      r.q75 = quantile_inplace(diffs[m], 0.75);
      r.iqr = r.q75 - r.q25;
      res.rows.push_back(r);
      std::vector<double>().swap(diffs[m]);
    }
    res.gbs_force_evals += gbs.force_evals();
  }
  res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return res;
}

struct CpuTimeConfig {
  NBodySetup setup = [] {
    NBodySetup s;
    s.n = 10000;
    return s;
  }();
  std::vector<std::string> methods;
  double h = 1e-3;
  long steps = 3;
  int repeats = 3;
};

struct CpuTimeRow {
  std::string method;
  int forces_per_step = 0;
  bool complex = false;
  double seconds_per_step = 0;  // minimum over repeats
  double ratio = 0;             // to the leapfrog's
};

struct CpuTimeResult {
  std::string description;
  double leapfrog_seconds = 0;
  std::vector<CpuTimeRow> rows;
};

inline CpuTimeResult run_cputime(const CpuTimeConfig& cfg, const std::function<void(long, long)>& progress = {}) {
  if (cfg.methods.empty()) throw std::invalid_argument("no methods given");
  if (cfg.steps < 1 || cfg.steps > 1000) throw std::invalid_argument("--steps must be between 1 and 1000");
  if (cfg.repeats < 1 || cfg.repeats > 100) throw std::invalid_argument("--repeats must be between 1 and 100");
  if (!(cfg.h > 0) || !std::isfinite(cfg.h)) throw std::invalid_argument("--h must be positive");
  const NBodyInstance inst = make_nbody_instance(cfg.setup);
  std::vector<MethodDef> defs{resolve_method("VV")};  // the leapfrog, measured first
  for (const auto& m : cfg.methods) defs.push_back(resolve_method(m));
  CpuTimeResult res;
  res.description = inst.description;
  std::vector<double> best(defs.size(), 1e300);
  const long total = static_cast<long>(defs.size()) * cfg.repeats;
  long done = 0;
  // Repeats interleave the methods, so that a change of machine load affects all of them alike.
  for (int r = 0; r < cfg.repeats; ++r)
    for (std::size_t m = 0; m < defs.size(); ++m) {
      NBodyMethodStepper st(defs[m], inst.force);
      auto s = inst.particles.s;
      st.integrate(s, cfg.h, 1);
      // Processor time of the process (std::clock: all threads), as the paper's "CPU time": on a shared
      // machine it does not count the time other processes hold the cores, which wall-clock time does
      // (BR1, exactly 5 real forces, read 4.0-6.1 leapfrog steps by wall clock, 5.00 by CPU time).
      const std::clock_t c0 = std::clock();
      st.integrate(s, cfg.h, cfg.steps);
      const double dt = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
      if (!all_finite(s.q)) throw std::invalid_argument("method " + defs[m].info.name + " produced a non-finite state");
      best[m] = std::min(best[m], dt / static_cast<double>(cfg.steps));
      if (progress) progress(++done, total);
    }
  res.leapfrog_seconds = best[0];
  for (std::size_t m = 1; m < defs.size(); ++m) {
    CpuTimeRow row;
    row.method = defs[m].info.name;
    row.forces_per_step = defs[m].info.forces_per_step;
    row.complex = defs[m].info.complex;
    row.seconds_per_step = best[m];
    row.ratio = best[m] / best[0];
    res.rows.push_back(row);
  }
  return res;
}

}  // namespace nystrom
