// Building integrators from several threads at once. Coefficients are built in MPFR at a reference
// precision that Boost 1.74 keeps in one process-wide variable (core/bignum.hpp, BigPrecision); threads
// that build methods for different working precisions must each get exactly the coefficients a
// single-threaded build gives them, and leave the default precision as they found it. Boost's variable is
// atomic, so sharing it is a race of logic that ThreadSanitizer does not see; the bitwise comparison does
// (without BigPrecision's lock this test measured thousands of mismatched coefficients, and the default
// left at 79 digits instead of 20). The same variable holds the working precision of mpfr_real (MpfrPrecision,
// core/extended.hpp), whose scope takes the same lock. The tsan preset (NYSTROM_TSAN) runs the test under
// ThreadSanitizer too, for the data races it can see (the refinement cache, MPFR's own caches).
#include <gtest/gtest.h>

#include <mpfr.h>

#include <array>
#include <cmath>
#include <string>
#include <thread>
#include <vector>

#include "experiments/kepler.hpp"
#include "nystrom/nystrom.hpp"

using namespace nystrom;

namespace {

// Methods of every family: closed forms (FR, Y6), exact rationals (DP12, N4), published decimals that are
// refined beyond their digits (KL8 at wide precisions), complex coefficients (AC1), a multi-product method.
const std::vector<std::string> kMethods = {"FR", "Y6", "DP12", "N4", "KL8", "AC1", "M8"};
// Working precisions whose reference precisions differ (reference_bits: 256, 256, 364, 664).
const std::vector<long> kBits = {53, 113, 300, 600};

void append(std::vector<bigfloat>& out, const bigcomplex& z) {
  out.push_back(z.re);
  out.push_back(z.im);
}

void append(std::vector<bigfloat>& out, const std::vector<bigcomplex>& v) {
  for (const auto& z : v) append(out, z);
}

void append(std::vector<bigfloat>& out, const SplittingScheme<bigcomplex>& s) {
  for (const auto& st : s.steps) append(out, st.coef);
}

// Every coefficient of a method, in a fixed order (of a multi-product method, its base: the sequence {k_i} is
// integers).
// (Copies keep the precision of their source; a bigfloat made from a number here, outside any BigPrecision,
// would take whatever default precision another thread's guard has set.)
std::vector<bigfloat> coefficients(const MethodData& data) {
  std::vector<bigfloat> out;
  if (const auto* sp = std::get_if<SplittingScheme<bigcomplex>>(&data)) {
    append(out, *sp);
  } else if (const auto* t = std::get_if<RknTableau<bigcomplex>>(&data)) {
    append(out, t->c);
    for (const auto& row : t->a) append(out, row);
    append(out, t->b);
    append(out, t->B);
    append(out, t->bhat);
    append(out, t->Bhat);
  } else {
    append(out, std::get<MpeDef>(data).base);
  }
  return out;
}

// Bitwise equality of two MPFR numbers: the same precision, sign and value.
bool same_bits(const bigfloat& a, const bigfloat& b) {
  mpfr_srcptr x = a.backend().data();
  mpfr_srcptr y = b.backend().data();
  if (mpfr_get_prec(x) != mpfr_get_prec(y) || mpfr_signbit(x) != mpfr_signbit(y)) return false;
  return mpfr_equal_p(x, y) || (mpfr_nan_p(x) && mpfr_nan_p(y));
}

// The coefficients of every (method, bits) pair, in kMethods x kBits order.
std::vector<std::vector<bigfloat>> build_all(const std::vector<MethodDef>& defs, std::size_t rotate) {
  const std::size_t n = defs.size() * kBits.size();
  std::vector<std::vector<bigfloat>> out(n);
  for (std::size_t j = 0; j < n; ++j) {
    const std::size_t i = (j + rotate) % n;  // each thread starts elsewhere, so different precisions overlap
    const long bits = kBits[i % kBits.size()];
    out[i] = coefficients(method_data_for(defs[i / kBits.size()], bits, std::to_string(bits) + " bits"));
  }
  return out;
}

template <class T>
State<std::array<T, 2>> run_kepler_steps(const MethodDef& def) {
  auto integ = make_integrator<std::array<T, 2>>(def, KeplerForce{});
  auto s = KeplerProblem<T>(T(0.5)).initial_state();
  integ.integrate(s, T(1) / T(16), 40);
  return s;
}

// An mpfr_real exactly, as text: its precision in bits and its value in hexadecimal ("%Ra" prints every bit).
std::string exact_text(const mpfr_real& x) {
  char* hex = nullptr;
  if (mpfr_asprintf(&hex, "%Ra", x.backend().data()) < 0) return "(mpfr_asprintf failed)";
  std::string out = std::to_string(mpfr_get_prec(x.backend().data())) + " bits " + hex;
  mpfr_free_str(hex);
  return out;
}

// A method's final state after Kepler steps in mpfr_real at `bits`: the scope is opened, the integrator built
// and run, and the state written out exactly before the scope ends.
std::vector<std::string> mpfr_kepler_steps(const MethodDef& def, long bits) {
  const MpfrPrecision scope(bits);
  const auto s = run_kepler_steps<mpfr_real>(def);
  return {exact_text(s.q[0]), exact_text(s.q[1]), exact_text(s.v[0]), exact_text(s.v[1])};
}

// Bitwise equality of two states, value by value (long double's padding bytes are not part of the value).
template <class T>
bool same_state(const State<std::array<T, 2>>& a, const State<std::array<T, 2>>& b) {
  auto same = [](T x, T y) { return x == y && std::signbit(x) == std::signbit(y); };
  for (std::size_t i = 0; i < 2; ++i)
    if (!same(a.q[i], b.q[i]) || !same(a.v[i], b.v[i])) return false;
  return true;
}

}  // namespace

// MPFR keeps its caches (constants such as pi, and the like) per thread: a thread that used MPFR frees them
// with mpfr_free_cache() before it ends, as MPFR's manual asks, or LeakSanitizer reports them as leaks.
template <class F>
std::thread mpfr_thread(F f) {
  return std::thread([f] {
    f();
    mpfr_free_cache();
  });
}

TEST(Threads, ConcurrentCoefficientBuildsAreBitwiseThoseOfOneThread) {
  std::vector<MethodDef> defs;
  for (const auto& name : kMethods) defs.push_back(resolve_method(name));
  const unsigned before = bigfloat::default_precision();
  const auto expected = build_all(defs, 0);
  ASSERT_EQ(bigfloat::default_precision(), before);

  constexpr int kThreads = 4;
  constexpr int kRounds = 3;
  std::vector<std::vector<std::vector<std::vector<bigfloat>>>> got(kThreads);
  std::vector<std::thread> pool;
  for (int t = 0; t < kThreads; ++t)
    pool.push_back(mpfr_thread([&, t] {
      for (int r = 0; r < kRounds; ++r) got[t].push_back(build_all(defs, static_cast<std::size_t>(t * 5 + r)));
    }));
  for (auto& th : pool) th.join();

  EXPECT_EQ(bigfloat::default_precision(), before);
  for (int t = 0; t < kThreads; ++t)
    for (int r = 0; r < kRounds; ++r)
      for (std::size_t i = 0; i < expected.size(); ++i) {
        const auto& want = expected[i];
        const auto& have = got[t][r][i];
        const std::string where = kMethods[i / kBits.size()] + " at " + std::to_string(kBits[i % kBits.size()]) +
                                  " bits, thread " + std::to_string(t) + ", round " + std::to_string(r);
        ASSERT_EQ(have.size(), want.size()) << where;
        for (std::size_t k = 0; k < want.size(); ++k)
          EXPECT_TRUE(same_bits(have[k], want[k])) << where << ", coefficient " << k;
      }
}

// Integrators in double and long double built and run while other threads build coefficients at wide
// precisions: the final states are bitwise those of the same runs in one thread. (Real methods only: a
// complex-coefficient method needs a complex state.)
TEST(Threads, ConcurrentIntegratorsRunBitwiseAsInOneThread) {
  std::vector<MethodDef> defs;
  for (const auto& name : kMethods)
    if (!resolve_method(name).info.complex) defs.push_back(resolve_method(name));
  ASSERT_GE(defs.size(), 5u);
  std::vector<State<std::array<double, 2>>> want_d;
  std::vector<State<std::array<long double, 2>>> want_l;
  for (const auto& d : defs) {
    want_d.push_back(run_kepler_steps<double>(d));
    want_l.push_back(run_kepler_steps<long double>(d));
  }
  const unsigned before = bigfloat::default_precision();

  std::vector<State<std::array<double, 2>>> got_d(defs.size());
  std::vector<State<std::array<long double, 2>>> got_l(defs.size());
  std::vector<std::thread> pool;
  pool.push_back(mpfr_thread([&] {
    for (std::size_t i = 0; i < defs.size(); ++i) got_d[i] = run_kepler_steps<double>(defs[i]);
  }));
  pool.push_back(mpfr_thread([&] {
    for (std::size_t i = defs.size(); i-- > 0;) got_l[i] = run_kepler_steps<long double>(defs[i]);
  }));
  for (std::size_t w = 0; w < 2; ++w)
    pool.push_back(mpfr_thread([&, w] {
      for (const auto& d : defs) method_data_for(d, w == 0 ? 600 : 300, "wide");
    }));
  for (auto& th : pool) th.join();

  EXPECT_EQ(bigfloat::default_precision(), before);
  for (std::size_t i = 0; i < defs.size(); ++i) {
    EXPECT_TRUE(same_state(got_d[i], want_d[i])) << defs[i].info.name << " in double";
    EXPECT_TRUE(same_state(got_l[i], want_l[i])) << defs[i].info.name << " in long double";
  }
}

// Threads that each open an MpfrPrecision scope at a different precision, build an integrator and run Kepler
// steps in mpfr_real, while another thread builds coefficients at a wide reference precision: every final state
// is bitwise (precision and value) that of the same run in one thread, and the default precision is left as it
// was. (Without the scope's lock, a value made from T(1) or a temporary takes whichever thread's precision is
// the default at that moment.)
TEST(Threads, ConcurrentMpfrScopesRunBitwiseAsInOneThread) {
  std::vector<MethodDef> defs;
  for (const auto& name : kMethods)
    if (!resolve_method(name).info.complex) defs.push_back(resolve_method(name));
  ASSERT_GE(defs.size(), 5u);
  const std::size_t n = defs.size() * kBits.size();
  std::vector<std::vector<std::string>> want(n);
  for (std::size_t i = 0; i < n; ++i) want[i] = mpfr_kepler_steps(defs[i / kBits.size()], kBits[i % kBits.size()]);
  const unsigned before = bigfloat::default_precision();
  ASSERT_EQ(MpfrPrecision::requested(), 0);

  constexpr std::size_t kThreads = 4;
  std::vector<std::vector<std::vector<std::string>>> got(kThreads, std::vector<std::vector<std::string>>(n));
  std::vector<std::thread> pool;
  for (std::size_t t = 0; t < kThreads; ++t)
    pool.push_back(mpfr_thread([&, t] {
      for (std::size_t j = 0; j < n; ++j) {
        // Method j / 4 at precision kBits[(j + t) % 4]: the threads' scopes ask for different precisions at once.
        const std::size_t i = j / kBits.size() * kBits.size() + (j + t) % kBits.size();
        got[t][i] = mpfr_kepler_steps(defs[i / kBits.size()], kBits[i % kBits.size()]);
      }
    }));
  pool.push_back(mpfr_thread([&] {
    for (const auto& d : defs) method_data_for(d, 600, "wide");
  }));
  for (auto& th : pool) th.join();

  EXPECT_EQ(bigfloat::default_precision(), before);
  EXPECT_EQ(MpfrPrecision::requested(), 0);
  for (std::size_t t = 0; t < kThreads; ++t)
    for (std::size_t i = 0; i < n; ++i)
      EXPECT_EQ(got[t][i], want[i]) << defs[i / kBits.size()].info.name << " at " << kBits[i % kBits.size()]
                                    << " bits, thread " << t;
}
