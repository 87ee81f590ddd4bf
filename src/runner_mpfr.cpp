// run_in_precision for mpfr_real (one translation unit per precision: they compile in parallel).
#include "runner_typed.hpp"

namespace nystrom::cli {
NYSTROM_RUNNER_INSTANTIATE(mpfr_real)
}  // namespace nystrom::cli
