// The Arenstorf orbit (Hairer, Norsett & Wanner I, sec. II.0: the restricted three-body problem in the rotating
// frame, a Coriolis force, so q'' = a(q, v)) over one period from C++: nystrom's solve() with DOP853 in Nystrom
// form, GBS, Fine's RKNG5(4) and the adaptive multi-product expansion of order 8 over the midpoint rule (compiled,
// std::vector states), DOP853, GBS and that expansion on the inline path (solve_inline, std::array states) against
// Boost.Odeint's controlled runge_kutta_fehlberg78 and bulirsch_stoer on the first-order system, in the same run.
// Error = |q(T) - q0| (the orbit closes to about 1e-15 with the printed digits). For each integrator a sweep of
// tolerances (rtol = atol = 1e-4 ... 1e-14 and 5e-15), the wall time the best of --repeat runs; then for each target
// error the cheapest run of each that reaches it, and the ratio of the best peer's time to the best of nystrom's.
//
//   bench_arenstorf [--quick] [--repeat N]
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <boost/numeric/odeint.hpp>

#include "nystrom/problems/arenstorf.hpp"
#include "nystrom/solve.hpp"
#include "nystrom/solve/solve.hpp"

namespace {

namespace odeint = boost::numeric::odeint;
using A = nystrom::Arenstorf<double>;
using Y = std::array<double, 4>;

struct Row {
  std::string name;
  double tol, error, seconds;
  long forces;
};

double return_error(double x, double y) { return std::hypot(x - A::q0x(), y); }

// The compiled solve() on std::vector states (the force through one indirect call), or the inline template
// path on std::array states (the force inlined). Only the end state is recorded (t_eval = {T}), as odeint's
// integrate_adaptive keeps none.
Row nystrom_run(const std::string& method, double tol, bool inline_path) {
  const nystrom::SolveOptions opt{.rtol = tol, .atol = tol, .t_eval = {A::period()}};
  if (inline_path) {
    using V2 = std::array<double, 2>;
    const nystrom::SecondOrderProblem prob(nystrom::ArenstorfForce{}, V2{A::q0x(), 0.0}, V2{0.0, A::v0y()}, 0.0,
                                           A::period());
    const auto sol = nystrom::solve_inline(prob, method, opt);
    return {"inline " + method, tol, return_error(sol.q_final[0], sol.q_final[1]), 0, sol.force_evals};
  }
  const nystrom::SecondOrderProblem prob(nystrom::ArenstorfForce{}, std::vector<double>{A::q0x(), 0.0},
                                         std::vector<double>{0.0, A::v0y()}, 0.0, A::period());
  const auto sol = nystrom::solve(prob, method, opt);
  return {"nystrom " + method, tol, return_error(sol.q_final[0], sol.q_final[1]), 0, sol.force_evals};
}

// The first-order system y = (q, v) for odeint, counting its calls.
struct System {
  long* calls;
  void operator()(const Y& y, Y& dy, double) const {
    ++*calls;
    const std::array<double, 2> q{y[0], y[1]}, v{y[2], y[3]};
    std::array<double, 2> a{};
    nystrom::ArenstorfForce{}(q, v, a);
    dy = {y[2], y[3], a[0], a[1]};
  }
};

Row odeint_run(const std::string& which, double tol) {
  long calls = 0;
  Y y{A::q0x(), 0.0, 0.0, A::v0y()};
  if (which == "rkf78") {
    auto st = odeint::make_controlled(tol, tol, odeint::runge_kutta_fehlberg78<Y>());
    odeint::integrate_adaptive(st, System{&calls}, y, 0.0, A::period(), 1e-3);
  } else {
    odeint::bulirsch_stoer<Y> st(tol, tol);
    odeint::integrate_adaptive(st, System{&calls}, y, 0.0, A::period(), 1e-3);
  }
  return {"odeint " + which, tol, return_error(y[0], y[1]), 0, calls};
}

Row timed(const std::function<Row()>& run, int repeat) {
  Row best{};
  double t = std::numeric_limits<double>::infinity();
  for (int i = 0; i < repeat; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    Row r = run();
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (s < t) {
      t = s;
      best = r;
    }
  }
  best.seconds = t;
  return best;
}

const Row* cheapest(const std::vector<Row>& rows, const std::string& prefix, double target) {
  const Row* best = nullptr;
  for (const auto& r : rows)
    if (r.name.rfind(prefix, 0) == 0 && r.error <= target && (!best || r.seconds < best->seconds)) best = &r;
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false;
  int repeat = 3;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--quick") == 0) {
      quick = true;
      repeat = 1;
    } else if (std::strcmp(argv[i], "--repeat") == 0 && i + 1 < argc) {
      repeat = std::max(1, std::atoi(argv[++i]));
    } else {
      std::fprintf(stderr, "usage: bench_arenstorf [--quick] [--repeat N]\n");
      return 2;
    }
  }
  std::vector<double> tols;
  for (int k = 4; k <= 14; k += quick ? 3 : 1) tols.push_back(std::pow(10.0, -k));
  tols.push_back(5e-15);  // about the tightest tolerance all of nystrom's integrators accept in double (GBS: 20 eps)
  std::vector<Row> rows;
  std::printf("Arenstorf orbit, one period, error |q(T) - q0|, wall time best of %d\n", repeat);
  auto sweep = [&](const std::function<Row(double)>& run) {
    for (double tol : tols) {
      const Row r = timed([&] { return run(tol); }, repeat);
      std::printf("  %-22s tol %7.0e  error %9.2e  forces %8ld  %9.3f ms\n", r.name.c_str(), r.tol, r.error, r.forces,
                  r.seconds * 1e3);
      rows.push_back(r);
    }
  };
  const char* const mpe8 = "mpe-midpoint-adaptive:1,2,3,4";
  for (const char* m : {"DOP853", "GBS", "Fine5-adaptive", mpe8})
    sweep([m](double tol) { return nystrom_run(m, tol, false); });
  for (const char* m : {"DOP853", "GBS", mpe8}) sweep([m](double tol) { return nystrom_run(m, tol, true); });
  for (const char* p : {"rkf78", "bulirsch_stoer"}) sweep([p](double tol) { return odeint_run(p, tol); });
  std::printf("\ncheapest run reaching each error (time; forces):\n");
  for (double target : {1e-6, 1e-9, 1e-12, 1e-13}) {
    const Row* ours = nullptr;
    for (const char* m : {"nystrom DOP853", "nystrom GBS", "nystrom Fine5", "nystrom mpe-midpoint", "inline DOP853",
                          "inline GBS", "inline mpe-midpoint"}) {
      const Row* r = cheapest(rows, m, target);
      if (r && (!ours || r->seconds < ours->seconds)) ours = r;
    }
    const Row* peer = nullptr;
    for (const char* p : {"odeint rkf78", "odeint bulirsch_stoer"}) {
      const Row* r = cheapest(rows, p, target);
      if (r && (!peer || r->seconds < peer->seconds)) peer = r;
    }
    std::printf("  error <= %.0e: ", target);
    if (ours)
      std::printf("%s %.3f ms, %ld forces; ", ours->name.c_str(), ours->seconds * 1e3, ours->forces);
    else
      std::printf("nystrom does not reach it; ");
    if (peer)
      std::printf("%s %.3f ms, %ld forces", peer->name.c_str(), peer->seconds * 1e3, peer->forces);
    else
      std::printf("odeint does not reach it");
    if (ours && peer) std::printf("; best peer / nystrom: time %.2fx", peer->seconds / ours->seconds);
    std::printf("\n");
  }
  return 0;
}
