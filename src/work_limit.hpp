// How much work a command may take: requests whose estimated cost is beyond a limit are refused with one line
// (a UsageError) before anything runs.
#pragma once

#include <string>

namespace nystrom::cli {

/// A count computed from doubles (e.g. N / f, duration / h): finite, within [1, max], else a UsageError.
long checked_count(double value, double max, const std::string& what);

/// Refuses work beyond the limit (1e14 units, or NYSTROM_WORK_LIMIT): `units` is the estimate in force
/// evaluations of a double Kepler force (an N-body force of n bodies counts n(n-1)/2). The message gives the
/// estimate.
void check_work_budget(double units, const std::string& what);

/// Relative cost of one force evaluation in a scalar type (double 1; measured ratios of bench_precision).
double precision_cost(const std::string& precision);

}  // namespace nystrom::cli
