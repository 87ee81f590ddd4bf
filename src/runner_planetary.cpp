#include "runner_planetary.hpp"

#include <time.h>

#include <chrono>
#include <cmath>
#include <future>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <mpfr.h>

#include "cli.hpp"
#include "nystrom/methods/catalog.hpp"
#include "nystrom/planetary/system.hpp"
#include "nystrom/planetary/wisdom_holman.hpp"
#include "nystrom/solve/solve.hpp"
#include "runner.hpp"

namespace nystrom::cli {

namespace {

using namespace nystrom::planetary;

constexpr double kDaysPerYear = 365.25;
// The reference: Chin's multi-product expansion of order 12 over the Wisdom-Holman map, in long double, at the
// run's step divided by the smallest integer that brings it to 200 days or less.
const std::string kReferenceMethod = "WH-mpe:1,2,3,4,5,6";
constexpr double kReferenceMaxStep = 200;

/// CPU time of the calling thread: the runs are compared by it, as the reference runs in another thread and the
/// machine may be shared.
double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

nlohmann::json num(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); }

template <class R>
nlohmann::json vec(const Vec3<R>& a) {
  return nlohmann::json::array(
      {num(static_cast<double>(a[0])), num(static_cast<double>(a[1])), num(static_cast<double>(a[2]))});
}

struct Outcome {
  std::string method, family;
  int order = 0;
  long steps = 0, force_evals = 0, kepler_drifts = 0;
  long rejected = 0;  // adaptive direct methods
  double energy_error = 0, energy_error_max = 0, angular_momentum_error = 0, seconds = 0, cpu_seconds = 0;
  Vec3<long double> jupiter{};
};

template <class R>
void diagnose(const PlanetarySystem<R>& start, const PlanetarySystem<R>& end, Outcome& o) {
  const R e0 = energy(start.G, start.mass, start.x, start.v);
  o.energy_error = static_cast<double>(energy(end.G, end.mass, end.x, end.v) / e0 - 1);
  const Vec3<R> l0 = angular_momentum(start.mass, start.x, start.v), l1 = angular_momentum(end.mass, end.x, end.v);
  R d = 0, n = 0;
  for (int k = 0; k < 3; ++k) {
    d += (l1[k] - l0[k]) * (l1[k] - l0[k]);
    n += l0[k] * l0[k];
  }
  using std::sqrt;
  o.angular_momentum_error = static_cast<double>(sqrt(d / n));
  for (int k = 0; k < 3; ++k) o.jupiter[k] = static_cast<long double>(end.x[1][k]);
}

/// A Wisdom-Holman map, with the largest relative energy error over about a thousand samples.
template <class R>
Outcome run_map(const std::string& method, R h, long steps) {
  const PlanetarySystem<R> sys = outer_solar_system<R>();
  const R e0 = energy(sys.G, sys.mass, sys.x, sys.v);
  Outcome o;
  std::vector<Vec3<R>> x, v;
  PropagateOptions<R> opt;
  opt.every = std::max(1L, steps / 1000);
  opt.observer = [&](long, const std::vector<R>& s) {
    from_jacobi(sys.mass, s, x, v);
    o.energy_error_max =
        std::max(o.energy_error_max, std::fabs(static_cast<double>(energy(sys.G, sys.mass, x, v) / e0 - 1)));
  };
  const auto t0 = std::chrono::steady_clock::now();
  const double c0 = thread_cpu_seconds();
  const PropagateResult<R> r = propagate(sys, method, h, steps, opt);
  o.cpu_seconds = thread_cpu_seconds() - c0;
  o.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  o.method = r.method.name;
  o.family = r.method.family;
  o.order = r.method.order;
  o.steps = steps;
  o.force_evals = r.kicks;
  o.kepler_drifts = r.kepler_drifts;
  diagnose(sys, r.system, o);
  return o;
}

/// A direct method of the catalog on the Cartesian equations of motion (positions then velocities, body by body).
Outcome run_direct(const MethodDef& def, double h, long steps, double tol) {
  const PlanetarySystem<double> sys = outer_solar_system<double>();
  // Integrated in the centre-of-mass frame and moved back at the end: the barycentre of Hairer's data moves 2.5 AU
  // per thousand years, and positions that grow with time lose digits in every difference x_j - x_i.
  const PlanetarySystem<double> bary = barycentric(sys);
  const auto [com_x, com_v] = centre_of_mass(sys);
  const CartesianForce<double> force(bary);
  const double t1 = h * static_cast<double>(steps);
  const SecondOrderProblem problem(force, flatten(bary.x), flatten(bary.v), 0.0, t1);
  SolveOptions opt;
  if (def.info.adaptive)
    opt.rtol = tol;
  else
    opt.steps = steps;
  opt.t_eval = {t1};
  opt.dense = false;
  opt.max_steps = 1000000000;
  const auto t0 = std::chrono::steady_clock::now();
  const double c0 = thread_cpu_seconds();
  const Solution<std::vector<double>> sol = solve(problem, def, opt);
  Outcome o;
  o.cpu_seconds = thread_cpu_seconds() - c0;
  o.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  o.method = def.info.name;
  o.family = def.info.family;
  o.order = def.info.order;
  o.steps = def.info.adaptive ? sol.accepted : steps;
  o.force_evals = sol.force_evals;
  o.rejected = sol.rejected;
  PlanetarySystem<double> end = sys;
  unflatten(sol.q_final, end.x);
  unflatten(sol.v_final, end.v);
  for (std::size_t i = 0; i < end.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      end.x[i][k] += com_x[k] + com_v[k] * t1;
      end.v[i][k] += com_v[k];
    }
  diagnose(sys, end, o);
  o.energy_error_max = std::fabs(o.energy_error);
  return o;
}

bool is_map(const std::string& method) {
  return method == "WH" || method.rfind("WH-", 0) == 0 || method.rfind("WHC", 0) == 0 || method.rfind("WHD", 0) == 0 ||
         method.rfind("SABA", 0) == 0 || method.rfind("SBAB", 0) == 0;
}

}  // namespace

nlohmann::json run_planetary(const PlanetaryRequest& req) {
  if (req.method.empty()) throw UsageError("--method is required");
  if (!std::isfinite(req.h) || !(req.h > 0)) throw UsageError("--h must be a positive number of days");
  if (!std::isfinite(req.years) || !(req.years > 0)) throw UsageError("--years must be positive");
  const double steps_d = std::round(req.years * kDaysPerYear / req.h);
  if (!(steps_d >= 1)) throw UsageError("--years is shorter than one step of --h days");
  if (!(steps_d <= 1e10)) throw UsageError("--years / --h asks for more than 1e10 steps");
  const long steps = static_cast<long>(steps_d);
  const bool map = is_map(req.method);
  if (req.precision != "double" && !(map && req.precision == "long-double"))
    throw UsageError("outer-solar-system runs in double, or long-double for the Wisdom-Holman maps, not '" +
                     req.precision + "'");
  MethodDef direct;
  if (map) {
    // resolve first: an unknown or inapplicable method is reported before any work
    const auto fm = resolve_wh_method(req.method, 64, "long-double");
    (void)fm;
    // 15 pairs per force, at most about 20 kicks per step for the maps of order <= 12
    check_work_budget(steps_d * 15 * 20 * precision_cost(req.precision) * (req.reference ? 4 : 1), "run");
  } else {
    direct = resolve_run_method(req.method);
    if (direct.info.adaptive && !(req.tol > 0)) throw UsageError("'" + req.method + "' is adaptive: give --tol");
    if (!direct.info.adaptive && req.tol > 0) throw UsageError("--tol applies to adaptive methods only");
    check_work_budget(steps_d * 15 * std::max(1, direct.info.forces_per_step) * (req.reference ? 2 : 1), "run");
  }

  // the reference runs in a second thread while the requested run goes on
  const long ref_factor = std::max(1L, static_cast<long>(std::ceil(req.h / kReferenceMaxStep)));
  std::future<Outcome> reference;
  if (req.reference)
    reference = std::async(std::launch::async, [&] {
      // MPFR keeps per-thread caches (of constants such as pi) until the thread frees them (MPFR's manual).
      struct FreeMpfrCache {
        ~FreeMpfrCache() { mpfr_free_cache(); }
      } free_cache;
      return run_map<long double>(kReferenceMethod, static_cast<long double>(req.h) / ref_factor, steps * ref_factor);
    });
  Outcome o;
  if (!map)
    o = run_direct(direct, req.h, steps, req.tol);
  else if (req.precision == "long-double")
    o = run_map<long double>(req.method, static_cast<long double>(req.h), steps);
  else
    o = run_map<double>(req.method, req.h, steps);

  nlohmann::json j{{"problem", "outer-solar-system"},
                   {"method", o.method},
                   {"family", o.family},
                   {"order", o.order},
                   {"precision", req.precision},
                   {"h", num(req.h)},
                   {"adaptive", !map && direct.info.adaptive},  // then h sets only the span: steps * h days
                   {"years", num(req.years)},
                   {"steps", o.steps},
                   {"force_evals", o.force_evals},
                   {"kepler_drifts", o.kepler_drifts},
                   {"rejected", o.rejected},
                   {"energy_error", num(o.energy_error)},
                   {"energy_error_max", num(o.energy_error_max)},
                   {"angular_momentum_error", num(o.angular_momentum_error)},
                   {"jupiter_position", vec(o.jupiter)},
                   {"seconds", num(o.seconds)},
                   {"cpu_seconds", num(o.cpu_seconds)}};
  if (req.reference) {
    const Outcome r = reference.get();
    long double d = 0;
    for (int k = 0; k < 3; ++k) d += (o.jupiter[k] - r.jupiter[k]) * (o.jupiter[k] - r.jupiter[k]);
    j["jupiter_position_error"] = num(static_cast<double>(std::sqrt(d)));
    j["reference"] = {{"method", r.method},
                      {"precision", "long-double"},
                      {"h", num(req.h / static_cast<double>(ref_factor))},
                      {"energy_error", num(r.energy_error)},
                      {"jupiter_position", vec(r.jupiter)},
                      {"seconds", num(r.seconds)},
                      {"cpu_seconds", num(r.cpu_seconds)}};
  } else {
    j["jupiter_position_error"] = nullptr;
    j["reference"] = nullptr;
  }
  return j;
}

void print_planetary(const nlohmann::json& r) {
  auto d = [&](const char* key) { return r[key].is_null() ? std::nan("") : r[key].get<double>(); };
  fmt::print("method                 {} ({}, order {})\n", r["method"].get<std::string>(),
             r["family"].get<std::string>(), r["order"].get<int>());
  fmt::print("problem                outer solar system (Hairer, Lubich & Wanner, GNI sec. I.2.4)\n");
  fmt::print("precision              {}\n", r["precision"].get<std::string>());
  const long steps = r["steps"].get<long>();
  if (r.value("adaptive", false))  // the span is a whole number of --h days
    fmt::print("steps                  {} accepted, {} rejected (mean h = {:.6g} days, {:.6g} years)\n", steps,
               r.value("rejected", 0L),
               d("h") * std::round(d("years") * kDaysPerYear / d("h")) / static_cast<double>(steps > 0 ? steps : 1),
               d("years"));
  else
    fmt::print("steps                  {} (h = {:.6g} days, {:.6g} years)\n", steps, d("h"), d("years"));
  fmt::print("force evaluations      {}\n", r["force_evals"].get<long>());
  fmt::print("energy error           {:.6e} (relative; largest over the run {:.6e})\n", d("energy_error"),
             d("energy_error_max"));
  fmt::print("angular momentum error {:.6e} (relative)\n", d("angular_momentum_error"));
  const auto& p = r["jupiter_position"];
  fmt::print("Jupiter                ({:.12f}, {:.12f}, {:.12f}) AU\n", p[0].get<double>(), p[1].get<double>(),
             p[2].get<double>());
  if (!r["reference"].is_null())
    fmt::print("Jupiter error          {:.6e} AU (against {} in long double at h = {:.6g} days)\n",
               d("jupiter_position_error"), r["reference"]["method"].get<std::string>(),
               r["reference"]["h"].get<double>());
  fmt::print("time                   {:.6f} s ({:.6f} s of CPU)\n", d("seconds"), d("cpu_seconds"));
}

}  // namespace nystrom::cli
