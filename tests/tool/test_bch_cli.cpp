// The `bch` and `discover` subcommands and `run --method file:PATH` through the tool (NYSTROM_BIN, set by CTest):
// JSON contracts, Table 4.3 from the command line, discovered methods written and run, bad input.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/cli_runner.hpp"
#include "support/gurkan.hpp"

namespace {

/// A folder of the running test's own, which also holds the tool's captured output (cli_runner.hpp).
std::filesystem::path scratch() { return cli_test::temp_dir(); }

using cli_test::slurp;

cli_test::Result run_tool(const std::string& args) { return cli_test::run(args); }

}  // namespace

TEST(BchCli, JsonReportsOrderAndLeadingTerms) {
  const auto r = run_tool("bch --method BR1 --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["method"], "BR1");
  EXPECT_EQ(j["order"], 5);
  EXPECT_EQ(j["declared_order"], 5);
  EXPECT_TRUE(j["order_confirmed"].get<bool>());
  EXPECT_EQ(j["basis"], "hall");
  EXPECT_EQ(j["algebra"], "rkn");
  ASSERT_EQ(j["degrees"].size(), 7u);
  EXPECT_EQ(j["leading"]["degree"], 6);
  EXPECT_NEAR(j["leading"]["norm"].get<double>(), 4.71e-4, 0.005e-4);  // Gürkan Table 4.3
  EXPECT_EQ(j["leading"]["terms"][0]["name"], "X11");
  EXPECT_EQ(j["degrees"][6]["terms"].size(), 10u);  // degree 7 of the RKN algebra
}

TEST(BchCli, ExactRationalsForVerlet) {
  const auto r = run_tool("bch --method VV --degree 3 --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j["exact"].get<bool>());
  // e^{V/2} e^{T} e^{V/2}: H - Z in degree 3 is -1/12 [T,[T,V]] - 1/24 [V,[T,V]] (Yoshida 1990, with T <-> V)
  EXPECT_EQ(j["leading"]["terms"][0]["exact"], "-1/12");
  EXPECT_EQ(j["leading"]["terms"][1]["exact"], "-1/24");
}

TEST(BchCli, TextOutputAndGurkanTable) {
  const auto r = run_tool("bch --method AC1");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("order: 5 (declared 5: confirmed)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("X11"), std::string::npos);
  // The norm of the leading error terms: Gurkan Table 4.3 prints 1.02e-5 for AC1 (three digits; the
  // whole table is compared at its printed precision in GurkanTableHasEveryPrintedDigit below).
  const auto j = nlohmann::json::parse(run_tool("bch --method AC1 --json").out);
  EXPECT_NEAR(j["leading"]["norm"].get<double>(), 1.02e-5, 0.005e-5);
  const auto t = run_tool("bch --gurkan-table");
  ASSERT_EQ(t.code, 0) << t.err;
  EXPECT_NE(t.out.find("AR1"), std::string::npos) << t.out;
}

TEST(BchCli, GurkanTableHasEveryPrintedDigit) {
  // Gürkan, Table 4.3 (coefficients of H - Z in degree 6 and their norm), as printed in the paper: two significant
  // digits for X11, X16, X17, X19, X20 (purely imaginary for the complex methods) and three for the norm.
  const auto& table = nystrom::test::printed_gurkan_table_4_3();
  // The table shows 3 significant digits for the terms and 4 for the norm, themselves rounded, so "agrees with the
  // paper's `digits` digits" means: within half a unit of the paper's last digit plus half a unit of the shown last
  // digit (the exact rounding of the full values is asserted in test_bch, ReproducesGurkanTable43).
  auto agrees = [](double shown, int shown_digits, double printed, int digits) {
    const auto unit = [](double x, int d) { return std::pow(10.0, std::floor(std::log10(std::abs(x))) - (d - 1)); };
    return std::abs(shown - printed) <=
           0.5 * unit(printed, digits) + 0.5 * unit(shown, shown_digits) + 1e-12 * std::abs(printed);
  };
  const auto r = run_tool("bch --gurkan-table");
  ASSERT_EQ(r.code, 0) << r.err;
  std::istringstream lines(r.out);
  std::map<std::string, std::vector<std::string>> rows;
  for (std::string line; std::getline(lines, line);) {
    std::istringstream f(line);
    std::vector<std::string> tok;
    for (std::string t; f >> t;) tok.push_back(t);
    if (tok.size() == 7) rows[tok[0]] = {tok.begin() + 1, tok.end()};
  }
  for (const auto& want : table) {
    ASSERT_EQ(rows.count(want.name), 1u) << want.name << " row missing:\n" << r.out;
    const auto& got = rows[want.name];
    // the paper prints the AC2 row with the signs of AC2's adjoint (see ReproducesGurkanTable43 in test_bch)
    const double sign = want.name == "AC2" ? -1.0 : 1.0;
    for (std::size_t k = 0; k < 5; ++k) {
      const std::string& t = got[k];
      EXPECT_EQ(t.back() == 'i', want.imaginary) << want.name << " X" << k << ": " << t;
      const double v = std::stod(want.imaginary ? t.substr(0, t.size() - 1) : t);
      EXPECT_TRUE(agrees(sign * v, 3, want.x[k], 2))
          << want.name << " term " << k << ": " << t << " vs printed " << want.x[k];
    }
    EXPECT_TRUE(agrees(std::stod(got[5]), 4, want.norm, 3))
        << want.name << " norm " << got[5] << " vs printed " << want.norm;
  }
}

TEST(BchCli, DiscoverWritesMethodsThatRun) {
  const auto dir = scratch() / "found";
  const auto r = run_tool("discover --scheme A --starts 120 --seed 2 --threads 2 --show imaginary --write " +
                          dir.string() + " --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j.size(), 1u);
  EXPECT_EQ(j[0]["scheme"], "RKNA");
  EXPECT_GE(j[0]["imaginary"].get<int>(), 1);
  std::string ac1_file;
  for (const auto& m : j[0]["methods"]) {
    EXPECT_EQ(m["class"], "IMAGINARY");
    EXPECT_GE(m["digits"].get<int>(), 30);
  }
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (slurp(e.path()).find("equals AC1") != std::string::npos) ac1_file = e.path().string();
  ASSERT_FALSE(ac1_file.empty()) << "no written method file matches AC1";
  const auto run = run_tool("run --method file:" + ac1_file + " --ecc 0.2 --steps-per-period 200 --periods 2 --json");
  ASSERT_EQ(run.code, 0) << run.err;
  const auto jr = nlohmann::json::parse(run.out);
  EXPECT_LT(jr["position_error"].get<double>(), 1e-9) << run.out;
  const auto b = run_tool("bch --method file:" + ac1_file + " --json");
  ASSERT_EQ(b.code, 0) << b.err;
  // AC1's error norm as Gurkan Table 4.3 prints it (three digits)
  EXPECT_NEAR(nlohmann::json::parse(b.out)["leading"]["norm"].get<double>(), 1.02e-5, 0.005e-5);
}

TEST(BchCli, SixStageFromPublishedMethod) {
  const auto r = run_tool("discover --six-stage --from AC1 --tries 4 --seed 5 --six-bits 0 --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_NEAR(j["published_error_norm"].get<double>(), 2.6e-7, 0.05e-7);
  EXPECT_NEAR(j["start_error_norm"].get<double>(), 1.02e-5, 0.005e-5);
  ASSERT_GE(j["minima"].size(), 1u);
  EXPECT_LT(j["minima"][0]["error_norm"].get<double>(), j["start_error_norm"].get<double>());
}

TEST(BchCli, BadInputIsOneLineAndExitCode2) {
  const auto bad = scratch() / "bad.txt";  // a second-order method that claims order 5
  std::ofstream(bad) << "name x\norder 5\ndrift 1/2\nkick 1\ndrift 1/2\n";
  const auto nan = scratch() / "nan.txt";
  std::ofstream(nan) << "name x\norder 2\ndrift nan\nkick 1\ndrift 1/2\n";
  const auto noname = scratch() / "noname.txt";
  std::ofstream(noname) << "order 2\ndrift 1/2\nkick 1\ndrift 1/2\n";
  const auto garbage = scratch() / "garbage.txt";
  std::ofstream(garbage) << std::string(
                                "\x7f"
                                "ELF\x01\x02\x03\x00\xff\xfe kick",
                                15)
                         << "\n";
  for (const std::string& args :
       {std::string("bch --method NoSuchMethod"), std::string("bch --method N4"),
        std::string("bch --method VV --degree 0"), std::string("bch --method VV --basis hal"), std::string("bch"),
        std::string("discover --starts 0"), std::string("discover --scheme C"), std::string("discover --solver bfgs"),
        std::string("discover --show some"), std::string("discover --six-stage --from VV"),
        "run --method file:" + bad.string(), "run --method file:" + nan.string(),
        "run --method file:" + noname.string(), "run --method file:" + garbage.string(),
        "bch --method file:" + bad.string(), "run --method file:" + scratch().string(),
        std::string("run --method file:/nonexistent/x.txt")}) {
    const auto r = run_tool(args);
    EXPECT_EQ(r.code, 2) << args << "\n" << r.out << r.err;
    EXPECT_EQ(r.err.rfind("nystrom: error: ", 0), 0u) << args << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << ": " << r.err;
  }
}
