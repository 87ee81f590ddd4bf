// The products of a multi-product step are independent; the engine can run them one after the other
// (sequential), in lockstep (sub-step j of every product before sub-step j + 1 of any: the processor
// overlaps their chains of force evaluations) or on OpenMP threads (concurrent). Every schedule performs
// the same operations per product in the same order, so the results must be bitwise identical and the
// force counts equal; these tests check that over velocity and position Verlet bases, with and
// without compensated summation, in double, long double and complex arithmetic, for fixed-size and
// dynamic states, and on a small Plummer sphere through the N-body force.
#include <gtest/gtest.h>

#include <array>
#include <complex>
#include <string>
#include <vector>

#include "nystrom/nystrom.hpp"
#include "nystrom/problems/nbody.hpp"
#include "nystrom/problems/plummer.hpp"

using namespace nystrom;

namespace {

// KeplerForce's arithmetic on a dynamic (std::vector) state.
struct KeplerVectorForce {
  void operator()(const std::vector<double>& q, std::vector<double>& a) const {
    std::array<double, 2> x{q[0], q[1]}, y{};
    KeplerForce{}(x, y);
    a.assign(y.begin(), y.end());
  }
};

template <class V>
struct Result {
  State<V> s;
  long evals = 0;
};

template <class V, class F>
Result<V> run(const std::string& spec, F force, const State<V>& s0, double h, long n, MpeSchedule schedule,
              Compensation comp, int threads = 0) {
  EngineOptions opt;
  opt.mpe_schedule = schedule;
  opt.compensated = comp;
  opt.mpe_threads = threads;
  auto integ = make_integrator<V>(resolve_method(spec), force, opt);
  Result<V> r{s0, 0};
  using S = typename V::value_type;
  integ.integrate(r.s, real_t<S>(h), n);
  r.evals = integ.force_evals();
  return r;
}

template <class V>
void expect_identical(const Result<V>& a, const Result<V>& b, const std::string& what) {
  ASSERT_EQ(a.s.q.size(), b.s.q.size()) << what;
  for (std::size_t j = 0; j < a.s.q.size(); ++j) {
    EXPECT_TRUE(a.s.q[j] == b.s.q[j]) << what << ": q[" << j << "] differs";
    EXPECT_TRUE(a.s.v[j] == b.s.v[j]) << what << ": v[" << j << "] differs";
  }
  EXPECT_EQ(a.evals, b.evals) << what << ": force counts differ";
}

const std::vector<std::string> kSpecs{
    "M4", "M6", "M8", "M12", "M16", "mpe-vv:1,2,3,4", "mpe:2,3,5", "mpe:1,3,4,7,9,10"};

TEST(MpeSchedule, KeplerFixedSizeAllSchedulesBitwiseIdentical) {
  using V = std::array<double, 2>;
  const KeplerProblem<double> prob(0.9);
  const double h = KeplerProblem<double>::period() / 137.0;  // 100 steps: 0.73 periods
  for (const auto& spec : kSpecs) {
    for (auto comp : {Compensation::off, Compensation::on}) {
      const std::string what = spec + (comp == Compensation::on ? " compensated" : " plain");
      const auto seq = run<V>(spec, KeplerForce{}, prob.initial_state(), h, 100, MpeSchedule::sequential, comp);
      const auto lock = run<V>(spec, KeplerForce{}, prob.initial_state(), h, 100, MpeSchedule::lockstep, comp);
      const auto conc = run<V>(spec, KeplerForce{}, prob.initial_state(), h, 100, MpeSchedule::concurrent, comp, 2);
      const auto dflt = run<V>(spec, KeplerForce{}, prob.initial_state(), h, 100, MpeSchedule::automatic, comp);
      expect_identical(seq, lock, what + " lockstep");
      expect_identical(seq, conc, what + " concurrent");
      expect_identical(seq, dflt, what + " automatic");
      // The run moved the state and made the declared number of force evaluations (n(n+1)/2 per step
      // over PV, one more over VV).
      EXPECT_GT(std::abs(seq.s.q[0] - prob.initial_state().q[0]), 1e-3) << what;
      const auto def = resolve_method(spec);
      EXPECT_EQ(seq.evals, 100L * def.info.forces_per_step) << what;
    }
  }
}

TEST(MpeSchedule, DynamicStatesAndExtendedPrecision) {
  using VD = std::vector<double>;
  using VL = std::array<long double, 2>;
  const KeplerProblem<double> prob(0.6);
  const auto s0 = prob.initial_state();
  const State<VD> d0{VD(s0.q.begin(), s0.q.end()), VD(s0.v.begin(), s0.v.end())};
  const double h = KeplerProblem<double>::period() / 61.0;
  for (const std::string spec : {"M8", "mpe-vv:1,2,3"}) {
    const auto fixed =
        run<std::array<double, 2>>(spec, KeplerForce{}, s0, h, 200, MpeSchedule::sequential, Compensation::on);
    for (auto sch : {MpeSchedule::sequential, MpeSchedule::lockstep, MpeSchedule::concurrent}) {
      const auto dyn = run<VD>(spec, KeplerVectorForce{}, d0, h, 200, sch, Compensation::on, 2);
      for (std::size_t j = 0; j < 2; ++j) {
        EXPECT_TRUE(dyn.s.q[j] == fixed.s.q[j]) << spec << " dynamic q[" << j << "]";
        EXPECT_TRUE(dyn.s.v[j] == fixed.s.v[j]) << spec << " dynamic v[" << j << "]";
      }
      EXPECT_EQ(dyn.evals, fixed.evals);
    }
    const State<VL> l0{{s0.q[0], s0.q[1]}, {s0.v[0], s0.v[1]}};
    const auto lseq = run<VL>(spec, KeplerForce{}, l0, h, 200, MpeSchedule::sequential, Compensation::off);
    const auto llock = run<VL>(spec, KeplerForce{}, l0, h, 200, MpeSchedule::lockstep, Compensation::off);
    expect_identical(lseq, llock, spec + " long double");
  }
}

TEST(MpeSchedule, ComplexKeptStateIdentical) {
  // An MPE over a complex state (keep_complex) runs the same way under every schedule.
  using C = std::complex<double>;
  using V = std::array<C, 2>;
  const KeplerProblem<double> prob(0.5);
  const auto s0 = prob.initial_state();
  const State<V> c0{{C(s0.q[0], 1e-3), C(s0.q[1], 0)}, {C(s0.v[0], 0), C(s0.v[1], -1e-3)}};
  const double h = KeplerProblem<double>::period() / 50.0;
  auto go = [&](MpeSchedule sch) {
    EngineOptions opt;
    opt.keep_complex = true;
    opt.mpe_schedule = sch;
    opt.mpe_threads = 2;
    auto integ = make_integrator<V>(resolve_method("M8"), KeplerForce{}, opt);
    Result<V> r{c0, 0};
    integ.integrate(r.s, h, 100);
    r.evals = integ.force_evals();
    return r;
  };
  const auto seq = go(MpeSchedule::sequential);
  expect_identical(seq, go(MpeSchedule::lockstep), "complex lockstep");
  expect_identical(seq, go(MpeSchedule::concurrent), "complex concurrent");
  EXPECT_NE(seq.s.q[0].imag(), 0.0);  // the imaginary parts were kept
}

TEST(MpeSchedule, NBodyConcurrentProductsIdentical) {
  auto p = plummer_sphere<double>(128, 7);
  const NBodyForce<double> force(p.m, 1e-4);
  for (auto comp : {Compensation::off, Compensation::on}) {
    const auto seq = run<std::vector<double>>("M8", force, p.s, 1e-3, 4, MpeSchedule::sequential, comp);
    const auto conc = run<std::vector<double>>("M8", force, p.s, 1e-3, 4, MpeSchedule::concurrent, comp, 2);
    const auto lock = run<std::vector<double>>("M8", force, p.s, 1e-3, 4, MpeSchedule::lockstep, comp);
    expect_identical(seq, conc, "N-body concurrent");
    expect_identical(seq, lock, "N-body lockstep");
    EXPECT_EQ(seq.evals, 4 * 10);
  }
}

TEST(MpeSchedule, BadThreadCountRejected) {
  EngineOptions opt;
  opt.mpe_schedule = MpeSchedule::concurrent;
  opt.mpe_threads = -1;
  EXPECT_THROW((make_integrator<std::array<double, 2>>(resolve_method("M8"), KeplerForce{}, opt)),
               std::invalid_argument);
}

}  // namespace
