// `nystrom run --problem outer-solar-system`: Hairer's outer solar system integrated with a Wisdom-Holman map
// (WH, WH-<catalog method>, SABA_n, SBAB_n; planetary/wisdom_holman.hpp) or a direct method of the catalog on
// the Cartesian N-body equations, with its energy and angular momentum errors and Jupiter's position against a
// long double reference run.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

namespace nystrom::cli {

struct PlanetaryRequest {
  std::string method;
  double h = 100;      // days
  double years = 1e3;  // Julian years of 365.25 days
  std::string precision = "double";
  double tol = 0;         // adaptive direct methods
  bool reference = true;  // compute the reference run (long double, in a second thread)
};

/// The report as JSON (keys documented in docs/planetary.md). Throws std::invalid_argument or UsageError for
/// bad input.
nlohmann::json run_planetary(const PlanetaryRequest& req);

/// The report as text.
void print_planetary(const nlohmann::json& report);

}  // namespace nystrom::cli
