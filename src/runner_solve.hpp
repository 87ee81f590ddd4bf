// `nystrom run --problem kepler` through solve(): output times, events, checkpoint and restart.
#pragma once

#include <cmath>
#include <limits>
#include <string>

#include <nlohmann/json.hpp>

#include "nystrom/methods/method.hpp"
#include "runner.hpp"

namespace nystrom::cli {

struct SolveRequest {
  std::string output_times;  // "A:B:N": N equally spaced output times from A to B (dense output)
  std::string events;        // comma-separated: pericentre, apocentre, y=0
  std::string checkpoint;    // file written at the first step boundary at or after checkpoint_at
  double checkpoint_at = std::numeric_limits<double>::quiet_NaN();
  std::string restart;  // checkpoint file to continue from
  bool any() const {
    return !output_times.empty() || !events.empty() || !checkpoint.empty() || !restart.empty() ||
           !std::isnan(checkpoint_at);
  }
};

struct SolveRunResult {
  RunReport report;
  nlohmann::json extra;  // t, q, v (the final state, exactly), output, events, ...
};

/// Kepler in double precision through solve(); throws UsageError for bad input.
SolveRunResult run_kepler_solve(const RunRequest& req, const SolveRequest& sreq, const MethodDef& def);

/// The method specification a checkpoint file was taken with; throws UsageError for an unreadable file.
std::string checkpoint_method(const std::string& path);

}  // namespace nystrom::cli
