// Langevin dynamics in the double well U = (q^2 - 1)^2 at kT = 0.5 (docs/stochastic.md): <q^2> as the time average
// over the second half of [0, 100], averaged over 1000 paths of BAOAB at h = 0.05, extrapolated with 1,2,3.
#include <cstdio>

#include <nystrom/stochastic/potentials.hpp>

int main() {
  namespace st = nystrom::stochastic;
  const auto problem = st::builtin_problem_1d("double-well", /*gamma=*/1, /*kT=*/0.5, /*t_end=*/100);
  st::LangevinOptions o;  // BAOAB, h = 0.05, 1000 paths, seed 1
  o.extrapolate = {1, 2, 3};
  o.threads = 2;
  const st::LangevinResult r = st::langevin(problem, o);
  const auto& q2 = r.observables[1];  // q, q2, q4, v2, energy
  std::printf("<q^2> = %.5f +- %.5f (%lld forces)\n", q2.average.value, q2.average.stderr_, r.force_evaluations);
}
