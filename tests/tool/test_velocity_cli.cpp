// The `nystrom flows` contract: the JSON fields, the built-in problems against their exact solutions or their
// period, both time directions, and bad input (exit code 2, one line `nystrom: error: ...`). The tool is found
// through NYSTROM_BIN.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include <nlohmann/json.hpp>

#include "support/cli_runner.hpp"

namespace {

using namespace cli_test;

nlohmann::json run_json(const std::string& args) {
  const auto r = run("flows " + args + " --json");
  EXPECT_EQ(r.code, 0) << args << ": " << r.err;
  return r.code == 0 ? nlohmann::json::parse(r.out) : nlohmann::json::object();
}

}  // namespace

TEST(FlowsCli, ArenstorfReturnsAfterOnePeriod) {
  const auto j = run_json("--problem arenstorf --method KL8 --periods 1");
  for (const char* k : {"problem", "method", "order", "dt", "steps", "time", "q", "v", "force_evals", "return_error",
                        "periods", "invariant", "invariant_error", "seconds"})
    EXPECT_TRUE(j.contains(k)) << k;
  EXPECT_EQ(j["method"], "KL8");
  EXPECT_EQ(j["order"], 8);
  EXPECT_EQ(j["symplectic"], true);
  EXPECT_EQ(j["steps"], 20000);  // the default steps per period
  EXPECT_NEAR(j["time"].get<double>(), 17.0652165601579625588917206249, 1e-12);
  EXPECT_LT(j["return_error"].get<double>(), 1e-8);
  EXPECT_LT(j["invariant_error"].get<double>(), 1e-8);
  // KL8: 17 compositions of drift-kick-drift, one kick each (the drifts merge)
  EXPECT_EQ(j["force_evals"], 20000 * 17);
  // backward: the orbit runs the other way round and returns as well
  const auto b = run_json("--problem arenstorf --periods -1");
  EXPECT_LT(b["time"].get<double>(), 0);
  EXPECT_LT(b["return_error"].get<double>(), 1e-8);
}

TEST(FlowsCli, MagneticAndDampedProblemsMatchTheirExactSolutions) {
  for (const std::string p : {"helix", "penning", "damped"})
    for (const std::string m : {"KL8", "M8"}) {
      const auto j = run_json("--problem " + p + " --method " + m + " --periods 3.5 --steps-per-period 64");
      EXPECT_LT(j["position_error"].get<double>(), 1e-9) << p << " " << m;
      EXPECT_LT(j["velocity_error"].get<double>(), 1e-9) << p << " " << m;
      EXPECT_GT(j["velocity_error"].get<double>(), 0) << p << " " << m;
    }
  // the order shows from the command line too: FR at 16 and 32 steps per gyration
  const auto a = run_json("--problem penning --method FR --periods 3.5 --steps-per-period 16");
  const auto b = run_json("--problem penning --method FR --periods 3.5 --steps-per-period 32");
  EXPECT_NEAR(std::log2(a["position_error"].get<double>() / b["position_error"].get<double>()), 4, 0.35);
  const auto l = run_json("--problem damped --precision long-double --periods -2");
  EXPECT_LT(l["position_error"].get<double>(), 1e-9);
  EXPECT_LT(l["time"].get<double>(), 0);
}

TEST(FlowsCli, BadInputExitsTwoWithOneLine) {
  for (const std::string args :
       {"--problem nowhere", "--method N4", "--method DP12-adaptive", "--method AC1", "--method nonsense",
        "--periods 0", "--periods nan", "--steps-per-period -1", "--precision float", "--problem helix --b 0,0,0",
        "--problem helix --b 1,2", "--problem penning --b 1,0,1", "--problem penning --kappa 1", "--mu 2",
        "--problem damped --omega0 0", "--q0 1,2", "--samples -3"}) {
    const auto r = run("flows " + args);
    EXPECT_EQ(r.code, 2) << args << ": " << r.err;
    EXPECT_EQ(r.err.rfind("nystrom: error: ", 0), 0u) << args << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << ": " << r.err;
  }
}
