// Example: the multi-product integrators of orders 4 to 16 on the Kepler orbit e = 0.9 in long double. Each
// runs one period with about 36000 force evaluations (1000 steps of M16); after a period the exact orbit is
// back at its initial state, so |q(T) - q(0)| is the error. Build: see examples/CMakeLists.txt.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <nystrom/solve.hpp>

int main() {
  using V = std::vector<long double>;
  const long double e = 0.9L, period = 2 * std::acos(-1.0L);
  auto force = [](const V& q, V& a) {
    const long double r2 = q[0] * q[0] + q[1] * q[1], m = -1 / (r2 * std::sqrt(r2));
    a[0] = m * q[0];
    a[1] = m * q[1];
  };
  const V q0{1 + e, 0}, v0{0, std::sqrt((1 - e) / (1 + e))};
  const nystrom::SecondOrderProblem problem(force, q0, v0, 0.0L, period);
  std::printf("%-6s %8s %12s %14s\n", "method", "steps", "forces", "|q(T) - q0|");
  for (int order = 4; order <= 16; order += 2) {
    const int n = order / 2;  // M<2n>: n products, sum of k = n(n+1)/2 forces per step
    const long steps = 36000 / (n * (n + 1) / 2);
    const auto sol = nystrom::solve(problem, "M" + std::to_string(order), {.steps = steps});
    const double err = static_cast<double>(std::hypot(sol.q_final[0] - q0[0], sol.q_final[1] - q0[1]));
    std::printf("%-6s %8ld %12ld %14.3e\n", ("M" + std::to_string(order)).c_str(), steps, sol.force_evals, err);
  }
}
