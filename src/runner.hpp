// One measured run of a method on a problem, shared by `run`, `sweep` and `demo`.
// All instantiations over precisions live in runner.cpp (one translation unit).
#pragma once

#include <limits>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include <nlohmann/json.hpp>

#include "nystrom/methods/method.hpp"
#include "progress.hpp"

namespace nystrom::cli {

struct RunRequest {
  std::string problem = "kepler";  // kepler | harmonic | twobody | nbody
  double ecc = 0.9;                // kepler eccentricity
  long steps_per_period = 1000;    // steps per orbital period
  long periods = 10;               // whole periods integrated
  std::string precision = "double";
  bool keep_complex = false;    // complex methods: keep the complexified state
  double tol = 0;               // adaptive methods: tolerance (required for them, refused otherwise)
  std::string force = "plain";  // kepler, twobody, nbody: plain or compensated (CompensatedKeplerForce, ...NBodyForce)
  // nbody / twobody (double precision):
  long n = 400;             // Plummer particles
  unsigned long seed = 42;  // Plummer sample
  std::string ic_file;      // particle file (m x y z vx vy vz per line) instead of a Plummer sphere
  double eps2 = -1;         // softening squared; < 0: (1/N)^2 for nbody, 0 for twobody
  double h = 0.01;          // nbody: step size (time units)
  long steps = 100;         // nbody: number of steps
  bool progress = false;    // a progress line on a terminal (RunMeter) for a long fixed-step Kepler/harmonic run
};

/// The progress of one run, measured in force evaluations: MeteredForce calls tick() every interval()
/// evaluations, which reads the clock and, once the run has lasted a second, draws the progress line
/// (Progress: on a terminal or with NYSTROM_PROGRESS=1, which draws from the start). `expected` is the
/// number of force evaluations the run will make, `cost` the relative cost of one (precision_cost).
class RunMeter {
 public:
  RunMeter(long expected, double cost);
  RunMeter(const RunMeter&) = delete;
  RunMeter& operator=(const RunMeter&) = delete;
  ~RunMeter();
  /// interval() more evaluations were made; returns how many to make before the next call.
  long tick();
  /// Evaluations between two ticks: about 20 microseconds of work, at least one.
  long interval() const { return interval_; }
  /// The run is over: the line shows it complete (if it was drawn).
  void finish();

 private:
  long expected_, interval_, done_ = 0;
  double start_;
  bool immediate_ = false, shown_ = false;
  std::unique_ptr<Progress> line_;
};

/// A force that counts its evaluations for a RunMeter (none: never calls it) and otherwise is `F`: the
/// same operations in the same order, so results are bitwise those of `F`.
template <class F>
struct MeteredForce {
  F f;
  RunMeter* meter = nullptr;
  mutable long left = meter ? meter->interval() : std::numeric_limits<long>::max();
  template <class Q, class A>
  void operator()(const Q& q, A& a) const {
    f(q, a);
    if (--left == 0) left = meter ? meter->tick() : std::numeric_limits<long>::max();
  }
  template <class Q, class A>
  requires std::is_invocable_v<const F&, const Q&, const Q&, A&, A&>
  void operator()(const Q& q, const Q& cq, A& a, A& alo) const {
    f(q, cq, a, alo);
    if (--left == 0) left = meter ? meter->tick() : std::numeric_limits<long>::max();
  }
};

/// The Gragg-Bulirsch-Stoer reference integrator is a method of `run`/`sweep` too, named "GBS"
/// (adaptive: it needs --tol): gbs_method_def() of the catalog.
MethodDef gbs_method();
/// resolve_solve_method(): resolve_method() plus "GBS".
MethodDef resolve_run_method(const std::string& spec);

struct RunReport {
  static constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  std::string method, family, problem, precision;
  std::string force;  // kepler, harmonic, twobody and nbody runs: the force form (RunRequest::force)
  int order = 0;
  double ecc = nan;
  long steps = 0;
  long force_evals = 0;
  // Adaptive methods and GBS (JSON keys `rejected`, `precise_products` when adaptive is set): the rejected steps, and
  // whether the products of an adaptive multi-product method carried their own rounding (Solution::precise_products)
  bool adaptive = false;
  long rejected = 0;
  bool precise_products = false;
  double h = nan;
  double precession_per_period = nan;  // Kepler: signed LRL rotation per period (rad), CCW positive
  double energy_error = nan;           // relative energy error at the end
  double position_error = nan;         // |q - q_exact| at the end
  double seconds = nan;
  // kepler, harmonic: the end time and the final state (nearest doubles; JSON with 17 significant digits)
  double t = nan;
  std::vector<double> q, v;

  nlohmann::json to_json() const;
};

/// Problem names known to run_case.
const std::vector<std::string>& problem_names();

/// Validates the request (throws std::invalid_argument with a clear message) and runs it.
RunReport run_case(const RunRequest& req, const MethodDef& method);

/// run_case's checks of a request for `method` that hold for every problem (the steps, the periods, the
/// tolerance; throws UsageError).
void check_run_request(const RunRequest& req, const MethodDef& method);
/// The --force option alone: plain, or compensated for the problems that have a compensated force (kepler, twobody,
/// nbody) in double; UsageError otherwise.
void check_force_option(const RunRequest& req);

/// Fills the method, its family and order, the problem and the precision of a report.
void label_report(RunReport& r, const RunRequest& req, const MethodDef& method);

}  // namespace nystrom::cli
