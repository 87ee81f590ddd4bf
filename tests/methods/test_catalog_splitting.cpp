// The splitting methods of the catalog built from published tables (compositions.hpp,
// blanes_moan2002.hpp, gurkan.hpp): consistency of the tables, the composition order conditions,
// observed orders on Kepler and on Hénon-Heiles, the complex methods with and without their
// imaginary parts, force counts, adjoints and the parametric specifications.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <complex>
#include <functional>
#include <string>
#include <vector>

#include <boost/numeric/odeint/stepper/runge_kutta_fehlberg78.hpp>

#include "nystrom/nystrom.hpp"

using namespace nystrom;

namespace {

using LD = long double;
using V2 = std::array<LD, 2>;

// The splitting methods of three publication headers: compositions (PV defaults, VV variants),
// Blanes-Moan, Gürkan (with Chambers).
const std::vector<std::string> kCompositions = {"Y4",   "Y6",   "KL6",   "KL8",   "SS10",
                                                "Y4-V", "Y6-V", "KL6-V", "KL8-V", "SS10-V"};
const std::vector<std::string> kBlanesMoan = {"RKNb6", "RKNa14"};
const std::vector<std::string> kGurkanReal = {"AR1", "AR2", "BR1", "BR2", "BR3"};
const std::vector<std::string> kGurkanComplex = {"AC1", "AC2", "BC1", "BC2", "AC1-6"};

std::vector<std::string> publication_splitting_methods() {
  std::vector<std::string> all;
  for (const auto* list : {&kCompositions, &kBlanesMoan, &kGurkanReal, &kGurkanComplex})
    all.insert(all.end(), list->begin(), list->end());
  all.push_back("Chambers");
  return all;
}

/// The normalized scheme of a method at `bits` of reference precision.
SplittingScheme<bigcomplex> scheme_of(const MethodDef& d, unsigned bits = 256) {
  BigPrecision guard(bits);
  const MethodData data = d.build();
  const auto* s = std::get_if<SplittingScheme<bigcomplex>>(&data);
  if (!s) throw std::invalid_argument(d.info.name + " is not a splitting method");
  return normalized(*s);
}

bigfloat cabs(const bigcomplex& z) { return boost::multiprecision::sqrt(z.re * z.re + z.im * z.im); }

/// Least-squares slope of log(err) against log(n): the observed order when h = T/n.
double fit_order(const std::vector<long>& ns, const std::vector<double>& errs) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const double m = static_cast<double>(ns.size());
  for (std::size_t i = 0; i < ns.size(); ++i) {
    const double x = std::log(static_cast<double>(ns[i])), y = -std::log(errs[i]);
    sx += x;
    sy += y;
    sxx += x * x;
    sxy += x * y;
  }
  return (m * sxy - sx * sy) / (m * sxx - sx * sx);
}

struct RunOut {
  V2 q;
  double imag_q = 0;  // |Im q| at the end (keep_complex runs)
};

/// n steps of size T/n in long double (complex long double for complex methods).
template <class F>
RunOut run_ld(const MethodDef& def, F force, const State<V2>& s0, LD T, long n, EngineOptions opt = {}) {
  const LD h = T / static_cast<LD>(n);
  RunOut out;
  if (def.info.complex) {
    using C = std::complex<LD>;
    auto integ = make_integrator<std::array<C, 2>>(def, force, opt);
    auto sc = convert_state<std::array<C, 2>>(s0);
    integ.integrate(sc, h, n);
    out.q = {sc.q[0].real(), sc.q[1].real()};
    out.imag_q = static_cast<double>(std::hypot(sc.q[0].imag(), sc.q[1].imag()));
  } else {
    auto integ = make_integrator<V2>(def, force, opt);
    State<V2> s = s0;
    integ.integrate(s, h, n);
    out.q = s.q;
  }
  return out;
}

double dist(const V2& a, const V2& b) { return static_cast<double>(std::hypot(a[0] - b[0], a[1] - b[1])); }

// Kepler at a final time that is not a multiple of the period (see test_order.cpp): 1.37 periods.
constexpr LD kPeriods = 1.37L;

double kepler_error(const MethodDef& def, double e, long n, EngineOptions opt = {}, double* imag = nullptr) {
  const KeplerProblem<LD> prob(static_cast<LD>(e));
  const LD T = KeplerProblem<LD>::period() * kPeriods;
  const RunOut r = run_ld(def, KeplerForce{}, prob.initial_state(), T, n, opt);
  if (imag) *imag = r.imag_q;
  return dist(r.q, prob.exact(T).q);
}

double kepler_order(const MethodDef& def, double e, const std::vector<long>& ns) {
  std::vector<double> errs;
  for (long n : ns) errs.push_back(kepler_error(def, e, n));
  return fit_order(ns, errs);
}

// Hénon-Heiles, a = (-x - 2xy, -y - x^2 + y^2): a problem without the symmetries of Kepler (on Kepler,
// the fifth-order term of the real Gürkan methods does not show; see below). Polynomial, so it
// works for complex states too. Reference: independent of the library (see henon_heiles_reference).
struct HenonHeilesForce {
  template <class S>
  void operator()(const std::array<S, 2>& q, std::array<S, 2>& a) const {
    a[0] = -q[0] - S(2) * q[0] * q[1];
    a[1] = -q[1] - q[0] * q[0] + q[1] * q[1];
  }
};
const State<V2> kHenonHeilesStart{{0.3L, 0.1L}, {0.05L, 0.2L}};
constexpr LD kHenonHeilesTime = 10.0L;

/// Boost.Odeint's Runge-Kutta-Fehlberg 7(8), another family of methods in another code, on the first-order
/// system (x, y, vx, vy), 20000 fixed steps in long double: h = 5e-4, local errors ~ h^9, far below the
/// long double rounding that limits the result.
const V2& henon_heiles_reference() {
  static const V2 ref = [] {
    using X = std::array<LD, 4>;
    X x{kHenonHeilesStart.q[0], kHenonHeilesStart.q[1], kHenonHeilesStart.v[0], kHenonHeilesStart.v[1]};
    boost::numeric::odeint::runge_kutta_fehlberg78<X, LD, X, LD> rk;
    auto rhs = [](const X& s, X& d, LD) {
      d[0] = s[2];
      d[1] = s[3];
      d[2] = -s[0] - 2 * s[0] * s[1];
      d[3] = -s[1] - s[0] * s[0] + s[1] * s[1];
    };
    const long n = 20000;
    const LD h = kHenonHeilesTime / n;
    for (long i = 0; i < n; ++i) rk.do_step(rhs, x, h * static_cast<LD>(i), h);
    return V2{x[0], x[1]};
  }();
  return ref;
}

double henon_heiles_order(const MethodDef& def, const std::vector<long>& ns) {
  std::vector<double> errs;
  for (long n : ns)
    errs.push_back(
        dist(run_ld(def, HenonHeilesForce{}, kHenonHeilesStart, kHenonHeilesTime, n).q, henon_heiles_reference()));
  return fit_order(ns, errs);
}

/// The method with the roles of drift and kick exchanged.
MethodDef swapped(const MethodDef& d) {
  MethodDef s = d;
  s.info.name = "swapped:" + d.info.name;
  // A deliberately wrong method: run its digits as they are. (Refining a decimal table to a wider type
  // solves the method's own order conditions, which the swapped table does not satisfy.)
  s.info.published_digits = 0;
  auto build = d.build;
  s.build = [build] {
    auto sc = std::get<SplittingScheme<bigcomplex>>(build());
    for (auto& st : sc.steps) st.flow = st.flow == Flow::drift ? Flow::kick : Flow::drift;
    return MethodData{sc};
  };
  return s;
}

// ---- the composition order checker -------------------------------------------------------------
//
// A splitting scheme is applied to the linear system y' = (A + B) y with generic (random,
// non-commuting) 4x4 matrices A and B: drift c = exp(c h A), kick c = exp(c h B), in high precision.
// Generic matrices satisfy no Lie identity of low degree, so the local error
// ||Psi_h - exp(h (A+B))|| = D h^{p+1} + O(h^{p+2}) measures the order p of the scheme as a general
// splitting, i.e. for compositions of a symmetric second-order method, all composition order
// conditions (HLW (2006) Sec. V.3) at once. We check that the observed local order is p + 1 and that
// the defect D at order p + 1 is nonzero.

using Mat = std::vector<bigfloat>;  // 4x4, row major
constexpr int kDim = 4;

Mat mat_mul(const Mat& a, const Mat& b) {
  Mat c(kDim * kDim, bigfloat(0));
  for (int i = 0; i < kDim; ++i)
    for (int k = 0; k < kDim; ++k) {
      const bigfloat& aik = a[i * kDim + k];
      for (int j = 0; j < kDim; ++j) c[i * kDim + j] += aik * b[k * kDim + j];
    }
  return c;
}
Mat identity() {
  Mat m(kDim * kDim, bigfloat(0));
  for (int i = 0; i < kDim; ++i) m[i * kDim + i] = 1;
  return m;
}
bigfloat max_abs(const Mat& m) {
  bigfloat x = 0;
  for (const auto& v : m) x = std::max(x, bigfloat(abs(v)));
  return x;
}
/// exp(s X) by its Taylor series (s |X| is small here), to the working precision.
Mat expm(const Mat& X, const bigfloat& s) {
  const bigfloat tiny =
      boost::multiprecision::ldexp(bigfloat(1), -static_cast<int>(bigfloat::default_precision() * 3.33) - 8);
  Mat result = identity(), term = identity();
  for (int k = 1; k < 400; ++k) {
    term = mat_mul(term, X);
    for (auto& v : term) v *= s / k;
    for (int i = 0; i < kDim * kDim; ++i) result[i] += term[i];
    if (max_abs(term) < tiny) break;
  }
  return result;
}
/// Deterministic "random" matrix entries in [-1, 1].
Mat generic_matrix(unsigned seed) {
  Mat m(kDim * kDim);
  unsigned long x = seed;
  for (auto& v : m) {
    x = (x * 6364136223846793005UL + 1442695040888963407UL);
    v = bigfloat(static_cast<long>((x >> 33) % 2001) - 1000) / 1000;
  }
  return m;
}

/// max |Psi_h - exp(h(sA A + sB B))| for a real splitting scheme, where sA and sB are the sums of its
/// drift and kick coefficients (1 up to the rounding of the last published digit, <= 3e-26 for the
/// 26-digit tables: that first-order defect would otherwise hide the order at small h; the sums are
/// checked on their own in DriftsAndKicksEachSumToOne).
bigfloat local_error(const SplittingScheme<bigcomplex>& s, const bigfloat& h) {
  static const Mat A = generic_matrix(12345), B = generic_matrix(67890);
  bigfloat sa = 0, sb = 0;
  for (const auto& st : s.steps) (st.flow == Flow::drift ? sa : sb) += st.coef.re;
  Mat AB(kDim * kDim);
  for (int i = 0; i < kDim * kDim; ++i) AB[i] = sa * A[i] + sb * B[i];
  Mat psi = identity();
  for (const auto& st : s.steps) psi = mat_mul(expm(st.flow == Flow::drift ? A : B, st.coef.re * h), psi);
  const Mat ex = expm(AB, h);
  for (int i = 0; i < kDim * kDim; ++i) psi[i] -= ex[i];
  return max_abs(psi);
}

struct LocalOrder {
  double order;   // log2(e(h)/e(h/2)): the local order p + 1
  double defect;  // e(h/2) / (h/2)^{p+1}
};
LocalOrder local_order(const SplittingScheme<bigcomplex>& s, int p, const bigfloat& h) {
  const bigfloat e1 = local_error(s, h), e2 = local_error(s, h / 2);
  const double order = static_cast<double>(boost::multiprecision::log2(e1 / e2));
  const double defect = static_cast<double>(e2 / boost::multiprecision::pow(h / 2, p + 1));
  return {order, defect};
}

/// The composition weights of a symmetric composition of a symmetric leapfrog, read back from a
/// PV-based scheme: the kicks of position-first leapfrogs are the weights themselves.
std::vector<bigfloat> kick_weights(const SplittingScheme<bigcomplex>& s) {
  std::vector<bigfloat> w;
  for (const auto& st : s.steps)
    if (st.flow == Flow::kick) w.push_back(st.coef.re);
  return w;
}

}  // namespace

// ---- registration and names ---------------------------------------------------------------------

TEST(CatalogSplitting, PublicationSplittingMethodsAreRegisteredWithTheirSources) {
  for (const auto& name : publication_splitting_methods()) {
    const MethodDef d = resolve_method(name);
    EXPECT_EQ(d.info.name, name);
    EXPECT_FALSE(d.info.source.empty()) << name;
    EXPECT_TRUE(std::holds_alternative<SplittingScheme<bigcomplex>>(d.build())) << name;
  }
  // Gürkan's figure labels and the published names resolve to the same entries.
  const std::vector<std::pair<std::string, std::string>> aliases = {
      {"RKNar1", "AR1"},   {"RKNar2", "AR2"},    {"RKNbr1", "BR1"},     {"RKNbr2", "BR2"},
      {"RKNbr3", "BR3"},   {"RKNac1", "AC1"},    {"RKNac2", "AC2"},     {"RKNbc1", "BC1"},
      {"RKNbc2", "BC2"},   {"SRKN6b", "RKNb6"},  {"SRKN14a", "RKNa14"}, {"s9odr6a", "KL6"},
      {"s17odr8a", "KL8"}, {"SofSpa10", "SS10"}, {"yoshida6", "Y6"},    {"rknac1-6", "AC1-6"}};
  for (const auto& [alias, name] : aliases) EXPECT_EQ(resolve_method(alias).info.name, name) << alias;
  // The complex ones are recognised as complex, the others not.
  for (const auto& n : kGurkanComplex) EXPECT_TRUE(resolve_method(n).info.complex) << n;
  EXPECT_TRUE(resolve_method("Chambers").info.complex);
  for (const auto* list : {&kCompositions, &kBlanesMoan, &kGurkanReal})
    for (const auto& n : *list) EXPECT_FALSE(resolve_method(n).info.complex) << n;
}

// ---- table consistency --------------------------------------------------------------------------

TEST(CatalogSplitting, DriftsAndKicksEachSumToOne) {
  // Every splitting method of the catalog: sum of drift = sum of kick coefficients = 1, exactly for
  // exact tables (rationals, closed forms: to 1e-70 at 256 bits), to the published digits otherwise.
  int checked = 0;
  for (const auto& d : catalog()) {
    if (!std::holds_alternative<SplittingScheme<bigcomplex>>(d.build())) continue;
    BigPrecision guard(256);
    const auto s = scheme_of(d);
    bigcomplex sd, sk;
    bigfloat biggest = 1;
    int terms = 0;
    for (const auto& st : s.steps) {
      (st.flow == Flow::drift ? sd : sk) += st.coef;
      biggest = std::max(biggest, cabs(st.coef));
      ++terms;
    }
    const bigfloat tol = d.info.published_digits == 0
                             ? bigfloat("1e-70")
                             : terms * biggest * boost::multiprecision::pow(bigfloat(10), -d.info.published_digits);
    EXPECT_LT(cabs(sd - bigcomplex(bigfloat(1))), tol) << d.info.name << " drifts";
    EXPECT_LT(cabs(sk - bigcomplex(bigfloat(1))), tol) << d.info.name << " kicks";
    ++checked;
  }
  EXPECT_GE(checked, static_cast<int>(publication_splitting_methods().size()) + 4);  // + VV, PV, FR, FR-V
}

TEST(CatalogSplitting, SymmetricFlagMatchesPalindromes) {
  for (const auto& d : catalog()) {
    if (!std::holds_alternative<SplittingScheme<bigcomplex>>(d.build())) continue;
    const auto s = scheme_of(d);
    const auto r = adjoint(s);
    bool palindrome = true;
    for (std::size_t i = 0; i < s.steps.size(); ++i)
      palindrome = palindrome && s.steps[i].flow == r.steps[i].flow &&
                   cabs(s.steps[i].coef - r.steps[i].coef) < bigfloat("1e-70");
    EXPECT_EQ(palindrome, d.info.symmetric) << d.info.name;
  }
}

// Gürkan, Table 4.2, as printed: the first half of each skew-symmetric method (real and imaginary parts),
// the flow printed in full (three coefficients) first. For AC1/AC2 (RKNA) these are alpha_1..3 (drifts),
// then beta_1..2 (kicks); for BC1/BC2 (RKNB) beta_1..3 (kicks), then alpha_1..2 (drifts).
struct PrintedSkewMethod {
  std::string name;
  std::vector<std::pair<std::string, std::string>> full;  // three printed coefficients of the flow printed in full
  std::vector<std::pair<std::string, std::string>> half;  // two printed coefficients of the other flow
};
const std::vector<PrintedSkewMethod> kTable42{
    {"AC1",
     {{"0.087808410045663212", "0.028523844251341822"},
      {"0.17916539354193987", "-0.067857083007249973"},
      {"0.23302619641239692", "-0.097952003128893425"}},
     {{"0.17526734338348050", "0.057642040076250593"}, {"0.18488007701471166", "-0.19410647329733509"}}},
    {"AC2",
     {{"0.087634204536037057", "0.028807372065269351"},
      {"0.18007104463252914", "-0.068253589313355443"},
      {"0.23229475083143381", "-0.097060961378624794"}},
     {{"0.17526840907207411", "0.057614744130538702"}, {"0.18487368019298416", "-0.19412192275724959"}}},
    {"BC1",
     {{"0.093106790861751605", "-0.026812950639104607"},
      {"0.14578332225686154", "0.076033669531385746"},
      {"0.26110988688138685", "0.10851236434561279"}},
     {{"0.15950063058390336", "-0.060127448366782494"}, {"0.19085044206705213", "0.20369642527600502"}}},
    {"BC2",
     {{"0.10625796854753310", "-0.037213537431233983"},
      {"0.35767992721948460", "-0.022169204268009056"},
      {"0.036062104232982296", "0.057072185585748646"}},
     {{"0.26934942679787788", "-0.093675141997563700"}, {"0.14580813747862993", "0.49930185549019606"}}}};

/// Half a unit of the last printed digit of a decimal string ("0.0123" -> 5e-5).
double half_unit(const std::string& s) {
  const auto dot = s.find('.');
  const int decimals = dot == std::string::npos ? 0 : static_cast<int>(s.size() - dot - 1);
  return 0.5 * std::pow(10.0, -decimals);
}

/// `c` agrees with the printed (re, im) within half a unit of each printed last digit.
void expect_rounds_to(const bigcomplex& c, const std::pair<std::string, std::string>& printed,
                      const std::string& name) {
  EXPECT_LE(std::abs(static_cast<double>(c.re - big(printed.first))), half_unit(printed.first))
      << name << " " << printed.first;
  EXPECT_LE(std::abs(static_cast<double>(c.im - big(printed.second))), half_unit(printed.second))
      << name << " " << printed.second;
}

TEST(CatalogSplitting, PublishedSkewSymmetricTablesSatisfyTheirSumRule) {
  // Table 4.2 prints half of each method; the caption says the rest follows from skew-symmetry (reversing
  // the list gives the complex conjugates) and sum(alpha) = sum(beta) = 1. For the flow printed in full
  // (six sub-steps: x1, x2, x3, conj x3, conj x2, conj x1) these two together say 2 Re(x1 + x2 + x3) = 1,
  // a relation between the printed numbers themselves, checked here on the paper's digits (copied below
  // from the paper, not from the catalog), so it holds or fails whatever the catalog builds. The bound
  // is twice the sum of half a unit of each printed last digit (measured: 4e-18 to 1.4e-17 against
  // bounds of 2.1e-17 to 2.2e-17); a misprint beyond the 16th digit or a miscopied digit fails it.
  for (const auto& m : kTable42) {
    BigPrecision guard(256);
    bigfloat re_sum(0);
    double bound = 0;
    for (const auto& [re, im] : m.full) {
      re_sum += big(re);
      bound += 2 * half_unit(re);
    }
    EXPECT_LT(static_cast<double>(boost::multiprecision::abs(2 * re_sum - 1)), bound) << m.name;
  }
  // The catalog's coefficients are the printed ones, in time order (RKNA: drift alpha_1, kick beta_1, ...;
  // RKNB: kick beta_1, drift alpha_1, ...): refined to the working precision (methods/refine.hpp), they
  // still round to the printed digits (real and imaginary parts within half a unit of the last one). The
  // second half is the reversed conjugates, and the central coefficient of the other flow is real and
  // equal to 1 - 2 Re(first two).
  for (const auto& m : kTable42) {
    const auto s = scheme_of(resolve_method(m.name));
    ASSERT_EQ(s.steps.size(), 11u) << m.name;
    const Flow full_flow = m.name[0] == 'A' ? Flow::drift : Flow::kick;
    for (std::size_t i = 0; i < 3; ++i) {
      const auto& st = s.steps[2 * i];
      const auto& mirror = s.steps[10 - 2 * i];
      EXPECT_EQ(st.flow, full_flow) << m.name;
      expect_rounds_to(st.coef, m.full[i], m.name);
      EXPECT_LT(cabs(mirror.coef - st.coef.conj()), bigfloat("1e-60")) << m.name << " " << i;
    }
    bigfloat half_sum(0);
    for (std::size_t i = 0; i < 2; ++i) {
      const auto& st = s.steps[2 * i + 1];
      EXPECT_NE(st.flow, full_flow) << m.name;
      expect_rounds_to(st.coef, m.half[i], m.name);
      EXPECT_LT(cabs(s.steps[9 - 2 * i].coef - st.coef.conj()), bigfloat("1e-60")) << m.name << " " << i;
      half_sum += st.coef.re;
    }
    EXPECT_LT(cabs(s.steps[5].coef - bigcomplex(1 - 2 * half_sum)), bigfloat("1e-60")) << m.name;
  }
  // The reconstructed central coefficients agree with the authors' program (testing/
  // err_check_dynamics_integrator.c): AC1 b3 = 0.27970515920361567, BC1 a3 = 0.29929785469808900.
  const auto ac1 = scheme_of(resolve_method("AC1"));
  EXPECT_EQ(ac1.steps.size(), 11u);
  EXPECT_NEAR(static_cast<double>(ac1.steps[5].coef.re), 0.27970515920361567, 2e-17);
  const auto bc1 = scheme_of(resolve_method("BC1"));
  EXPECT_EQ(bc1.steps.size(), 11u);
  EXPECT_NEAR(static_cast<double>(bc1.steps[5].coef.re), 0.29929785469808900, 2e-17);
}

TEST(CatalogSplitting, GurkanSchemesStartWithTheRightFlow) {
  // RKNA (eq 3.6): drift alpha_1 first; RKNB (eq 3.7): kick beta_1 first; eq (6.1): kick first.
  const auto first = [](const std::string& n) { return scheme_of(resolve_method(n)).steps.front(); };
  for (const auto& n : {"AR1", "AR2", "AC1", "AC2", "Chambers", "RKNa14"}) EXPECT_EQ(first(n).flow, Flow::drift) << n;
  for (const auto& n : {"BR1", "BR2", "BR3", "BC1", "BC2", "AC1-6", "RKNb6"}) EXPECT_EQ(first(n).flow, Flow::kick) << n;
  EXPECT_NEAR(static_cast<double>(first("AR1").coef.re), 0.96172990014645096, 1e-17);
  EXPECT_NEAR(static_cast<double>(first("BR1").coef.re), 0.24566294009066009, 1e-17);
  EXPECT_NEAR(static_cast<double>(first("AC1").coef.im), 0.028523844251341822, 1e-18);
  EXPECT_NEAR(static_cast<double>(first("AC1-6").coef.re), 0.0489489561074426954, 1e-18);
}

// ---- compositions ------------------------------------------------------------------------------

TEST(Compositions, Y4IsForestRuth) {
  // The triple jump of order 4 on position Verlet is Forest-Ruth in the position-first form, and on
  // velocity Verlet FR-V: same sub-steps, coefficients equal to the reference precision.
  for (const auto& [y4, fr] : {std::pair<std::string, std::string>{"Y4", "FR"}, {"Y4-V", "FR-V"}}) {
    const auto a = scheme_of(resolve_method(y4)), b = scheme_of(resolve_method(fr));
    ASSERT_EQ(a.steps.size(), b.steps.size()) << y4;
    for (std::size_t i = 0; i < a.steps.size(); ++i) {
      EXPECT_EQ(a.steps[i].flow, b.steps[i].flow);
      EXPECT_LT(cabs(a.steps[i].coef - b.steps[i].coef), bigfloat("1e-70")) << y4 << " step " << i;
    }
    // ... hence identical trajectories in long double.
    const auto ra = run_ld(resolve_method(y4), KeplerForce{}, KeplerProblem<LD>(0.5L).initial_state(), 10.0L, 300);
    const auto rb = run_ld(resolve_method(fr), KeplerForce{}, KeplerProblem<LD>(0.5L).initial_state(), 10.0L, 300);
    EXPECT_EQ(ra.q, rb.q) << y4;
  }
}

TEST(Compositions, OddPowerSumsOfTheWeightsVanish) {
  // Necessary conditions for order p of a symmetric composition of a symmetric method (HLW (2006)
  // Example V.3.5, the one-vertex trees): sum w = 1 and sum w^k = 0 for odd k = 3, ..., p-1. A wrong
  // digit anywhere in a 26-digit table breaks them (negative control below).
  BigPrecision guard(256);
  auto check = [](const std::vector<bigfloat>& w, int p, int digits, const std::string& what) {
    const bigfloat tol = boost::multiprecision::pow(bigfloat(10), -digits);
    bigfloat s1 = 0;
    for (const auto& x : w) s1 += x;
    EXPECT_LT(abs(s1 - 1), tol * w.size()) << what;
    for (int k = 3; k < p; k += 2) {
      bigfloat s = 0, scale = 0;
      for (const auto& x : w) {
        s += boost::multiprecision::pow(x, k);
        scale += abs(boost::multiprecision::pow(x, k));
      }
      EXPECT_LT(abs(s), 10 * tol * scale) << what << " k=" << k;
    }
  };
  for (const auto& t : methods::composition_tables()) {
    std::vector<bigfloat> w;
    for (const auto& x : methods::table_weights(t)) w.push_back(x.re);
    check(w, t.order, 25, t.name);
    // The same weights are what the PV scheme kicks with.
    const auto kw = kick_weights(scheme_of(resolve_method(t.name)));
    ASSERT_EQ(kw.size(), w.size()) << t.name;
    for (std::size_t i = 0; i < w.size(); ++i) EXPECT_EQ(kw[i], w[i]) << t.name;
  }
  for (int p = 4; p <= 12; p += 2) {
    std::vector<bigfloat> tj, sz;
    for (const auto& x : methods::triple_jump_weights(p)) tj.push_back(x.re);
    for (const auto& x : methods::suzuki_weights(p)) sz.push_back(x.re);
    EXPECT_EQ(tj.size(), static_cast<std::size_t>(std::pow(3, p / 2 - 1)));
    EXPECT_EQ(sz.size(), static_cast<std::size_t>(std::pow(5, p / 2 - 1)));
    check(tj, p, 70, "triple jump " + std::to_string(p));
    check(sz, p, 70, "Suzuki " + std::to_string(p));
  }
  // Negative control: KL6 with one digit changed (the 12th of gamma_2): sum w^3 becomes ~7e-13,
  // twelve orders of magnitude above the tolerance used above.
  auto t = methods::composition_tables()[1];
  ASSERT_EQ(t.name, "KL6");
  t.half[1] = "0.33259913678835943859974864";
  std::vector<bigfloat> bad;
  for (const auto& x : methods::table_weights(t)) bad.push_back(x.re);
  bigfloat s3 = 0;
  for (const auto& x : bad) s3 += x * x * x;
  EXPECT_GT(abs(s3), bigfloat("1e-13"));
}

TEST(Compositions, OrderConditionsOnGenericMatrices) {
  // Local order p + 1 and a nonzero defect at order p + 1, for every composition in the catalog
  // (both bases), the recursive constructions, and the other nine-stage sixth-order set in
  // circulation (McLachlan 1995 SS9, 20 digits), which is a different but equally valid method.
  BigPrecision guard(256);
  struct Case {
    std::string name;
    int order;
    SplittingScheme<bigcomplex> scheme;
  };
  std::vector<Case> cases;
  for (const auto& n : kCompositions)
    cases.push_back({n, resolve_method(n).info.order, scheme_of(resolve_method(n), 256)});
  for (const auto& spec : {"triplejump:6", "triplejump:8", "triplejump-vv:8", "triplejump:10", "suzuki:4", "suzuki:6",
                           "suzuki-vv:6", "suzuki:8"})
    cases.push_back({spec, resolve_method(spec).info.order, scheme_of(resolve_method(spec), 256)});
  {
    const std::vector<bigcomplex> half = {big("0.1867"), big("0.55549702371247839916"), big("0.12946694891347535806"),
                                          big("-0.84326562338773460855"), big("0.9432033015235617027")};
    cases.push_back(
        {"McLachlan SS9", 6, normalized(compose(position_verlet_scheme(), palindrome(half, PalindromeLength::odd)))});
  }
  for (const auto& c : cases) {
    const LocalOrder lo = local_order(c.scheme, c.order, bigfloat(1) / (c.order >= 10 ? 64 : 32));
    EXPECT_NEAR(lo.order, c.order + 1, 0.15) << c.name;
    EXPECT_GT(lo.defect, 1e-12) << c.name;  // measured: 3e-8 (SS10) ... 7 (triple jump 10)
  }
  // Negative control: a KL6 table with a wrong 7th digit loses its order on the same test.
  auto t = methods::composition_tables()[1];
  t.half[1] = "0.33259923678935943859974864";
  const auto bad = normalized(compose(position_verlet_scheme(), methods::table_weights(t)));
  EXPECT_LT(local_order(bad, 6, bigfloat(1) / 32).order, 6.0);
  // ... and the RKN splittings are not compositions: as general splittings, the sixth-order RKNa14
  // and the fifth-order Gürkan methods have a lower order ([V,[V,[T,V]]] = 0 is used), while
  // RKNb6 (symmetric, order 4) is a genuine fourth-order general splitting.
  EXPECT_LT(local_order(scheme_of(resolve_method("RKNa14"), 256), 6, bigfloat(1) / 32).order, 6.0);
  EXPECT_LT(local_order(scheme_of(resolve_method("BR1"), 256), 5, bigfloat(1) / 32).order, 5.0);
  EXPECT_NEAR(local_order(scheme_of(resolve_method("RKNb6"), 256), 4, bigfloat(1) / 32).order, 5.0, 0.15);
}

// ---- observed orders ----------------------------------------------------------------------------

TEST(ObservedOrder, KeplerCompositionsAndBlanesMoan) {
  // Kepler e = 0.5, 1.37 periods, long double. Step counts chosen in the asymptotic range and above
  // the round-off floor (~1e-17): for SS10 that window is narrow (errors 1e-14 ... 1e-15). RKNb6 is
  // an optimized fourth-order method whose h^6 term dominates down to ~1e-11 (n ~ 700).
  const std::vector<std::pair<std::string, std::vector<long>>> cases = {{"Y4", {512, 724, 1024}},
                                                                        {"Y4-V", {512, 724, 1024}},
                                                                        {"Y6", {256, 362, 512}},
                                                                        {"Y6-V", {256, 362, 512}},
                                                                        {"KL6", {256, 362, 512}},
                                                                        {"KL6-V", {256, 362, 512}},
                                                                        {"KL8", {128, 181, 256}},
                                                                        {"KL8-V", {128, 181, 256}},
                                                                        {"SS10", {100, 112, 126}},
                                                                        {"SS10-V", {100, 126, 158}},
                                                                        {"RKNb6", {1024, 1448, 2048}},
                                                                        {"RKNa14", {128, 181, 256}},
                                                                        {"triplejump:6", {724, 1024, 1448}},
                                                                        {"triplejump-vv:6", {724, 1024, 1448}},
                                                                        {"suzuki:4", {256, 362, 512}},
                                                                        {"suzuki:6", {181, 256, 362}}};
  for (const auto& [name, ns] : cases) {
    const MethodDef d = resolve_method(name);
    const double p = kepler_order(d, 0.5, ns);
    EXPECT_NEAR(p, d.info.order, 0.3) << name;
  }
}

TEST(ObservedOrder, RealGurkanMethodsAreFifthOrder) {
  // On Kepler (e = 0.5, 1.37 periods) the real fifth-order methods converge with slope 6: the
  // fifth-order error term does not show on the two-body problem (as observed for BR1 at
  // whole periods; it stays hidden at this final time too). On Hénon-Heiles, a problem without that
  // structure, the fifth order appears once h is small enough.
  for (const auto& name : kGurkanReal) {
    const MethodDef d = resolve_method(name);
    EXPECT_GT(kepler_order(d, 0.5, {256, 362, 512}), 4.7) << name;
    EXPECT_NEAR(henon_heiles_order(d, {1280, 1810, 2560}), 5.0, 0.3) << name;
  }
}

TEST(ObservedOrder, ExchangingDriftAndKickBreaksTheRknMethods) {
  // The RKN methods rely on [V,[V,[T,V]]] = 0: with drift and kick exchanged the order drops (to 4
  // for RKNa14, to 3 for the real Gürkan methods). This pins down which flow each table starts with.
  // (Reversal, i.e. the adjoint, is a valid method for all of them and cannot be told apart this way.)
  for (const auto& name : {"RKNa14", "AR1", "AR2", "BR1", "BR2", "BR3"}) {
    const MethodDef d = resolve_method(name);
    EXPECT_LT(henon_heiles_order(swapped(d), {640, 1280, 2560}), d.info.order - 0.7) << name;
  }
  // RKNb6 is symmetric and of order 4 either way (the RKN condition only enters at order 6), but it
  // was optimized for the kick-first form: there its error is hundreds of times smaller.
  const MethodDef b6 = resolve_method("RKNb6");
  EXPECT_LT(100 * kepler_error(b6, 0.5, 1024), kepler_error(swapped(b6), 0.5, 1024));
}

TEST(ObservedOrder, ComplexMethodsWithImaginaryPartsDropped) {
  // Gürkan Fig. 5.1: with the imaginary parts dropped after each step (the engine default), on the
  // two-body problem (Kepler e = 0.2), AC1 behaves as a sixth-order and Chambers as a fourth-order
  // method although formally of orders 5 and 3. The other complex methods of Table 4.2 and eq (6.1)
  // behave the same way. Final time 1.37 periods.
  const std::vector<long> ns = {64, 91, 128, 181};
  const double ac1 = kepler_order(resolve_method("AC1"), 0.2, ns);
  const double chambers = kepler_order(resolve_method("Chambers"), 0.2, {128, 181, 256, 362});
  EXPECT_GE(ac1, 5.6);
  EXPECT_LE(ac1, 6.6);
  EXPECT_GE(chambers, 3.6);
  EXPECT_LE(chambers, 4.6);
  for (const auto& name : {"AC2", "BC1", "BC2", "AC1-6"})
    EXPECT_NEAR(kepler_order(resolve_method(name), 0.2, ns), 6.0, 0.4) << name;
  // The same on Hénon-Heiles: the effect is not special to Kepler.
  EXPECT_NEAR(henon_heiles_order(resolve_method("AC1"), {40, 80, 160}), 6.0, 0.3);
  EXPECT_NEAR(henon_heiles_order(resolve_method("Chambers"), {160, 320, 640}), 4.0, 0.3);
}

TEST(ObservedOrder, ComplexMethodsKeepingTheImaginaryPart) {
  // Without the projection the complexified methods have their formal orders: the imaginary part of
  // q grows like h^p (p = 5 for Gürkan's, 3 for Chambers), while the real part is one order better
  // (the leading error terms are purely imaginary).
  EngineOptions keep;
  keep.keep_complex = true;
  const std::vector<long> ns = {64, 128, 256};
  for (const auto& name : [] {
         auto v = kGurkanComplex;
         v.push_back("Chambers");
         return v;
       }()) {
    const MethodDef d = resolve_method(name);
    std::vector<double> im, re;
    for (long n : ns) {
      double imag = 0;
      re.push_back(kepler_error(d, 0.2, n, keep, &imag));
      im.push_back(imag);
    }
    EXPECT_NEAR(fit_order(ns, im), d.info.order, 0.1) << name;
    EXPECT_NEAR(fit_order(ns, re), d.info.order + 1, 0.25) << name;
  }
}

// ---- force counts ------------------------------------------------------------------------------

TEST(CatalogSplitting, ForcesPerStep) {
  const std::vector<std::pair<std::string, int>> expected = {
      {"Y4", 3},
      {"Y6", 7},
      {"Y6-V", 7},
      {"KL6", 9},
      {"KL6-V", 9},
      {"KL8", 17},
      {"KL8-V", 17},
      {"SS10", 35},
      {"SS10-V", 35},
      {"RKNb6", 6},
      {"RKNa14", 14},
      {"AR1", 5},
      {"AR2", 5},
      {"BR1", 5},
      {"BR2", 5},
      {"BR3", 5},
      {"AC1", 5},
      {"AC2", 5},
      {"Chambers", 2},
      // Kick-first complex methods: the last force is taken at a complex position and the state is
      // projected to real after the step, so it cannot be reused (no FSAL): 5 + 1 and 6 + 1.
      {"BC1", 6},
      {"BC2", 6},
      {"AC1-6", 7},
      {"triplejump:8", 27},
      {"suzuki:6", 25}};
  for (const auto& [name, f] : expected) {
    const MethodDef d = resolve_method(name);
    EXPECT_EQ(d.info.forces_per_step, f) << name;
    // The engine spends exactly that many (plus the first force of a kick-first real method).
    const long steps = 40;
    const KeplerProblem<LD> prob(0.3L);
    long evals = 0;
    if (d.info.complex) {
      using C = std::complex<LD>;
      auto integ = make_integrator<std::array<C, 2>>(d, KeplerForce{});
      auto s = convert_state<std::array<C, 2>>(prob.initial_state());
      integ.integrate(s, 0.01L, steps);
      evals = integ.force_evals();
    } else {
      auto integ = make_integrator<V2>(d, KeplerForce{});
      auto s = prob.initial_state();
      integ.integrate(s, 0.01L, steps);
      evals = integ.force_evals();
    }
    EXPECT_EQ(evals, steps * f + (d.info.fsal ? 1 : 0)) << name;
  }
  EXPECT_TRUE(resolve_method("RKNb6").info.fsal);
  EXPECT_TRUE(resolve_method("Y6-V").info.fsal);
  EXPECT_FALSE(resolve_method("BC1").info.fsal);
  EXPECT_EQ(resolve_method("KL8").info.stages, 17);
  EXPECT_EQ(resolve_method("RKNb6").info.stages, 7);
  EXPECT_EQ(resolve_method("SS10").info.published_digits, 26);
  EXPECT_EQ(resolve_method("RKNa14").info.published_digits, 15);
  EXPECT_FALSE(resolve_method("AC1").info.symplectic);  // projection destroys symplecticity
  EXPECT_TRUE(resolve_method("BR1").info.symplectic);
}

// ---- adjoints ----------------------------------------------------------------------------------

TEST(CatalogSplitting, AdjointReversesEveryPublicationSplittingMethod) {
  for (const auto& name : publication_splitting_methods()) {
    const MethodDef base = resolve_method(name);
    const MethodDef adj = resolve_method("adjoint:" + name);
    EXPECT_EQ(adj.info.name, "adjoint:" + name);
    EXPECT_EQ(adj.info.order, base.info.order);
    EXPECT_EQ(adj.info.forces_per_step, base.info.forces_per_step) << name;
    const auto s = scheme_of(base), a = scheme_of(adj);
    ASSERT_EQ(s.steps.size(), a.steps.size());
    const std::size_t m = s.steps.size();
    for (std::size_t i = 0; i < m; ++i) {
      EXPECT_EQ(a.steps[i].flow, s.steps[m - 1 - i].flow);
      EXPECT_EQ(a.steps[i].coef, s.steps[m - 1 - i].coef);
    }
  }
  // The adjoints of the real fifth-order methods are fifth-order methods too (Table 4.1 caption);
  // the adjoint of AC1 is its conjugate and behaves like it.
  EXPECT_NEAR(henon_heiles_order(resolve_method("adjoint:AR1"), {1280, 1810, 2560}), 5.0, 0.3);
  EXPECT_NEAR(henon_heiles_order(resolve_method("adjoint:BR2"), {1280, 1810, 2560}), 5.0, 0.3);
  EXPECT_NEAR(kepler_order(resolve_method("adjoint:AC1"), 0.2, {64, 91, 128, 181}), 6.0, 0.4);
  EXPECT_NEAR(kepler_order(resolve_method("adjoint:KL8"), 0.5, {128, 181, 256}), 8.0, 0.3);
}

// ---- parametric specifications and bad input ----------------------------------------------------

TEST(CatalogSplitting, ParametricCompositions) {
  const MethodDef tj = resolve_method("triplejump:6");
  EXPECT_EQ(tj.info.order, 6);
  EXPECT_EQ(tj.info.family, "composition");
  EXPECT_EQ(tj.info.stages, 9);
  EXPECT_FALSE(tj.info.fsal);
  const MethodDef tjv = resolve_method("TripleJump-VV:6");
  EXPECT_EQ(tjv.info.stages, 10);
  EXPECT_TRUE(tjv.info.fsal);
  EXPECT_EQ(tjv.info.forces_per_step, 9);
  EXPECT_EQ(resolve_method("triplejump-pv:6").info.stages, 9);
  EXPECT_EQ(resolve_method("suzuki:6").info.stages, 25);
  EXPECT_EQ(resolve_method("suzuki-vv:4").info.forces_per_step, 5);
  EXPECT_EQ(resolve_method("triplejump:2").info.stages, 1);  // order 2: the leapfrog itself
  for (const auto& bad : {"triplejump:5", "triplejump:0", "triplejump:-4", "triplejump:", "triplejump:x",
                          "triplejump:6a", "triplejump:22", "suzuki:16", "suzuki:3", "suzuki-xx:4", "triplejump:99999"})
    EXPECT_THROW(resolve_method(bad), invalid_input) << bad;  // a nystrom::error
  EXPECT_THROW(methods::triple_jump_weights(7), std::invalid_argument);
  EXPECT_THROW(methods::suzuki_weights(0), std::invalid_argument);
  EXPECT_THROW(methods::leapfrog_base("XV"), std::invalid_argument);
  EXPECT_THROW(methods::alternating(Flow::drift, {big("1")}, {big("1"), big("2")}), std::invalid_argument);
}
