// The command-line contract of `run` on the problems with velocity-dependent forces (NYSTROM_BIN, set by
// CTest): `nystrom run --problem arenstorf --method GBS --tol 1e-12 --periods 1 --json` prints return_error =
// |q(T) - q0| and force_evals; the damped oscillator's errors against its exact solution; a method that does
// not support velocity-dependent forces exits 2 with one line.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include <nlohmann/json.hpp>

#include "support/cli_runner.hpp"

using namespace cli_test;

TEST(CliVelocity, ArenstorfReturnErrorFollowsTheTolerance) {
  const auto r12 = run("run --problem arenstorf --method GBS --tol 1e-12 --periods 1 --json");
  ASSERT_EQ(r12.code, 0) << r12.err;
  const auto j12 = nlohmann::json::parse(r12.out);
  const auto r8 = run("run --problem arenstorf --method GBS --tol 1e-8 --periods 1 --json");
  ASSERT_EQ(r8.code, 0) << r8.err;
  const auto j8 = nlohmann::json::parse(r8.out);
  const double e12 = j12.at("return_error").get<double>(), e8 = j8.at("return_error").get<double>();
  EXPECT_LT(e12, 1e-8);
  EXPECT_LT(e8, 1e-4);
  EXPECT_LT(e12, e8 / 100);
  EXPECT_GT(j12.at("force_evals").get<long>(), j8.at("force_evals").get<long>());
  EXPECT_EQ(j12.at("method").get<std::string>(), "GBS");
  // The final state is the orbit's start again, one period on.
  EXPECT_NEAR(j12.at("t").get<double>(), 17.0652165601579625588917206249, 1e-12);
  EXPECT_NEAR(j12.at("q")[0].get<double>(), 0.994, 1e-8);
  EXPECT_LT(j12.at("jacobi_error").get<double>(), 1e-8);
}

TEST(CliVelocity, GeneralRknPairsRunTheArenstorfContract) {
  // Any method for velocity-dependent forces can be named: DOP853 (by its alias), Fine's pairs and the adaptive
  // multi-product expansion over the midpoint rule.
  for (const char* m : {"DOP853", "Fine5-adaptive", "Fine4-adaptive", "mpe-midpoint-adaptive:1,2,3,4"}) {
    const auto r = run(std::string("run --problem arenstorf --method ") + m + " --tol 1e-10 --periods 1 --json");
    ASSERT_EQ(r.code, 0) << m << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_LT(j.at("return_error").get<double>(), 1e-6) << m;
    EXPECT_GT(j.at("force_evals").get<long>(), 0) << m;
    EXPECT_EQ(j.at("adaptive").get<bool>(), true) << m;
  }
  const auto dop = nlohmann::json::parse(run("run --problem arenstorf --method DOP853 --tol 1e-10 --json").out);
  EXPECT_EQ(dop.at("method").get<std::string>(), "DOP853-adaptive");
  // Without a tolerance: exit 2, one line.
  const auto nt = run("run --problem arenstorf --method DOP853");
  EXPECT_EQ(nt.code, 2);
  EXPECT_EQ(nt.err.find('\n'), nt.err.size() - 1) << nt.err;
}

TEST(CliVelocity, DampedOscillatorAgainstItsExactSolution) {
  const auto r = run("run --problem damped-oscillator --method GBS --tol 1e-11 --periods 3 --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_LT(j.at("position_error").get<double>(), 1e-9);
  EXPECT_LT(j.at("velocity_error").get<double>(), 1e-9);
}

TEST(CliVelocity, MethodsForAccelerationsOnlyAreRefusedWithOneLine) {
  for (const char* args :
       {"run --problem arenstorf --method M8 --tol 1e-12 --periods 1 --json",
        "run --problem arenstorf --method DP12-adaptive --tol 1e-10", "run --problem damped-oscillator --method VV"}) {
    const auto r = run(args);
    EXPECT_EQ(r.code, 2) << args;
    EXPECT_TRUE(r.out.empty()) << args;
    EXPECT_EQ(r.err.find("nystrom: error: method '"), 0u) << r.err;
    EXPECT_NE(
        r.err.find(
            "does not support velocity-dependent forces a(t, q, v); methods that do: DOP853-adaptive, Fine4-adaptive, "
            "Fine5-adaptive, GBS, mpe-midpoint:K1,K2,..., mpe-midpoint-adaptive:K1,K2,...\n"),
        std::string::npos)
        << r.err;
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << r.err;  // one line
  }
  const auto nt = run("run --problem arenstorf --method GBS");
  EXPECT_EQ(nt.code, 2);
  EXPECT_NE(nt.err.find("--tol"), std::string::npos) << nt.err;
}
