// run_in_precision for double_double (one translation unit per precision: they compile in parallel).
#include "runner_typed.hpp"

namespace nystrom::cli {
NYSTROM_RUNNER_INSTANTIATE(double_double)
}  // namespace nystrom::cli
