// `nystrom run --problem outer-solar-system`: the JSON fields, the errors of a Wisdom-Holman map and of its
// multi-product extrapolation against the long double reference, and bad input (exit code 2, one line
// `nystrom: error: ...`). The tool is found through NYSTROM_BIN.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include <nlohmann/json.hpp>

#include "support/cli_runner.hpp"

namespace {

using namespace cli_test;

nlohmann::json run_json(const std::string& args) {
  const auto r = run("run --problem outer-solar-system " + args + " --json");
  EXPECT_EQ(r.code, 0) << r.err;
  return r.code == 0 ? nlohmann::json::parse(r.out) : nlohmann::json{};
}

}  // namespace

TEST(PlanetaryCli, JsonFieldsAndExtrapolationBeatsTheMap) {
  // 1000 years at 200 days: Jupiter makes 84 orbits
  const auto wh = run_json("--method WH --h 200 --years 1000");
  const auto m8 = run_json("--method WH-M8 --h 200 --years 1000");
  ASSERT_FALSE(wh.empty());
  ASSERT_FALSE(m8.empty());
  for (const char* k :
       {"method", "order", "precision", "h", "years", "steps", "force_evals", "energy_error", "energy_error_max",
        "angular_momentum_error", "jupiter_position", "jupiter_position_error", "reference", "seconds"})
    EXPECT_TRUE(m8.contains(k)) << k;
  EXPECT_EQ(m8["method"], "WH-M8");
  EXPECT_EQ(m8["order"], 8);
  EXPECT_EQ(m8["steps"], 1826);  // 1000 * 365.25 / 200, rounded
  // M8 = 1 + 2 + 3 + 4 Wisdom-Holman maps of one kick each per step
  EXPECT_EQ(m8["force_evals"], 1826 * 10);
  EXPECT_EQ(wh["force_evals"], 1826);
  ASSERT_EQ(m8["jupiter_position"].size(), 3u);
  // the initial data are heliocentric, not barycentric: the frame drifts, so compare with the reference's Jupiter
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(m8["jupiter_position"][k].get<double>(), m8["reference"]["jupiter_position"][k].get<double>(), 1e-6);
  // the map conserves energy to its eps h^2 oscillation, angular momentum to rounding
  EXPECT_LT(wh["energy_error_max"].get<double>(), 1e-5);
  EXPECT_GT(wh["energy_error_max"].get<double>(), 1e-9);
  EXPECT_LT(wh["angular_momentum_error"].get<double>(), 1e-12);
  // the eighth-order extrapolation is far more accurate at the same step
  EXPECT_LT(m8["energy_error_max"].get<double>(), wh["energy_error_max"].get<double>() * 1e-3);
  EXPECT_LT(m8["jupiter_position_error"].get<double>(), wh["jupiter_position_error"].get<double>() * 1e-3);
  EXPECT_EQ(m8["reference"]["precision"], "long-double");
}

TEST(PlanetaryCli, DirectMethodsRunOnTheCartesianEquations) {
  const auto j = run_json("--method M8 --h 20 --years 100 --no-reference");
  ASSERT_FALSE(j.empty());
  EXPECT_EQ(j["method"], "M8");
  EXPECT_LT(j["energy_error"].get<double>(), 1e-9);
  EXPECT_TRUE(j["reference"].is_null());
}

// A direct method runs in the centre-of-mass frame and reports in the data's frame: Hairer's barycentre moves 2.5 AU
// per thousand years, so in the data's frame the positions grow and every separation loses digits. DP12-adaptive
// over 10 000 years at tol 1e-14: energy 1.0e-15 and Jupiter 6e-11 AU in the centre-of-mass frame, 5.0e-14 and
// 9.0e-10 AU in the data's frame.
TEST(PlanetaryCli, DirectMethodsKeepTheirDigitsOverLongRuns) {
  const auto j = run_json("--method DP12-adaptive --tol 1e-14 --h 200 --years 10000");
  ASSERT_FALSE(j.empty());
  EXPECT_LT(std::fabs(j["energy_error"].get<double>()), 1e-14);
  EXPECT_LT(j["jupiter_position_error"].get<double>(), 3e-10);
  // the position is Jupiter's in the data's frame, 25 AU from where it started, as the reference's
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(j["jupiter_position"][k].get<double>(), j["reference"]["jupiter_position"][k].get<double>(), 1e-9);
  EXPECT_GT(std::fabs(j["jupiter_position"][0].get<double>()), 15);
}

// The corrected map and the democratic heliocentric maps run from the command line; the corrector costs kicks
// only at the outputs (about a thousand energy samples), and lowers the map's energy error.
TEST(PlanetaryCli, CorrectorAndDemocraticHeliocentricMaps) {
  const auto wh = run_json("--method WH --h 100 --years 1000 --no-reference");
  const auto c7 = run_json("--method WHC7 --h 100 --years 1000 --no-reference");
  const auto d8 = run_json("--method WHD-M8 --h 100 --years 1000 --no-reference");
  ASSERT_FALSE(wh.empty());
  ASSERT_FALSE(c7.empty());
  ASSERT_FALSE(d8.empty());
  EXPECT_EQ(c7["method"], "WHC7");
  EXPECT_LT(c7["energy_error_max"].get<double>(), wh["energy_error_max"].get<double>() / 2);
  EXPECT_EQ(d8["method"], "WHD-M8");
  EXPECT_EQ(d8["order"], 8);
  EXPECT_LT(d8["energy_error_max"].get<double>(), wh["energy_error_max"].get<double>() * 1e-3);
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(d8["jupiter_position"][k].get<double>(), c7["jupiter_position"][k].get<double>(), 1e-3);
}

TEST(PlanetaryCli, BadInputIsOneLineAndExitTwo) {
  for (const char* args :
       {"--method WH-BC1 --h 200 --years 10", "--method nonsense --h 200 --years 10", "--method WH --h 0 --years 10",
        "--method WH --h 200 --years -1", "--method WH --h 1e9 --years 1",
        "--method WH --h 200 --years 10 --precision qd", "--method DP12-adaptive --h 200 --years 10",
        "--h 200 --years 10", "--method WHC9 --h 200 --years 10", "--method WHD-VV --h 200 --years 10"}) {
    const auto r = run(std::string("run --problem outer-solar-system ") + args + " --no-reference");
    EXPECT_EQ(r.code, 2) << args;
    EXPECT_EQ(r.err.rfind("nystrom: error: ", 0), 0u) << args << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << ": " << r.err;
  }
  const auto r = run("run --problem kepler --method M8 --years 10");
  EXPECT_EQ(r.code, 2);
}
