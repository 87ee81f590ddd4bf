// solve() on the small built-in problems in the extended precisions: long double, float128, double-double,
// quad-double and MPFR, one translation unit each (solve_extended.hpp), dispatched here.
#include "solve_extended.hpp"

#include <optional>

#include "nystrom/core/precision.hpp"

namespace nystrom::python {

py::dict solve_builtin_extended(const std::string& problem, const std::vector<double>& params, const SolveRequest& r,
                                const std::string& precision) {
  if (r.method.info.complex)
    throw invalid_input("complex-coefficient methods run in double only (method '" + r.method.info.name + "')");
  const SmallProblemForce force = SmallProblemForce::of(problem, params, r.q0.size());
  // MPFR: the run holds the process-wide precision lock (recursive) for its whole length. It is taken here
  // with the GIL released, so that this thread never waits for it with the GIL held; dispatch_precision's
  // own scope below then finds it held by this thread. The run's heartbeat (Ctrl-C, progress) and the result's
  // conversion take the GIL while the lock is held: no thread waits for the lock with the GIL, so they get it.
  std::optional<MpfrPrecision> hold;
  if (precision.rfind("mpfr:", 0) == 0) {
    py::gil_scoped_release free;
    hold.emplace(parse_mpfr_bits(precision.substr(5)));
  }
  return dispatch_precision(precision, [&](auto tag) -> py::dict {
    using T = typename decltype(tag)::type;
    if constexpr (std::is_same_v<T, long double>) {
      return solve_small_long_double(force, r);
    } else if constexpr (std::is_same_v<T, float128>) {
      return solve_small_float128(force, r);
    } else if constexpr (std::is_same_v<T, double_double>) {
      return solve_small_dd(force, r);
    } else if constexpr (std::is_same_v<T, quad_double>) {
      return solve_small_qd(force, r);
    } else if constexpr (std::is_same_v<T, mpfr_real>) {
      return solve_small_mpfr(force, r, MpfrPrecision::requested());
    } else {
      throw invalid_input("precision '" + precision + "' is not an extended precision");
    }
  });
}

}  // namespace nystrom::python
