// The `nystrom quantum` contract: the JSON fields, physics checks of its output against exact values, and
// bad input (exit code 2, one line `nystrom: error: ...`). The tool is found through NYSTROM_BIN.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "cli_runner.hpp"

namespace {

using namespace cli_test;

}  // namespace

TEST(QuantumCli, ContractCommandGivesTheCoherentState) {
  const auto r =
      run("quantum --potential harmonic --dims 1 --grid 256 --box 20 --method M8 --dt 0.05 --steps 200 "
          "--x0 1 --p0 0 --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  for (const char* k :
       {"method", "dims", "grid", "dt", "steps", "norm", "energy", "mean_position", "time", "fft_count", "seconds"})
    EXPECT_TRUE(j.contains(k)) << k;
  EXPECT_EQ(j["method"], "M8");
  EXPECT_EQ(j["dims"], 1);
  EXPECT_EQ(j["grid"], 256);
  EXPECT_EQ(j["steps"], 200);
  EXPECT_NEAR(j["time"].get<double>(), 10.0, 1e-12);
  ASSERT_EQ(j["mean_position"].size(), 1u);
  EXPECT_NEAR(j["mean_position"][0].get<double>(), std::cos(10.0), 1e-8);  // the classical orbit
  EXPECT_NEAR(j["energy"].get<double>(), 1.0, 1e-8);                       // 1/2 + x0^2/2
  EXPECT_NEAR(j["norm"].get<double>(), 1.0, 1e-7);
  EXPECT_LT(j["exact_error"].get<double>(), 1e-7);
  // M8 = mpe:1,2,3,4 over position Verlet: 4 products with 2, 3, 4, 5 kinetic sub-steps, two FFTs each
  EXPECT_EQ(j["fft_count"], 200 * 2 * (2 + 3 + 4 + 5));
}

TEST(QuantumCli, ImaginaryTimeGroundState3DAndLongDouble) {
  const auto r =
      run("quantum --dims 3 --grid 24 --box 12 --method BC1 --dt 0.2 --steps 100 --imaginary-time "
          "--x0 0.5 --precision long-double --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_NEAR(j["energy"].get<double>(), 1.5, 1e-8);
  EXPECT_NEAR(j["norm"].get<double>(), 1.0, 1e-12);
  EXPECT_EQ(j["mean_position"].size(), 3u);
  EXPECT_EQ(j["precision"], "long-double");
}

TEST(QuantumCli, PlotWritesAPng) {
  const auto png = temp_dir() / "orbit.png";
  const auto r = run("quantum --grid 64 --steps 20 --method PV --plot " + png.string());
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string head = slurp(png).substr(0, 4);
  EXPECT_EQ(head, "\x89PNG");
}

TEST(QuantumCli, BadInputExitsTwoWithOneLine) {
  const auto dir = temp_dir();
  for (const std::string args : {"--grid 0", "--grid -4", "--box 0", "--box -3", "--box nan", "--dt nan", "--dt 0",
                                 "--potential nowhere", "--method A6", "--method DP12", "--method nonsense", "--dims 4",
                                 "--precision float", "--x0 1,2", "--g inf", "--steps -1", "--grid abc"}) {
    const auto r = run("quantum " + args);
    EXPECT_EQ(r.code, 2) << args << ": " << r.err;
    EXPECT_EQ(r.err.rfind("nystrom: error: ", 0), 0u) << args << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << ": " << r.err;
  }
  const auto missing = run("quantum --grid 32 --steps 2 --plot " + (dir / "no" / "such" / "f.png").string());
  EXPECT_EQ(missing.code, 2) << missing.err;
}
