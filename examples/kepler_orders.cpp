// Example: the multi-product integrators of orders 4 to 16 on the Kepler orbit e = 0.9 in long double.
// For each order, the precession of the Laplace-Runge-Lenz vector after one period with N = 36000 force
// evaluations per period (the cost of 1000 steps of M16). Build: see examples/CMakeLists.txt.
#include <cstdio>

#include <nystrom/nystrom.hpp>

int main() {
  using namespace nystrom;
  std::printf("%-6s %8s %14s %14s\n", "method", "steps", "|dtheta|", "pos error");
  for (int order = 4; order <= 16; order += 2) {
    const MethodDef method = resolve_method("M" + std::to_string(order));
    const long steps = 36000 / method.info.forces_per_step;
    const KeplerRunResult r = run_kepler<long double>(method, 0.9, steps, 1);
    std::printf("%-6s %8ld %14.3e %14.3e\n", r.method.c_str(), r.steps, std::abs(r.precession_per_period),
                r.position_error);
  }
}
