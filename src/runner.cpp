#include "runner.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

#include "cli.hpp"
#include "experiments/nbody_run.hpp"
#include "nystrom/core/precision.hpp"
#include "nystrom/methods/catalog.hpp"
#include "nystrom/methods/compensated_force.hpp"

namespace nystrom::cli {

namespace {

nlohmann::json num(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); }

double seconds_now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

RunMeter::RunMeter(long expected, double cost) : expected_(std::max(expected, 1L)), start_(seconds_now()) {
  const char* env = std::getenv("NYSTROM_PROGRESS");
  immediate_ = env && std::strcmp(env, "1") == 0;
  const bool enabled = immediate_ || (!env && ::isatty(STDERR_FILENO));
  // about 20 microseconds of work between two looks at the clock (a double Kepler force takes a few ns)
  interval_ = enabled ? std::max(1L, static_cast<long>(5000 / std::max(cost, 1.0))) : std::numeric_limits<long>::max();
  if (enabled) line_ = std::make_unique<Progress>("run", expected_);
}

RunMeter::~RunMeter() = default;

long RunMeter::tick() {
  done_ += interval_;
  if (line_ && (shown_ || immediate_ || seconds_now() - start_ >= 1)) {
    line_->tick(std::min(done_, expected_ - 1));  // complete only when finish() says so
    shown_ = true;
  }
  return interval_;
}

void RunMeter::finish() {
  if (line_ && shown_) line_->tick(expected_);
  line_.reset();
}

// Defined in runner_typed.hpp, instantiated for each precision in runner_<precision>.cpp.
template <class T>
RunReport run_in_precision(const RunRequest& req, const MethodDef& def);

nlohmann::json RunReport::to_json() const {
  nlohmann::json j{{"method", method},
                   {"adaptive", adaptive},
                   {"family", family},
                   {"order", order},
                   {"problem", problem},
                   {"precision", precision},
                   {"ecc", num(ecc)},
                   {"steps", steps},
                   {"force_evals", force_evals},
                   {"h", num(h)},
                   {"precession_per_period", num(precession_per_period)},
                   {"energy_error", num(energy_error)},
                   {"position_error", num(position_error)},
                   {"seconds", num(seconds)}};
  if (!force.empty()) j["force"] = force;
  if (adaptive) {
    j["rejected"] = rejected;
    j["precise_products"] = precise_products;
  }
  if (!q.empty()) {  // the final state, each number to 17 significant digits (it reads back to the same double)
    j["t"] = num(t);
    j["q"] = q;
    j["v"] = v;
  }
  return j;
}

const std::vector<std::string>& problem_names() {
  static const std::vector<std::string> names{"kepler", "harmonic", "twobody", "nbody"};
  return names;
}

MethodDef gbs_method() { return gbs_method_def(); }

MethodDef resolve_run_method(const std::string& spec) { return resolve_solve_method(spec); }

namespace {

RunReport run_nbody_case(const RunRequest& req, const MethodDef& def) {
  if (req.precision != "double") throw UsageError("--problem " + req.problem + " runs in double precision only");
  if (req.keep_complex) throw UsageError("--keep-complex is not available for --problem " + req.problem);
  NBodySetup setup;
  setup.problem = req.problem;
  if (req.n <= 0 || req.n > 1000000) throw UsageError("--n must be between 1 and 1000000");
  setup.n = static_cast<std::size_t>(req.n);
  setup.seed = req.seed;
  setup.ic_file = req.ic_file;
  setup.ecc = req.ecc;
  setup.eps2 = req.eps2;
  double h = req.h;
  long steps = req.steps;
  if (req.problem == "twobody") {  // whole periods of the relative orbit, as for kepler
    if (!std::isfinite(req.ecc) || req.ecc < 0 || req.ecc >= 1) throw UsageError("--ecc must satisfy 0 <= e < 1");
    h = 2 * std::acos(-1.0) / static_cast<double>(req.steps_per_period);
    steps = req.steps_per_period * req.periods;
  }
  NBodyRunResult r;
  try {
    const double tol = def.info.adaptive ? req.tol : 0.0;
    r = req.force == "compensated" ? run_nbody_compensated(def.info.name, setup, h, steps, tol)
                                   : run_nbody(def.info.name, setup, h, steps, tol);
  } catch (const invalid_input& e) {
    throw UsageError(e.what());
  }
  RunReport out;
  out.ecc = req.problem == "twobody" ? req.ecc : RunReport::nan;
  out.steps = r.steps;
  out.force_evals = r.force_evals;
  out.rejected = r.rejected;
  out.precise_products = r.precise_products;
  out.h = r.h;
  out.energy_error = r.energy_error;
  out.position_error = r.position_error;
  out.seconds = r.seconds;
  return out;
}

}  // namespace

void check_run_request(const RunRequest& req, const MethodDef& def) {
  if (def.info.family == "mpe-midpoint")
    throw UsageError("method '" + def.info.name +
                     "' is for velocity-dependent forces (--problem arenstorf, damped-oscillator); for --problem " +
                     req.problem + " run " + verlet_mpe_counterpart(def));
  if (req.steps_per_period <= 0) throw UsageError("--steps-per-period must be a positive integer");
  if (req.periods <= 0) throw UsageError("--periods must be a positive integer");
  if (req.steps <= 0) throw UsageError("--steps must be a positive integer");
  if (!(req.h > 0) || !std::isfinite(req.h)) throw UsageError("--h must be positive and finite");
  if (req.steps_per_period > 1'000'000'000L / req.periods)
    throw UsageError("too many steps requested (steps-per-period x periods must be at most 1e9)");
  if (def.info.adaptive && !(req.tol > 0 && std::isfinite(req.tol)))
    throw UsageError("method '" + def.info.name + "' is adaptive: give a positive --tol");
  if (!def.info.adaptive && req.tol != 0)
    throw UsageError("--tol applies to adaptive methods only; '" + def.info.name + "' runs with fixed steps");
  check_force_option(req);
  if (req.force != "plain" && !uses_compensated_force(def.info))
    throw UsageError(compensated_force_refusal("--force compensated", def.info.name));
}

void check_force_option(const RunRequest& req) {
  if (req.force == "plain") return;
  if (req.force != "compensated") throw UsageError("--force must be plain or compensated, got '" + req.force + "'");
  if (req.problem != "kepler" && req.problem != "twobody" && req.problem != "nbody")
    throw UsageError("--force compensated applies to --problem kepler, twobody and nbody");
  if (req.precision != "double") throw UsageError("--force compensated runs in --precision double");
}

void label_report(RunReport& r, const RunRequest& req, const MethodDef& def) {
  r.method = def.info.name;
  r.family = def.info.family;
  r.order = def.info.order;
  r.problem = req.problem;
  r.precision = req.precision;
  r.adaptive = def.info.adaptive;  // GBS too: its h is then the mean accepted step
  if (req.problem == "kepler" || req.problem == "harmonic" || req.problem == "twobody" || req.problem == "nbody")
    r.force = req.force;
}

RunReport run_case(const RunRequest& req, const MethodDef& def) {
  check_run_request(req, def);
  RunReport r = req.problem == "nbody" || req.problem == "twobody"
                    ? run_nbody_case(req, def)
                    : dispatch_precision(req.precision, [&](auto tag) -> RunReport {
                        return run_in_precision<typename decltype(tag)::type>(req, def);
                      });
  label_report(r, req, def);
  return r;
}

}  // namespace nystrom::cli
