// Cost of the library's engines on Kepler (Chin eqs 35-36, e = 0.9) in double: nanoseconds per step of
// VV, FR, M4 and M8 through the library (make_integrator + integrate over a batch of steps) against a
// plain hand-written loop of the same method, measured in the same run:
//
//   VV        velocity Verlet, FSAL, the half kicks of consecutive steps merged (leapfrog form)
//   FR        Forest-Ruth position-first: 7 sub-steps, 3 forces, the last drift merged with the next first
//   M4        Chin eqs (33)-(34): the {1,2} PV multi-product method written out, 3 forces, against the
//             MPE engine (catalog "M4"); "M4-RKN" the same loop against the RKN engine (catalog
//             "M4-RKN"); "M4-sum" the MPE engine against the hand-written sum of products of eq (19)
//   M8        the {1,2,3,4} PV multi-product method, sum of products with the exact c_i of eq (21),
//             10 forces
// The MPE engine runs its products in lockstep (the default for fixed-size states); it is also measured
// with them in sequence ("sequential", as in the hand-written loops). The summary gives the cost of an M8
// step relative to 10 sequential force evaluations (10 hand VV steps); the target is <= 0.5.
//
// One benchmark iteration integrates a batch of kSteps steps from the apocentre (h = 2 pi / kSteps, one
// period per batch), the state reset every iteration (both variants then evaluate the first force anew).
// Both variants use the same force arithmetic (r2 = x^2 + y^2, r = sqrt(r2), a = -q / (r2 r)).
//
// Before benchmarking, every hand-written loop is checked against the library (same method, so the final
// states must agree to rounding). After the run, a table gives ns/step of both variants (the minimum over
// repetitions of the CPU time, robust on a shared machine) and the ratio library / hand-written.
// Target: ratio <= 1.10. Where the library has compensated summation (EngineOptions::compensated), it
// is measured with its default options and with compensation off ("plain", like the hand-written loops).
//
// The driver: solve() (solve/solve.hpp) with fixed steps, VV and M8, over kDriverPeriods periods of kSteps
// steps, against the bare loop of the same engine steps (make_integrator, then step(s, h) in a for loop:
// the engine calls solve() makes), in the same run; "saveat": the state saved at every kSaveEvery-th step
// end (solve: those step ends as output times); "vector": on std::vector<double> states (the Python module). Before the
// run, solve()'s states are checked to be bitwise those of the bare loop. Target: solve / bare loop <= 1.05.
//
//   bench_kepler --benchmark_repetitions=5     (the default here: 5 repetitions, 0.2 s each)
#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "bench_common.hpp"
#include "nystrom/engines/integrator.hpp"
#include "nystrom/methods/catalog.hpp"
#include "nystrom/problems/kepler.hpp"
#include "nystrom/solve/solve.hpp"

using namespace nystrom;

namespace {

constexpr double kEcc = 0.9;
constexpr long kSteps = 2000;  // per batch: one period at h = 2 pi / 2000

using V = std::array<double, 2>;

State<V> start() { return KeplerProblem<double>(kEcc).initial_state(); }
double step_size() { return 2 * std::acos(-1.0) / kSteps; }

// ---- hand-written loops -----------------------------------------------------------------------------

struct P {
  double x, y, vx, vy;
};

inline void force(double x, double y, double& ax, double& ay) {
  const double r2 = x * x + y * y;
  const double r = std::sqrt(r2);
  const double m = -1.0 / (r2 * r);
  ax = m * x;
  ay = m * y;
}

/// Velocity Verlet, FSAL, with the half kicks of consecutive steps merged.
P hand_vv(P s, double h, long n) {
  double ax, ay;
  force(s.x, s.y, ax, ay);
  s.vx += 0.5 * h * ax;
  s.vy += 0.5 * h * ay;
  for (long k = 0; k < n; ++k) {
    s.x += h * s.vx;
    s.y += h * s.vy;
    force(s.x, s.y, ax, ay);
    const double c = (k + 1 < n) ? h : 0.5 * h;
    s.vx += c * ax;
    s.vy += c * ay;
  }
  return s;
}

/// Forest-Ruth, position-first: drift th/2, kick th, drift (1-t)h/2, kick (1-2t)h, drift (1-t)h/2,
/// kick th, drift th/2; the last drift merged with the next step's first.
P hand_fr(P s, double h, long n) {
  const double theta = 1.0 / (2.0 - std::cbrt(2.0));
  const double d1 = 0.5 * theta * h, d2 = 0.5 * (1 - theta) * h, k1 = theta * h, k2 = (1 - 2 * theta) * h;
  double ax, ay;
  s.x += d1 * s.vx;
  s.y += d1 * s.vy;
  for (long k = 0; k < n; ++k) {
    force(s.x, s.y, ax, ay);
    s.vx += k1 * ax;
    s.vy += k1 * ay;
    s.x += d2 * s.vx;
    s.y += d2 * s.vy;
    force(s.x, s.y, ax, ay);
    s.vx += k2 * ax;
    s.vy += k2 * ay;
    s.x += d2 * s.vx;
    s.y += d2 * s.vy;
    force(s.x, s.y, ax, ay);
    s.vx += k1 * ax;
    s.vy += k1 * ay;
    const double d = (k + 1 < n) ? 2 * d1 : d1;
    s.x += d * s.vx;
    s.y += d * s.vy;
  }
  return s;
}

/// M4, Chin eqs (33)-(34).
P hand_m4(P s, double h, long n) {
  const double h2 = h * h;
  for (long k = 0; k < n; ++k) {
    double a1x, a1y, a2x, a2y, a3x, a3y;
    force(s.x + 0.25 * h * s.vx, s.y + 0.25 * h * s.vy, a1x, a1y);
    force(s.x + 0.5 * h * s.vx, s.y + 0.5 * h * s.vy, a2x, a2y);
    force(s.x + 0.75 * h * s.vx + 0.25 * h2 * a1x, s.y + 0.75 * h * s.vy + 0.25 * h2 * a1y, a3x, a3y);
    s.x += h * s.vx + (h2 / 6) * (3 * a1x - a2x + a3x);
    s.y += h * s.vy + (h2 / 6) * (3 * a1y - a2y + a3y);
    s.vx += (h / 3) * (2 * a1x - a2x + 2 * a3x);
    s.vy += (h / 3) * (2 * a1y - a2y + 2 * a3y);
  }
  return s;
}

/// sum_k c_k PV^k(h/k), k = 1..K, the drifts between the k applications of PV merged.
template <int K>
P hand_mpe(P s, double h, long n, const double (&c)[K]) {
  for (long step = 0; step < n; ++step) {
    P acc{0, 0, 0, 0};
    for (int k = 1; k <= K; ++k) {
      const double hk = h / k, half = 0.5 * hk;
      double x = s.x + half * s.vx, y = s.y + half * s.vy, vx = s.vx, vy = s.vy, ax, ay;
      for (int j = 0; j < k; ++j) {
        force(x, y, ax, ay);
        vx += hk * ax;
        vy += hk * ay;
        const double d = (j + 1 < k) ? hk : half;
        x += d * vx;
        y += d * vy;
      }
      const double ck = c[k - 1];
      acc.x += ck * x;
      acc.y += ck * y;
      acc.vx += ck * vx;
      acc.vy += ck * vy;
    }
    s = acc;
  }
  return s;
}

/// M4 as the sum of products, eq (19): c = (-1/3, 4/3).
P hand_m4_products(P s, double h, long n) {
  static constexpr double c[2] = {-1.0 / 3, 4.0 / 3};
  return hand_mpe(s, h, n, c);
}

/// M8: c = (-1/360, 16/45, -729/280, 1024/315), eq (21).
P hand_m8(P s, double h, long n) {
  static constexpr double c[4] = {-1.0 / 360, 16.0 / 45, -729.0 / 280, 1024.0 / 315};
  return hand_mpe(s, h, n, c);
}

using HandLoop = P (*)(P, double, long);

struct Case {
  const char* name;    // the benchmark label
  const char* method;  // the catalog method of the library variant
  HandLoop hand;       // the hand-written loop
};

const std::vector<Case>& cases() {
  static const std::vector<Case> c{{"VV", "VV", hand_vv},
                                   {"FR", "FR", hand_fr},
                                   {"M4", "M4", hand_m4},               // MPE engine vs eqs (33)-(34)
                                   {"M4-sum", "M4", hand_m4_products},  // MPE engine vs sum of products
                                   {"M4-RKN", "M4-RKN", hand_m4},       // RKN engine vs eqs (33)-(34)
                                   {"M8", "M8", hand_m8}};
  return c;
}

P to_p(const State<V>& s) { return {s.q[0], s.q[1], s.v[0], s.v[1]}; }

// ---- benchmarks ---------------------------------------------------------------------------------------

// Compensated summation of the updates (EngineOptions::compensated, where the library has it; on by
// default in double) costs extra additions that the plain hand-written loops do not do: the library is
// measured with its default options and, where the option exists, with compensation off ("plain").
template <class O>
constexpr bool has_compensation_option = requires(O o) {
  decltype(o.compensated)::off;
};

template <class O>
O plain_options(O o) {
  if constexpr (has_compensation_option<O>) o.compensated = decltype(o.compensated)::off;
  return o;
}

// The multi-product engine runs its independent products in lockstep by default for fixed-size states
// (EngineOptions::mpe_schedule); "sequential" forces one product after the other, as the hand loops do.
bool is_mpe(const Case& c) { return std::string(c.method).rfind("M", 0) == 0 && std::string(c.method) != "M4-RKN"; }

// How the library is run: plain = compensated summation off, as in the hand-written loops; sequential = the
// products of a multi-product method one after the other.
struct LibraryRun {
  bool plain = false;
  bool sequential = false;
};

void bm_library(benchmark::State& state, const Case& c, LibraryRun run) {
  EngineOptions opt = run.plain ? plain_options(EngineOptions{}) : EngineOptions{};
  if (run.sequential) opt.mpe_schedule = MpeSchedule::sequential;
  auto integ = make_integrator<V>(resolve_method(c.method), KeplerForce{}, opt);
  const double h = step_size();
  const State<V> s0 = start();
  for (auto _ : state) {
    State<V> s = s0;
    integ.integrate(s, h, kSteps);
    benchmark::DoNotOptimize(s);
  }
  state.SetItemsProcessed(state.iterations() * kSteps);
}

void bm_hand(benchmark::State& state, const Case& c) {
  const double h = step_size();
  const P s0 = to_p(start());
  for (auto _ : state) {
    P s = s0;
    benchmark::DoNotOptimize(s);
    s = c.hand(s, h, kSteps);
    benchmark::DoNotOptimize(s);
  }
  state.SetItemsProcessed(state.iterations() * kSteps);
}

/// The hand-written loops are the library's methods: final states agree to rounding.
bool check_hand_loops() {
  bool ok = true;
  for (const auto& c : cases()) {
    auto integ = make_integrator<V>(resolve_method(c.method), KeplerForce{}, plain_options(EngineOptions{}));
    State<V> s = start();
    integ.integrate(s, step_size(), kSteps);
    const P lib = to_p(s), hand = c.hand(to_p(start()), step_size(), kSteps);
    const double diff = std::max(
        {std::abs(lib.x - hand.x), std::abs(lib.y - hand.y), std::abs(lib.vx - hand.vx), std::abs(lib.vy - hand.vy)});
    std::printf("check %-7s library vs hand-written after one period: max |difference| = %.2e\n", c.name, diff);
    if (!(diff < 1e-8)) {
      std::fprintf(stderr, "error: the hand-written %s loop does not reproduce the library's %s\n", c.name, c.method);
      ok = false;
    }
  }
  return ok;
}

// ---- the driver: solve() against the bare loop of its engine steps ----------------------------------------

constexpr long kDriverPeriods = 50;
constexpr long kSaveEvery = 20;
const std::vector<std::string> kDriverMethods{"VV", "M8"};

long driver_steps() { return kDriverPeriods * kSteps; }
double driver_t1() { return 2 * std::acos(-1.0) * kDriverPeriods; }
// solve()'s step size for {.steps = n} and the step ends it computes (t0 = 0).
double driver_h() { return driver_t1() / static_cast<double>(driver_steps()); }
double driver_step_end(long j) { return j == driver_steps() ? driver_t1() : driver_h() * static_cast<double>(j); }

using VD = std::vector<double>;  // the state of the Python module's built-in problems

/// The saved times, positions and velocities of a run.
template <class W>
struct Saved {
  std::vector<double> t;
  std::vector<W> q, v;
};

template <class W>
State<W> start_as() {
  const State<V> s = start();
  return {W(s.q.begin(), s.q.end()), W(s.v.begin(), s.v.end())};
}
template <>
State<V> start_as<V>() {
  return start();
}

/// The bare loop: the engine steps one at a time, the state saved every `every` steps (0: only the end).
template <class W>
State<W> bare_run(Integrator<W, KeplerForce>& integ, long every, Saved<W>* out) {
  State<W> s = start_as<W>();
  const double h = driver_h();
  const long n = driver_steps();
  for (long k = 0; k < n; ++k) {
    integ.step(s, h);
    if (every > 0 && (k + 1) % every == 0) {
      out->t.push_back(driver_step_end(k + 1));
      out->q.push_back(s.q);
      out->v.push_back(s.v);
    }
  }
  return s;
}

SolveOptions driver_options(bool saveat) {
  SolveOptions o{.steps = driver_steps(), .dense = false};
  if (saveat) {
    for (long j = kSaveEvery; j <= driver_steps(); j += kSaveEvery) o.t_eval.push_back(driver_step_end(j));
  } else {
    o.t_eval = {driver_t1()};
  }
  return o;
}

template <class W>
auto driver_problem() {
  const State<W> s0 = start_as<W>();
  return SecondOrderProblem(KeplerForce{}, s0.q, s0.v, 0.0, driver_t1());
}

template <class W>
void bm_bare(benchmark::State& state, const std::string& method, bool saveat) {
  auto integ = make_integrator<W>(resolve_method(method), KeplerForce{});
  for (auto _ : state) {
    Saved<W> out;
    State<W> s = bare_run(integ, saveat ? kSaveEvery : 0, &out);
    benchmark::DoNotOptimize(s);
    benchmark::DoNotOptimize(out);
  }
}

/// solve(): on std::vector<double> the compiled path (libnystrom, the force behind ErasedForce); `inl`: the
/// inline path (solve_inline, the driver compiled here for KeplerForce), the baseline of the compiled one.
template <class W>
void bm_solve(benchmark::State& state, const std::string& method, bool saveat, bool inl = false) {
  const auto prob = driver_problem<W>();
  const SolveOptions opt = driver_options(saveat);
  for (auto _ : state) {
    auto sol = inl ? solve_inline(prob, method, opt) : solve(prob, method, opt);
    benchmark::DoNotOptimize(sol);
  }
}

/// DP12-adaptive over the driver's span at rtol 1e-10, end state only: compiled against inline path.
template <class W>
void bm_adaptive(benchmark::State& state, bool inl) {
  const auto prob = driver_problem<W>();
  const SolveOptions opt{.rtol = 1e-10, .t_eval = {driver_t1()}};
  for (auto _ : state) {
    auto sol = inl ? solve_inline(prob, "DP12-adaptive", opt) : solve(prob, "DP12-adaptive", opt);
    benchmark::DoNotOptimize(sol);
  }
}

/// solve() takes the engine steps of the bare loop: the same states, bit for bit.
bool check_driver() {
  bool ok = true;
  for (const auto& m : kDriverMethods) {
    auto integ = make_integrator<V>(resolve_method(m), KeplerForce{});
    Saved<V> bare;
    const State<V> end = bare_run(integ, kSaveEvery, &bare);
    const auto sol = solve(driver_problem<V>(), m, driver_options(true));
    const auto sol_end = solve(driver_problem<V>(), m, driver_options(false));
    const bool same = sol.t == bare.t && sol.q == bare.q && sol.v == bare.v && sol.q_final == end.q &&
                      sol.v_final == end.v && sol_end.q_final == end.q && sol_end.v_final == end.v;
    std::printf("check %-7s solve() vs the bare loop of its steps (%zu saved states): %s\n", m.c_str(), bare.t.size(),
                same ? "bitwise equal" : "DIFFERENT");
    if (!same) {
      std::fprintf(stderr, "error: solve() with %s does not take the bare loop's steps\n", m.c_str());
      ok = false;
    }
  }
  return ok;
}

/// The summary: minimum CPU time per step of every benchmark (bench_common.hpp), ratios to the hand loops.
class SummaryReporter : public bench::MinTimeReporter {
 public:
  SummaryReporter() : MinTimeReporter(Clock::cpu, static_cast<double>(kSteps), 1e9) {}
  void summary() const {
    std::printf("\nKepler e = %.1f, double, %ld steps per batch; minimum over repetitions of CPU time per step\n", kEcc,
                kSteps);
    const bool plain = has_compensation_option<EngineOptions>;
    std::printf("%-8s %10s %12s %9s", "method", "hand ns", "library ns", "lib/hand");
    if (plain) std::printf(" %12s %9s", "plain ns", "plain/hand");
    std::printf("\n");
    for (const auto& c : cases()) {
      const double* hand = best(std::string("hand/") + c.name);
      const double* lib = best(std::string("library/") + c.name);
      if (!lib || !hand) continue;
      std::printf("%-8s %10.2f %12.2f %9.3f", c.name, *hand, *lib, *lib / *hand);
      const double* pl = best(std::string("library-plain/") + c.name);
      if (plain && pl) std::printf(" %12.2f %9.3f", *pl, *pl / *hand);
      const double* sq = best(std::string("library-plain-sequential/") + c.name);
      if (sq) std::printf("   sequential products: %8.2f ns, %6.3f x hand", *sq, *sq / *hand);
      std::printf("\n");
    }
    std::printf("(target: library / hand-written <= 1.10%s)\n",
                plain ? "; 'plain' = the library with compensated summation off, as the hand-written loops" : "");
    // An M8 step (10 forces, products in lockstep) against 10 sequential force evaluations, i.e.
    // 10 steps of the hand-written velocity Verlet loop (one force per step, each depending on the last).
    const double *vv = best("hand/VV"), *m8 = best("library-plain/M8"), *m8s = best("library-plain-sequential/M8");
    if (vv && m8) {
      std::printf(
          "M8 step (lockstep products, plain) / 10 sequential forces (10 hand VV steps): %.3f (target <= 0.5)\n",
          *m8 / (10 * *vv));
      if (m8s) std::printf("M8 step (sequential products, plain) / 10 sequential forces: %.3f\n", *m8s / (10 * *vv));
    }
    bool header = false;
    for (const auto& m : kDriverMethods) {
      for (const char* kind : {"", "-saveat", "-vector", "-vector-saveat"}) {
        const double* bare = best("bare" + std::string(kind) + "/" + m);
        const double* drv = best("solve" + std::string(kind) + "/" + m);
        if (!bare || !drv) continue;
        if (!header) {
          std::printf(
              "\nsolve() against the bare loop of its engine steps, %ld steps (%ld periods), default engine "
              "options; saveat: every %ld-th step end saved; vector: std::vector<double> states\n%-17s %10s %10s "
              "%12s\n",
              driver_steps(), kDriverPeriods, kSaveEvery, "method", "bare ns", "solve ns", "solve/bare");
          header = true;
        }
        const double per = static_cast<double>(kDriverPeriods);  // the reporter divides by kSteps
        std::printf("%-17s %10.2f %10.2f %12.3f\n", (m + kind).c_str(), *bare / per, *drv / per, *drv / *bare);
      }
    }
    if (header) std::printf("(target: solve / bare <= 1.05)\n");
    // The compiled path of solve() against the inline one on std::vector<double> (the same steps, bit for bit).
    std::printf("\nsolve() on std::vector<double>: compiled (libnystrom) / inline (solve_inline), time per run\n");
    for (const std::string m : {"VV", "M8", "DP12-adaptive"}) {
      const double* c = best("compiled-vector/" + m);
      const double* i = best("inline-vector/" + m);
      if (c && i) std::printf("%-17s %12.2f %12.2f %9.3f\n", m.c_str(), *c, *i, *c / *i);
    }
    std::printf("(target: compiled / inline <= 1.15)\n");
  }
};

}  // namespace

int main(int argc, char** argv) {
  for (const auto& c : cases()) {
    benchmark::RegisterBenchmark((std::string("hand/") + c.name).c_str(), [&c](benchmark::State& s) {
      bm_hand(s, c);
    })->MinTime(0.2);
    benchmark::RegisterBenchmark((std::string("library/") + c.name).c_str(), [&c](benchmark::State& s) {
      bm_library(s, c, {});
    })->MinTime(0.2);
    if (has_compensation_option<EngineOptions>)
      benchmark::RegisterBenchmark((std::string("library-plain/") + c.name).c_str(), [&c](benchmark::State& s) {
        bm_library(s, c, {.plain = true});
      })->MinTime(0.2);
    if (is_mpe(c) && has_compensation_option<EngineOptions>)
      benchmark::RegisterBenchmark((std::string("library-plain-sequential/") + c.name).c_str(),
                                   [&c](benchmark::State& s) { bm_library(s, c, {.plain = true, .sequential = true}); })
          ->MinTime(0.2);
  }
  for (const auto& m : kDriverMethods) {
    for (const bool saveat : {false, true}) {
      const std::string kind = saveat ? "-saveat/" : "/";
      benchmark::RegisterBenchmark(("bare" + kind + m).c_str(), [m, saveat](benchmark::State& s) {
        bm_bare<V>(s, m, saveat);
      })->MinTime(0.2);
      benchmark::RegisterBenchmark(("solve" + kind + m).c_str(), [m, saveat](benchmark::State& s) {
        bm_solve<V>(s, m, saveat);
      })->MinTime(0.2);
      const std::string vkind = saveat ? "-vector-saveat/" : "-vector/";
      benchmark::RegisterBenchmark(("bare" + vkind + m).c_str(), [m, saveat](benchmark::State& s) {
        bm_bare<VD>(s, m, saveat);
      })->MinTime(0.2);
      benchmark::RegisterBenchmark(("solve" + vkind + m).c_str(), [m, saveat](benchmark::State& s) {
        bm_solve<VD>(s, m, saveat);
      })->MinTime(0.2);
    }
  }
  for (const auto& m : kDriverMethods) {
    benchmark::RegisterBenchmark(("compiled-vector/" + m).c_str(), [m](benchmark::State& s) {
      bm_solve<VD>(s, m, false, false);
    })->MinTime(0.2);
    benchmark::RegisterBenchmark(("inline-vector/" + m).c_str(), [m](benchmark::State& s) {
      bm_solve<VD>(s, m, false, true);
    })->MinTime(0.2);
  }
  benchmark::RegisterBenchmark("compiled-vector/DP12-adaptive", [](benchmark::State& s) {
    bm_adaptive<VD>(s, false);
  })->MinTime(0.2);
  benchmark::RegisterBenchmark("inline-vector/DP12-adaptive", [](benchmark::State& s) {
    bm_adaptive<VD>(s, true);
  })->MinTime(0.2);
  if (!bench::initialize({argv, argv + argc}, 5)) return 1;  // five repetitions unless told otherwise
  if (!check_hand_loops() || !check_driver()) return 1;
  SummaryReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  reporter.summary();
  benchmark::Shutdown();
  return 0;
}
