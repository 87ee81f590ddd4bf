// The command-line contract of `run` through solve(): --output-times (dense output), --events, and
// --checkpoint/--restart (bitwise the same end), in text as in JSON; the step of an adaptive method is
// labelled as a mean. The tool is found through NYSTROM_BIN (set by CTest).
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/cli_runner.hpp"

#include "nystrom/problems/kepler.hpp"

namespace {

using namespace cli_test;

constexpr double pi = std::numbers::pi;

}  // namespace

TEST(CliSolve, OutputTimesComeFromTheDenseOutput) {
  const auto r =
      run("run --problem kepler --ecc 0.5 --method M8 --steps-per-period 200 --periods 2 --output-times 0:12.566:201 "
          "--json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  const auto& out = j.at("output");
  ASSERT_EQ(out.size(), 201u);
  EXPECT_EQ(out[0]["t"].get<double>(), 0.0);
  EXPECT_EQ(out[200]["t"].get<double>(), 12.566);
  const nystrom::KeplerProblem<double> kp(0.5);
  double worst = 0;
  for (const auto& p : out) {
    const double t = p["t"].get<double>();
    const auto ex = kp.exact(t);
    worst = std::max(worst, std::hypot(p["q"][0].get<double>() - ex.q[0], p["q"][1].get<double>() - ex.q[1]));
    EXPECT_NEAR(p["v"][0].get<double>(), ex.v[0], 1e-6);
  }
  // The output points are as accurate as the method: within 10x of its error at the end of the run (the
  // global error grows with time, and the last output time lies just before the end).
  const double end_err = j.at("position_error").get<double>();
  EXPECT_GT(end_err, 0.0);
  EXPECT_LE(worst, 10 * end_err) << "end of the run " << end_err;
  EXPECT_EQ(j.at("q").size(), 2u);
}

TEST(CliSolve, PericentreApocentreAndAxisCrossingEvents) {
  const auto r =
      run("run --problem kepler --ecc 0.9 --method DP12-adaptive --tol 1e-12 --periods 3 --events "
          "pericentre,apocentre,y=0 --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  std::vector<double> peri, apo, axis;
  for (const auto& e : j.at("events")) {
    const std::string n = e["name"];
    (n == "pericentre" ? peri : n == "apocentre" ? apo : axis).push_back(e["t"].get<double>());
    ASSERT_EQ(e["q"].size(), 2u);
    ASSERT_EQ(e["v"].size(), 2u);
  }
  ASSERT_EQ(peri.size(), 3u);
  // The method's accuracy, from the state at the end of the run (an apocentre, at 6 pi): the error of a
  // Kepler orbit is mostly a shift along it, whose time is dq / |v| there; it grows with time, so the
  // earlier passages are shifted less. A located pericentre lies within twice that shift of the analytic
  // time (plus a few ulps of t), and within the contract's 1e-12 relative.
  const nystrom::KeplerProblem<double> kp(0.9);
  const auto ex = kp.exact(6 * pi);
  const double dq = std::hypot(j["q"][0].get<double>() - ex.q[0], j["q"][1].get<double>() - ex.q[1]);
  const double dv = std::hypot(j["v"][0].get<double>() - ex.v[0], j["v"][1].get<double>() - ex.v[1]);
  const double va = std::hypot(ex.v[0], ex.v[1]), ra = std::hypot(ex.q[0], ex.q[1]);
  const double eps = std::numeric_limits<double>::epsilon();
  for (int i = 0; i < 3; ++i) {
    const double ts = (2 * i + 1) * pi;
    EXPECT_NEAR(peri[i], ts, 2 * dq / va + 8 * eps * ts);
    EXPECT_LE(std::abs(peri[i] - ts), 1e-12 * ts);
  }
  // 2 pi and 4 pi; 6 pi is the end of the span, where r.v = 0 up to rounding (found or not). At an
  // apocentre g = r.v moves by at most |v| dq + r dv with g' = |v|^2 - 1/r.
  ASSERT_GE(apo.size(), 2u);
  ASSERT_LE(apo.size(), 3u);
  const double gdot = std::abs(va * va - 1 / ra);
  for (int i = 0; i < 2; ++i) {
    const double ts = 2 * (i + 1) * pi;
    EXPECT_NEAR(apo[i], ts, 2 * (va * dq + ra * dv) / gdot + 8 * eps * ts);
  }
  // The x axis is crossed at every pericentre and apocentre.
  EXPECT_GE(axis.size(), 5u);
  EXPECT_LE(axis.size(), 6u);
  const auto only =
      run("run --problem kepler --ecc 0.9 --method DP12-adaptive --tol 1e-12 --periods 3 --events "
          "pericentre --json");
  ASSERT_EQ(only.code, 0) << only.err;
  EXPECT_EQ(nlohmann::json::parse(only.out).at("events").size(), 3u);
}

TEST(CliSolve, EventsAndOutputTimesKeepTheChosenOutputFormat) {
  const std::string args =
      "run --problem kepler --ecc 0.9 --method DP12-adaptive --tol 1e-12 --periods 3 --events pericentre";
  const auto text = run(args);
  const auto json = run(args + " --json");
  ASSERT_EQ(text.code, 0) << text.err;
  ASSERT_EQ(json.code, 0) << json.err;
  // Without --json: the table, then the events, one per line; no JSON.
  EXPECT_FALSE(nlohmann::json::accept(text.out)) << text.out;
  EXPECT_NE(text.out.find("method            DP12-adaptive"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("position error"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("events            3\n"), std::string::npos) << text.out;
  const std::regex line(R"(\n  pericentre +t = (\S+)  q = \((\S+), (\S+)\)  v = \((\S+), (\S+)\))");
  std::vector<std::vector<double>> listed;
  for (std::sregex_iterator it(text.out.begin(), text.out.end(), line), end; it != end; ++it)
    listed.push_back(
        {std::stod((*it)[1]), std::stod((*it)[2]), std::stod((*it)[3]), std::stod((*it)[4]), std::stod((*it)[5])});
  // With --json: the same events, the same numbers to the last bit.
  const auto j = nlohmann::json::parse(json.out);
  const auto& ev = j.at("events");
  ASSERT_EQ(ev.size(), 3u);
  ASSERT_EQ(listed.size(), 3u) << text.out;
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(ev[i]["name"], "pericentre");
    EXPECT_EQ(listed[i][0], ev[i]["t"].get<double>());
    EXPECT_EQ(listed[i][1], ev[i]["q"][0].get<double>());
    EXPECT_EQ(listed[i][2], ev[i]["q"][1].get<double>());
    EXPECT_EQ(listed[i][3], ev[i]["v"][0].get<double>());
    EXPECT_EQ(listed[i][4], ev[i]["v"][1].get<double>());
    EXPECT_NEAR(listed[i][0], (2 * static_cast<double>(i) + 1) * pi, 1e-9);
  }
  EXPECT_EQ(j.at("adaptive"), true);
  // Output times in text too: one line per time.
  const auto times =
      run("run --problem kepler --ecc 0.5 --method M8 --steps-per-period 200 --periods 2 --output-times 0:12:4");
  ASSERT_EQ(times.code, 0) << times.err;
  EXPECT_FALSE(nlohmann::json::accept(times.out)) << times.out;
  EXPECT_NE(times.out.find("output times      4\n  t = 0  q = (1.5, 0)"), std::string::npos) << times.out;
  EXPECT_NE(times.out.find("\n  t = 12  q = ("), std::string::npos) << times.out;
  EXPECT_NE(times.out.find("steps             400 (h = 0.0314159)"), std::string::npos) << times.out;
}

TEST(CliSolve, AdaptiveStepIsLabelledAsAMean) {
  // The table of an adaptive run gives the mean accepted step (span / steps), and says so; a fixed-step run
  // gives its step. JSON says which (`adaptive`).
  const std::regex mean(R"(\nsteps +(\d+) accepted(?:, \d+ rejected)? \(mean h = (\S+)\)\n)");
  for (const std::string m :
       {"--method DP12-adaptive --tol 1e-10", "--method GBS --tol 1e-10", "--method M10-adaptive --tol 1e-10"})
    for (const std::string extra : {"", " --events apocentre"}) {
      SCOPED_TRACE(m + extra);
      const auto r = run("run --problem kepler --ecc 0.5 --periods 2 " + m + extra);
      ASSERT_EQ(r.code, 0) << r.err;
      std::smatch s;
      ASSERT_TRUE(std::regex_search(r.out, s, mean)) << r.out;
      const double steps = std::stod(s[1]), h = std::stod(s[2]);
      EXPECT_GT(steps, 10);
      EXPECT_NEAR(h, 4 * pi / steps, 1e-5 * h);
      EXPECT_EQ(r.out.find("(h = "), std::string::npos) << r.out;
      const auto j =
          nlohmann::json::parse(run("run --problem kepler --ecc 0.5 --periods 2 " + m + extra + " --json").out);
      EXPECT_EQ(j.at("adaptive"), true);
      EXPECT_EQ(j.at("steps").get<double>(), steps);
    }
  const auto fixed = run("run --problem kepler --ecc 0.5 --periods 2 --method M8 --steps-per-period 100");
  ASSERT_EQ(fixed.code, 0) << fixed.err;
  EXPECT_NE(fixed.out.find("\nsteps             200 (h = 0.0628319)\n"), std::string::npos) << fixed.out;
  EXPECT_EQ(fixed.out.find("mean"), std::string::npos) << fixed.out;
  const auto jf = nlohmann::json::parse(
      run("run --problem kepler --ecc 0.5 --periods 2 --method M8 --steps-per-period 100 --json").out);
  EXPECT_EQ(jf.at("adaptive"), false);
}

TEST(CliSolve, RestartFromACheckpointEndsInBitwiseTheSameState) {
  const auto dir = temp_dir();
  for (const std::string m : {"--method M8 --steps-per-period 100", "--method DP12-adaptive --tol 1e-10",
                              "--method M12-adaptive --tol 1e-10", "--method GBS --tol 1e-10"}) {
    SCOPED_TRACE(m);
    const auto f = (dir / "state.ckpt").string();
    std::filesystem::remove(f);
    const std::string base = "run --problem kepler --ecc 0.6 " + m + " --periods 20 --json";
    const auto a = run(base + " --checkpoint " + f + " --checkpoint-at 31.4");
    ASSERT_EQ(a.code, 0) << a.err;
    ASSERT_TRUE(std::filesystem::exists(f));
    EXPECT_FALSE(std::filesystem::exists(f + ".tmp"));
    const auto b = run(base + " --restart " + f);
    ASSERT_EQ(b.code, 0) << b.err;
    const auto ja = nlohmann::json::parse(a.out), jb = nlohmann::json::parse(b.out);
    EXPECT_GE(ja.at("checkpoint_t").get<double>(), 31.4);
    for (const char* k : {"q", "v"})
      for (int i = 0; i < 2; ++i) EXPECT_EQ(ja.at(k)[i].get<double>(), jb.at(k)[i].get<double>()) << k << i;
    EXPECT_EQ(ja.at("steps"), jb.at("steps"));
    // Output times from the checkpoint on: the end is the same; one before the checkpoint is refused (the
    // restarted run has no state there).
    const auto c = run(base + " --restart " + f + " --output-times 40:" + ja.at("t").dump() + ":3");
    ASSERT_EQ(c.code, 0) << c.err;
    const auto jc = nlohmann::json::parse(c.out);
    EXPECT_EQ(jc.at("output").at(2).at("q"), ja.at("q"));
    EXPECT_EQ(jc.at("q"), ja.at("q"));
    const auto early = run(base + " --restart " + f + " --output-times 0:60:5");
    EXPECT_EQ(early.code, 2);
    EXPECT_NE(early.err.find("nystrom: error: output time 0 lies before the checkpoint's time 3"), std::string::npos)
        << early.err;
    // Another method, eccentricity or step count is refused with one clear error.
    const auto other = run("run --problem kepler --ecc 0.5 " + m + " --periods 20 --restart " + f);
    EXPECT_EQ(other.code, 2);
    EXPECT_NE(other.err.find("nystrom: error: "), std::string::npos) << other.err;
  }
  const auto missing =
      run("run --problem kepler --ecc 0.5 --method M8 --periods 2 --restart " + (dir / "none").string());
  EXPECT_EQ(missing.code, 2);
  std::ofstream(dir / "bad.ckpt") << "not a checkpoint\n";
  const auto bad =
      run("run --problem kepler --ecc 0.5 --method M8 --periods 2 --restart " + (dir / "bad.ckpt").string());
  EXPECT_EQ(bad.code, 2);
  const auto half = run("run --problem kepler --ecc 0.5 --method M8 --periods 2 --checkpoint-at 3");
  EXPECT_EQ(half.code, 2);
  const auto times = run("run --problem kepler --ecc 0.5 --method M8 --periods 2 --output-times 0:100:5");
  EXPECT_EQ(times.code, 2);
  const auto ev = run("run --problem kepler --ecc 0.5 --method M8 --periods 2 --events perihelion");
  EXPECT_EQ(ev.code, 2);
  std::filesystem::remove_all(dir);
}

TEST(CliSolve, PlainRunsAndRunsWithOutputTimesAreOneSolveBitwise) {
  // `run` reaches every method through solve(): a run with output times (partial steps on the side) ends in
  // bitwise the same state as the plain run, for fixed steps, an adaptive pair and GBS with its sequence.
  for (const std::string method : {"M8 --steps-per-period 500", "DP12-adaptive --tol 1e-11", "GBS:romberg --tol 1e-11",
                                   "Chambers --steps-per-period 800"}) {
    SCOPED_TRACE(method);
    const std::string base = "run --problem kepler --ecc 0.7 --periods 2 --json --method " + method;
    const auto plain = run(base), timed = run(base + " --output-times 0:3:4");
    ASSERT_EQ(plain.code, 0) << plain.err;
    ASSERT_EQ(timed.code, 0) << timed.err;
    const auto a = nlohmann::json::parse(plain.out), b = nlohmann::json::parse(timed.out);
    EXPECT_EQ(a.at("q"), b.at("q"));
    EXPECT_EQ(a.at("v"), b.at("v"));
    EXPECT_EQ(a.at("force_evals"), b.at("force_evals"));
    EXPECT_EQ(a.at("steps"), b.at("steps"));
    EXPECT_LT(a.at("position_error").get<double>(), 1e-6);
  }
  // the harmonic oscillator takes adaptive methods too, and GBS reports the order it can reach
  const auto h = run("run --problem harmonic --method DP12-adaptive --tol 1e-12 --periods 3 --json");
  ASSERT_EQ(h.code, 0) << h.err;
  EXPECT_LT(nlohmann::json::parse(h.out).at("position_error").get<double>(), 1e-10);
  const auto g = run("run --problem kepler --ecc 0.5 --method GBS:bulirsch:8 --tol 1e-10 --periods 1 --json");
  ASSERT_EQ(g.code, 0) << g.err;
  EXPECT_EQ(nlohmann::json::parse(g.out).at("order"), 16);
  EXPECT_EQ(nlohmann::json::parse(g.out).at("method"), "GBS:bulirsch:8");
  const auto bad = run("run --problem kepler --method GBS:fibonacci --tol 1e-10");
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("unknown step-number sequence 'fibonacci'"), std::string::npos) << bad.err;
}
