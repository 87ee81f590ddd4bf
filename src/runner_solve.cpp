// `nystrom run --problem kepler` with output times, events, checkpoint and restart (double precision): the
// options read into RunOutputs for run_orbit (runner_typed.hpp), its solution into JSON.
#include <array>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "cli.hpp"
#include "nystrom/solve/checkpoint.hpp"
#include "runner_solve.hpp"

namespace nystrom::cli {

namespace {

using V2 = std::array<double, 2>;

// "A:B:N" -> N equally spaced times from A to B.
std::vector<double> parse_output_times(const std::string& spec) {
  const auto a = spec.find(':');
  const auto b = a == std::string::npos ? a : spec.find(':', a + 1);
  if (b == std::string::npos || spec.find(':', b + 1) != std::string::npos)
    throw UsageError("--output-times must be A:B:N (from A to B, N points)");
  const double t0 = parse_double(spec.substr(0, a), "--output-times A");
  const double t1 = parse_double(spec.substr(a + 1, b - a - 1), "--output-times B");
  const long n = static_cast<long>(parse_integer(spec.substr(b + 1), "--output-times N", 1, 10000000));
  if (n == 1 && t0 != t1) throw UsageError("--output-times: one point needs A = B");
  if (t1 < t0) throw UsageError("--output-times: B must not be before A");
  std::vector<double> t(static_cast<std::size_t>(n));
  for (long i = 0; i < n; ++i)
    t[static_cast<std::size_t>(i)] = n == 1 ? t0 : t0 + (t1 - t0) * static_cast<double>(i) / static_cast<double>(n - 1);
  if (n > 1) t.back() = t1;
  return t;
}

std::vector<Event<V2>> parse_events(const std::string& spec) {
  std::vector<Event<V2>> ev;
  std::stringstream ss(spec);
  std::string name;
  auto radial = [](double, const V2& q, const V2& v) { return q[0] * v[0] + q[1] * v[1]; };
  while (std::getline(ss, name, ',')) {
    if (name == "pericentre" || name == "pericenter")
      ev.push_back({"pericentre", radial, +1, false});  // r.v turns from negative to positive
    else if (name == "apocentre" || name == "apocenter")
      ev.push_back({"apocentre", radial, -1, false});
    else if (name == "y=0")
      ev.push_back({"y=0", [](double, const V2& q, const V2&) { return q[1]; }, 0, false});
    else
      throw UsageError("unknown event '" + name + "' (known: pericentre, apocentre, y=0)");
  }
  if (ev.empty()) throw UsageError("--events: no event given (known: pericentre, apocentre, y=0)");
  return ev;
}

nlohmann::json vec(const V2& x) { return nlohmann::json::array({x[0], x[1]}); }

}  // namespace

SolveRunResult run_kepler_solve(const RunRequest& req, const SolveRequest& sreq, const MethodDef& def) {
  if (req.problem != "kepler")
    throw UsageError("--output-times, --events, --checkpoint and --restart run on the kepler problem");
  check_run_request(req, def);
  if (req.precision != "double")
    throw UsageError("--output-times, --events, --checkpoint and --restart run in double precision");
  if (sreq.checkpoint.empty() != std::isnan(sreq.checkpoint_at))
    throw UsageError("--checkpoint FILE and --checkpoint-at T go together");
  if (!sreq.checkpoint.empty() && !sreq.restart.empty() && sreq.checkpoint == sreq.restart)
    throw UsageError("--checkpoint and --restart name the same file");
  RunOutputs<V2> outputs;
  if (!sreq.output_times.empty()) outputs.t_eval = parse_output_times(sreq.output_times);
  if (!sreq.events.empty()) outputs.events = parse_events(sreq.events);
  // What a checkpoint must match: everything that defines the steps, except the end of the span.
  const bool tolerance = def.info.adaptive;
  char tag[256];
  std::snprintf(tag, sizeof tag, "kepler ecc=%a precision=double %s=%a keep_complex=%d%s", req.ecc,
                tolerance ? "tol" : "steps_per_period", tolerance ? req.tol : static_cast<double>(req.steps_per_period),
                req.keep_complex ? 1 : 0, req.force == "compensated" ? " force=compensated" : "");
  outputs.checkpoint_problem = tag;
  if (!sreq.checkpoint.empty()) {
    if (!(sreq.checkpoint_at >= 0) || !std::isfinite(sreq.checkpoint_at))
      throw UsageError("--checkpoint-at must be a finite time >= 0");
    outputs.checkpoint_at = sreq.checkpoint_at;
    const std::string file = sreq.checkpoint;
    // atomically, its temporary file removed on SIGINT/SIGTERM too; a link or a non-regular file is refused
    outputs.on_checkpoint = [file](const std::string& text) { write_checkpoint_text(file, text); };
  }
  if (!sreq.restart.empty()) {
    try {
      outputs.restart = read_checkpoint<double>(sreq.restart);
    } catch (const invalid_input& e) {
      throw UsageError(e.what());
    }
  }
  auto run = run_orbit<double, 2>(req, def, outputs);
  const Solution<V2>& sol = run.sol;
  if (!sreq.checkpoint.empty() && !sol.checkpoint)
    throw UsageError("--checkpoint-at lies at or after the end of the run: no checkpoint was written");

  SolveRunResult result;
  result.report = std::move(run.report);
  auto& extra = result.extra;
  // The final state exactly (the shortest decimal that reads back to the same double: a comparison of
  // two runs' q and v is a bitwise one).
  extra["t"] = sol.t_final;
  extra["q"] = vec(sol.q_final);
  extra["v"] = vec(sol.v_final);
  extra["output_force_evals"] = sol.output_force_evals;
  if (!sreq.output_times.empty()) {
    auto out = nlohmann::json::array();
    for (std::size_t i = 0; i < sol.t.size(); ++i)
      out.push_back({{"t", sol.t[i]}, {"q", vec(sol.q[i])}, {"v", vec(sol.v[i])}});
    extra["output"] = out;
  }
  if (!outputs.events.empty()) {
    auto out = nlohmann::json::array();
    for (const auto& e : sol.events) out.push_back({{"name", e.name}, {"t", e.t}, {"q", vec(e.q)}, {"v", vec(e.v)}});
    extra["events"] = out;
  }
  if (sol.checkpoint) extra["checkpoint_t"] = sol.checkpoint->t;
  return result;
}

std::string checkpoint_method(const std::string& path) {
  try {
    return read_checkpoint<double>(path).method;
  } catch (const invalid_input& e) {
    throw UsageError(e.what());
  }
}

}  // namespace nystrom::cli
