// The N-body runs of `nystrom run --force compensated` (problems twobody and nbody): the inline drivers of solve()
// for CompensatedNBodyForce on std::vector<double>, compiled in this file alone.
#include "experiments/nbody_run.hpp"
#include "nystrom/solve_inline.hpp"

namespace nystrom {

NBodyRunResult run_nbody_compensated(const std::string& method, const NBodySetup& setup, double h, long steps,
                                     double tol) {
  return run_nbody<CompensatedNBodyForce<double>>(method, setup, h, steps, tol);
}

}  // namespace nystrom
