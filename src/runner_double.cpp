// run_in_precision for double (one translation unit per precision: they compile in parallel).
#include "runner_typed.hpp"

namespace nystrom::cli {
NYSTROM_RUNNER_INSTANTIATE(double)
}  // namespace nystrom::cli
