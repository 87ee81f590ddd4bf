// run_in_precision for mpfr_real (one translation unit per precision: they compile in parallel).
// GCC 12 at -O2 reports the bool members of RknStepper (initialised in the class) as "may be used
// uninitialized" when solve() copies the std::variant of steppers for MPFR states: a false positive of its
// flow analysis through the variant's storage, silenced for this translation unit only.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include "runner_typed.hpp"

namespace nystrom::cli {
NYSTROM_RUNNER_INSTANTIATE(mpfr_real)
}  // namespace nystrom::cli
