// The Kepler drift of the Wisdom-Holman maps: nanoseconds per drift of one planet on the outer solar system's
// Jacobi orbits (Hairer, Lubich & Wanner, Geometric Numerical Integration, sec. I.2.4) at h = 50, 100, 200 and
// 400 days, and nanoseconds per step of WH-M8 and WH-KL8 at h = 200 days, for the library's solver
// (include/nystrom/planetary/kepler_drift.hpp) and, as the baseline measured in the same run, the solver it
// replaced (kept below as `baseline::kepler_drift`: Laguerre-Conway from the quadratic series guess, the
// Stumpff series with a fixed number of terms evaluated afresh at every iterate, and once more at the
// converged anomaly).
//
// A drift benchmark advances the five Jacobi orbits by h again and again (one iteration = one drift of every
// planet, as in a map's flow A: kepler_drift_many; "drift-one-at-a-time": kepler_drift on each planet in turn,
// against the same baseline); a step benchmark runs the map over JacobiFlows, or over the same flows with
// the baseline drift. Before timing, both solvers drift the orbits 2000 times and their largest difference
// relative to |x| and |v| is printed (both are exact to rounding, so it must stay at a few 1e-16), and so are the
// heap allocations per step of each map (the drifts and the kicks allocate nothing).
// The table at the end gives the minimum over repetitions of the CPU time per drift or per step, and the
// ratio baseline / library.
//
//   bench_planetary --benchmark_repetitions=5     (the default here: 5 repetitions)
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench_common.hpp"
#include "nystrom/planetary/kepler_drift.hpp"
#include "nystrom/planetary/system.hpp"
#include "nystrom/planetary/wisdom_holman.hpp"

using namespace nystrom::planetary;

// Heap allocations of the whole program, counted to show that a step of a map allocates nothing (the
// library's operator delete frees what this malloc returns).
namespace {
std::size_t g_allocations = 0;
}
void* operator new(std::size_t n) {
  ++g_allocations;
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}

namespace baseline {

template <class R>
Stumpff<R> stumpff(R x) {
  using std::abs;
  int quarterings = 0;
  while (abs(x) > R(0.1) && quarterings < 200) {
    x /= 4;
    ++quarterings;
  }
  struct Table {
    std::array<R, 64> inv_fact{};
    int terms = 0;
    Table() {
      inv_fact[0] = 1;
      for (int k = 1; k < 64; ++k) inv_fact[k] = inv_fact[k - 1] / R(k);
      const R eps = std::numeric_limits<R>::epsilon();
      R bound = 1;
      while (terms < 29 && bound * inv_fact[2 * terms + 2] > eps / 16) {
        bound /= 10;
        ++terms;
      }
    }
  };
  static const Table table;
  R c2 = 0, c3 = 0;
  for (int j = table.terms; j >= 0; --j) {
    c2 = table.inv_fact[2 * j + 2] - x * c2;
    c3 = table.inv_fact[2 * j + 3] - x * c3;
  }
  R c1 = 1 - x * c3;
  R c0 = 1 - x * c2;
  for (; quarterings > 0; --quarterings) {
    c3 = (c2 + c0 * c3) / 4;
    c2 = c1 * c1 / 2;
    c1 = c0 * c1;
    c0 = 2 * c0 * c0 - 1;
  }
  return {c0, c1, c2, c3};
}

template <class R>
void kepler_drift(R mu, R dt, Vec3<R>& x, Vec3<R>& v) {
  using std::abs;
  using std::sqrt;
  if (dt == 0) return;
  const R r0 = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
  if (!(r0 > 0) || !std::isfinite(static_cast<double>(r0)))
    throw std::invalid_argument("Kepler drift: the distance to the central body must be positive and finite");
  const R eta0 = x[0] * v[0] + x[1] * v[1] + x[2] * v[2];
  const R v2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
  const R beta = 2 * mu / r0 - v2;
  const R zeta0 = mu - beta * r0;
  R t = dt;
  if (beta > 0) {
    const R pi = R(3.14159265358979323846264338327950288L);
    const R period = 2 * pi * mu / (beta * sqrt(beta));
    if (abs(t) > period) t = std::fmod(t, period);
  }
  const R eps = std::numeric_limits<R>::epsilon();
  R lo = t > 0 ? R(0) : -std::numeric_limits<R>::infinity();
  R hi = t > 0 ? std::numeric_limits<R>::infinity() : R(0);
  R s = t / r0 - eta0 * t * t / (2 * r0 * r0 * r0);
  if (beta > 0 && abs(t) * sqrt(beta * beta * beta) / mu > R(0.5)) s = t * beta / mu;
  if (!std::isfinite(static_cast<double>(s))) s = t / r0;
  R g1 = 0, g2 = 0, g3 = 0, r = r0;
  bool converged = false;
  R prev_abs_f = std::numeric_limits<R>::infinity();
  for (int it = 0; it < 200; ++it) {
    const R s2 = s * s;
    const Stumpff<R> c = stumpff(beta * s2);
    g1 = s * c.c1;
    g2 = s2 * c.c2;
    g3 = s2 * s * c.c3;
    const R g0 = c.c0;
    const R f = r0 * s + eta0 * g2 + zeta0 * g3 - t;
    r = r0 + eta0 * g1 + zeta0 * g2;
    const R fpp = eta0 * g0 + zeta0 * g1;
    if (converged) break;
    if (abs(f) <= 4 * eps * (abs(r0 * s) + abs(eta0 * g2) + abs(zeta0 * g3) + abs(t))) {
      converged = true;
      break;
    }
    if (f < 0)
      lo = s;
    else
      hi = s;
    const R n = 5;
    const R disc = abs((n - 1) * (n - 1) * r * r - n * (n - 1) * f * fpp);
    const R den = r + (r >= 0 ? sqrt(disc) : -sqrt(disc));
    R next = s - n * f / den;
    const bool slow = abs(f) > prev_abs_f / 64 && std::isfinite(static_cast<double>(hi - lo));
    prev_abs_f = abs(f);
    if (slow || !(next > lo && next < hi) || !std::isfinite(static_cast<double>(next))) {
      if (std::isfinite(static_cast<double>(lo)) && std::isfinite(static_cast<double>(hi)))
        next = lo + (hi - lo) / 2;
      else if (std::isfinite(static_cast<double>(hi)))
        next = hi - 2 * (abs(hi) + abs(t / r0) + 1);
      else
        next = lo + 2 * (abs(lo) + abs(t / r0) + 1);
    }
    const R ds = next - s;
    s = next;
    if (abs(ds) <= 4 * eps * abs(s) || next == lo || next == hi) converged = true;
  }
  if (!converged || !std::isfinite(static_cast<double>(r)) || !(r > 0))
    throw std::runtime_error("Kepler drift: Kepler's equation did not converge");
  const R fm1 = -mu * g2 / r0;
  const R g = r0 * g1 + eta0 * g2;
  const R fdot = -mu * g1 / (r * r0);
  const R gdm1 = -mu * g2 / r;
  const Vec3<R> x0 = x, v0 = v;
  for (int k = 0; k < 3; ++k) {
    x[k] = x0[k] + (fm1 * x0[k] + g * v0[k]);
    v[k] = v0[k] + (fdot * x0[k] + gdm1 * v0[k]);
  }
}

}  // namespace baseline

namespace {

struct Orbits {
  std::vector<double> mu;          // mu[i], i >= 1
  std::vector<Vec3<double>> x, v;  // Jacobi coordinates of the planets (index 0 unused)
};

Orbits jacobi_orbits() {
  const PlanetarySystem<double> sys = outer_solar_system<double>();
  const std::vector<double> s = to_jacobi(sys);
  const std::size_t n = sys.size();
  Orbits o;
  o.mu = jacobi_kepler_mu(sys.G, sys.mass);
  o.x.resize(n);
  o.v.resize(n);
  for (std::size_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) {
      o.x[i][k] = s[3 * i + k];
      o.v[i][k] = s[3 * n + 3 * i + k];
    }
  return o;
}

enum class Drift { baseline, library, library_one_at_a_time };

template <Drift kDrift>
void drift_all(Orbits& o, double h) {
  if constexpr (kDrift == Drift::library) {  // as the flow drifts its planets: all at once
    kepler_drift_many<double>(
        o.mu.size() - 1, h, [&](std::size_t k) { return o.mu[k + 1]; }, o.x[1].data(), o.v[1].data());
    return;
  }
  for (std::size_t i = 1; i < o.mu.size(); ++i) {
    if constexpr (kDrift == Drift::baseline)
      baseline::kepler_drift(o.mu[i], h, o.x[i], o.v[i]);
    else
      kepler_drift(o.mu[i], h, o.x[i], o.v[i]);
  }
}

template <Drift kDrift>
void BM_drift(benchmark::State& state, double h) {
  Orbits o = jacobi_orbits();
  const Orbits start = o;
  long n = 0;
  for (auto _ : state) {
    drift_all<kDrift>(o, h);
    benchmark::DoNotOptimize(o.x.data());
    if (++n % 100000 == 0) o = start;  // stay on the initial orbits' scale of time
  }
  state.counters["units"] = static_cast<double>(o.mu.size() - 1);
}

/// JacobiFlows with the baseline drift as flow A.
class BaselineJacobiFlows : public JacobiFlows<double> {
 public:
  BaselineJacobiFlows(double G, std::vector<double> mass)
      : JacobiFlows<double>(G, mass), mu_(jacobi_kepler_mu(G, mass)) {}
  void apply_a(state_type& s, std::complex<double> z) {
    const double dt = z.real();
    const std::size_t n = bodies();
    double* x = s.data();
    double* v = s.data() + 3 * n;
    for (int k = 0; k < 3; ++k) x[k] += dt * v[k];
    for (std::size_t i = 1; i < n; ++i) {
      Vec3<double> xi{x[3 * i], x[3 * i + 1], x[3 * i + 2]}, vi{v[3 * i], v[3 * i + 1], v[3 * i + 2]};
      baseline::kepler_drift(mu_[i], dt, xi, vi);
      for (int k = 0; k < 3; ++k) {
        x[3 * i + k] = xi[k];
        v[3 * i + k] = vi[k];
      }
    }
  }

 private:
  std::vector<double> mu_;
};

constexpr long kStepBatch = 100;

template <class F>
void BM_step(benchmark::State& state, const std::string& method, double h) {
  const PlanetarySystem<double> sys = outer_solar_system<double>();
  const nystrom::operators::FlowMethod fm = resolve_wh_method(method, 53, "double");
  F flows(sys.G, sys.mass);
  nystrom::operators::FlowIntegrator<F> integ(fm);
  const std::vector<double> start = to_jacobi(sys);
  std::vector<double> s = start;
  long n = 0;
  for (auto _ : state) {
    integ.integrate(flows, s, h, kStepBatch);
    benchmark::DoNotOptimize(s.data());
    if (++n % 1000 == 0) s = start;
  }
  state.counters["units"] = static_cast<double>(kStepBatch);
}

/// Heap allocations per step of a map over JacobiFlows (after a first step, which sizes the kick's scratch).
double allocations_per_step(const std::string& method) {
  const PlanetarySystem<double> sys = outer_solar_system<double>();
  JacobiFlows<double> flows(sys.G, sys.mass);
  nystrom::operators::FlowIntegrator<JacobiFlows<double>> integ(resolve_wh_method(method, 53, "double"));
  std::vector<double> s = to_jacobi(sys);
  integ.integrate(flows, s, 200.0, 1);
  const std::size_t before = g_allocations;
  integ.integrate(flows, s, 200.0, 1000);
  return static_cast<double>(g_allocations - before) / 1000;
}

/// The largest difference between the two solvers over 2000 drifts of every orbit, relative to |x| and |v|.
double largest_difference(double h) {
  Orbits a = jacobi_orbits(), b = a;
  double d = 0;
  for (int k = 0; k < 2000; ++k) {
    drift_all<Drift::library>(a, h);
    drift_all<Drift::baseline>(b, h);
    for (std::size_t i = 1; i < a.mu.size(); ++i) {
      double dx = 0, dv = 0, nx = 0, nv = 0;
      for (int c = 0; c < 3; ++c) {
        dx += (a.x[i][c] - b.x[i][c]) * (a.x[i][c] - b.x[i][c]);
        dv += (a.v[i][c] - b.v[i][c]) * (a.v[i][c] - b.v[i][c]);
        nx += a.x[i][c] * a.x[i][c];
        nv += a.v[i][c] * a.v[i][c];
      }
      d = std::max({d, std::sqrt(dx / nx), std::sqrt(dv / nv)});
    }
    // restart both from the library's state: the difference of one drift, not of 2000 accumulated ones
    b = a;
  }
  return d;
}

class TableReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const auto& r : runs) {
      if (r.run_type != Run::RT_Iteration || r.error_occurred || r.iterations <= 0) continue;
      const auto u = r.counters.find("units");
      if (u == r.counters.end()) continue;
      const double ns = r.cpu_accumulated_time / static_cast<double>(r.iterations) / u->second.value * 1e9;
      const std::string name = r.benchmark_name();
      if (!best_.count(name) || ns < best_[name]) best_[name] = ns;
    }
  }
  void print_ratios(const std::vector<std::string>& cases) const {
    std::printf("\n%-28s %14s %14s %10s\n", "case", "baseline ns", "library ns", "speed-up");
    for (const std::string& c : cases) {
      const auto a = best_.find("baseline/" + c), b = best_.find("library/" + c);
      if (a == best_.end() || b == best_.end()) continue;
      std::printf("%-28s %14.1f %14.1f %9.2fx\n", c.c_str(), a->second, b->second, a->second / b->second);
    }
  }

 private:
  std::map<std::string, double> best_;
};

}  // namespace

int main(int argc, char** argv) {
  if (!nystrom::bench::initialize(std::vector<char*>(argv, argv + argc), 5)) return 1;
  std::vector<std::string> cases;
  for (double h : {50.0, 100.0, 200.0, 400.0}) {
    const std::string c = "drift/h=" + std::to_string(static_cast<int>(h));
    cases.push_back(c);
    benchmark::RegisterBenchmark(("baseline/" + c).c_str(), BM_drift<Drift::baseline>, h);
    benchmark::RegisterBenchmark(("library/" + c).c_str(), BM_drift<Drift::library>, h);
    const std::string one = "drift-one-at-a-time/h=" + std::to_string(static_cast<int>(h));
    cases.push_back(one);
    benchmark::RegisterBenchmark(("baseline/" + one).c_str(), BM_drift<Drift::baseline>, h);
    benchmark::RegisterBenchmark(("library/" + one).c_str(), BM_drift<Drift::library_one_at_a_time>, h);
    std::printf("h = %3.0f d: largest difference library - baseline after one drift: %.2e (relative)\n", h,
                largest_difference(h));
  }
  for (const char* m : {"WH-M8", "WH-KL8"}) {
    std::printf("%s: %.2f heap allocations per step\n", m, allocations_per_step(m));
    const std::string c = std::string(m) + "/h=200";
    cases.push_back(c);
    benchmark::RegisterBenchmark(("baseline/" + c).c_str(), BM_step<BaselineJacobiFlows>, std::string(m), 200.0);
    benchmark::RegisterBenchmark(("library/" + c).c_str(), BM_step<JacobiFlows<double>>, std::string(m), 200.0);
  }
  TableReporter rep;
  benchmark::RunSpecifiedBenchmarks(&rep);
  rep.print_ratios(cases);
  std::printf("(ns per drift of one planet, or per step of the map; minimum over repetitions, CPU time)\n");
  benchmark::Shutdown();
  return 0;
}
