// `nystrom reproduce all --quick`: every target writes its CSV, PNG and JSON, the report and summary.json,
// and the claims the papers make in words hold. The tool is found through NYSTROM_BIN (set by CTest).
// The tool's own verdicts (summary.json) are checked for consistency only; what makes the test is the
// comparison, recomputed here from the CSV files, of the tool's numbers with the values the papers print,
// written out below with the table, figure or passage they come from:
//   S. A. Chin, "Multi-product splitting and Runge-Kutta-Nystrom integrators", Celest. Mech. Dyn. Astron.
//     106 (2010) 391 (sec. III-V, Figs. 1-3);
//   M. A. Gurkan, "Fifth order Runge-Kutta-Nystrom methods with complex coefficients" (preprint, 2012;
//     Table 4.3, sec. 5, Figs. 5.1-5.2).
// The published values in the tool's CSV files are compared with these too (a mistyped published value in
// the tool fails), and the orders of Fig. 5.1 are measured against theory.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/cli_runner.hpp"

namespace {

namespace fs = std::filesystem;

using cli_test::run;
using cli_test::slurp;

/// A CSV file as rows of column name -> text.
std::vector<std::map<std::string, std::string>> read_csv(const fs::path& p) {
  std::ifstream in(p);
  std::string line;
  std::vector<std::string> header;
  std::vector<std::map<std::string, std::string>> rows;
  auto split = [](const std::string& s) {
    std::vector<std::string> v;
    std::stringstream ss(s);
    std::string item;
    while (std::getline(ss, item, ',')) v.push_back(item);
    return v;
  };
  if (!std::getline(in, line)) return rows;
  header = split(line);
  while (std::getline(in, line)) {
    const auto cells = split(line);
    std::map<std::string, std::string> row;
    for (std::size_t i = 0; i < header.size() && i < cells.size(); ++i) row[header[i]] = cells[i];
    rows.push_back(row);
  }
  return rows;
}

/// |precession| per period of `method` at nominal N in a Chin precision-effort CSV.
double error_at(const std::vector<std::map<std::string, std::string>>& rows, const std::string& method, double n) {
  for (const auto& r : rows)
    if (r.at("method") == method && std::abs(std::stod(r.at("nominal_force_evals_per_period")) / n - 1) < 1e-9)
      return std::abs(std::stod(r.at("precession_per_period")));
  ADD_FAILURE() << "no row for " << method << " at N = " << n;
  return std::nan("");
}

const std::vector<std::string> kTargets{"chin-fig1",     "chin-fig2",     "chin-fig3",       "gurkan-table4.3",
                                        "gurkan-fig5.1", "gurkan-fig5.2", "gurkan-table5.1", "gurkan-fig5.3"};

void check_files_and_report(const fs::path& out) {
  const auto summary = nlohmann::json::parse(slurp(out / "summary.json"));
  std::set<std::string> names;
  for (const auto& t : summary["targets"]) {
    const std::string name = t["name"];
    names.insert(name);
    EXPECT_TRUE(t["quick"].get<bool>());
    EXPECT_FALSE(t["claims"].empty()) << name;
    for (const std::string f : t["files"]) {
      const std::string data = slurp(out / f);
      ASSERT_GT(data.size(), 8u) << f;
      if (f.size() > 4 && f.substr(f.size() - 4) == ".png") {
        EXPECT_EQ(data.substr(1, 3), "PNG") << f;
      }
      if (f.size() > 4 && f.substr(f.size() - 4) == ".csv") {
        EXPECT_GT(read_csv(out / f).size(), 1u) << f;
      }
    }
    EXPECT_TRUE(fs::exists(out / (name + ".json"))) << name;
  }
  for (const auto& n : kTargets) EXPECT_TRUE(names.count(n)) << n;
  EXPECT_EQ(names.size(), kTargets.size());
  // The report: one section per target, with the claims table.
  const std::string md = slurp(fs::path(out.string() + ".md"));
  for (const auto& n : names) EXPECT_NE(md.find("## " + n + ":"), std::string::npos) << n;
  EXPECT_NE(md.find("| claim of the paper | published | measured |"), std::string::npos);
}

/// Every claim in words holds, except those that rest on CPU timings (machine-dependent; not asserted).
void check_claims(const fs::path& out) {
  const auto summary = nlohmann::json::parse(slurp(out / "summary.json"));
  int claims = 0;
  for (const auto& t : summary["targets"])
    for (const auto& c : t["claims"]) {
      EXPECT_FALSE(c["measured_text"].get<std::string>().empty());
      if (c["timing"].get<bool>()) continue;
      ++claims;
      EXPECT_TRUE(c["qualitative_holds"].get<bool>())
          << t["name"].get<std::string>() << ": " << c["paper"].get<std::string>() << " -- "
          << c["qualitative"].get<std::string>() << "; measured " << c["measured_text"].get<std::string>();
    }
  EXPECT_GE(claims, 15);
}

void check_chin_fig1(const fs::path& out) {
  const auto rows = read_csv(out / "chin-fig1.csv");
  auto eP = [&](const std::string& m, double e) {
    for (const auto& r : rows)
      if (r.at("method") == m && std::abs(std::stod(r.at("ecc")) - e) < 1e-9 && r.at("steps_per_period") == "5000")
        return std::stod(r.at("e_P"));
    ADD_FAILURE() << "no row for " << m << " at e = " << e;
    return std::nan("");
  };
  // Chin, sec. III (text on Fig. 1): "The error coefficient e_P at e = 0.9 for FR, N, A' and M4 are -23.1 x 10^4,
  // 7.1 x 10^4, -1.4 x 10^4 and -1.1 x 10^4", computed at h = 2 pi/5000 ("the final value used"), the step of the
  // rows read here. Printed to 0.1 x 10^4: each must agree within half that unit.
  const std::map<std::string, double> printed{{"FR", -23.1e4}, {"N4", 7.1e4}, {"Aprime", -1.4e4}, {"M4", -1.1e4}};
  for (const auto& [m, p] : printed) EXPECT_NEAR(eP(m, 0.9), p, 0.05e4 * (1 + 1e-9)) << m;
  // "The coefficient e_P grows steeply with e, by four orders of magnitude from e = 0.4 to e = 0.9" (one
  // significant digit): log10 |e_P(0.9)/e_P(0.4)| within [3.5, 4.5] for every method.
  for (const auto& [m, p] : printed) {
    const double decades = std::log10(std::abs(eP(m, 0.9) / eP(m, 0.4)));
    EXPECT_GE(decades, 3.5) << m;
    EXPECT_LE(decades, 4.5) << m;
  }
}

/// `ratio` compared with a value the paper gives in words ("about", "nearly", "comparable"), read off its
/// log-log figures: within a factor 2 either way. This is the text's precision, not a property of the
/// method: a method of the wrong order is caught by the slopes below and by test_order.
void expect_about(double ratio, double printed, const std::string& what) {
  EXPECT_GT(ratio, printed / 2) << what << ": published " << printed << ", measured " << ratio;
  EXPECT_LT(ratio, printed * 2) << what << ": published " << printed << ", measured " << ratio;
}

void check_chin_fig2_and_3(const fs::path& out) {
  const auto f2 = read_csv(out / "chin-fig2.csv");
  // Chin, sec. V (text on Fig. 2), at N = 10^5 force evaluations, e = 0.9: "KL6's error is only half of Y6's",
  // "their respective error are nearly 50 and 100 times larger than those of RKN integrators A6 and M6".
  const double y6 = error_at(f2, "Y6", 1e5), kl6 = error_at(f2, "KL6", 1e5);
  expect_about(kl6 / y6, 0.5, "KL6/Y6");
  for (const char* r : {"A6", "M6"}) {
    expect_about(kl6 / error_at(f2, r, 1e5), 50, std::string("KL6/") + r);
    expect_about(y6 / error_at(f2, r, 1e5), 100, std::string("Y6/") + r);
  }
  const auto f3 = read_csv(out / "chin-fig3.csv");
  // Chin, sec. V (text on Fig. 3), at N = 10^5: "the error of KL8 is more than 300 times that of" M8; "the error
  // of SS10 ... is about 100 times that of" M10; "DP10 is comparable to 10"; "DP12's error ... is 10 times smaller
  // than 12"; M14's error "is then 100 times smaller than DP12".
  EXPECT_GT(error_at(f3, "KL8", 1e5) / error_at(f3, "M8", 1e5), 300.0);
  expect_about(error_at(f3, "SS10", 1e5) / error_at(f3, "M10", 1e5), 100, "SS10/M10");
  expect_about(error_at(f3, "DP10", 1e5) / error_at(f3, "M10", 1e5), 1, "DP10/M10");
  expect_about(error_at(f3, "M12", 1e5) / error_at(f3, "DP12", 1e5), 10, "M12/DP12");
  // M14 beating DP12 "100 times" is not reproduced (measured 28 at N = 10^5; the report says so): only the
  // direction is asserted.
  EXPECT_LT(error_at(f3, "M14", 1e5), error_at(f3, "DP12", 1e5));
  // "The enveloping error curve is steeper than any fixed order integrator": the best order rises with N.
  auto best = [&](double n) {
    std::string m;
    double e = INFINITY;
    for (const char* o : {"M4", "M6", "M8", "M10", "M12", "M14", "M16"}) {
      const double x = error_at(f3, o, n);
      if (x < e) {
        e = x;
        m = o;
      }
    }
    return std::stoi(m.substr(1));
  };
  EXPECT_LT(best(std::pow(10.0, 3.5)), best(1e5));
}

/// IQR of `method` at step h in a Gurkan local-error CSV.
double iqr_at(const std::vector<std::map<std::string, std::string>>& rows, const std::string& method, double h) {
  for (const auto& r : rows)
    if (r.at("method") == method && std::abs(std::stod(r.at("h")) / h - 1) < 1e-9) return std::stod(r.at("iqr"));
  ADD_FAILURE() << "no row for " << method << " at h = " << h;
  return std::nan("");
}

std::vector<double> steps_of(const std::vector<std::map<std::string, std::string>>& rows) {
  std::set<double> hs;
  for (const auto& r : rows) hs.insert(std::stod(r.at("h")));
  return {hs.begin(), hs.end()};
}

void check_gurkan(const fs::path& out) {
  {
    // Gurkan, Table 4.3 (coefficients of H - Z in degree 6 and their norm), as printed: two significant digits
    // for X11, X16, X17, X19, X20 (real for Table 4.1's methods, purely imaginary for Table 4.2's), three for
    // the norm. The tool's published columns must be these; its computed values (17 digits) must round to
    // them: within half a unit of the last printed digit. The AC2 row is printed with the signs of AC2's
    // adjoint (its complex conjugate; test_bch, ReproducesGurkanTable43), so its terms are compared with the
    // signs reversed.
    struct Printed {
      std::vector<double> x;
      double norm;
      bool imaginary;
    };
    const std::map<std::string, Printed> table{{"AR1", {{-3.1e-3, 4.5e-4, 5.6e-3, 1.8e-5, -6.3e-5}, 6.44e-3, false}},
                                               {"AR2", {{5.0e-3, -3.1e-4, -5.7e-3, 1.5e-5, 2.5e-4}, 7.58e-3, false}},
                                               {"BR1", {{1.5e-4, 6.2e-5, -4.1e-4, 5.7e-5, 1.6e-4}, 4.71e-4, false}},
                                               {"BR2", {{-7.0e-5, 9.7e-4, 2.7e-4, 5.2e-4, 5.2e-4}, 1.25e-3, false}},
                                               {"BR3", {{3.5e-2, 1.9e-4, -3.5e-2, -3.0e-5, -1.0e-4}, 4.90e-2, false}},
                                               {"AC1", {{-2.5e-6, 7.3e-6, -5.0e-6, 8.3e-7, 4.2e-6}, 1.02e-5, true}},
                                               {"AC2", {{3.0e-6, -7.9e-6, 6.0e-6, -9.4e-7, -4.7e-6}, 1.15e-5, true}},
                                               {"BC1", {{1.2e-5, -1.3e-5, 8.4e-6, 2.2e-7, -4.2e-6}, 1.96e-5, true}},
                                               {"BC2", {{-4.1e-5, 4.9e-5, -1.2e-4, 7.7e-6, 5.0e-5}, 1.49e-4, true}}};
    const std::vector<std::string> terms{"X11", "X16", "X17", "X19", "X20"};
    auto half_unit = [](double printed, int digits) {
      return 0.5 * std::pow(10.0, std::floor(std::log10(std::abs(printed))) - digits + 1) * (1 + 1e-9);
    };
    const auto rows = read_csv(out / "gurkan-table4.3.csv");
    std::map<std::string, int> seen;
    for (const auto& r : rows) {
      const std::string m = r.at("method"), term = r.at("term");
      ASSERT_EQ(table.count(m), 1u) << m;
      const Printed& p = table.at(m);
      const double pre = std::stod(r.at("published_re")), pim = std::stod(r.at("published_im"));
      const double cre = std::stod(r.at("computed_re")), cim = std::stod(r.at("computed_im"));
      ++seen[m];
      if (term == "norm") {
        EXPECT_EQ(pre, p.norm) << m << ": the tool's published norm";
        EXPECT_NEAR(cre, p.norm, half_unit(p.norm, 3)) << m << " norm";
        continue;
      }
      const auto k = static_cast<std::size_t>(std::find(terms.begin(), terms.end(), term) - terms.begin());
      ASSERT_LT(k, terms.size()) << m << " " << term;
      const double want = p.x[k];
      EXPECT_EQ(p.imaginary ? pim : pre, want) << m << " " << term << ": the tool's published value";
      EXPECT_EQ(p.imaginary ? pre : pim, 0.0) << m << " " << term << ": the tool's published value";
      const double got = (m == "AC2" ? -1 : 1) * (p.imaginary ? cim : cre), other = p.imaginary ? cre : cim;
      EXPECT_NEAR(got, want, half_unit(want, 2)) << m << " " << term;
      EXPECT_LE(std::abs(other), 1e-9 * std::abs(got)) << m << " " << term;
    }
    EXPECT_EQ(seen.size(), table.size());
    for (const auto& [m, n] : seen) EXPECT_EQ(n, 6) << m;
  }
  {
    // Fig. 5.1 (two-body problem, e = 0.2): the interquartile range of the error made in one step, i.e. the
    // local error, of order p + 1 for a method of order p. Expected slopes against h: leapfrog 3, Y4 and
    // RKNb6 5, RKNa14 7, BR1 6; Chambers 5 and AC1 7, one more than their formal orders 3 and 5 because the
    // imaginary parts are dropped (sec. 5: "Chambers shows fourth order and method AC1 shows sixth order
    // behaviour"). The quick grid has three steps, h = 0.01, 10^-1.5, 0.1 periods; the slope between the two
    // smallest must lie within 0.35 of the expected one (measured: 3.00, 5.25, 4.97, 6.98, 6.03, 5.01, 6.98).
    const auto rows = read_csv(out / "gurkan-fig5.1.csv");
    const auto hs = steps_of(rows);
    ASSERT_EQ(hs.size(), 3u);
    const std::map<std::string, double> local_order{{"VV", 3},  {"Y4", 5},  {"RKNb6", 5},   {"RKNa14", 7},
                                                    {"BR1", 6}, {"AC1", 7}, {"Chambers", 5}};
    for (const auto& [m, p] : local_order) {
      const double slope = std::log(iqr_at(rows, m, hs[1]) / iqr_at(rows, m, hs[0])) / std::log(hs[1] / hs[0]);
      EXPECT_NEAR(slope, p, 0.35) << m;
    }
    // "RKNb6 outperforms a method of higher order, RKNbr1, down to machine accuracy level".
    for (double h : hs) {
      if (iqr_at(rows, "BR1", h) > 1e-13) {
        EXPECT_LT(iqr_at(rows, "RKNb6", h), iqr_at(rows, "BR1", h)) << h;
      }
    }
  }
  {
    // Fig. 5.2 caption: Triple jump "nearly coincides with Chambers for this problem" (the 400-body problem;
    // measured ratios 0.92 and 0.74).
    const auto rows = read_csv(out / "gurkan-fig5.2.csv");
    for (double h : steps_of(rows)) {
      expect_about(iqr_at(rows, "Y4", h) / iqr_at(rows, "Chambers", h), 1, "Y4/Chambers at h = " + std::to_string(h));
    }
  }
}

// One run of `reproduce all --quick` (CTest runs every TEST in its own process, so the checks share one TEST).
TEST(Reproduce, AllQuickWritesEveryFileAndTheClaimsInWordsHold) {
  const auto dir = fs::temp_directory_path() / ("nystrom-reproduce-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const fs::path out = dir / "out";
  const auto r = run("reproduce all --quick --out-dir " + out.string(), dir);
  ASSERT_EQ(r.code, 0) << r.err;
  {
    SCOPED_TRACE("files and report");
    check_files_and_report(out);
  }
  {
    SCOPED_TRACE("claims");
    check_claims(out);
  }
  {
    SCOPED_TRACE("chin-fig1 CSV");
    check_chin_fig1(out);
  }
  {
    SCOPED_TRACE("chin-fig2/3 CSV");
    check_chin_fig2_and_3(out);
  }
  {
    SCOPED_TRACE("gurkan CSV");
    check_gurkan(out);
  }
  if (!::testing::Test::HasFailure()) fs::remove_all(dir);
}

TEST(Reproduce, BadInputExitsWithStatus2) {
  const auto dir = fs::temp_directory_path() / ("nystrom-reproduce-bad-" + std::to_string(::getpid()));
  auto r = run("reproduce no-such-figure --out-dir " + (dir / "o").string(), dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("unknown target"), std::string::npos) << r.err;
  r = run("reproduce chin-fig1 --quick --quad float64 --out-dir " + (dir / "o").string(), dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--quad"), std::string::npos) << r.err;
  r = run("reproduce chin-fig1 --quick --report /nonexistent-folder/r.md --out-dir " + (dir / "o").string(), dir);
  EXPECT_EQ(r.code, 2);
  r = run("reproduce chin-fig1 --quick --threads -1 --out-dir " + (dir / "o").string(), dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--threads"), std::string::npos) << r.err;
  r = run("reproduce --quick --out-dir " + (dir / "o").string(), dir);  // no target
  EXPECT_EQ(r.code, 2);
  r = run("reproduce all --quick --no-such-option", dir);
  EXPECT_EQ(r.code, 2);
  // Nothing was computed or written by the refused runs.
  EXPECT_FALSE(fs::exists(dir / "o" / "summary.json"));
  fs::remove_all(dir);
}

}  // namespace
