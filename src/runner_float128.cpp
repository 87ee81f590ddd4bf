// run_in_precision for float128 (one translation unit per precision: they compile in parallel).
#include "runner_typed.hpp"

namespace nystrom::cli {
NYSTROM_RUNNER_INSTANTIATE(float128)
}  // namespace nystrom::cli
