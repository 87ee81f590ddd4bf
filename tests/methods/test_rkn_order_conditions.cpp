// The RKN order conditions by special Nystrom trees (analysis/rkn_order_conditions.hpp): the tree
// machinery against known counts and hand-written conditions, every RKN tableau of the catalog
// against its declared order, splitting methods converted to tableaux (and the conversion checked
// against the splitting engine), the scalar types, and bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <complex>
#include <cstdio>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "nystrom/analysis/rkn_order_conditions.hpp"
#include "nystrom/engines/rkn.hpp"
#include "nystrom/engines/splitting.hpp"
#include "nystrom/methods/catalog.hpp"
#include "nystrom/problems/kepler.hpp"

using namespace nystrom;

namespace {

constexpr unsigned kBits = 256;

MethodData build_at(const MethodDef& d) { return d.build(); }  // call inside a BigPrecision guard

bool is_real(const RknTableau<bigcomplex>& t) {
  auto real = [](const std::vector<bigcomplex>& v) {
    for (const auto& x : v)
      if (!x.is_real()) return false;
    return true;
  };
  for (const auto& row : t.a)
    if (!real(row)) return false;
  return real(t.c) && real(t.b) && real(t.B) && real(t.bhat) && real(t.Bhat);
}

RknTableau<bigfloat> real_tableau(const RknTableau<bigcomplex>& t) {
  return convert_tableau<bigfloat>(t, [](const bigcomplex& x) { return x.re; });
}

/// Max residuals of the conditions of orders 1..n (element k - 1 for order k), for a real or complex
/// reference tableau (real arithmetic where the coefficients are real: four times cheaper).
std::vector<double> residuals_by_order(const RknTableau<bigcomplex>& t, int n) {
  std::vector<double> out;
  auto run = [&](auto oc) {
    for (int k = 1; k <= n; ++k) out.push_back(static_cast<double>(oc.max_residual_of_order(k)));
  };
  if (is_real(t)) {
    run(RknOrderConditions<bigfloat>(real_tableau(t)));
  } else {
    run(RknOrderConditions<bigcomplex>(t));
  }
  return out;
}

/// Tolerance for the conditions of a method's declared order: rounding for exact coefficients
/// (1e-50: the Dormand-Prince rows 14-17 as published are consistent to ~1e-53 only, see
/// test_dp12.cpp); for decimal tables 1e5 units of the last published digit (tables found by
/// numerical minimisation, e.g. Gurkan's 7-stage AC1-6, satisfy their conditions to ~1e-12 only).
double declared_tolerance(const MethodInfo& info) {
  if (info.published_digits == 0) return 1e-50;
  return std::pow(10.0, 5 - info.published_digits);
}

SplittingScheme<bigcomplex> scheme_of(std::initializer_list<std::pair<Flow, const char*>> steps) {
  SplittingScheme<bigcomplex> s;
  for (const auto& [f, x] : steps) s.steps.push_back({f, big(x)});
  return s;
}

// Gurkan, Table 4.1: AR1 (RKNA structure, eq 3.6: drift alpha_1 is applied first) and BR1 (RKNB,
// eq 3.7: kick beta_1 first), 17 published digits.
SplittingScheme<bigcomplex> gurkan_ar1() {
  const char* al[] = {"0.96172990014645096", "-0.09525408032034999", "-0.73942683539212613",
                      "0.62730935078241887", "-0.52506178465602220", "0.77070344943962849"};
  const char* be[] = {"0.39682804502722538", "-0.824377563589592", "0.2042028689314904", "1.0021847152077973",
                      "0.22116193442307898"};
  SplittingScheme<bigcomplex> s;
  for (int i = 0; i < 5; ++i) {
    s.steps.push_back(drift(big(al[i])));
    s.steps.push_back(kick(big(be[i])));
  }
  s.steps.push_back(drift(big(al[5])));
  return s;
}
SplittingScheme<bigcomplex> gurkan_br1() {
  const char* al[] = {"0.54200976680171613", "-0.04060817665564392", "-0.87779698530109766", "0.86474236062251646",
                      "0.51165303453250898"};
  const char* be[] = {"0.24566294009066009",   "1.1433587581365421",  "-1.3796706973507000",
                      "-0.019611260781217307", "0.87087215441178844", "0.13938810549292669"};
  SplittingScheme<bigcomplex> s;
  for (int i = 0; i < 5; ++i) {
    s.steps.push_back(kick(big(be[i])));
    s.steps.push_back(drift(big(al[i])));
  }
  s.steps.push_back(kick(big(be[5])));
  return s;
}
// Gurkan, Table 4.2: AC1, skew-symmetric (alpha_{7-i} = conj(alpha_i), beta_{6-i} = conj(beta_i),
// beta_3 = 1 - 2 Re(beta_1 + beta_2)).
SplittingScheme<bigcomplex> gurkan_ac1() {
  const bigcomplex a1 = bigc("0.087808410045663212", "0.028523844251341822");
  const bigcomplex a2 = bigc("0.17916539354193987", "-0.067857083007249973");
  const bigcomplex a3 = bigc("0.23302619641239692", "-0.097952003128893425");
  const bigcomplex b1 = bigc("0.17526734338348050", "0.057642040076250593");
  const bigcomplex b2 = bigc("0.18488007701471166", "-0.19410647329733509");
  const bigcomplex b3(1 - 2 * (b1.re + b2.re));
  return scheme({drift(a1), kick(b1), drift(a2), kick(b2), drift(a3), kick(b3), drift(a3.conj()), kick(b2.conj()),
                 drift(a2.conj()), kick(b1.conj()), drift(a1.conj())});
}

}  // namespace

// ---- the trees ----------------------------------------------------------------------------------

TEST(SnTrees, CountsMatchHairerNorsettWanner) {
  // HNW I, Table II.14.3 (special case y'' = f(y)): SN-trees of orders 1..10.
  const std::vector<std::size_t> hnw = {1, 1, 2, 3, 6, 10, 20, 36, 72, 137};
  for (int n = 1; n <= 10; ++n) EXPECT_EQ(sn_tree_count(n), hnw[static_cast<std::size_t>(n - 1)]) << "order " << n;
}

TEST(SnTrees, CountsMatchTheGeneratingFunction) {
  // Independent count: a fat tree of order n is a multiset of meagre trees of total order n - 1; there
  // are M(1) = 1 meagre trees of order 1 (v) and M(k) = F(k - 1) of order k. Multisets are counted by
  // the Euler transform prod_k (1 - x^k)^(-M(k)).
  const int N = 15;
  std::vector<unsigned long long> F(N + 1, 0), M(N + 1, 0);
  F[1] = 1;
  for (int n = 2; n <= N; ++n) {
    M[1] = 1;
    for (int k = 2; k < n; ++k) M[static_cast<std::size_t>(k)] = F[static_cast<std::size_t>(k - 1)];
    // multisets of total weight n - 1 from M(k) kinds of weight k, k = 1..n-1
    std::vector<unsigned long long> g(static_cast<std::size_t>(n), 0);
    g[0] = 1;
    for (int k = 1; k <= n - 1; ++k)
      for (unsigned long long kind = 0; kind < M[static_cast<std::size_t>(k)]; ++kind)
        for (int w = k; w <= n - 1; ++w) g[static_cast<std::size_t>(w)] += g[static_cast<std::size_t>(w - k)];
    F[static_cast<std::size_t>(n)] = g[static_cast<std::size_t>(n - 1)];
  }
  for (int n = 1; n <= N; ++n) EXPECT_EQ(sn_tree_count(n), F[static_cast<std::size_t>(n)]) << "order " << n;
  EXPECT_EQ(sn_tree_count(13), 1098u);
}

TEST(SnTrees, SmallTreesTheirDensitiesAndConditionCounts) {
  const auto t = sn_trees(4);
  ASSERT_EQ(t.size(), 7u);
  std::map<std::string, std::uint64_t> gamma;
  for (const auto& x : t) gamma[x.name] = x.gamma;
  const std::map<std::string, std::uint64_t> expect = {
      {"f", 1}, {"f'(v)", 2}, {"f'(f)", 6}, {"f''(v,v)", 3}, {"f'(f'(v))", 24}, {"f''(f,v)", 8}, {"f'''(v,v,v)", 4}};
  EXPECT_EQ(gamma, expect);
  // Conditions for order p: velocity for rho <= p, position for rho <= p - 1 (partial sums of the counts).
  const std::vector<std::size_t> cumulative = {1, 3, 6, 11, 20, 36, 66, 122};
  for (int p = 1; p <= 8; ++p) EXPECT_EQ(rkn_conditions(p).size(), cumulative[static_cast<std::size_t>(p - 1)]);
  EXPECT_EQ(rkn_conditions_of_order(1).front().name, "B: f");
  EXPECT_EQ(rkn_conditions_of_order(2).front().name, "b: f");
}

// The conditions up to order 4 written out by hand (HNW I, sec. II.14) for a random explicit tableau.
TEST(RknOrderConditions, AgreeWithHandWrittenConditionsUpToOrderFour) {
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> u(-1, 1);
  const std::size_t s = 5;
  RknTableau<long double> t;
  t.c.resize(s);
  t.b.resize(s);
  t.B.resize(s);
  t.a.assign(s, std::vector<long double>(s, 0));
  for (std::size_t i = 0; i < s; ++i) {
    t.c[i] = u(rng);
    t.b[i] = u(rng);
    t.B[i] = u(rng);
    for (std::size_t j = 0; j < i; ++j) t.a[i][j] = u(rng);
  }
  auto sum = [&](auto f) {
    long double r = 0;
    for (std::size_t i = 0; i < s; ++i) r += f(i);
    return r;
  };
  auto ac = [&](std::size_t i) {  // sum_j a_ij c_j
    long double r = 0;
    for (std::size_t j = 0; j < i; ++j) r += t.a[i][j] * t.c[j];
    return r;
  };
  auto a1 = [&](std::size_t i) {  // sum_j a_ij
    long double r = 0;
    for (std::size_t j = 0; j < i; ++j) r += t.a[i][j];
    return r;
  };
  std::map<std::string, long double> hand = {
      {"B: f", sum([&](auto i) { return t.B[i]; }) - 1.0L},
      {"b: f", sum([&](auto i) { return t.b[i]; }) - 0.5L},
      {"B: f'(v)", sum([&](auto i) { return t.B[i] * t.c[i]; }) - 0.5L},
      {"b: f'(v)", sum([&](auto i) { return t.b[i] * t.c[i]; }) - 1.0L / 6},
      {"B: f'(f)", sum([&](auto i) { return t.B[i] * a1(i); }) - 1.0L / 6},
      {"B: f''(v,v)", sum([&](auto i) { return t.B[i] * t.c[i] * t.c[i]; }) - 1.0L / 3},
      {"b: f'(f)", sum([&](auto i) { return t.b[i] * a1(i); }) - 1.0L / 24},
      {"b: f''(v,v)", sum([&](auto i) { return t.b[i] * t.c[i] * t.c[i]; }) - 1.0L / 12},
      {"B: f'(f'(v))", sum([&](auto i) { return t.B[i] * ac(i); }) - 1.0L / 24},
      {"B: f''(f,v)", sum([&](auto i) { return t.B[i] * t.c[i] * a1(i); }) - 1.0L / 8},
      {"B: f'''(v,v,v)", sum([&](auto i) { return t.B[i] * t.c[i] * t.c[i] * t.c[i]; }) - 1.0L / 4},
  };
  std::size_t seen = 0;
  for (int n = 1; n <= 4; ++n)
    for (const auto& r : rkn_residuals(t, n)) {
      ASSERT_TRUE(hand.count(r.info.name)) << r.info.name;
      EXPECT_NEAR(static_cast<double>(r.residual), static_cast<double>(hand[r.info.name]), 1e-15) << r.info.name;
      ++seen;
    }
  EXPECT_EQ(seen, hand.size());
}

// ---- the catalog --------------------------------------------------------------------------------

TEST(RknOrderConditions, EveryCatalogTableauHasExactlyItsDeclaredOrder) {
  BigPrecision guard(kBits);
  int checked = 0;
  for (const auto& d : catalog()) {
    if (d.info.family != "rkn") continue;
    const MethodData data = build_at(d);
    const auto* t = std::get_if<RknTableau<bigcomplex>>(&data);
    ASSERT_NE(t, nullptr) << d.info.name << " is in family rkn but is not a tableau";
    const int p = d.info.order;
    const double tol = declared_tolerance(d.info);
    const auto r = residuals_by_order(*t, p + 1);
    EXPECT_LE(*std::max_element(r.begin(), r.end() - 1), tol)
        << d.info.name << ": a condition of order <= " << p << " fails";
    // A general (RKNG) pair's order is that for y'' = f(t, y, y'), whose conditions include these: on
    // y'' = f(y) it may be higher (its order on f(y, y') is measured in test_adaptive_rkn, Rkng.*).
    if (!t->general()) {
      EXPECT_GT(r.back(), 1e3 * tol) << d.info.name << " satisfies the conditions of order " << p + 1;
    }
    std::printf("%-16s order %d: residuals of order %d %.1e\n", d.info.name.c_str(), p, p + 1, r.back());
    ++checked;
  }
  EXPECT_GE(checked, 5);  // N4, M4-RKN, M6-5F, A6, Aprime at least
}

TEST(RknOrderConditions, ChinMethodsHaveTheOrdersOfThePaper) {
  BigPrecision guard(kBits);
  const std::map<std::string, int> expect = {{"N4", 4}, {"M4-RKN", 4}, {"M6-5F", 6}, {"A6", 6}, {"Aprime", 4}};
  for (const auto& [name, p] : expect) {
    const auto t = std::get<RknTableau<bigcomplex>>(build_at(resolve_method(name)));
    EXPECT_EQ(rkn_order(real_tableau(t), bigfloat("1e-60")), p) << name;
  }
}

TEST(RknOrderConditions, ConvertedVerletAndForestRuthHaveTheirOrders) {
  BigPrecision guard(kBits);
  const std::map<std::string, int> expect = {{"VV", 2}, {"PV", 2}, {"FR", 4}, {"FR-V", 4}};
  for (const auto& [name, p] : expect) {
    const auto t = to_rkn_tableau(std::get<SplittingScheme<bigcomplex>>(build_at(resolve_method(name))));
    RknOrderConditions<bigfloat> oc(real_tableau(t));
    EXPECT_LE(oc.max_residual(p), bigfloat("1e-60")) << name;
    EXPECT_GT(oc.max_residual_of_order(p + 1), bigfloat("1e-3")) << name;
    EXPECT_EQ(oc.order(bigfloat("1e-60")), p) << name;
  }
}

// Every splitting or composition method of the catalog, converted, against its declared order.
TEST(RknOrderConditions, EveryCatalogSplittingMethodHasItsDeclaredOrder) {
  BigPrecision guard(kBits);
  int checked = 0;
  for (const auto& d : catalog()) {
    if (d.info.family != "splitting" && d.info.family != "composition") continue;
    const MethodData data = build_at(d);
    const auto* s = std::get_if<SplittingScheme<bigcomplex>>(&data);
    if (!s) continue;
    const double tol = declared_tolerance(d.info);
    const auto t = to_rkn_tableau(*s, std::max(tol, 1e-60));
    const auto r = residuals_by_order(t, d.info.order + 1);
    EXPECT_LE(*std::max_element(r.begin(), r.end() - 1), tol) << d.info.name;
    EXPECT_GT(r.back(), 10 * tol) << d.info.name;
    ++checked;
  }
  EXPECT_GE(checked, 4);
}

// Gurkan's fifth-order methods (Tables 4.1, 4.2) from their published digits: order 5; for the
// complex AC1 the order-6 residuals are purely imaginary (the paper: "the leading order terms in the
// error expansion ... are purely imaginary").
TEST(RknOrderConditions, GurkanFifthOrderMethods) {
  BigPrecision guard(kBits);
  for (const auto& s : {gurkan_ar1(), gurkan_br1()}) {
    RknOrderConditions<bigfloat> oc(real_tableau(to_rkn_tableau(s, 1e-15)));
    EXPECT_LE(oc.max_residual(5), bigfloat("1e-15"));
    EXPECT_GT(oc.max_residual_of_order(6), bigfloat("1e-6"));
    EXPECT_EQ(oc.order(bigfloat("1e-14")), 5);
  }
  RknOrderConditions<bigcomplex> oc(to_rkn_tableau(gurkan_ac1(), 1e-15));
  EXPECT_LE(oc.max_residual(5), bigfloat("1e-15"));
  bigfloat re_max = 0, im_max = 0;
  for (const auto& r : oc.residuals(6)) {
    re_max = std::max(re_max, bigfloat(abs(r.residual.re)));
    im_max = std::max(im_max, bigfloat(abs(r.residual.im)));
  }
  EXPECT_LE(re_max, bigfloat("1e-15"));
  EXPECT_GT(im_max, bigfloat("1e-7"));
}

// ---- machinery ----------------------------------------------------------------------------------

TEST(RknOrderConditions, APerturbationIsSeenAtTheRightOrderWithTheRightSize) {
  BigPrecision guard(kBits);
  auto t = real_tableau(std::get<RknTableau<bigcomplex>>(build_at(resolve_method("A6"))));
  const bigfloat delta("1e-30");
  t.a[2][1] += delta;  // the first tree that sees a_32 is f'(f): B-condition sum_ij B_i a_ij = 1/6 (order 3)
  RknOrderConditions<bigfloat> oc(t);
  EXPECT_EQ(oc.order(bigfloat("1e-40")), 2);
  for (const auto& r : oc.residuals(3)) {
    if (r.info.name == "B: f'(f)") {
      EXPECT_LE(abs(r.residual - t.B[2] * delta), bigfloat("1e-45"));
    } else {
      EXPECT_LE(abs(r.residual), bigfloat("1e-60")) << r.info.name;
    }
  }
}

TEST(RknOrderConditions, ScalarTypesAgree) {
  BigPrecision guard(kBits);
  const auto ref = std::get<RknTableau<bigcomplex>>(build_at(resolve_method("M6-5F")));
  const auto tb = real_tableau(ref);
  const auto td = convert_tableau<double>(ref, [](const bigcomplex& x) { return to_real<double>(x.re); });
  const auto tl = convert_tableau<long double>(ref, [](const bigcomplex& x) { return to_real<long double>(x.re); });
  const auto tc = convert_tableau<std::complex<double>>(
      ref, [](const bigcomplex& x) { return std::complex<double>(to_real<double>(x.re), to_real<double>(x.im)); });
  EXPECT_LE(max_residual(td, 6), 1e-14);
  EXPECT_LE(max_residual(tl, 6), 1e-17L);
  EXPECT_LE(max_residual(tc, 6), 1e-14);
  EXPECT_LE(max_residual(tb, 6), bigfloat("1e-70"));
  EXPECT_LE(max_residual(ref, 6), bigfloat("1e-70"));
  EXPECT_EQ(rkn_order(td, 1e-13), 6);
  EXPECT_EQ(rkn_order(tl, 1e-16L), 6);
  EXPECT_EQ(rkn_order(tc, 1e-13), 6);
  // The order-7 residuals agree between the types.
  const auto rb = rkn_residuals(tb, 7);
  const auto rd = rkn_residuals(td, 7);
  const auto rc = rkn_residuals(tc, 7);
  const auto rz = rkn_residuals(ref, 7);
  ASSERT_EQ(rb.size(), rd.size());
  for (std::size_t k = 0; k < rb.size(); ++k) {
    const double x = static_cast<double>(rb[k].residual);
    EXPECT_NEAR(rd[k].residual, x, 1e-14) << rb[k].info.name;
    EXPECT_NEAR(rc[k].residual.real(), x, 1e-14) << rb[k].info.name;
    EXPECT_EQ(rc[k].residual.imag(), 0.0);
    EXPECT_LE(abs(rz[k].residual.re - rb[k].residual), bigfloat("1e-70")) << rb[k].info.name;
    EXPECT_EQ(rz[k].residual.im, 0);
  }
}

// The residual vector is what a Newton iteration in MPFR needs: refine Forest-Ruth's theta from 16
// published-style digits to the closed form 1/(2 - 2^(1/3)) by Gauss-Newton on all conditions of
// order <= 4, with a central-difference Jacobian.
TEST(RknOrderConditions, ResidualVectorDrivesANewtonRefinement) {
  BigPrecision guard(kBits);
  auto fr = [](const bigfloat& th) {
    const bigfloat h = big("1/2");
    SplittingScheme<bigfloat> s;
    s.steps = {{Flow::drift, th * h},       {Flow::kick, th}, {Flow::drift, (1 - th) * h}, {Flow::kick, 1 - 2 * th},
               {Flow::drift, (1 - th) * h}, {Flow::kick, th}, {Flow::drift, th * h}};
    return rkn_residual_vector(to_rkn_tableau(s), 4);
  };
  const bigfloat exact = 1 / (2 - boost::multiprecision::cbrt(bigfloat(2)));
  bigfloat th("1.351207191959658");
  EXPECT_EQ(fr(th).size(), rkn_conditions(4).size());
  const bigfloat d("1e-40");
  for (int it = 0; it < 4; ++it) {
    const auto r = fr(th), rp = fr(th + d), rm = fr(th - d);
    bigfloat jtj = 0, jtr = 0;
    for (std::size_t k = 0; k < r.size(); ++k) {
      const bigfloat j = (rp[k] - rm[k]) / (2 * d);
      jtj += j * j;
      jtr += j * r[k];
    }
    th -= jtr / jtj;
  }
  EXPECT_LE(abs(th - exact), bigfloat("1e-60"));
  bigfloat worst = 0;
  for (const auto& x : fr(th)) worst = std::max(worst, bigfloat(abs(x)));
  EXPECT_LE(worst, bigfloat("1e-60"));
}

// ---- splitting schemes as tableaux --------------------------------------------------------------

namespace {

template <class V, class F>
double one_step_difference(const SplittingScheme<bigcomplex>& s, F force, const State<V>& y0, double h) {
  using S = typename V::value_type;
  auto conv = [](const bigcomplex& x) { return to_scalar<S>(x); };
  SplittingStepper<V, F> sp(convert_scheme<S>(s, conv), force);
  RknStepper<V, F> rk(convert_tableau<S>(to_rkn_tableau(s, 1e-15), conv), force);
  State<V> a = y0, b = y0;
  sp.step(a, h);
  rk.step(b, h);
  double d = 0;
  for (std::size_t i = 0; i < a.q.size(); ++i) {
    using std::abs;
    d = std::max(d, static_cast<double>(abs(a.q[i] - b.q[i])));
    d = std::max(d, static_cast<double>(abs(a.v[i] - b.v[i])));
  }
  return d;
}

}  // namespace

TEST(ToRknTableau, OneStepAgreesWithTheSplittingEngine) {
  BigPrecision guard(kBits);
  const KeplerProblem<long double> kp(0.5L);
  const auto y0 = kp.initial_state();
  std::vector<std::pair<std::string, SplittingScheme<bigcomplex>>> cases = {
      {"VV", std::get<SplittingScheme<bigcomplex>>(build_at(resolve_method("VV")))},
      {"PV", std::get<SplittingScheme<bigcomplex>>(build_at(resolve_method("PV")))},
      {"FR", std::get<SplittingScheme<bigcomplex>>(build_at(resolve_method("FR")))},
      {"FR-V", std::get<SplittingScheme<bigcomplex>>(build_at(resolve_method("FR-V")))},
      {"AR1", gurkan_ar1()},
      {"BR1", gurkan_br1()}};
  for (const auto& [name, s] : cases) {
    const double d = one_step_difference<std::array<long double, 2>>(s, KeplerForce{}, y0, 0.3);
    EXPECT_LE(d, 1e-17) << name;
  }
  // Complex coefficients (both engines drop the imaginary parts at the end of the step).
  using VC = std::array<std::complex<double>, 2>;
  const State<VC> yc = convert_state<VC>(KeplerProblem<double>(0.5).initial_state());
  EXPECT_LE(one_step_difference<VC>(gurkan_ac1(), KeplerForce{}, yc, 0.3), 1e-14);
}

TEST(ToRknTableau, StructureOfTheConversion) {
  BigPrecision guard(kBits);
  // Velocity Verlet: kicks at c = 0 and c = 1 (FSAL: one force per step, as in the splitting engine).
  const auto vv = real_tableau(to_rkn_tableau(velocity_verlet_scheme()));
  ASSERT_EQ(vv.stages(), 2u);
  EXPECT_EQ(vv.c[0], 0);
  EXPECT_EQ(vv.c[1], 1);
  EXPECT_EQ(vv.a[1][0], big("1/2"));
  EXPECT_EQ(vv.b[0], big("1/2"));
  EXPECT_EQ(vv.b[1], 0);
  EXPECT_TRUE(vv.fsal());
  EXPECT_EQ(vv.forces_per_step(), velocity_verlet_scheme().forces_per_step());
  // Position Verlet: one kick at c = 1/2, b = 1/2, B = 1.
  const auto pv = real_tableau(to_rkn_tableau(position_verlet_scheme()));
  ASSERT_EQ(pv.stages(), 1u);
  EXPECT_EQ(pv.c[0], big("1/2"));
  EXPECT_EQ(pv.b[0], big("1/2"));
  EXPECT_EQ(pv.B[0], 1);
  // Adjacent kicks merge; a_ij = B_j (c_i - c_j).
  const auto t = real_tableau(to_rkn_tableau(scheme_of(
      {{Flow::kick, "1/4"}, {Flow::kick, "1/4"}, {Flow::drift, "1/3"}, {Flow::kick, "1/2"}, {Flow::drift, "2/3"}})));
  ASSERT_EQ(t.stages(), 2u);
  EXPECT_EQ(t.B[0], big("1/2"));
  EXPECT_EQ(t.a[1][0], big("1/2") * big("1/3"));
  EXPECT_LE(abs(t.b[1] - big("1/3")), bigfloat("1e-70"));
}

TEST(ToRknTableau, RejectsBadSchemes) {
  BigPrecision guard(kBits);
  EXPECT_THROW(to_rkn_tableau(scheme_of({{Flow::drift, "1"}})), std::invalid_argument);  // no kick
  EXPECT_THROW(to_rkn_tableau(scheme_of({{Flow::drift, "1/2"}, {Flow::kick, "1"}})), std::invalid_argument);
  SplittingScheme<double> nan;
  nan.steps = {{Flow::drift, 0.5}, {Flow::kick, std::nan("")}, {Flow::drift, 0.5}};
  EXPECT_THROW(to_rkn_tableau(nan), std::invalid_argument);
  // Published decimals are consistent to their digits only: the tolerance decides.
  const auto slightly = scheme_of({{Flow::drift, "0.5"}, {Flow::kick, "1"}, {Flow::drift, "0.50000000000000001"}});
  EXPECT_NO_THROW(to_rkn_tableau(slightly, 1e-15));
  EXPECT_THROW(to_rkn_tableau(slightly, 1e-20), std::invalid_argument);
}

TEST(RknOrderConditions, RejectsBadInput) {
  EXPECT_THROW(rkn_conditions_of_order(0), std::invalid_argument);
  EXPECT_THROW(rkn_conditions_of_order(kMaxSnOrder + 1), std::invalid_argument);
  EXPECT_THROW(sn_tree_count(0), std::invalid_argument);
  EXPECT_THROW(sn_trees(-1), std::invalid_argument);
  RknTableau<double> t;
  EXPECT_THROW(RknOrderConditions<double>{t}, std::invalid_argument);  // no stages
  t.c = {0.5};
  t.a = {{0.0}};
  t.b = {0.5};
  t.B = {1.0};
  EXPECT_EQ(rkn_order(t, 1e-15), 2);  // position Verlet
  EXPECT_THROW(rkn_order(t, -1.0), std::invalid_argument);
  EXPECT_THROW(embedded_tableau(t), std::invalid_argument);
  t.a = {{1.0}};  // implicit
  EXPECT_THROW(RknOrderConditions<double>{t}, std::invalid_argument);
}
