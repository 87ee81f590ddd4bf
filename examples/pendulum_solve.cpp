// Example: a user's own system through solve(). A driven pendulum, theta'' = -sin(theta) + A cos(w t)
// (a time-dependent force written as a capturing lambda), integrated with the adaptive multi-product
// method M12-adaptive; the state at 11 output times from the dense output, and the times at which the
// pendulum passes the bottom moving right (an event). Build: see examples/CMakeLists.txt.
#include <cmath>
#include <cstdio>
#include <vector>

#include <nystrom/solve.hpp>

int main() {
  using V = std::vector<double>;
  const double A = 0.2, w = 0.7;
  auto force = [A, w](double t, const V& q, V& a) { a[0] = -std::sin(q[0]) + A * std::cos(w * t); };
  const nystrom::SecondOrderProblem problem(force, V{1.0}, V{0.0}, 0.0, 50.0);

  std::vector<double> times;
  for (int i = 0; i <= 10; ++i) times.push_back(5.0 * i);
  const std::vector<nystrom::Event<V>> events = {
      {.name = "bottom", .g = [](double, const V& q, const V&) { return q[0]; }, .direction = +1}};

  const auto sol = nystrom::solve(problem, "M12-adaptive", {.rtol = 1e-12, .t_eval = times, .dense = true}, events);

  std::printf("%8s %14s %14s\n", "t", "theta", "theta'");
  for (std::size_t i = 0; i < sol.t.size(); ++i)
    std::printf("%8.3f %14.10f %14.10f\n", sol.t[i], sol.q[i][0], sol.v[i][0]);
  for (const auto& e : sol.events) std::printf("bottom, moving right, at t = %.12f\n", e.t);
  std::printf("%ld steps (%ld rejected), %ld force evaluations; sol(12.3) = %.10f\n", sol.accepted, sol.rejected,
              sol.force_evals, sol(12.3).q[0]);
}
