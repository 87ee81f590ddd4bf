// run_in_precision for double (one translation unit per precision: they compile in parallel), and the
// Kepler run with output times, events and checkpoints (run_kepler_solve, runner_solve.cpp).
#include "runner_typed.hpp"

namespace nystrom::cli {
NYSTROM_RUNNER_INSTANTIATE(double)
template OrbitRun<double, 2> run_orbit<double, 2>(const RunRequest&, const MethodDef&,
                                                  const RunOutputs<std::array<double, 2>>&);
}  // namespace nystrom::cli
