#include "work_limit.hpp"

#include <cmath>
#include <cstdlib>

#include <fmt/core.h>

#include "usage_error.hpp"

namespace nystrom::cli {

long checked_count(double value, double max, const std::string& what) {
  if (!std::isfinite(value) || !(value < max + 0.5))
    throw UsageError(fmt::format("{} would be {:.3g}, more than the limit {:.3g}", what, value, max));
  const long n = std::lround(value);
  return n < 1 ? 1 : n;
}

double precision_cost(const std::string& precision) {
  if (precision == "double" || precision == "float") return 1;
  if (precision == "long-double") return 3;
  if (precision == "dd") return 10;
  if (precision == "float128") return 55;
  if (precision == "qd") return 100;
  if (precision.rfind("mpfr", 0) == 0) return 300;
  return 1;
}

void check_work_budget(double units, const std::string& what) {
  double limit = 1e14;
  if (const char* env = std::getenv("NYSTROM_WORK_LIMIT")) {
    char* end = nullptr;
    const double v = std::strtod(env, &end);
    if (end != env && *end == '\0' && v > 0 && std::isfinite(v)) limit = v;
  }
  if (!(units <= limit))  // also NaN
    throw UsageError(
        fmt::format("{}: the estimated work is {:.3g} force evaluations (of a double Kepler force; an N-body force "
                    "counts n(n-1)/2), above the limit {:.3g}, about {:.3g} hours (NYSTROM_WORK_LIMIT raises it)",
                    what, units, limit, units * 3e-9 / 3600));
}

}  // namespace nystrom::cli
