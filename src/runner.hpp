// One measured run of a method on a problem, shared by `run`, `sweep` and `demo`.
// All instantiations over precisions live in runner.cpp (one translation unit).
#pragma once

#include <limits>
#include <string>

#include <nlohmann/json.hpp>

#include "nystrom/methods/method.hpp"

namespace nystrom::cli {

struct RunRequest {
  std::string problem = "kepler";  // kepler | harmonic
  double ecc = 0.9;                // kepler eccentricity
  long steps_per_period = 1000;    // steps per orbital period
  long periods = 10;               // whole periods integrated
  std::string precision = "double";
  bool keep_complex = false;       // complex methods: keep the complexified state
  double tol = 0;                  // adaptive methods: tolerance (required for them, refused otherwise)
};

struct RunReport {
  static constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  std::string method, family, problem, precision;
  int order = 0;
  double ecc = nan;
  long steps = 0;
  long force_evals = 0;
  double h = nan;
  double precession_per_period = nan;  // Kepler: signed LRL rotation per period (rad), CCW positive
  double energy_error = nan;           // relative energy error at the end
  double position_error = nan;         // |q - q_exact| at the end
  double seconds = nan;

  nlohmann::json to_json() const;
};

/// Problem names known to run_case.
const std::vector<std::string>& problem_names();

/// Validates the request (throws std::invalid_argument with a clear message) and runs it.
RunReport run_case(const RunRequest& req, const MethodDef& method);

}  // namespace nystrom::cli
