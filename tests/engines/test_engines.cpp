// Engine-level checks of the core: MPE coefficients (Chin eqs 19-22), the MPE/tableau equivalence of M4,
// force counting, FSAL caching and bad input.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <complex>
#include <string>
#include <utility>
#include <vector>

#include "nystrom/nystrom.hpp"

using namespace nystrom;

namespace {

std::vector<std::string> as_strings(const MpeCoefficients& m) {
  std::vector<std::string> out;
  for (const auto& c : m.c) out.push_back(c.get_str());
  return out;
}

}  // namespace

TEST(MpeCoefficients, MatchChinEquations19To22) {
  EXPECT_EQ(as_strings(mpe_coefficients({1, 2})), (std::vector<std::string>{"-1/3", "4/3"}));
  EXPECT_EQ(as_strings(mpe_coefficients({1, 2, 3})), (std::vector<std::string>{"1/24", "-16/15", "81/40"}));
  EXPECT_EQ(as_strings(mpe_coefficients({1, 2, 3, 4})),
            (std::vector<std::string>{"-1/360", "16/45", "-729/280", "1024/315"}));
  EXPECT_EQ(as_strings(mpe_coefficients({1, 2, 3, 4, 5})),
            (std::vector<std::string>{"1/8640", "-64/945", "6561/4480", "-16384/2835", "390625/72576"}));
  // Albrecht's alternative expansion, eq (48).
  EXPECT_EQ(as_strings(mpe_coefficients({1, 2, 4})), (std::vector<std::string>{"1/45", "-4/9", "64/45"}));
}

TEST(MpeCoefficients, SumToOneAndErrorCoefficient) {
  for (int n = 1; n <= 12; ++n) {
    std::vector<long> k;
    for (long i = 1; i <= n; ++i) k.push_back(i);
    const auto m = mpe_coefficients(k);
    mpq_class s(0);
    for (const auto& c : m.c) s += c;
    EXPECT_EQ(s, 1) << "n = " << n;
    // eq (18): e = (-1)^(n-1) / (n!)^2
    mpz_class f(1);
    for (long i = 2; i <= n; ++i) f *= i;
    mpq_class e(1, f * f);
    if (n % 2 == 0) e = -e;
    EXPECT_EQ(m.error, e) << "n = " << n;
  }
  // eq (10) for two members l, m: e5 = -1/(l^2 m^2)
  EXPECT_EQ(mpe_coefficients({3, 5}).error, mpq_class(-1, 225));
}

TEST(MpeCoefficients, RejectsBadSequences) {
  EXPECT_THROW(mpe_coefficients({}), std::invalid_argument);
  EXPECT_THROW(mpe_coefficients({1, 1}), std::invalid_argument);
  EXPECT_THROW(mpe_coefficients({0, 1}), std::invalid_argument);
  EXPECT_THROW(mpe_coefficients({-2, 1}), std::invalid_argument);
  EXPECT_THROW(parse_sequence("1,,2"), std::invalid_argument);
  EXPECT_THROW(parse_sequence("1,2,"), std::invalid_argument);
  EXPECT_THROW(parse_sequence("1,x"), std::invalid_argument);
  EXPECT_THROW(parse_sequence(""), std::invalid_argument);
  EXPECT_EQ(parse_sequence("1,2,4"), (std::vector<long>{1, 2, 4}));
}

TEST(MpeCoefficients, OptimalSequenceMaximisesTheProduct) {
  // Brute force over all sets of n distinct positive integers with sum K.
  for (int n = 1; n <= 4; ++n)
    for (long K = n * (n + 1) / 2; K <= 24; ++K) {
      const auto k = optimal_mpe_sequence(n, K);
      long sum = 0;
      for (long x : k) sum += x;
      ASSERT_EQ(sum, K);
      const auto best = mpe_coefficients(k).error;
      std::function<void(int, long, long, std::vector<long>&)> rec = [&](int left, long minv, long rest,
                                                                         std::vector<long>& cur) {
        if (left == 0) {
          if (rest == 0) {
            EXPECT_LE(abs(best), abs(mpe_coefficients(cur).error)) << "n=" << n << " K=" << K;
          }
          return;
        }
        for (long v = minv; v <= rest; ++v) {
          cur.push_back(v);
          rec(left - 1, v + 1, rest - v, cur);
          cur.pop_back();
        }
      };
      std::vector<long> cur;
      rec(n, 1, K, cur);
    }
  EXPECT_THROW(optimal_mpe_sequence(3, 5), std::invalid_argument);
}

TEST(Engines, GenericMpeEqualsExplicitM4Tableau) {
  using V = std::array<long double, 2>;
  auto mpe = make_integrator<V>(resolve_method("M4"), KeplerForce{});
  auto rkn = make_integrator<V>(resolve_method("M4-RKN"), KeplerForce{});
  const KeplerProblem<long double> p(0.7L);
  auto a = p.initial_state(), b = p.initial_state();
  mpe.integrate(a, 0.01L, 500);
  rkn.integrate(b, 0.01L, 500);
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR(static_cast<double>(a.q[i]), static_cast<double>(b.q[i]), 1e-15);
    EXPECT_NEAR(static_cast<double>(a.v[i]), static_cast<double>(b.v[i]), 1e-15);
  }
  EXPECT_EQ(mpe.force_evals(), 1500);
  EXPECT_EQ(rkn.force_evals(), 1500);
}

// The schedules of the fixed-step multi-product engine run the same products and combine them in the same order:
// sequential (one product after the other through the base's merged loop) and lockstep (all products' sub-steps
// side by side) give bitwise the same states and force counts, on both bases (drift first: M8; kick first:
// mpe-vv), compensated or not, for fixed-size and run-time-size states.
TEST(Engines, MpeSchedulesAreBitwiseIdentical) {
  const KeplerProblem<double> p(0.7);
  for (const std::string spec : {"M8", "mpe-vv:1,2,3,4"}) {
    for (const Compensation comp : {Compensation::off, Compensation::on}) {
      SCOPED_TRACE(spec + (comp == Compensation::on ? " compensated" : ""));
      auto run = [&](MpeSchedule sched) {
        EngineOptions eo;
        eo.compensated = comp;
        eo.mpe_schedule = sched;
        auto integ = make_integrator<std::array<double, 2>>(resolve_method(spec), KeplerForce{}, eo);
        auto s = p.initial_state();
        integ.integrate(s, 0.02, 300);
        auto vec = make_integrator<std::vector<double>>(resolve_method(spec), KeplerForce{}, eo);
        const auto s0 = p.initial_state();
        State<std::vector<double>> sv{{s0.q[0], s0.q[1]}, {s0.v[0], s0.v[1]}};
        vec.integrate(sv, 0.02, 300);
        for (int i = 0; i < 2; ++i) {
          EXPECT_EQ(sv.q[static_cast<std::size_t>(i)], s.q[i]);
          EXPECT_EQ(sv.v[static_cast<std::size_t>(i)], s.v[i]);
        }
        EXPECT_EQ(vec.force_evals(), integ.force_evals());
        return std::pair{s, integ.force_evals()};
      };
      const auto [a, fa] = run(MpeSchedule::lockstep);
      const auto [b, fb] = run(MpeSchedule::sequential);
      EXPECT_EQ(a.q, b.q);
      EXPECT_EQ(a.v, b.v);
      EXPECT_EQ(fa, fb);
      // and on the orbit: the products are not all wrong in the same way
      EXPECT_LT(std::hypot(a.q[0] - p.exact(6.0).q[0], a.q[1] - p.exact(6.0).q[1]), 1e-8);
    }
  }
}

TEST(Engines, ForceCountsFollowTheFormulas) {
  using V = std::array<double, 2>;
  for (int n = 1; n <= 6; ++n) {
    std::string seq;
    for (int i = 1; i <= n; ++i) {
      if (i > 1) seq += ',';
      seq += std::to_string(i);
    }
    auto pv = make_integrator<V>(resolve_method("mpe:" + seq), KeplerForce{});
    auto vv = make_integrator<V>(resolve_method("mpe-vv:" + seq), KeplerForce{});
    auto s1 = KeplerProblem<double>(0.3).initial_state(), s2 = s1;
    pv.integrate(s1, 0.01, 10);
    vv.integrate(s2, 0.01, 10);
    EXPECT_EQ(pv.force_evals(), 10L * n * (n + 1) / 2);
    EXPECT_EQ(vv.force_evals(), 10L * (n * (n + 1) / 2 + 1));
  }
  // FSAL: velocity Verlet needs one force per step plus the first one.
  auto vv = make_integrator<V>(resolve_method("VV"), KeplerForce{});
  auto s = KeplerProblem<double>(0.3).initial_state();
  vv.integrate(s, 0.01, 100);
  EXPECT_EQ(vv.force_evals(), 101);
  for (int i = 0; i < 50; ++i) vv.step(s, 0.01);  // separate calls keep reusing the force
  EXPECT_EQ(vv.force_evals(), 151);
  s.q[0] += 1e-3;  // moving q behind the engine's back invalidates the cached force
  vv.step(s, 0.01);
  EXPECT_EQ(vv.force_evals(), 153);
}

// The force count a method declares (MethodInfo::forces_per_step, used for the work axes of every
// sweep) is what the engine spends per step in a long run: every non-adaptive catalog entry and
// multi-product specifications on both bases, 20 and 30 steps in one call (the difference removes the
// first force of a kick-first method).
TEST(Engines, DeclaredForceCountsAreWhatTheEnginesSpend) {
  std::vector<MethodDef> defs;
  for (const auto& d : catalog())
    if (!d.info.adaptive) defs.push_back(d);
  for (const char* spec : {"mpe-vv:1,2,3", "mpe-vv:2,3,5", "mpe:1,2,4"}) defs.push_back(resolve_method(spec));
  for (const auto& d : defs) {
    auto spent = [&](long steps) {
      const auto s0 = KeplerProblem<long double>(0.3L).initial_state();
      if (d.info.complex) {
        using C = std::complex<long double>;
        auto integ = make_integrator<std::array<C, 2>>(d, KeplerForce{});
        auto s = convert_state<std::array<C, 2>>(s0);
        integ.integrate(s, 0.01L, steps);
        return integ.force_evals();
      }
      auto integ = make_integrator<std::array<long double, 2>>(d, KeplerForce{});
      auto s = s0;
      integ.integrate(s, 0.01L, steps);
      return integ.force_evals();
    };
    EXPECT_EQ(spent(30) - spent(20), 10L * d.info.forces_per_step) << d.info.name;
  }
}

TEST(Engines, RejectsUnknownMethodsAndHugeOrders) {
  EXPECT_THROW(resolve_method("NOPE"), invalid_input);
  EXPECT_THROW(resolve_method("M7"), invalid_input);
  EXPECT_THROW(resolve_method("mpe:1,1"), invalid_input);
  using V = std::array<double, 2>;
  EXPECT_THROW(make_integrator<V>(resolve_method("M60"), KeplerForce{}), std::invalid_argument);
  EXPECT_NO_THROW(make_integrator<V>(resolve_method("M40"), KeplerForce{}));
  using VL = std::array<long double, 2>;
  EXPECT_NO_THROW(make_integrator<VL>(resolve_method("M56"), KeplerForce{}));
}

TEST(Kepler, AnalyticSolutionIsConsistent) {
  for (double e : {0.0, 0.5, 0.9, 0.99}) {
    const KeplerProblem<long double> p(e);
    const auto s0 = p.initial_state();
    const auto x0 = p.exact(0);
    EXPECT_NEAR(static_cast<double>(x0.q[0] - s0.q[0]), 0, 1e-15);
    EXPECT_NEAR(static_cast<double>(x0.v[1] - s0.v[1]), 0, 1e-15);
    for (long double t : {0.3L, 1.0L, 2.5L, 7.0L}) {
      const auto x = p.exact(t);
      EXPECT_NEAR(static_cast<double>(kepler_energy(x)), -0.5, 1e-15);
      const auto A = lrl_vector(x);
      EXPECT_NEAR(static_cast<double>(A[0]), -e, 1e-14);
      EXPECT_NEAR(static_cast<double>(A[1]), 0, 1e-14);
    }
  }
  EXPECT_THROW(KeplerProblem<double>(1.0), std::invalid_argument);
  EXPECT_THROW(KeplerProblem<double>(-0.1), std::invalid_argument);
}
