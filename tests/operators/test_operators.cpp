// The operator layer over a pair of general matrices: e^{h(A+B)} with A, B random 4x4 complex matrices
// (no structure: [B,[B,[A,B]]] != 0). Every catalog method that applies to general operators, and the
// multi-product expansions M2 ... M12 and over a fourth-order base, show their declared order against
// the exact exponential (scaling and squaring of a Taylor series in long double).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <complex>
#include <cstdio>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "nystrom/engines/integrator.hpp"
#include "nystrom/methods/catalog.hpp"
#include "nystrom/operators/drift_kick.hpp"
#include "nystrom/operators/flow_methods.hpp"
#include "nystrom/problems/kepler.hpp"

using namespace nystrom;
using namespace nystrom::operators;

namespace {

using R = long double;
using C = std::complex<R>;
constexpr int N = 4;
using Mat = std::array<C, N * N>;
constexpr R kTime = 2;  // the time integrated: long enough that order 12 is measurable above rounding

Mat mul(const Mat& a, const Mat& b) {
  Mat c{};
  for (int i = 0; i < N; ++i)
    for (int k = 0; k < N; ++k)
      for (int j = 0; j < N; ++j) c[i * N + j] += a[i * N + k] * b[k * N + j];
  return c;
}

/// e^{M}: scale by 2^-s until the norm is below 1/2, Taylor series to rounding, square s times.
Mat expm(const Mat& m) {
  R norm = 0;
  for (const auto& x : m) norm += std::abs(x);
  int s = 0;
  while (norm > 0.5L) {
    norm /= 2;
    ++s;
  }
  Mat a = m;
  for (std::size_t i = 0; i < a.size(); ++i) a[i] = C(std::ldexp(m[i].real(), -s), std::ldexp(m[i].imag(), -s));
  Mat result{}, term{};
  for (int i = 0; i < N; ++i) result[i * N + i] = term[i * N + i] = 1;
  for (int k = 1; k <= 40; ++k) {
    term = mul(term, a);
    for (auto& x : term) x /= static_cast<R>(k);
    for (std::size_t i = 0; i < result.size(); ++i) result[i] += term[i];
  }
  for (int i = 0; i < s; ++i) result = mul(result, result);
  return result;
}

/// Flows e^{zA}, e^{zB} of two fixed matrices, with the exponentials cached per coefficient.
struct MatrixFlows {
  using state_type = std::vector<C>;
  using real_type = R;
  Mat A, B;
  std::map<std::pair<R, R>, Mat> cache_a, cache_b;
  long applications = 0;

  static void apply(std::map<std::pair<R, R>, Mat>& cache, const Mat& m, state_type& s, C z) {
    auto it = cache.find({z.real(), z.imag()});
    if (it == cache.end()) {
      Mat zm;
      for (std::size_t i = 0; i < m.size(); ++i) zm[i] = z * m[i];
      it = cache.emplace(std::pair<R, R>{z.real(), z.imag()}, expm(zm)).first;
    }
    state_type out(N);
    for (int i = 0; i < N; ++i)
      for (int j = 0; j < N; ++j) out[i] += it->second[i * N + j] * s[j];
    s = out;
  }
  void apply_a(state_type& s, C z) {
    ++applications;
    apply(cache_a, A, s, z);
  }
  void apply_b(state_type& s, C z) {
    ++applications;
    apply(cache_b, B, s, z);
  }
  void assign(state_type& d, const state_type& s) { d = s; }
  void scale(state_type& s, R r) {
    for (auto& x : s) x *= r;
  }
  void axpy(state_type& d, R r, const state_type& s) {
    for (std::size_t i = 0; i < d.size(); ++i) d[i] += r * s[i];
  }
};

MatrixFlows random_pair() {
  std::mt19937 gen(17);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  MatrixFlows f;
  for (auto& x : f.A) x = C(u(gen), u(gen));
  for (auto& x : f.B) x = C(u(gen), u(gen));
  return f;
}

R error_after(MatrixFlows& f, const FlowMethod& m, long steps) {
  const std::vector<C> s0{C(1), C(0.5L, -0.25L), C(-0.75L), C(0, 1)};
  Mat ab;
  for (std::size_t i = 0; i < ab.size(); ++i) ab[i] = f.A[i] + f.B[i];
  for (auto& x : ab) x *= kTime;
  const Mat e = expm(ab);
  std::vector<C> exact(N);
  for (int i = 0; i < N; ++i)
    for (int j = 0; j < N; ++j) exact[i] += e[i * N + j] * s0[j];
  FlowIntegrator<MatrixFlows> integ(m);
  std::vector<C> s = s0;
  integ.integrate(f, s, kTime / steps, steps);
  R err = 0;
  for (int i = 0; i < N; ++i) err = std::max(err, std::abs(s[i] - exact[i]));
  return err;
}

/// Observed order from errors at steps n, 2n, 4n, ...: the slope of the last pair whose finer error is
/// above 1e-12 (the rounding floor of this test is 1e-15: |e^{2(A+B)}| ~ 1e3 amplifies the long double
/// rounding of every step) and whose coarser error is below 1e-3 (asymptotic range).
double observed_order(const FlowMethod& m, std::string& log) {
  MatrixFlows f = random_pair();
  std::vector<std::pair<long, R>> e;
  for (long n = 1; n <= 512; n *= 2) {
    e.emplace_back(n, error_after(f, m, n));
    if (e.back().second < 1e-15L) break;
  }
  double order = std::nan("");
  for (std::size_t i = 0; i + 1 < e.size(); ++i) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%ld:%.3Le ", e[i].first, e[i].second);
    log += buf;
    if (e[i].second < 1e-3L && e[i + 1].second > 1e-12L)
      order = std::log2(static_cast<double>(e[i].second / e[i + 1].second));
  }
  return order;
}

FlowMethod flow(const std::string& spec) {
  return resolve_flow_method(spec, OperatorStructure::general, 64, "long double");
}

}  // namespace

TEST(Extrapolation, SecondOrderBaseGivesChinsCoefficients) {
  for (const std::vector<long>& k : {std::vector<long>{1, 2}, {1, 2, 3}, {1, 2, 3, 4, 5}, {1, 2, 4}, {2, 3, 7}})
    EXPECT_EQ(extrapolation_coefficients(k, 2), mpe_coefficients(k).c);
}

TEST(Extrapolation, FourthOrderBaseIsChinEq27) {
  const auto c = extrapolation_coefficients({1, 2}, 4);
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(c[0], mpq_class(-1, 15));
  EXPECT_EQ(c[1], mpq_class(16, 15));
  mpq_class s = 0;
  for (const auto& x : extrapolation_coefficients({1, 2, 3, 5}, 4)) s += x;
  EXPECT_EQ(s, 1);
}

TEST(Applicability, ClassicalOnlyMethodsAreRefusedWithTheReason) {
  for (const std::string spec : {"N4", "M4-RKN", "A6", "DP12", "Aprime"}) {
    try {
      (void)resolve_flow_method(spec, OperatorStructure::rkn, 53, "double");
      ADD_FAILURE() << spec << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("q'' = a(q) only"), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW((void)resolve_flow_method("M10-adaptive", OperatorStructure::rkn, 53, "double"), std::invalid_argument);
  // RKN splittings run on Schrodinger-type pairs, not on general ones.
  EXPECT_NO_THROW((void)resolve_flow_method("AC1", OperatorStructure::rkn, 53, "double"));
  EXPECT_THROW((void)resolve_flow_method("AC1", OperatorStructure::general, 53, "double"), std::invalid_argument);
  EXPECT_THROW((void)resolve_flow_method("RKNb6", OperatorStructure::general, 53, "double"), std::invalid_argument);
  EXPECT_THROW((void)resolve_flow_method("mpe-over:AC1:1,2", OperatorStructure::rkn, 53, "double"),
               std::invalid_argument);  // not symmetric
  EXPECT_THROW((void)resolve_flow_method("mpe-over:FR", OperatorStructure::rkn, 53, "double"), std::invalid_argument);
  EXPECT_THROW((void)resolve_flow_method("mpe4:1,1", OperatorStructure::rkn, 53, "double"), std::invalid_argument);
}

// The forward methods named in refusals: Chin's 4A only where its gradient term exists and is asked for (a
// kinetic-potential pair, whose double commutator is a function), the multi-product expansions everywhere, the
// complex RKN splittings only for kinetic-potential pairs.
TEST(Applicability, ForwardAlternativesNameOnlyMethodsThatApply) {
  const std::string rkn_grad = forward_alternatives(OperatorStructure::rkn, true);
  const std::string rkn = forward_alternatives(OperatorStructure::rkn, false);
  const std::string general = forward_alternatives(OperatorStructure::general, true);
  EXPECT_NE(rkn_grad.find("Chin's 4A"), std::string::npos) << rkn_grad;
  EXPECT_EQ(rkn.find("4A"), std::string::npos) << rkn;
  EXPECT_EQ(general.find("4A"), std::string::npos) << general;
  for (const auto& s : {rkn_grad, rkn, general}) EXPECT_NE(s.find("multi-product M4..M"), std::string::npos) << s;
  EXPECT_NE(rkn.find("AC1"), std::string::npos) << rkn;
  EXPECT_EQ(general.find("AC1"), std::string::npos) << general;
  EXPECT_EQ(rkn_grad.find('\n'), std::string::npos);
}

TEST(OperatorOrder, EveryApplicableCatalogMethod) {
  int tested = 0;
  for (const auto& def : catalog()) {
    if (def.info.family == "rkn" || def.info.adaptive || !order_holds_for_general_operators(def.info)) continue;
    if (def.info.order > 12) continue;  // M14, M16: below the rounding floor at every step size measurable here
    const FlowMethod m = flow(def.info.name);
    std::string log;
    const double p = observed_order(m, log);
    EXPECT_NEAR(p, def.info.order, 0.35) << def.info.name << " errors " << log;
    std::printf("%-12s order %2d observed %.2f\n", def.info.name.c_str(), def.info.order, p);
    ++tested;
  }
  EXPECT_GE(tested, 10);
}

TEST(OperatorOrder, MultiProductOrders2To12AndHigherOrderBases) {
  for (int n = 1; n <= 6; ++n) {
    const FlowMethod m = flow("M" + std::to_string(2 * n));
    std::string log;
    EXPECT_NEAR(observed_order(m, log), 2 * n, 0.35) << "M" << 2 * n << " errors " << log;
  }
  for (const auto& [spec, order] : std::vector<std::pair<std::string, int>>{
           {"mpe-vv:1,2,3", 6}, {"mpe4:1,2", 6}, {"mpe4:1,2,3", 8}, {"mpe-over:Y6:1,2", 8}}) {
    const FlowMethod m = flow(spec);
    EXPECT_EQ(m.info.order, order) << spec;
    std::string log;
    EXPECT_NEAR(observed_order(m, log), order, 0.35) << spec << " errors " << log;
  }
}

TEST(OperatorEngine, MergingAcrossStepsChangesNothingButTheCount) {
  MatrixFlows f = random_pair();
  const FlowMethod m = flow("PV");
  FlowIntegrator<MatrixFlows> integ(m);
  std::vector<C> a{C(1), C(0), C(0), C(0)}, b = a;
  integ.integrate(f, a, 0.1L, 10);
  const long merged = f.applications;
  f.applications = 0;
  for (int i = 0; i < 10; ++i) integ.step(f, b, 0.1L);
  EXPECT_EQ(merged, 21);  // drift, then 10 x (kick, drift)
  EXPECT_EQ(f.applications, 30);
  EXPECT_EQ(integ.applications(f, 10), (std::pair<long, long>{11, 10}));
  for (int i = 0; i < N; ++i) EXPECT_LT(std::abs(a[i] - b[i]), 1e-15L);
}

// Drift and kick for q'' = a(q) as operator flows: the operator layer runs the classical methods through
// the classical engine's loop. Velocity Verlet is bitwise the classical engine (the same sub-steps in the
// same order; the merged kick h/2 + h/2 = h is exact either way); Forest-Ruth and the multi-product M8
// agree to rounding (the merged coefficient and the MPE's combination round differently), with the same
// force count (the classical engine's cache saves nothing on these schemes).
TEST(OperatorEngine, DriftKickFlowsRunTheClassicalMethods) {
  using V = std::array<double, 2>;
  const KeplerProblem<double> p(0.5);
  EngineOptions plain;
  plain.compensated = Compensation::off;
  const double h = 0.01;
  const long n = 400;
  for (const std::string name : {"VV", "FR", "M8"}) {
    SCOPED_TRACE(name);
    auto classical = make_integrator<V>(resolve_method(name), KeplerForce{}, plain);
    State<V> a = p.initial_state();
    classical.integrate(a, h, n);
    DriftKickFlows<V, KeplerForce> flows{KeplerForce{}};
    FlowIntegrator<DriftKickFlows<V, KeplerForce>> integ(
        resolve_flow_method(name, OperatorStructure::rkn, 53, "double"));
    State<V> b = p.initial_state();
    integ.integrate(flows, b, h, n);
    for (int i = 0; i < 2; ++i) {
      if (name == "VV") {
        EXPECT_EQ(a.q[i], b.q[i]);
        EXPECT_EQ(a.v[i], b.v[i]);
      } else {
        EXPECT_NEAR(a.q[i], b.q[i], 1e-12);
        EXPECT_NEAR(a.v[i], b.v[i], 1e-12);
      }
    }
    EXPECT_EQ(flows.force_evals(), classical.force_evals());
  }
  DriftKickFlows<V, KeplerForce> flows{KeplerForce{}};
  FlowIntegrator<DriftKickFlows<V, KeplerForce>> complex_method(
      resolve_flow_method("AC1", OperatorStructure::rkn, 53, "double"));
  State<V> s = p.initial_state();
  EXPECT_THROW(complex_method.integrate(flows, s, h, 1), std::invalid_argument);
}

// The counts applications() declares are those the flows receive, for splittings and multi-product expansions,
// over one step and over many.
TEST(OperatorEngine, DeclaredApplicationsAreTheFlowsCalls) {
  for (const std::string spec : {"PV", "FR", "M4", "M6", "mpe-vv:1,2,3"}) {
    for (long n : {1L, 7L}) {
      SCOPED_TRACE(spec + " n = " + std::to_string(n));
      MatrixFlows f = random_pair();
      FlowIntegrator<MatrixFlows> integ(flow(spec));
      std::vector<C> s{C(1), C(0), C(0), C(0)};
      integ.integrate(f, s, 0.1L, n);
      const auto [a, b] = integ.applications(f, n);
      EXPECT_EQ(a + b, f.applications);
      EXPECT_GT(b, 0);
    }
  }
}

// A scheme whose first and last sub-steps are of different flows (Lie-Trotter: A, then B) has nothing to merge
// across steps: n steps of integrate() are n single steps, bitwise and flow call for flow call; Strang's splitting
// (B/2, A, B/2) merges its half kicks, n - 1 calls fewer, and ends where its single steps end.
TEST(OperatorEngine, OnlyASchemeEndingInItsFirstFlowMergesAcrossSteps) {
  constexpr long n = 7;
  const SplittingScheme<C> lie{{{Flow::drift, C(1)}, {Flow::kick, C(1)}}};
  const SplittingScheme<C> strang{{{Flow::kick, C(0.5L)}, {Flow::drift, C(1)}, {Flow::kick, C(0.5L)}}};
  for (const auto& [scheme, merged] : {std::pair{lie, 0L}, std::pair{strang, n - 1}}) {
    SCOPED_TRACE(merged ? "Strang" : "Lie-Trotter");
    MatrixFlows f = random_pair(), g = f;
    const SplittingFlowStepper<MatrixFlows> st(scheme);
    EXPECT_EQ(st.merges(f), merged > 0);
    std::vector<C> s{C(1), C(0), C(0), C(0)}, t = s;
    st.integrate(f, s, 0.1L, n);
    for (long i = 0; i < n; ++i) st.step(g, t, 0.1L);
    const auto [a, b] = st.applications(f, n);
    EXPECT_EQ(a + b, f.applications);
    EXPECT_EQ(f.applications, g.applications - merged);
    for (int i = 0; i < N; ++i) EXPECT_LT(std::abs(s[i] - t[i]), 1e-15L) << i;
  }
}
