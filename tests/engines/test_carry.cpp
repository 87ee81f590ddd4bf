// The state between calls, for every engine: when the caller moves q, v or both between two calls, the next
// call starts afresh from the caller's state (compensation carries dropped, force caches recomputed), and is
// bitwise the run of an engine that starts there; when the caller leaves the state alone, the carries go on.
#include <gtest/gtest.h>

#include <array>
#include <string>

#include "nystrom/engines/adaptive_mpe.hpp"
#include "nystrom/engines/adaptive_rkn.hpp"
#include "nystrom/engines/integrator.hpp"
#include "nystrom/methods/catalog.hpp"
#include "nystrom/problems/kepler.hpp"

using namespace nystrom;
using V = std::array<double, 2>;

namespace {

enum class Move { q, v, both };

const char* name(Move m) { return m == Move::q ? "q moved" : (m == Move::v ? "v moved" : "q and v moved"); }

void move(State<V>& s, Move m) {
  if (m != Move::v) s.q[0] += 1.0 / 1024;
  if (m != Move::q) s.v[1] -= 1.0 / 2048;
}

bool nonzero(const V& x) { return x[0] != 0 || x[1] != 0; }

void expect_bitwise(const State<V>& a, const State<V>& b) {
  EXPECT_EQ(a.q[0], b.q[0]);
  EXPECT_EQ(a.q[1], b.q[1]);
  EXPECT_EQ(a.v[0], b.v[0]);
  EXPECT_EQ(a.v[1], b.v[1]);
}

}  // namespace

TEST(Carry, FixedStepEnginesStartAfreshFromAMovedState) {
  // Splitting (FR; VV, whose force is reused from the step before), RKN (M6-5F; A', first same as last),
  // multi-product expansions (M8 on its splitting base, M8-RKN... the catalog's N4), all compensated in double.
  const KeplerProblem<double> kp(0.5);
  const double h = KeplerProblem<double>::period() / 128;
  for (const std::string m : {"FR", "VV", "M6-5F", "A'", "M8", "N4", "BR2"}) {
    for (Move mv : {Move::q, Move::v, Move::both}) {
      SCOPED_TRACE(m + ", " + name(mv));
      const MethodDef def = resolve_method(m);
      auto a = make_integrator<V>(def, KeplerForce{});
      State<V> sa = kp.initial_state();
      a.integrate(sa, h, 37);
      // The carries are in use (else this test could not see them kept).
      EXPECT_TRUE(nonzero(a.compensator().cq) || nonzero(a.compensator().cv));
      move(sa, mv);
      State<V> sb = sa;
      a.integrate(sa, h, 41);
      auto b = make_integrator<V>(def, KeplerForce{});
      b.integrate(sb, h, 41);
      expect_bitwise(sa, sb);
      // The forces: the fresh engine spends those of its 41 steps, the continuing one the same (a cache of
      // the old state's force must not be reused).
      const long fresh = b.force_evals();
      auto c = make_integrator<V>(def, KeplerForce{});
      State<V> sc = kp.initial_state();
      c.integrate(sc, h, 37);
      EXPECT_GE(a.force_evals() - c.force_evals(), fresh - 1);
    }
  }
}

TEST(Carry, FixedStepEnginesContinueAnUnmovedStateBitwise) {
  // Calls of one step each are bitwise one call of many: the carries survive when the state is not moved.
  const KeplerProblem<double> kp(0.5);
  const double h = KeplerProblem<double>::period() / 128;
  for (const std::string m : {"M6-5F", "A'", "DP10"}) {
    SCOPED_TRACE(m);
    const MethodDef def = resolve_method(m);
    auto a = make_integrator<V>(def, KeplerForce{});
    auto b = make_integrator<V>(def, KeplerForce{});
    State<V> sa = kp.initial_state(), sb = sa;
    a.integrate(sa, h, 300);
    for (int i = 0; i < 300; ++i) b.step(sb, h);
    expect_bitwise(sa, sb);
    EXPECT_EQ(a.force_evals(), b.force_evals());
  }
}

namespace {

// Two adaptive engines run [0, 2] and [2, 4.5]; between the calls the caller moves the state. The second call
// of one engine must be bitwise that of an identical engine whose carries were dropped by hand.
template <class Make>
void expect_adaptive_restart(Make make) {
  const KeplerProblem<double> kp(0.5);
  for (Move mv : {Move::q, Move::v, Move::both}) {
    SCOPED_TRACE(name(mv));
    auto a = make();
    auto b = make();
    State<V> sa = kp.initial_state(), sb = sa;
    a.integrate_to(sa, 0.0, 2.0);
    b.integrate_to(sb, 0.0, 2.0);
    expect_bitwise(sa, sb);
    EXPECT_TRUE(nonzero(a.compensator().cq) || nonzero(a.compensator().cv));
    move(sa, mv);
    move(sb, mv);
    b.compensator().invalidate();
    const auto st_a = a.integrate_to(sa, 2.0, 4.5);
    const auto st_b = b.integrate_to(sb, 2.0, 4.5);
    expect_bitwise(sa, sb);
    EXPECT_EQ(st_a.accepted, st_b.accepted);
    EXPECT_EQ(st_a.rejected, st_b.rejected);
  }
  // Unmoved: the carries go on, and the run is bitwise one call over [0, 4.5] stopped at 2 ... or not: the
  // step carried over is the one proposed at 2, so the steps differ; the carries must at least be kept, which
  // a dropped carry shows against an engine whose carries were dropped by hand.
  auto a = make();
  auto b = make();
  State<V> sa = kp.initial_state(), sb = sa;
  a.integrate_to(sa, 0.0, 2.0);
  b.integrate_to(sb, 0.0, 2.0);
  const auto cq = a.compensator().cq, cv = a.compensator().cv;
  a.integrate_to(sa, 2.0, 2.0);  // an empty call leaves the carries
  EXPECT_EQ(a.compensator().cq, cq);
  EXPECT_EQ(a.compensator().cv, cv);
  a.integrate_to(sa, 2.0, 4.5);
  b.compensator().invalidate();
  b.integrate_to(sb, 2.0, 4.5);
  EXPECT_TRUE(sa.q != sb.q || sa.v != sb.v) << "dropping the carries changed nothing: the test sees nothing";
}

}  // namespace

TEST(Carry, AdaptiveRknStartsAfreshFromAMovedState) {
  const MethodDef def = resolve_method("DP12-adaptive");
  expect_adaptive_restart([&] { return make_adaptive_integrator<V>(def, KeplerForce{}, {.rtol = 1e-11}); });
}

TEST(Carry, AdaptiveMpeStartsAfreshFromAMovedState) {
  for (const std::string m : {"M10-adaptive", "MPE-adaptive"}) {
    SCOPED_TRACE(m);
    const MethodDef def = resolve_method(m);
    expect_adaptive_restart([&] { return make_adaptive_mpe_integrator<V>(def, KeplerForce{}, {.rtol = 1e-11}); });
  }
}
