// Observed order of convergence of EVERY method in the catalog, against its declared order.
//
// The methods are read from nystrom::catalog() at run time (one value-parameterised test per
// entry), so methods added to the catalog are covered without touching this file.
//
// Measurement (measure_order<T>: the real type T is a template parameter):
//   * planar Kepler (Chin eqs 35-36), e = 0.5, from the apocentre to t_end = 2.5, i.e. 0.4 of an orbit,
//     on the way in towards the pericentre (reached at t = pi). Short on purpose, and not a multiple
//     of the period (at whole periods the Kepler error can look one order higher, e.g. BR1 at e = 0.2).
//     Over longer times the error grows secularly (~ t h^(p+1)) while part of the order-p error stays
//     bounded, so the asymptotic range moves to ever smaller errors. Measured, long double, e = 0.3:
//     Gurkan's real fifth-order AR1 shows a slope of 5.99 from 1e-6 down to 1e-13 at t = 5 and 7
//     (two thirds of an orbit and more), but 5.00 at t = 1 and 2; A6 shows 6.2 at 1e-15 at t = 9.
//     At e = 0.5, t = 2.5 every catalog method settles within 0.02 of its order above 1e-14;
//   * error = max-norm of (q, v) - exact solution at t_end, computed in T;
//   * the number of steps N grows geometrically from 2 by r = 2 up to order 10, r = 10^(3/p) above
//     (one refinement gains about three decades, so several points fit into the asymptotic range);
//   * errors above 1e-3 are pre-asymptotic and not used. Errors below a floor end the refinement:
//     100 N eps(T) for round-off (measured: about 0.2..1 N eps for the MPE methods) and, for methods
//     with published decimal coefficients used as published, 100 * 10^-digits (the method is only that
//     consistent);
//   * refinement stops once the last three slopes agree within 0.05 and the error is below
//     sqrt(eps(T)), or when the next refinement would fall under the floor;
//   * the observed order is the slope log(e1/e2)/log(h1/h2) between the two smallest step sizes used;
//     the range counts as asymptotic when the last two slopes agree within 0.15 (slopes that still
//     jump, pre-asymptotic or round-off dominated, fail the test).
// Precision: long double up to order 6. From order 8 on, long double has little asymptotic range
// (measured: M12..M16 at e = 0.3 drop from 1e-9 to the round-off level, 1e-16, within a factor 2.5 in
// h, with slopes jumping between 4 and 21; M8 and KL8 settle only just above it), so orders >= 8 run
// in IEEE quadruple precision (nystrom::float128), as does any (real) method whose long double slopes
// do not settle. Decimal coefficient tables are refined to the working precision where their digits do
// not reach it (methods/refine.hpp); where they are used as published, their digits set a floor.
// Acceptance: |observed - declared| < 0.35. Complex-coefficient methods (run with complex state,
// imaginary parts dropped after every step) may show one order MORE than declared: for Gürkan's
// fifth-order methods and Chambers' third-order one the leading error term is purely imaginary and
// disappears with the imaginary parts (Gürkan, abstract and Fig 5.1: AC1 is formally 5th order but
// shows 6th). Only for complex methods is declared <= observed <= declared + 1 (each +-0.35)
// accepted; real methods must match their declared order.
// Adaptive methods are skipped by the order test; ToleranceProportionality (end of this file) runs each
// adaptive catalog entry and adaptive multi-product specifications at two tolerances instead.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <complex>
#include <cstdint>
#include <iomanip>
#include <iostream>
#include <limits>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "experiments/kepler.hpp"
#include "nystrom/methods/refine.hpp"
#include "nystrom/nystrom.hpp"
#include "support/catalog.hpp"

using namespace nystrom;
using test::catalog_names;
using test::find_in_catalog;
using test::param_name;

namespace {

struct OrderOptions {
  double ecc = 0.5;
  double t_end = 2.5;            // 0.4 of an orbit, before the pericentre (t = pi); see the top of the file
  long n_start = 2;              // first number of steps tried
  long n_max = 1L << 21;         // no run longer than this many steps
  double pre_asymptotic = 1e-3;  // errors above this are not used
  double settled = 0.05;         // stop once the last three slopes agree this well and err < sqrt(eps)
  double agree = 0.15;           // asymptotic: the last two slopes agree this well
  double floor_per_step = 100;   // round-off floor: floor_per_step * N * epsilon_of<T>() ...
  double floor_per_digit = 1e2;  // ... and floor_per_digit * 10^-published_digits (0: exact coefficients)
};

struct OrderPoint {
  long steps = 0;
  double h = 0;
  double error = 0;
};

struct OrderMeasurement {
  std::string precision;
  std::vector<OrderPoint> points;                              // the usable points, coarse to fine
  std::vector<OrderPoint> tried;                               // every run, for the log
  double observed = std::numeric_limits<double>::quiet_NaN();  // slope between the last two usable points
  bool asymptotic = false;                                     // the last two slopes agree within OrderOptions::agree
  std::string log() const {
    std::ostringstream os;
    os << std::setprecision(4) << "  in " << precision << ":\n";
    const OrderPoint* prev = nullptr;
    for (const auto& p : tried) {
      os << "  N=" << p.steps << " h=" << p.h << " err=" << p.error;
      if (prev && prev->error > 0 && p.error > 0)
        os << " slope=" << std::log(prev->error / p.error) / std::log(prev->h / p.h);
      os << "\n";
      prev = &p;
    }
    os << "  observed order " << observed << (asymptotic ? " (slopes settled)" : " (slopes NOT settled)");
    return os.str();
  }
};

/// Refinement ratio of the number of steps for a declared order p.
double refinement_ratio(int p) { return std::min(2.0, std::pow(10.0, 3.0 / std::max(p, 1))); }

/// Final-state error (max-norm over q and v) after n steps of size t_end/n, in real type T.
/// Complex methods run with complex state (as run_kepler does), imaginary parts dropped after each step.
template <class T>
T kepler_error(const MethodDef& def, const KeplerProblem<T>& prob, const T& t_end, long n) {
  const T h = t_end / T(n);
  const auto s0 = prob.initial_state();
  State<std::array<T, 2>> s;
  if (def.info.complex) {
    using C = std::complex<T>;
    auto integ = make_integrator<std::array<C, 2>>(def, KeplerForce{});
    auto sc = convert_state<std::array<C, 2>>(s0);
    integ.integrate(sc, h, n);
    s = convert_state<std::array<T, 2>>(sc);
  } else {
    auto integ = make_integrator<std::array<T, 2>>(def, KeplerForce{});
    s = s0;
    integ.integrate(s, h, n);
  }
  if (!all_finite(s.q) || !all_finite(s.v)) return T(std::numeric_limits<double>::infinity());
  const auto ex = prob.exact(h * T(n));
  using std::abs;
  T err(0);
  for (int i = 0; i < 2; ++i) {
    const T dq = abs(s.q[i] - ex.q[i]), dv = abs(s.v[i] - ex.v[i]);
    if (err < dq) err = dq;
    if (err < dv) err = dv;
  }
  return err;
}

/// Measures the observed order of `def` on Kepler in real type T (see the top of the file).
/// `order_hint` (the declared order) sets the refinement ratio and the stopping rule.
template <class T>
OrderMeasurement measure_order(const MethodDef& def, int order_hint, const OrderOptions& o = {}) {
  const KeplerProblem<T> prob(static_cast<T>(o.ecc));
  const T t_end = static_cast<T>(o.t_end);
  const double eps = as_double(epsilon_of<T>());
  const double deep = std::sqrt(eps);
  // Published digits limit the method only where they are used as published (not refined).
  const int digits = def.info.published_digits;
  const bool as_published = digits > 0 && published_digits_suffice(digits, scalar_traits<T>::bits());
  const double coef_floor = as_published ? o.floor_per_digit * std::pow(10.0, -digits) : 0;
  auto floor_at = [&](double n) { return std::max(o.floor_per_step * n * eps, coef_floor); };
  const double r = refinement_ratio(order_hint);
  OrderMeasurement m;
  m.precision = scalar_traits<T>::name();
  std::vector<double> slopes;
  double n_real = static_cast<double>(o.n_start);
  long last_n = 0;
  while (true) {
    const long n = std::max(last_n + 1, std::lround(n_real));
    if (n > o.n_max) break;
    last_n = n;
    n_real *= r;
    const double err = as_double(kepler_error<T>(def, prob, t_end, n));
    const OrderPoint p{n, o.t_end / static_cast<double>(n), err};
    m.tried.push_back(p);
    if (!std::isfinite(err) || err > o.pre_asymptotic) {
      m.points.clear();  // only an unbroken run of refinements counts
      slopes.clear();
      continue;
    }
    if (err < floor_at(static_cast<double>(n))) break;  // round-off dominated: not used
    m.points.push_back(p);
    const std::size_t k = m.points.size();
    if (k >= 2) {
      const auto& a = m.points[k - 2];
      slopes.push_back(std::log(a.error / p.error) / std::log(a.h / p.h));
      m.observed = slopes.back();
    }
    const std::size_t ns = slopes.size();
    auto settled_within = [&](double tol) {
      return ns >= 3 && std::abs(slopes[ns - 1] - slopes[ns - 2]) < tol &&
             std::abs(slopes[ns - 2] - slopes[ns - 3]) < tol;
    };
    m.asymptotic = ns >= 2 && std::abs(slopes[ns - 1] - slopes[ns - 2]) < o.agree;
    if (settled_within(o.settled) && err < deep) break;
    // The next refinement reduces the error by about r^order: stop before it crosses the floor.
    const double expected = std::max(static_cast<double>(order_hint), ns > 0 ? m.observed : 0.0);
    if (ns > 0 && err / std::pow(r, expected) < floor_at(static_cast<double>(n) * r)) break;
  }
  return m;
}

/// The measurement used for catalog entries: long double up to order 6 (complex methods always),
/// float128 from order 8, and float128 again when the long double slopes do not settle.
OrderMeasurement measure_catalog_order(const MethodDef& def) {
  if (def.info.complex) return measure_order<long double>(def, def.info.order);
  if (def.info.order >= 8) return measure_order<float128>(def, def.info.order);
  auto m = measure_order<long double>(def, def.info.order);
  if (!m.asymptotic) m = measure_order<float128>(def, def.info.order);
  return m;
}

constexpr double kOrderTolerance = 0.35;

/// The acceptance rule (see the top of the file).
bool order_matches(int declared, double observed, bool complex_method) {
  if (!std::isfinite(observed)) return false;
  if (complex_method) return observed > declared - kOrderTolerance && observed < declared + 1 + kOrderTolerance;
  return std::abs(observed - declared) < kOrderTolerance;
}

class ObservedOrder : public testing::TestWithParam<std::string> {};

}  // namespace

TEST_P(ObservedOrder, MatchesDeclaredOrder) {
  const MethodDef& def = find_in_catalog(GetParam());
  if (def.info.adaptive) GTEST_SKIP() << def.info.name << " is adaptive: its step-size control is tested separately";
  ASSERT_GT(def.info.order, 0) << def.info.name << " declares no order";
  const auto m = measure_catalog_order(def);
  RecordProperty("observed_order", std::to_string(m.observed));
  std::ostringstream line;
  line << "[ order    ] " << std::left << std::setw(16) << def.info.name << " declared " << std::setw(2)
       << def.info.order << "  observed " << std::fixed << std::setprecision(3) << m.observed << "  (" << m.precision
       << (def.info.complex ? ", complex" : "") << ")";
  if (def.info.complex && m.observed > def.info.order + 0.5) line << "  one order more: imaginary leading error term";
  std::cout << line.str() << std::endl;
  ASSERT_GE(m.points.size(), 2u) << def.info.name << ": fewer than two usable step sizes\n" << m.log();
  EXPECT_TRUE(m.asymptotic) << def.info.name << ": the slopes did not settle before the round-off floor\n" << m.log();
  EXPECT_TRUE(order_matches(def.info.order, m.observed, def.info.complex))
      << def.info.name << " declares order " << def.info.order << " but shows " << m.observed
      << (def.info.complex ? " (complex method: declared .. declared+1 accepted)" : "") << "\n"
      << m.log();
}

INSTANTIATE_TEST_SUITE_P(Catalog, ObservedOrder, testing::ValuesIn(catalog_names()), param_name);

// Specifications outside the catalog list: multi-product sequences on velocity Verlet (the catalog's
// M<2n> run on position Verlet) and a sequence that is not the natural one. Order 2n for n products.
TEST(ObservedOrderOutsideTheCatalog, MultiProductSpecifications) {
  for (const auto& [spec, order] : std::vector<std::pair<std::string, int>>{
           {"mpe-vv:1,2", 4}, {"mpe-vv:1,2,3", 6}, {"mpe-vv:1,2,3,4", 8}, {"mpe:1,2,4", 6}, {"mpe-vv:2,3,5", 6}}) {
    const MethodDef def = resolve_method(spec);
    ASSERT_EQ(def.info.order, order) << spec;
    const auto m = measure_catalog_order(def);
    std::cout << "[ order    ] " << std::left << std::setw(16) << spec << " declared " << order << "  observed "
              << std::fixed << std::setprecision(3) << m.observed << " (" << m.precision << ")" << std::endl;
    EXPECT_TRUE(m.asymptotic) << spec << "\n" << m.log();
    EXPECT_TRUE(order_matches(order, m.observed, false)) << spec << " shows " << m.observed << "\n" << m.log();
  }
}

// Adjoints (`adjoint:NAME`, the sub-steps reversed). The declared order of an adjoint is copied from its
// base; here it is measured instead. The adjoint of a method of order p has order p (Hairer, Lubich,
// Wanner, Geometric Numerical Integration, 2nd ed., Thm. II.3.1; Gürkan, Table 4.1 and 4.2 captions: "the
// adjoint methods are also valid"), so the expected orders below are the base methods' published orders,
// written out here, not read from the catalog. Non-symmetric real methods (AR1, BR2, BR3: the adjoint is
// another method; for AR1 and BR2 an adjoint that is not a true reversal is not even consistent), a
// symmetric one (KL8: the adjoint is the method itself), and complex ones (AC1, BC1: the adjoint is the
// complex conjugate; Chambers), with the acceptance rule of the catalog order test.
TEST(ObservedOrderOutsideTheCatalog, AdjointSpecifications) {
  for (const auto& [spec, order] : std::vector<std::pair<std::string, int>>{{"adjoint:AR1", 5},
                                                                            {"adjoint:BR2", 5},
                                                                            {"adjoint:BR3", 5},
                                                                            {"adjoint:KL8", 8},
                                                                            {"adjoint:AC1", 5},
                                                                            {"adjoint:BC1", 5},
                                                                            {"adjoint:Chambers", 3}}) {
    const MethodDef def = resolve_method(spec);
    ASSERT_EQ(def.info.order, order) << spec;
    const auto m = measure_catalog_order(def);
    std::cout << "[ order    ] " << std::left << std::setw(16) << spec << " declared " << order << "  observed "
              << std::fixed << std::setprecision(3) << m.observed << " (" << m.precision << ")" << std::endl;
    ASSERT_GE(m.points.size(), 2u) << spec << "\n" << m.log();
    EXPECT_TRUE(m.asymptotic) << spec << "\n" << m.log();
    EXPECT_TRUE(order_matches(order, m.observed, def.info.complex)) << spec << " shows " << m.observed << "\n"
                                                                    << m.log();
  }
}

// ---- the measurement can fail -----------------------------------------------------------------------

namespace {

/// Forest-Ruth (position-first) with the first drift lengthened by delta and the second shortened by
/// delta: still consistent (drifts and kicks each sum to 1), but no longer symmetric, so only first order.
MethodDef perturbed_forest_ruth(const std::string& delta) {
  MethodInfo info{.name = "FR-perturbed",
                  .family = "splitting",
                  .order = 4,
                  .symmetric = false,
                  .symplectic = true,
                  .source = "test",
                  .description = "Forest-Ruth with one drift perturbed",
                  .aliases = {}};
  MethodDef d{
      info, [delta] {
        const bigfloat theta = 1 / (2 - boost::multiprecision::cbrt(bigfloat(2)));
        const bigfloat half = big("1/2");
        const bigfloat dl = big(delta);
        return MethodData{scheme({drift(theta * half + dl), kick(theta), drift((1 - theta) * half - dl),
                                  kick(1 - 2 * theta), drift((1 - theta) * half), kick(theta), drift(theta * half)})};
      }};
  nystrom::detail::finalize_info(d);
  return d;
}

/// Albrecht's A6 with velocity weights B_2 += delta, B_4 -= delta: sum B_i = 1 still holds but
/// sum B_i c_i = 1/2 (the second-order condition) is off by -delta/2, so only first order.
MethodDef perturbed_a6(const std::string& delta) {
  MethodInfo info{.name = "A6-perturbed",
                  .family = "rkn",
                  .order = 6,
                  .symmetric = false,
                  .symplectic = false,
                  .source = "test",
                  .description = "A6 with two velocity weights perturbed",
                  .aliases = {}};
  MethodDef d{info, [delta] {
                auto t =
                    tableau({"0", "1/4", "1/2", "3/4", "1"},
                            {{}, {"1/32"}, {"-1/24", "4/24"}, {"3/32", "4/32", "2/32"}, {"0", "6/14", "-1/14", "2/14"}},
                            {"7/90", "24/90", "6/90", "8/90", "0"}, {"7/90", "32/90", "12/90", "32/90", "7/90"});
                t.B[1] += bigcomplex(big(delta));
                t.B[3] += bigcomplex(-big(delta));
                return MethodData{t};
              }};
  nystrom::detail::finalize_info(d);
  return d;
}

}  // namespace

// A first-order method never gets below sqrt(eps): cap its refinement (the slopes settle long before).
OrderOptions control_options() {
  OrderOptions o;
  o.n_max = 1L << 16;
  return o;
}

TEST(ObservedOrderControl, PerturbedForestRuthIsFirstOrder) {
  const MethodDef bad = perturbed_forest_ruth("1/100");
  const auto m = measure_order<long double>(bad, bad.info.order, control_options());
  std::cout << "[ order    ] FR-perturbed declared 4  observed " << m.observed << "\n";
  ASSERT_GE(m.points.size(), 2u) << m.log();
  EXPECT_TRUE(m.asymptotic) << m.log();
  EXPECT_NEAR(m.observed, 1.0, kOrderTolerance) << m.log();
  EXPECT_FALSE(order_matches(4, m.observed, false)) << m.log();
  // With the perturbation removed the same construction is fourth order again.
  const MethodDef good = perturbed_forest_ruth("0");
  const auto g = measure_order<long double>(good, 4);
  EXPECT_TRUE(order_matches(4, g.observed, false)) << g.log();
}

TEST(ObservedOrderControl, PerturbedAlbrechtIsFirstOrder) {
  const MethodDef bad = perturbed_a6("1/1000");
  const auto m = measure_order<long double>(bad, bad.info.order, control_options());
  std::cout << "[ order    ] A6-perturbed declared 6  observed " << m.observed << "\n";
  ASSERT_GE(m.points.size(), 2u) << m.log();
  EXPECT_NEAR(m.observed, 1.0, kOrderTolerance) << m.log();
  EXPECT_FALSE(order_matches(6, m.observed, false)) << m.log();
  const auto g = measure_order<long double>(perturbed_a6("0"), 6);  // unperturbed: sixth order again
  EXPECT_TRUE(order_matches(6, g.observed, false)) << g.log();
}

TEST(ObservedOrderControl, WrongDeclarationsAreRejectedBothWays) {
  // FR is fourth order: a declaration of 2 or 6 must not pass, nor may a real method pass with +1.
  const auto m = measure_order<long double>(find_in_catalog("FR"), 4);
  EXPECT_TRUE(order_matches(4, m.observed, false)) << m.log();
  EXPECT_FALSE(order_matches(2, m.observed, false));
  EXPECT_FALSE(order_matches(6, m.observed, false));
  EXPECT_FALSE(order_matches(3, m.observed, false));  // a real method showing declared+1 fails ...
  EXPECT_TRUE(order_matches(3, m.observed, true));    // ... only a complex one is allowed that
  EXPECT_FALSE(order_matches(2, m.observed, true));   // but not declared+2
}

TEST(ObservedOrderControl, MeasurementIsGenericInTheScalarType) {
  // The same measurement in double: a second-order method is far from the double round-off floor.
  const auto m = measure_order<double>(find_in_catalog("VV"), 2);
  EXPECT_TRUE(order_matches(2, m.observed, false)) << m.log();
}

// ---- adaptive methods: the error follows the tolerance ------------------------------------------------

namespace {

/// Every adaptive catalog entry, and adaptive multi-product specifications (resolved, not listed).
std::vector<std::string> adaptive_names() {
  std::vector<std::string> names;
  for (const auto& d : catalog())
    if (d.info.adaptive) names.push_back(d.info.name);
  for (const char* spec : {"M6-adaptive", "M10-adaptive", "M14-adaptive", "mpe-vv-adaptive:1,2,3,4"})
    names.push_back(spec);
  return names;
}

class ToleranceProportionality : public testing::TestWithParam<std::string> {};

}  // namespace

// The order test skips adaptive methods; here each one integrates Kepler e = 0.5 over one period in
// double at tol 1e-6 and 1e-9 (the controller's defaults). Every adaptive pair here propagates the
// solution of order p and controls an embedded one of order e = p - 2 (DP12(10); the multi-product pairs,
// engines/adaptive_mpe.hpp) or the order its general (RKNG) pair declares (Fine 4(3), 5(4); DOP853's stretched
// estimate from its weights of orders 5 and 3 behaves like an error of order 7). Under plain error-per-step
// control the pairs with e = p - 2 were measured to make a global error ~ tol^((p+1)/(e+1)) (DP12 tol^1.18, M6
// tol^1.4); their controller works to the tolerance tol_c = anchor (tol / anchor)^gamma with gamma = (e+1)/(p+1)
// (the method's tolerance_exponent and tolerance_anchor; engines/step_control.hpp, controlled_tolerance), so that
// the error follows tol itself, as it does for the pairs with e = p - 1 under plain control. The 1000x tighter
// tolerance then divides the error by about 1000. Accepted: within a factor 8 (1000^0.3) either way -- one period is
// 10-60 steps, whose number moves in integer jumps, and is short of the regime of the calibration (measured: DP12
// 2628, M10 132, M14 935, DOP853 372). This fails a controller that does not follow tol (a ratio of 1) and the
// uncalibrated exponents of the low orders (M4 tol^1.67); an embedded order off by one is checked directly
// (test_adaptive_mpe, EmbeddedEstimateHasItsOrder; test_adaptive_rkn, error_order), the proportionality over
// 1e-6..1e-15 on 100 orbits through the tool (test_adaptive_floor_cli). The error itself stays below tol (the
// controller aims at safety^(p-1) tol_c <= tol for the estimate, and local extrapolation propagates the more
// accurate solution) and above 0.003 tol_c (an estimator that overestimates by a power of h would spend far more
// forces for errors far below tol_c).
TEST_P(ToleranceProportionality, ErrorFollowsTheTolerance) {
  const MethodDef def = resolve_method(GetParam());
  ASSERT_TRUE(def.info.adaptive) << GetParam();
  const auto loose = run_kepler_adaptive<double>(def, 0.5, 1e-6, 1);
  const auto tight = run_kepler_adaptive<double>(def, 0.5, 1e-9, 1);
  std::cout << "[ tol      ] " << std::left << std::setw(24) << GetParam() << " error " << std::scientific
            << std::setprecision(2) << loose.position_error << " -> " << tight.position_error << "  forces "
            << loose.force_evals << " -> " << tight.force_evals << std::endl;
  const double p = def.info.order;
  // The embedded order e: p - 2, or what a general (RKNG) pair declares (Fine 4(3) and 5(4), DOP853's stretched
  // estimate 7), for which the exponent is p / (e + 1).
  double e = p - 2;
  {
    BigPrecision guard(128);
    const MethodData data = def.build();
    if (const auto* t = std::get_if<RknTableau<bigcomplex>>(&data); t && t->general())
      e = t->blow.empty() ? t->general_embedded_order : t->general_order - 1;  // DOP853's stretched estimate
  }
  // A pair whose estimate has the order of its propagated solution's own error (e = p - 1: DOP853's stretched
  // estimate, Fine's pairs) gains nothing from local extrapolation: its global error is the sum of the local
  // errors of its 30-200 steps, each held at the tolerance (measured 6 to 11 tol).
  const double bound = def.info.order == e + 1 ? 20 : 1;
  const double gamma = def.info.tolerance_exponent, anchor = def.info.tolerance_anchor;  // as the engine reads them
  const double loose_c = adaptive_detail::controlled_tolerance(1e-6, gamma, anchor);
  const double tight_c = adaptive_detail::controlled_tolerance(1e-9, gamma, anchor);
  EXPECT_LT(loose.position_error, bound * 1e-6);
  EXPECT_LT(tight.position_error, bound * 1e-9);
  EXPECT_GT(loose.position_error, 0.003 * loose_c);
  EXPECT_GT(tight.position_error, 0.003 * tight_c);
  const double ratio = loose.position_error / tight.position_error;
  EXPECT_GT(ratio, 1000.0 / 8);
  EXPECT_LT(ratio, 1000.0 * 8);
  EXPECT_GT(tight.force_evals, loose.force_evals);
}

INSTANTIATE_TEST_SUITE_P(Adaptive, ToleranceProportionality, testing::ValuesIn(adaptive_names()), param_name);
