// run_in_precision for quad_double (one translation unit per precision: they compile in parallel).
#include "runner_typed.hpp"

namespace nystrom::cli {
NYSTROM_RUNNER_INSTANTIATE(quad_double)
}  // namespace nystrom::cli
