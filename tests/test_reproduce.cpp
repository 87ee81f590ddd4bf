// `nystrom reproduce all --quick`: every target writes its CSV, PNG and JSON, the report and summary.json,
// and the claims the papers make in words hold. The tool is found through NYSTROM_BIN (set by CTest).
// Besides the tool's own verdicts, the key comparisons are recomputed here from the CSV files.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

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

namespace {

namespace fs = std::filesystem;

std::string tool() {
  const char* b = std::getenv("NYSTROM_BIN");
  return b ? b : "nystrom";
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

struct Result {
  int code = -1;
  std::string out, err;
};

Result run(const std::string& args, const fs::path& dir) {
  fs::create_directories(dir);
  const auto out = dir / "stdout.txt", err = dir / "stderr.txt";
  const std::string cmd = tool() + " " + args + " >" + out.string() + " 2>" + err.string() + " </dev/null";
  const int status = std::system(cmd.c_str());
  Result r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

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
  // Signs as published (FR, A', M4 negative; N positive), M4 the smallest at e = 0.9.
  EXPECT_LT(eP("FR", 0.9), 0);
  EXPECT_GT(eP("N4", 0.9), 0);
  EXPECT_LT(eP("Aprime", 0.9), 0);
  EXPECT_LT(eP("M4", 0.9), 0);
  for (const char* m : {"FR", "N4", "Aprime"}) EXPECT_LT(std::abs(eP("M4", 0.9)), std::abs(eP(m, 0.9))) << m;
  // Steep growth with e: more than three decades from e = 0.4 to 0.9 for every method.
  for (const char* m : {"FR", "N4", "Aprime", "M4"}) EXPECT_GT(std::abs(eP(m, 0.9) / eP(m, 0.4)), 1e3) << m;
}

void check_chin_fig2_and_3(const fs::path& out) {
  const auto f2 = read_csv(out / "chin-fig2.csv");
  // At N = 1e5: KL6 better than Y6, both symplectic methods worse than the RKN methods A6 and M6.
  EXPECT_LT(error_at(f2, "KL6", 1e5), error_at(f2, "Y6", 1e5));
  for (const char* r : {"A6", "M6"}) {
    for (const char* s : {"KL6", "Y6"}) {
      EXPECT_LT(10 * error_at(f2, r, 1e5), error_at(f2, s, 1e5)) << r << " vs " << s;
    }
  }
  const auto f3 = read_csv(out / "chin-fig3.csv");
  // At N = 1e5: KL8 and SS10 far worse than M8 and M10; DP12 beats M12, and M14 beats DP12.
  EXPECT_LT(10 * error_at(f3, "M8", 1e5), error_at(f3, "KL8", 1e5));
  EXPECT_LT(10 * error_at(f3, "M10", 1e5), error_at(f3, "SS10", 1e5));
  EXPECT_LT(error_at(f3, "DP12", 1e5), error_at(f3, "M12", 1e5));
  EXPECT_LT(error_at(f3, "M14", 1e5), error_at(f3, "DP12", 1e5));
  // The best MPE order rises with N (the envelope is not a fixed order).
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
    // Table 4.3: every norm within one unit of the third printed digit; the complex methods' X_i purely imaginary,
    // the real methods' real; every |X_i| within one unit of the second printed digit.
    const auto rows = read_csv(out / "gurkan-table4.3.csv");
    std::set<std::string> methods;
    int norms = 0;
    for (const auto& r : rows) {
      methods.insert(r.at("method"));
      const double pre = std::stod(r.at("published_re")), pim = std::stod(r.at("published_im"));
      const double cre = std::stod(r.at("computed_re")), cim = std::stod(r.at("computed_im"));
      const double pub = pim != 0 ? pim : pre, got = pim != 0 ? cim : cre, other = pim != 0 ? cre : cim;
      const int digits = std::stoi(r.at("printed_digits"));
      const double unit = std::pow(10.0, std::floor(std::log10(std::abs(pub))) - digits + 1);
      EXPECT_LE(std::abs(std::abs(got) - std::abs(pub)), 1.5 * unit) << r.at("method") << " " << r.at("term");
      EXPECT_LE(std::abs(other), 1e-9 * std::abs(got)) << r.at("method") << " " << r.at("term");
      if (r.at("term") == "norm") {
        ++norms;
        EXPECT_LE(std::abs(got - pub), 1.5 * unit) << r.at("method");
      }
    }
    EXPECT_EQ(methods.size(), 9u);
    EXPECT_EQ(norms, 9);
  }
  {
    // Fig. 5.1: errors shrink with h; the optimized fourth-order RKNb6 beats the fifth-order RKNbr1 above the
    // rounding floor; Chambers (third order) and RKNac1 (fifth) decrease faster than their formal orders predict.
    const auto rows = read_csv(out / "gurkan-fig5.1.csv");
    const auto hs = steps_of(rows);
    ASSERT_GE(hs.size(), 2u);
    for (const char* m : {"VV", "Y4", "Chambers", "RKNb6", "RKNa14", "BR1", "AC1"})
      EXPECT_LT(iqr_at(rows, m, hs.front()), iqr_at(rows, m, hs.back())) << m;
    for (double h : hs) {
      if (iqr_at(rows, "BR1", h) > 1e-13) {
        EXPECT_LT(iqr_at(rows, "RKNb6", h), iqr_at(rows, "BR1", h)) << h;
      }
    }
    const double h0 = hs[hs.size() - 2], h1 = hs.back();
    const double slope_ch = std::log(iqr_at(rows, "Chambers", h1) / iqr_at(rows, "Chambers", h0)) / std::log(h1 / h0);
    EXPECT_GT(slope_ch, 4.5);  // local error O(h^{p+1}) with p = 4 > 3
    const double slope_vv = std::log(iqr_at(rows, "VV", h1) / iqr_at(rows, "VV", h0)) / std::log(h1 / h0);
    EXPECT_GT(slope_vv, 2.5);
    EXPECT_LT(slope_vv, 3.5);
  }
  {
    // Fig. 5.2: Triple jump nearly coincides with Chambers for the 400-body problem.
    const auto rows = read_csv(out / "gurkan-fig5.2.csv");
    for (double h : steps_of(rows)) {
      const double q = iqr_at(rows, "Y4", h) / iqr_at(rows, "Chambers", h);
      EXPECT_GT(q, 1.0 / 3) << h;
      EXPECT_LT(q, 3.0) << h;
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
