// The local-error experiment (Gürkan sec. 5) and the CPU-time table: the statistics behave as the
// methods' orders say, complex methods run through it, bad input is refused.
#include <gtest/gtest.h>

#include <cmath>

#include "experiments/localerr.hpp"
#include "experiments/nbody_run.hpp"

using namespace nystrom;

namespace {

double iqr_of(const LocalErrResult& r, const std::string& m, double h) {
  for (const auto& row : r.rows)
    if (row.method == m && std::abs(row.h - h) < 1e-12 * h) return row.iqr;
  ADD_FAILURE() << "no row " << m << " " << h;
  return 0;
}

}  // namespace

TEST(LocalErr, TwoBodyErrorsScaleWithTheOrder) {
  LocalErrConfig c;
  c.setup.problem = "twobody";
  c.duration = 2;  // periods
  c.hs = {0.02, 0.04};
  c.methods = {"VV", "FR"};
  c.tol = 1e-14;
  const auto r = run_localerr(c);
  ASSERT_EQ(r.rows.size(), 4u);
  for (const auto& row : r.rows) {
    EXPECT_GT(row.iqr, 0);
    EXPECT_EQ(row.samples, row.steps * 4);  // x and y of two bodies
  }
  EXPECT_EQ(r.rows[0].steps, 100);
  // One step of an order-p method errs by O(h^{p+1}): doubling h multiplies the IQR by about 2^{p+1}.
  const double vv = iqr_of(r, "VV", 0.04) / iqr_of(r, "VV", 0.02);
  const double fr = iqr_of(r, "FR", 0.04) / iqr_of(r, "FR", 0.02);
  EXPECT_GT(vv, 5);
  EXPECT_LT(vv, 12);
  EXPECT_GT(fr, 20);
  EXPECT_LT(fr, 50);
  EXPECT_LT(iqr_of(r, "FR", 0.02), iqr_of(r, "VV", 0.02));
}

TEST(LocalErr, PlummerSphereAndComplexMethods) {
  LocalErrConfig c;
  c.setup.problem = "nbody";
  c.setup.n = 40;
  c.duration = 0.04;
  c.hs = {0.004, 0.008};
  c.methods = {"VV", "mpe:1,2"};
  const auto r = run_localerr(c);
  ASSERT_EQ(r.rows.size(), 4u);
  EXPECT_EQ(r.rows[0].samples, 10 * 120);
  const double vv = iqr_of(r, "VV", 0.008) / iqr_of(r, "VV", 0.004);
  EXPECT_GT(vv, 5);
  EXPECT_LT(vv, 12);
}

TEST(LocalErr, ComplexMethodsRunOnTheComplexifiedState) {
  // Chambers' complex third-order splitting (imaginary parts dropped after each step), given as data:
  // drift a1, kick 2 a1, drift 1/2, kick conj(2 a1), drift conj(a1), a1 = (1 + i/sqrt 3)/4.
  MethodDef ch;
  ch.info.name = "chambers-test";
  ch.info.order = 3;
  ch.info.complex = true;
  ch.build = [] {
    const bigfloat s3 = big("1") / sqrt(big("3"));
    const bigcomplex a1(big("1/4"), s3 / 4), b1(big("1/2"), s3 / 2);
    return MethodData{scheme({drift(a1), kick(b1), drift(big("1/2")), kick(b1.conj()), drift(a1.conj())})};
  };
  LocalErrConfig c;
  c.setup.problem = "twobody";
  c.duration = 1;
  c.hs = {0.01, 0.02};
  c.methods = {"VV"};
  c.method_defs = {ch};
  const auto r = run_localerr(c);
  ASSERT_EQ(r.rows.size(), 4u);
  // Third order with a purely imaginary leading error: after dropping the imaginary parts it behaves like
  // a fourth-order method (local error h^5), far below the leapfrog.
  const double ratio = iqr_of(r, "chambers-test", 0.02) / iqr_of(r, "chambers-test", 0.01);
  EXPECT_GT(ratio, 12);
  EXPECT_LT(iqr_of(r, "chambers-test", 0.01), 0.01 * iqr_of(r, "VV", 0.01));
}

TEST(LocalErr, RefusesBadInput) {
  LocalErrConfig c;
  c.methods = {"VV"};
  EXPECT_THROW(run_localerr(c), std::invalid_argument);  // no h
  c.hs = {0.01};
  c.setup.problem = "threebody";
  EXPECT_THROW(run_localerr(c), std::invalid_argument);
  c.setup.problem = "nbody";
  c.setup.n = 1;
  EXPECT_THROW(run_localerr(c), std::invalid_argument);
  c.setup.n = 10;
  c.hs = {-1};
  EXPECT_THROW(run_localerr(c), std::invalid_argument);
  c.hs = {0.01};
  c.methods = {"no-such-method"};
  EXPECT_THROW(run_localerr(c), invalid_input);
  c.methods = {"VV"};
  c.setup.problem = "twobody";
  c.setup.ecc = 1.5;
  EXPECT_THROW(run_localerr(c), std::invalid_argument);
}

TEST(CpuTime, MeasuresEveryMethodAgainstTheLeapfrog) {
  CpuTimeConfig c;
  c.setup.n = 128;
  c.methods = {"FR", "VV"};
  c.steps = 2;
  c.repeats = 1;
  const auto r = run_cputime(c);
  ASSERT_EQ(r.rows.size(), 2u);
  EXPECT_EQ(r.rows[0].method, "FR");
  EXPECT_EQ(r.rows[0].forces_per_step, 3);
  EXPECT_GT(r.leapfrog_seconds, 0);
  for (const auto& row : r.rows) EXPECT_GT(row.ratio, 0);
  c.steps = 0;
  EXPECT_THROW(run_cputime(c), std::invalid_argument);
}

TEST(NBodyRun, MethodsAndGbsOnBothProblems) {
  NBodySetup tb;
  tb.problem = "twobody";
  const double h = 2 * M_PI / 200;
  const auto vv = run_nbody("VV", tb, h, 200);
  const auto fr = run_nbody("FR", tb, h, 200);
  const auto gbs = run_nbody("GBS", tb, h, 200, 1e-12);
  EXPECT_LT(fr.position_error, vv.position_error);
  EXPECT_LT(gbs.position_error, 1e-9);
  EXPECT_LT(gbs.energy_error, 1e-10);
  EXPECT_EQ(fr.force_evals, 3 * 200 + 0 * 1);  // position-first FR: 3 forces per step
  NBodySetup nb;
  nb.n = 30;
  const auto a = run_nbody("VV", nb, 0.01, 10);
  EXPECT_GT(a.position_error, 0);
  EXPECT_LT(a.energy_error, 1e-3);
  EXPECT_THROW(run_nbody("GBS", nb, 0.01, 10), std::invalid_argument);       // no tolerance
  EXPECT_THROW(run_nbody("VV", nb, 0.01, 10, 1e-9), std::invalid_argument);  // tolerance for a fixed-step method
  EXPECT_THROW(run_nbody("VV", nb, -0.01, 10), std::invalid_argument);
}
