// The `nystrom langevin` contract: the JSON object (averages of q2 and q4 with standard errors), its values
// against quadrature of the Boltzmann density, the same numbers for any thread count, and bad input (exit
// code 2, one line `nystrom: error: ...`). The tool is found through NYSTROM_BIN.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include <nlohmann/json.hpp>

#include "support/cli_runner.hpp"
#include "support/double_well.hpp"

namespace {

using namespace cli_test;

// The contract's command with fewer paths (the contract itself: --paths 10000).
const std::string kCommand =
    "langevin --potential double-well --gamma 1 --kT 0.5 --method BAOAB --h 0.05 --paths 600 --t-end 100 "
    "--extrapolate 1,2,3 --seed 1 --json";

// `nystrom ARGS` exits 2 with one line `nystrom: error: ...` on stderr and nothing on stdout.
void expect_one_line_refusal(const std::string& args) {
  const auto r = run(args);
  EXPECT_EQ(r.code, 2) << args << "\n" << r.out << r.err;
  EXPECT_EQ(r.err.rfind("nystrom: error: ", 0), 0u) << args << ": " << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << args << ": " << r.err;
  EXPECT_TRUE(r.out.empty()) << args << ": " << r.out;
}

}  // namespace

TEST(LangevinCli, ContractJsonAgreesWithTheBoltzmannDensityForAnyThreadCount) {
  const auto one = run(kCommand + " --threads 1");
  ASSERT_EQ(one.code, 0) << one.err;
  const auto j = nlohmann::json::parse(one.out);
  const auto [m2, m4] = test_support::double_well_moments(0.5);
  for (const auto& [name, exact] : {std::pair{"q2", m2}, std::pair{"q4", m4}}) {
    const auto& e = j.at("averages").at(name);
    const double value = e.at("value").get<double>(), se = e.at("stderr").get<double>();
    EXPECT_GT(se, 0) << name;
    EXPECT_LT(se, 0.01) << name;
    EXPECT_LE(std::abs(value - exact), 5 * se) << name << " " << value << " +- " << se << " vs " << exact;
  }
  EXPECT_EQ(j.at("extrapolate"), nlohmann::json({1, 2, 3}));
  EXPECT_EQ(j.at("order").get<int>(), 6);
  EXPECT_EQ(j.at("members").size(), 3u);
  EXPECT_EQ(j.at("steps").get<long>(), 2000);
  EXPECT_EQ(j.at("window"), nlohmann::json({50.0, 100.0}));
  // BAOAB: one force per step and the first, for each of the three runs
  EXPECT_EQ(j.at("force_evaluations").get<long long>(), 600LL * (2000 + 4000 + 6000 + 3));
  for (const char* threads : {"2", "3"}) {
    const auto other = run(kCommand + " --threads " + threads);
    ASSERT_EQ(other.code, 0) << other.err;
    EXPECT_EQ(other.out, one.out) << "--threads " << threads;  // the same text: the same numbers
  }
}

TEST(LangevinCli, ExtrapolateOneIsTheSchemeAlone) {
  const auto r = run("langevin --potential harmonic --kT 0.5 --h 0.5 --t-end 100 --paths 300 --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("coefficients"), nlohmann::json({1.0}));
  // BAOAB at h omega = 1/2: <q^2> = kT exactly, <v^2> = kT (1 - 1/16)
  const auto& q2 = j.at("averages").at("q2");
  const auto& v2 = j.at("averages").at("v2");
  EXPECT_LE(std::abs(q2.at("value").get<double>() - 0.5), 5 * q2.at("stderr").get<double>());
  EXPECT_LE(std::abs(v2.at("value").get<double>() - 0.5 * 15 / 16), 5 * v2.at("stderr").get<double>());
}

TEST(LangevinCli, TextOutputNamesTheEstimates) {
  const auto r = run("langevin --paths 50 --t-end 1");
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* s : {"BAOAB", "q2", "q4", "v2", "energy", "+-"})
    EXPECT_NE(r.out.find(s), std::string::npos) << s << "\n" << r.out;
}

TEST(LangevinCli, BadInputIsOneLineAndExitTwo) {
  for (const char* args : {
           "langevin --method BAXAB",
           "langevin --method BAO --extrapolate 1,2",
           "langevin --potential quartic",
           "langevin --h 0.3 --t-end 1",
           "langevin --h 0",
           "langevin --h nan",
           "langevin --gamma -1",
           "langevin --kT -0.5",
           "langevin --paths 0",
           "langevin --extrapolate 1,1",
           "langevin --extrapolate 0",
           "langevin --extrapolate 1,x",
           "langevin --threads -1",
           "langevin --potential harmonic --omega 10 --gamma 0.01 --h 0.5 --t-end 100 --paths 10",
       }) {
    expect_one_line_refusal(args);
  }
}

// --stationary-law: the exact stationary averages of the scheme from its law on a phase-space grid. BAOAB at
// h omega = 1 samples q exactly (<q^2> = kT / omega^2) and <v^2> = kT (1 - h^2 omega^2 / 4); in the double well
// the three-term extrapolation's bias at h = 0.1 is below 1e-8 while BAOAB's own (its first member) is 2e-4, both
// against Simpson's rule for the Boltzmann density, which the reported "boltzmann" matches.
TEST(LangevinCli, StationaryLawIsExactWithoutPaths) {
  const auto r = run("langevin --stationary-law --potential harmonic --kT 0.5 --omega 2 --h 0.5 --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_NEAR(j.at("stationary").at("q2").get<double>(), 0.5 / 4, 1e-11);
  EXPECT_NEAR(j.at("stationary").at("v2").get<double>(), 0.5 * (1 - 0.25), 1e-11);
  EXPECT_NEAR(j.at("boltzmann").at("v2").get<double>(), 0.5, 1e-12);
  EXPECT_EQ(j.at("order").get<int>(), 2);
  EXPECT_LT(j.at("resolution").get<double>(), 1e-6);
  EXPECT_LT(j.at("edge").get<double>(), 1e-6);
  EXPECT_EQ(j.at("grid").at("points"), nlohmann::json({65, 65}));

  const auto w =
      run("langevin --stationary-law --potential double-well --gamma 1 --kT 0.5 --h 0.1 --extrapolate "
          "1,2,3 --json");
  ASSERT_EQ(w.code, 0) << w.err;
  const auto d = nlohmann::json::parse(w.out);
  const auto [m2, m4] = test_support::double_well_moments(0.5);
  EXPECT_NEAR(d.at("boltzmann").at("q2").get<double>(), m2, 1e-12);
  EXPECT_NEAR(d.at("boltzmann").at("q4").get<double>(), m4, 1e-12);
  EXPECT_LT(std::abs(d.at("stationary").at("q2").get<double>() - m2), 1e-8);
  EXPECT_LT(std::abs(d.at("stationary").at("q4").get<double>() - m4), 1e-8);
  const auto& members = d.at("members");
  ASSERT_EQ(members.size(), 3u);
  EXPECT_GT(std::abs(members[0].at("stationary").at("q2").get<double>() - m2), 1.5e-4);
  EXPECT_EQ(members[2].at("h").get<double>(), 0.1 / 3);
  EXPECT_GT(members[2].at("steps").get<long>(), 0);
  EXPECT_EQ(d.at("order").get<int>(), 6);

  const auto text = run("langevin --stationary-law --h 0.5");
  ASSERT_EQ(text.code, 0) << text.err;
  for (const char* s : {"stationary", "Boltzmann", "bias", "q2", "65 x 65"})
    EXPECT_NE(text.out.find(s), std::string::npos) << s << "\n" << text.out;
}

TEST(LangevinCli, StationaryLawRefusalsAreOneLineAndExitTwo) {
  for (const char* args : {
           "langevin --stationary-law --paths 10",
           "langevin --stationary-law --seed 3",
           "langevin --stationary-law --t-end 5",
           "langevin --grid-points 33",
           "langevin --stationary-law --grid-points 64",
           "langevin --stationary-law --grid-points 1001",
           "langevin --stationary-law --gamma 0",
           "langevin --stationary-law --kT 0",
           "langevin --stationary-law --method BAO --extrapolate 1,2",
           "langevin --stationary-law --potential double-well --kT 0.5 --h 0.4",
       }) {
    expect_one_line_refusal(args);
  }
  // The run's largest possible work (every member to max_steps) is checked against the work limit first.
  const auto limited = run("langevin --stationary-law", temp_dir(), "env NYSTROM_WORK_LIMIT=1e6");
  EXPECT_EQ(limited.code, 2) << limited.err;
  EXPECT_NE(limited.err.find("estimated work"), std::string::npos) << limited.err;
}
