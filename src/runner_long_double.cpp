// run_in_precision for long double (one translation unit per precision: they compile in parallel).
#include "runner_typed.hpp"

namespace nystrom::cli {
NYSTROM_RUNNER_INSTANTIATE(long double)
}  // namespace nystrom::cli
