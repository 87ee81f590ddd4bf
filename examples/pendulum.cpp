// Example: your own system. A pendulum q'' = -sin(q) written as a force functor, integrated with the
// eighth-order multi-product method M8 from q = 1, v = 0 to t = 10; prints the state, the energy error
// and the force evaluations spent. Any catalog name works in place of "M8" (`nystrom methods`).
#include <array>
#include <cmath>
#include <cstdio>

#include <nystrom/nystrom.hpp>

struct Pendulum {  // a(q) for a state vector q: here one angle
  void operator()(const std::array<double, 1>& q, std::array<double, 1>& a) const { a[0] = -std::sin(q[0]); }
};

int main() {
  using V = std::array<double, 1>;
  auto integ = nystrom::make_integrator<V>(nystrom::resolve_method("M8"), Pendulum{});
  nystrom::State<V> s{{1.0}, {0.0}};  // q, v
  auto energy = [](const nystrom::State<V>& x) { return 0.5 * x.v[0] * x.v[0] - std::cos(x.q[0]); };
  const double e0 = energy(s);
  integ.integrate(s, 0.1, 100);  // 100 steps of h = 0.1
  std::printf("t = 10: q = %.15f, v = %.15f, energy error %.1e, %ld force evaluations\n", s.q[0], s.v[0],
              energy(s) - e0, integ.force_evals());
}
