// The round-off floor of the adaptive engines through `nystrom run` (Kepler, 100 periods, double): a sweep of
// four tolerances per decade from 1e-6 down to the tightest the engine accepts, for DP12-adaptive (embedded RKN
// pair) and M12-/M16-adaptive (multi-product expansion), at e = 0.5 and 0.9. Asserted:
//   * above the floor the final position error falls with the tolerance (over a decade: at least 2x);
//   * tolerance proportionality: error / tol, averaged over each decade of tolerances from 1e-6 to the tightest,
//     stays within one decade (the controller works to the method's calibrated tolerance, controlled_tolerance in
//     engines/step_control.hpp);
//   * at the four tightest tolerances the error stays within Brouwer's law for round-off: steps whose rounding
//     changes the energy by about eps at random make the relative energy error a random walk, eps sqrt(n) after
//     n steps, and the mean motion (proportional to |E|^(3/2)) drifts with it, so that the phase, and with it the
//     position on an orbit of size 1, is off by about A eps sqrt(N) T after N steps over a time T (Brouwer,
//     Astron. J. 56 (1951) 9); A = 1 for an RKN step, and sum |c_i| for the multi-product expansion, whose
//     combination sum c_i T_i multiplies the rounding of its products by up to that (26.4 for M12, 119 for M16;
//     Chin, Celest. Mech. Dyn. Astron. 106 (2010) 391, eq 15). An engine that adds its increments plainly or
//     accumulates t += h exceeds it (DP12-adaptive so at e = 0.5, tolerance 1.8e-14: 8.4e-12, bound 8.0e-12);
//   * at those tolerances the step count grows as tol^(-1/(p+1)), p the order of the error estimate (at most 1.5
//     times that from tolerance 1e-13): a step that shrinks into the noise of the estimate grows it much faster
//     (M16-adaptive before its estimate was floored at its round-off: 1762 steps at 1e-13, 5742 at 3.2e-15).
//   * every run's cost adds up: force evaluations = per step x (accepted + rejected) + 2 (the starting step), and
//     the JSON's precise_products is true exactly where the method's calibration puts the controlled tolerance at
//     1e4 eps or below (the multi-product methods; never an RKN pair).
// The tolerance below the tightest is refused with a one-line error. The tool is found through NYSTROM_BIN.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/cli_runner.hpp"

namespace {

using namespace cli_test;

struct Point {
  double tol, error;
  long steps, rejected = 0, force_evals = 0;
  bool precise_products = false;
};

std::string tol_text(double tol) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", tol);
  return buf;
}

// `command --tol 10^(-k/4) --json` for k = k0 (24: 1e-6) to k1, as long as the tool accepts the tolerance; the error
// from the JSON key error_key.
std::vector<Point> sweep_command(const std::string& command, const char* error_key, int k0, int k1) {
  std::vector<Point> pts;
  for (int k = k0; k <= k1; ++k) {
    const double tol = std::pow(10.0, -k / 4.0);
    const auto r = run(command + " --tol " + tol_text(tol) + " --json");
    if (r.code != 0) {
      // The first refused tolerance ends the sweep: a clear one-line usage error.
      EXPECT_EQ(r.code, 2) << command << " tol " << tol << ": " << r.err;
      EXPECT_NE(r.err.find("nystrom: error: "), std::string::npos) << r.err;
      EXPECT_NE(r.err.find("tolerance"), std::string::npos) << r.err;
      break;
    }
    const auto j = nlohmann::json::parse(r.out);
    pts.push_back({tol, j.at(error_key).get<double>(), j.at("steps").get<long>(), j.value("rejected", -1L),
                   j.value("force_evals", -1L), j.value("precise_products", false)});
  }
  return pts;
}

// Kepler over 100 periods from tolerance 10^(-k0/4) down to the tightest the tool accepts; extra: more options.
std::vector<Point> sweep(const std::string& method, double ecc, int k0 = 24, const std::string& extra = "") {
  return sweep_command("run --problem kepler --periods 100 --ecc " + tol_text(ecc) + " --method " + method + extra,
                       "position_error", k0, 80);
}

// sum |c_i| of the natural-sequence MPE of order 2n: c_i = prod_{j != i} i^2 / (i^2 - j^2).
double mpe_abs_sum(int n) {
  double sum = 0;
  for (int i = 1; i <= n; ++i) {
    double c = 1;
    for (int j = 1; j <= n; ++j)
      if (j != i) c *= static_cast<double>(i * i) / static_cast<double>(i * i - j * j);
    sum += std::abs(c);
  }
  return sum;
}

// The smallest and the largest of the decades' largest error / tol, over the decades of four tolerances from the
// first point down to the tolerance proportional_to (included).
struct ToleranceRatios {
  double lo = std::numeric_limits<double>::infinity(), hi = 0;
  int decades = 0;
};
ToleranceRatios decade_ratios(const std::vector<Point>& pts, double proportional_to) {
  ToleranceRatios r;
  for (std::size_t d = 0; 4 * d + 4 <= pts.size() && pts[4 * d + 3].tol >= proportional_to * (1 - 1e-9); ++d) {
    double worst = 0;
    for (std::size_t i = 4 * d; i < 4 * d + 4; ++i) worst = std::max(worst, pts[i].error / pts[i].tol);
    r.lo = std::min(r.lo, worst);
    r.hi = std::max(r.hi, worst);
    ++r.decades;
  }
  return r;
}

// What the cost and the arithmetic of an adaptive run follow from: the force evaluations per step, the family and the
// controller's calibration (tolerance exponent gamma and anchor). A catalog method's come from `nystrom methods
// --json`; M<p>-adaptive (a specification, not in the list) is the multi-product expansion of the natural sequence
// k_i = i, i = 1..p/2, over the symmetric base: sum k_i = n (n + 1) / 2 forces per step (the products share nothing),
// and an error estimate of order p - 2, so gamma = (p - 1) / (p + 1), with the default anchor 1e-15.
struct AdaptiveInfo {
  long per_step = 0;
  bool mpe = false;
  double gamma = 0, anchor = 0;
};
AdaptiveInfo adaptive_info(const std::string& method) {
  const auto r = run("methods " + method + " --json");
  EXPECT_EQ(r.code, 0) << r.err;
  const auto m = nlohmann::json::parse(r.out).at(0);
  EXPECT_EQ(m.at("name"), method);
  return {m.at("force_evals_per_step").get<long>(), m.at("family") == "mpe", m.at("tolerance_exponent").get<double>(),
          m.at("tolerance_anchor").get<double>()};
}

// The cost the controller decided and how the run added: every step, accepted or rejected, costs the method's force
// evaluations per step (per_step), and the starting step (Hairer's) two more. Returns the rejected steps of all runs.
long check_force_counts(const std::string& method, long per_step, const std::vector<Point>& pts) {
  long rejected = 0;
  for (const auto& q : pts) {
    EXPECT_GE(q.rejected, 0) << method << " tol " << q.tol;
    EXPECT_EQ(q.force_evals, per_step * (q.steps + q.rejected) + 2) << method << " tol " << q.tol;
    rejected += q.rejected;
  }
  return rejected;
}

// The force counts (above), and an adaptive multi-product run's products carry their own rounding
// (precise_products) exactly at the tolerances whose controlled tolerance anchor (tol / anchor)^gamma is at most
// 1e4 eps (M12-adaptive from 9.0e-12 down), an RKN pair's never.
void check_cost_and_products(const std::string& method, const std::vector<Point>& pts) {
  const AdaptiveInfo info = adaptive_info(method);
  const double tstar =
      info.anchor * std::pow(1e4 * std::numeric_limits<double>::epsilon() / info.anchor, 1 / info.gamma);
  for (const auto& q : pts)
    EXPECT_EQ(q.precise_products, info.mpe && q.tol <= tstar) << method << " tol " << q.tol << ", tol* " << tstar;
  EXPECT_GT(check_force_counts(method, info.per_step, pts), 0)
      << method << ": a sweep over Kepler's pericentres rejects some steps";
  EXPECT_EQ(pts.back().precise_products, info.mpe) << method << " at the tightest tolerance";
}

// amplification: A above; p: the order of the error estimate; falls: assert the fall above the floor;
// proportional_to: the tightest tolerance of the proportionality check (below it the rounding floor sets the error).
void check(const std::string& method, double ecc, double amplification, int p, bool falls = true,
           double proportional_to = 0) {
  const auto pts = sweep(method, ecc);
  ASSERT_GE(pts.size(), 30u) << method << ": the tool accepts tolerances down to about 1e-14 at least";
  check_cost_and_products(method, pts);
  const double eps = std::numeric_limits<double>::epsilon();
  const double span = 200 * std::numbers::pi;
  auto bound = [&](const Point& q) { return amplification * eps * std::sqrt(static_cast<double>(q.steps)) * span; };
  const Point* at13 = nullptr;  // the run at tolerance 1e-13
  for (const auto& q : pts) {
    std::printf("[ floor ] %-14s e %.1f tol %-11.4g error %.3e steps %ld (bound %.2e)\n", method.c_str(), ecc, q.tol,
                q.error, q.steps, bound(q));
    if (std::abs(q.tol / 1e-13 - 1) < 1e-6) at13 = &q;
  }
  ASSERT_NE(at13, nullptr);
  // Above the floor: the geometric mean of the errors over a decade of tolerances (four runs) falls at least 2x
  // from one decade to the next, from 1e-6 down to 1e-11 (a single run scatters up to 10x around its neighbours:
  // the phase errors of the steps partly cancel).
  auto decade_mean = [&](std::size_t d) {
    double sum = 0;
    for (std::size_t i = 4 * d; i < 4 * d + 4; ++i) sum += std::log(pts[i].error);
    return std::exp(sum / 4);
  };
  for (std::size_t d = 0; falls && d < 5; ++d)
    EXPECT_LT(decade_mean(d + 1), 0.5 * decade_mean(d)) << method << " e " << ecc << " decade from " << pts[4 * d].tol;
  // Tolerance proportionality: the largest error / tol of each decade of tolerances (the envelope: a run whose phase
  // errors happen to cancel lies below it) stays within one decade from 1e-6 down to proportional_to (the
  // controller works to the method's calibrated tolerance, engines/step_control.hpp controlled_tolerance; with tol
  // itself it climbed 1.8 decades for DP12 at e = 0.5 and M12 at e = 0.5 between 1e-15 and 1e-6).
  const ToleranceRatios r = decade_ratios(pts, proportional_to);
  std::printf("[ floor ] %-14s e %.1f largest error / tol per decade down to %.0e: %.2e .. %.2e\n", method.c_str(), ecc,
              proportional_to, r.lo, r.hi);
  EXPECT_GE(r.decades, 7) << method;
  EXPECT_LE(r.hi, 10 * r.lo) << method << " e " << ecc << ": error / tol within one decade";
  // At the four tightest accepted tolerances: within Brouwer's law, and no step collapse.
  for (std::size_t i = pts.size() - 4; i < pts.size(); ++i) {
    EXPECT_LE(pts[i].error, bound(pts[i])) << method << " e " << ecc << " tol " << pts[i].tol;
    const double growth = std::pow(1e-13 / pts[i].tol, 1.0 / (p + 1));
    EXPECT_LE(static_cast<double>(pts[i].steps), 1.5 * growth * static_cast<double>(at13->steps))
        << method << " e " << ecc << " tol " << pts[i].tol;
  }
}

}  // namespace

// DP12-adaptive follows the tolerance down to the tightest (its floor lies near 1e-12, within a decade of what
// truncation leaves there); the multi-product expansion's floor (sum |c_i| times the products' rounding) lies above
// its truncation below tolerance 1e-13, so its proportionality is checked down to 1e-13.
TEST(AdaptiveFloorCli, Dp12AdaptiveEccentricity05) { check("DP12-adaptive", 0.5, 1, 10); }
TEST(AdaptiveFloorCli, Dp12AdaptiveEccentricity09) { check("DP12-adaptive", 0.9, 1, 10); }
TEST(AdaptiveFloorCli, M12AdaptiveEccentricity05) { check("M12-adaptive", 0.5, mpe_abs_sum(6), 10, true, 1e-13); }
TEST(AdaptiveFloorCli, M12AdaptiveEccentricity09) { check("M12-adaptive", 0.9, mpe_abs_sum(6), 10, true, 1e-13); }
TEST(AdaptiveFloorCli, M16AdaptiveEccentricity05) { check("M16-adaptive", 0.5, mpe_abs_sum(8), 14, true, 1e-13); }
// Not asserted: the fall of M16-adaptive's error at e = 0.9 above the floor. Its truncation error scatters up to
// 400x between neighbouring tolerances there (Release build: 3.1e-8 at tolerance 3.2e-9, 1.2e-5 at 1e-9), so the
// mean over the decade from 1e-9 (1.2e-6) lies above that from 1e-8 (5.6e-7): a property of its step control
// near pericentre, not of round-off.
TEST(AdaptiveFloorCli, M16AdaptiveEccentricity09) { check("M16-adaptive", 0.9, mpe_abs_sum(8), 14, false, 1e-13); }

// Tolerance proportionality on the outer solar system (`--problem outer-solar-system`, 100 Jupiter periods, the
// error of Jupiter's position against the tool's long-double reference): the largest error / tol of each decade of
// tolerances from 1e-6 to 1e-13 stays within one decade, for DP12-adaptive and M12-adaptive (with tol itself:
// 0.9 and 1.7 decades over 1e-6..1e-15, in long double); each run's force evaluations are its accepted and rejected
// steps' (JSON `rejected`) plus the starting step's two.
TEST(AdaptiveFloorCli, OuterSolarSystemErrorFollowsTheTolerance) {
  long rejected = 0;  // over both sweeps (DP12-adaptive rejects a few steps, M12-adaptive none here)
  for (const std::string method : {"DP12-adaptive", "M12-adaptive"}) {
    const auto pts = sweep_command("run --problem outer-solar-system --years 1186 --h 100 --method " + method,
                                   "jupiter_position_error", 24, 51);
    ASSERT_EQ(pts.size(), 28u) << method << ": every tolerance from 1e-6 to 1.8e-13 accepted";
    for (const auto& q : pts)
      std::printf("[ oss   ] %-14s tol %-11.4g error %.3e steps %ld\n", method.c_str(), q.tol, q.error, q.steps);
    rejected += check_force_counts(method, adaptive_info(method).per_step, pts);
    const ToleranceRatios r = decade_ratios(pts, 1e-13);
    std::printf("[ oss   ] %-14s largest error / tol per decade: %.2e .. %.2e\n", method.c_str(), r.lo, r.hi);
    EXPECT_EQ(r.decades, 7) << method;
    EXPECT_LE(r.hi, 10 * r.lo) << method << ": error / tol within one decade";
    for (std::size_t i = 4; i < pts.size(); ++i) EXPECT_GT(pts[i].steps, pts[i - 4].steps) << method;
  }
  EXPECT_GT(rejected, 0) << "the force counts must be checked on runs with rejected steps too";
}

// With the compensated Kepler force (--force compensated: the force in double-word, CompensatedKeplerForce) the
// precise update of DP12-adaptive also runs with the exact weights and a compensated velocity sum, and accepts
// tolerances down to eps/2: at the four tightest the final position error stays at most 1.5e-13 (e = 0.5) and 2e-13
// (e = 0.9; measured 1.2e-13 and 9.5e-14), below half the plain force's floor at its own tightest four (9.0e-13,
// 9.4e-13), for at most 1.6 times its steps.
TEST(AdaptiveFloorCli, Dp12AdaptiveWithTheCompensatedForce) {
  for (double ecc : {0.5, 0.9}) {
    const auto plain = sweep("DP12-adaptive", ecc, 52);
    const auto comp = sweep("DP12-adaptive", ecc, 52, " --force compensated");
    ASSERT_GE(plain.size(), 4u);
    ASSERT_GE(comp.size(), 4u);
    EXPECT_LE(comp.back().tol, 2e-16) << "tolerances down to eps/2 are accepted";
    EXPECT_GT(plain.back().tol, 2e-15) << "the plain force stops at 10 eps";
    double worst_plain = 0, worst = 0;
    for (std::size_t i = plain.size() - 4; i < plain.size(); ++i) worst_plain = std::max(worst_plain, plain[i].error);
    for (std::size_t i = comp.size() - 4; i < comp.size(); ++i) {
      std::printf("[ floor ] DP12-adaptive --force compensated e %.1f tol %-11.4g error %.3e steps %ld\n", ecc,
                  comp[i].tol, comp[i].error, comp[i].steps);
      worst = std::max(worst, comp[i].error);
      EXPECT_LE(static_cast<double>(comp[i].steps), 1.6 * static_cast<double>(plain.back().steps));
    }
    std::printf("[ floor ] e %.1f: largest error at the four tightest tolerances %.3e (plain force %.3e)\n", ecc, worst,
                worst_plain);
    EXPECT_LE(worst, ecc < 0.7 ? 1.5e-13 : 2e-13) << ecc;
    EXPECT_LT(worst, 0.5 * worst_plain) << ecc;
  }
}

// With the compensated Kepler force the adaptive multi-product expansion runs its products' drifts and kicks in
// double-word (trial_carried, engines/adaptive_mpe_kernels.hpp) and accepts tolerances down to eps/2: the error keeps
// falling with the tolerance below the plain force's floor, and at the four tightest tolerances it stays at most
// 1.5e-13 / 1.6e-12 (M12-adaptive, e = 0.5 / 0.9; measured 6.5e-14 and 8.1e-13) and 1e-13 / 2e-12 (M16-adaptive;
// measured 4.5e-14 and 1.1e-12), a fifth of the plain force's floor or less; every step, accepted or rejected,
// costs the method's forces; the JSON's precise_products is true at every tolerance.
TEST(AdaptiveFloorCli, AdaptiveMpeWithTheCompensatedForce) {
  for (const std::string method : {"M12-adaptive", "M16-adaptive"}) {
    const AdaptiveInfo info = adaptive_info(method);
    for (double ecc : {0.5, 0.9}) {
      SCOPED_TRACE(method + " e " + tol_text(ecc));
      const auto plain = sweep(method, ecc, 52);
      const auto comp = sweep(method, ecc, 52, " --force compensated");
      ASSERT_GE(plain.size(), 4u);
      ASSERT_GE(comp.size(), 12u);
      EXPECT_LE(comp.back().tol, 2e-16) << "tolerances down to eps/2 are accepted";
      double worst_plain = 0, worst = 0;
      for (std::size_t i = plain.size() - 4; i < plain.size(); ++i) worst_plain = std::max(worst_plain, plain[i].error);
      for (std::size_t i = comp.size() - 4; i < comp.size(); ++i) worst = std::max(worst, comp[i].error);
      for (const auto& p : comp) {
        EXPECT_EQ(p.force_evals, info.per_step * (p.steps + p.rejected) + 2) << "tol " << p.tol;
        EXPECT_TRUE(p.precise_products) << "tol " << p.tol;
      }
      // Below the plain force's tightest tolerance the error still falls: over the last two decades, 10x at least.
      EXPECT_LT(comp.back().error, 0.1 * comp[comp.size() - 9].error);
      std::printf(
          "[ floor ] %s --force compensated e %.1f: largest error at the four tightest tolerances %.3e (plain "
          "force %.3e)\n",
          method.c_str(), ecc, worst, worst_plain);
      const bool m12 = method == "M12-adaptive";
      EXPECT_LE(worst, ecc < 0.7 ? (m12 ? 1.5e-13 : 1e-13) : (m12 ? 1.6e-12 : 2e-12));
      EXPECT_LT(worst, 0.2 * worst_plain);
    }
  }
}

// The compensated force is refused where nothing would use it, with a one-line usage error.
TEST(AdaptiveFloorCli, CompensatedForceIsRefusedWhereNothingUsesIt) {
  for (const std::string args :
       {"--method DP12 --steps-per-period 100", "--method DP12-adaptive --tol 1e-12 --precision long-double",
        "--problem harmonic --method DP12-adaptive --tol 1e-12", "--method DP12-adaptive --tol 1e-12 --force exact",
        "--method MPE-adaptive --tol 1e-12", "--method MPE-adaptive-max:8 --tol 1e-12",
        "--problem outer-solar-system --method SS10", "--problem arenstorf --method GBS --tol 1e-10",
        "--problem nbody --n 8 --method DP12 --steps 10"}) {
    const std::string force = args.find("--force") == std::string::npos ? " --force compensated" : "";
    const auto r = run("run " + args + force + " --json");
    EXPECT_EQ(r.code, 2) << args << ": " << r.err;
    EXPECT_NE(r.err.find("nystrom: error: "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("--force"), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
  // Without it, the tolerance floor of double stays at 10 eps.
  const auto r = run("run --method DP12-adaptive --tol 1e-15 --json");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("eps / 2 with a compensated force"), std::string::npos) << r.err;
}

namespace {

// The largest position error `run PROBLEM_ARGS --steps-per-period N --json` reports over the step counts spp with the
// compensated force, and with the plain force ({compensated, plain}); both runs name their force and evaluate it
// equally often.
std::pair<double, double> largest_errors(const std::string& problem_args, const std::vector<long>& spp) {
  double worst = 0, worst_plain = 0;
  for (long n : spp) {
    const std::string args = "run " + problem_args + " --steps-per-period " + std::to_string(n) + " --json";
    const auto p = run(args), q = run(args + " --force compensated");
    EXPECT_EQ(p.code, 0) << p.err;
    EXPECT_EQ(q.code, 0) << q.err;
    if (p.code != 0 || q.code != 0) return {1, 1};
    const auto jp = nlohmann::json::parse(p.out), jq = nlohmann::json::parse(q.out);
    EXPECT_EQ(jq.at("force").get<std::string>(), "compensated");
    EXPECT_EQ(jp.at("force").get<std::string>(), "plain");
    EXPECT_EQ(jq.at("force_evals").get<long>(), jp.at("force_evals").get<long>());
    worst = std::max(worst, jq.at("position_error").get<double>());
    worst_plain = std::max(worst_plain, jp.at("position_error").get<double>());
  }
  return {worst, worst_plain};
}

}  // namespace

// The fixed-step methods with the compensated force (--force compensated: compensated drifts and kicks in
// double-word with the force's rounding error, engines/splitting.hpp; the multi-product increments as double-words,
// engines/mpe.hpp): at step counts whose truncation lies below the double result's rounding, the largest reported
// error of SS10, KL8 and M8 stays at most 3e-14 (e = 0.5) and 1e-13 (e = 0.9) where the plain force's rounding
// leaves 1e-13 to 1e-12, for the same force evaluations.
TEST(AdaptiveFloorCli, FixedStepMethodsWithTheCompensatedForce) {
  struct Case {
    const char* method;
    double ecc;
    std::vector<long> spp;
  };
  for (const Case& c : {Case{"SS10", 0.5, {1131, 1345, 1600, 1903}}, Case{"SS10", 0.9, {2691, 3200, 3805, 4525}},
                        Case{"KL8", 0.5, {1131, 1345, 1600, 1903}}, Case{"KL8", 0.9, {5382, 6400, 7611, 9051}},
                        Case{"M8", 0.5, {1131, 1345, 1600, 1903}}, Case{"M8", 0.9, {12800, 15222, 18102, 21527}}}) {
    const auto [worst, worst_plain] =
        largest_errors("--problem kepler --periods 100 --ecc " + tol_text(c.ecc) + " --method " + c.method, c.spp);
    std::printf("[ floor ] %s --force compensated e %.1f: largest error %.3e over four step sizes (plain force %.3e)\n",
                c.method, c.ecc, worst, worst_plain);
    EXPECT_LE(worst, c.ecc < 0.7 ? 3e-14 : 1e-13) << c.method << " e " << c.ecc;
    EXPECT_LT(worst, 0.2 * worst_plain) << c.method << " e " << c.ecc;
  }
}

// The two-body problem as an N-body system with the compensated N-body force (--problem twobody --force
// compensated, CompensatedNBodyForce): SS10 and M8 over 10 periods end within 3e-16 of the exact relative orbit
// at step counts whose truncation lies below that, where the plain force's rounding leaves 1e-15 to 4e-14; the same
// force evaluations; the JSON names the force.
TEST(AdaptiveFloorCli, TwoBodyWithTheCompensatedNBodyForce) {
  for (const char* method : {"SS10", "M8"}) {
    const auto [worst, worst_plain] =
        largest_errors(std::string("--problem twobody --ecc 0.5 --periods 10 --method ") + method, {951, 1131, 1345});
    std::printf("[ floor ] twobody %s --force compensated: largest error %.3e (plain force %.3e)\n", method, worst,
                worst_plain);
    EXPECT_LE(worst, 3e-16) << method;
    EXPECT_LT(worst, 0.1 * worst_plain) << method;
  }
}
