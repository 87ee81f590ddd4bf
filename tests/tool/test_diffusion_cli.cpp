// The `nystrom smoluchowski` and `nystrom thermal` contracts: the JSON fields against closed forms, the density file
// written atomically, bad input (exit 2, one line `nystrom: error: ...`). The tool is found through NYSTROM_BIN.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/cli_runner.hpp"

namespace {

using namespace cli_test;

void expect_one_line_error(const Result& r, const std::string& args) {
  EXPECT_EQ(r.code, 2) << args << ": " << r.err;
  EXPECT_EQ(r.err.rfind("nystrom: error: ", 0), 0u) << args << ": " << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << ": " << r.err;
}

}  // namespace

// The Ornstein-Uhlenbeck process from the command line: the exact mean x0 e^{-D beta t} and variance
// s^2 e^{-2 D beta t} + (1 - e^{-2 D beta t}) / beta.
TEST(SmoluchowskiCli, OrnsteinUhlenbeckMoments) {
  const auto r =
      run("smoluchowski --potential harmonic --beta 2 --diffusion 0.5 --box 12 --grid 128 --x0 1 "
          "--width 0.3 --method M6 --dt 0.05 --steps 20 --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  for (const char* k : {"method", "order", "mass", "mass_drift", "min_density", "negative_mass", "mean", "variance",
                        "boltzmann_distance", "exact_solution", "exact_error", "rates", "kramers_rate", "fft_count"})
    EXPECT_TRUE(j.contains(k)) << k;
  EXPECT_EQ(j["method"], "M6");
  EXPECT_EQ(j["exact_solution"], "Ornstein-Uhlenbeck");
  const double decay = std::exp(-1.0);
  EXPECT_NEAR(j["mean"][0].get<double>(), decay, 1e-8);
  EXPECT_NEAR(j["variance"][0].get<double>(), 0.09 * decay * decay + (1 - decay * decay) / 2, 1e-8);
  EXPECT_LT(j["exact_error"].get<double>(), 1e-8);
  EXPECT_LT(std::abs(j["mass_drift"].get<double>()), 1e-9);
  EXPECT_TRUE(j["kramers_rate"].is_null());
}

// The defaults: the double well, M8; the rate of the double well at beta = 3 (the value the library test checks
// against finite differences) and the density file, one grid point per line with the Boltzmann density beside.
TEST(SmoluchowskiCli, DoubleWellRateAndDensityFile) {
  const auto dir = temp_dir();
  const auto file = dir / "rho.txt";
  const auto r =
      run("smoluchowski --beta 3 --box 5 --grid 96 --diffusion 0.7 --dt 0.01 --steps 400 --rates 1 "
          "--density-file " +
          file.string() + " --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["method"], "M8");
  ASSERT_EQ(j["rates"].size(), 1u);
  // the second eigenvalue of the finite-difference generator (test_diffusion.cpp): 0.169301707768
  EXPECT_NEAR(j["rates"][0].get<double>(), 0.169301707768, 2e-9);
  EXPECT_LT(j["rate_residuals"][0].get<double>(), 1e-6);
  EXPECT_GT(j["kramers_rate"].get<double>(), 0.8 * j["rates"][0].get<double>());
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line.rfind("# x_1", 0), 0u) << line;
  int points = 0;
  double mass = 0, boltzmann = 0;
  for (double x, rho, rb; in >> x >> rho >> rb; ++points) {
    mass += rho * 5.0 / 96;
    boltzmann += rb * 5.0 / 96;
  }
  EXPECT_EQ(points, 96);
  EXPECT_NEAR(mass, j["mass"].get<double>(), 1e-12);
  EXPECT_NEAR(boltzmann, 1, 1e-12);
  EXPECT_TRUE(std::filesystem::exists(file));
  for (const auto& e : std::filesystem::directory_iterator(dir))  // no temporary file left beside it
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
}

TEST(SmoluchowskiCli, BackwardMethodsAndBadInputExitTwoWithOneLine) {
  for (const std::string args :
       {"--method FR", "--method KL8", "--method Y6", "--method A6", "--method nonsense", "--beta 0", "--beta -1",
        "--diffusion nan", "--dt 0", "--grid 8", "--dims 4", "--potential morse", "--x0 1,2", "--width 5", "--rates -1",
        "--steps -1", "--initial-file /dev/null", "--potential-file /nonexistent"}) {
    const auto r = run("smoluchowski " + args);
    expect_one_line_error(r, args);
  }
  const auto fr = run("smoluchowski --method FR");
  EXPECT_NE(fr.err.find("M4..M16"), std::string::npos) << fr.err;
  EXPECT_NE(fr.err.find("4A"), std::string::npos) << fr.err;
}

// The primitive approximation's closed form for the oscillator, Z_N = 1 / (2 sinh(N asinh(beta / 2N))), and the
// exact Z = 1 / (2 sinh(beta/2)) approached by the extrapolated propagator.
TEST(ThermalCli, OscillatorClosedForms) {
  const auto r = run("thermal --potential harmonic --beta 2 --beads 4,8 --extrapolate 1,2,3 --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["order"], 6);
  EXPECT_NEAR(j["z_exact"].get<double>() * 2 * std::sinh(1.0), 1, 1e-12);
  ASSERT_EQ(j["rows"].size(), 2u);
  for (const auto& row : j["rows"]) {
    const double n = row["beads"].get<double>();
    EXPECT_NEAR(row["z_primitive"].get<double>() * 2 * std::sinh(n * std::asinh(1 / n)), 1, 1e-12);
  }
  EXPECT_NEAR(j["rows"][1]["z_extrapolated"].get<double>() * 2 * std::sinh(1.0), 1, 1e-6);
  const auto text = run("thermal");
  ASSERT_EQ(text.code, 0) << text.err;
  EXPECT_NE(text.out.find("grid exact"), std::string::npos) << text.out;
}

TEST(ThermalCli, BadInputExitsTwoWithOneLine) {
  for (const std::string args :
       {"--beta 0", "--beta inf", "--grid 2000", "--grid 0", "--beads 0", "--beads 4,x", "--extrapolate 1,1",
        "--extrapolate 0", "--potential nowhere", "--potential-file /nonexistent"}) {
    const auto r = run("thermal " + args);
    expect_one_line_error(r, args);
  }
}
