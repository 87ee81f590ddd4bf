// Extended and arbitrary precision: the scalar types (float128, dd, qd, mpfr:BITS), their run-time
// dispatch, exact conversion of reference coefficients, complex arithmetic, and the regime of the
// Chin (2010) Fig. 3: M16 and DP12 on Kepler at e = 0.9 with precession errors below 1e-28 per period.
//
// All multi-precision instantiations of the library live in this one translation unit (and in the
// order test for the high orders), not in every test.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <complex>
#include <cstdio>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include "experiments/kepler.hpp"
#include "nystrom/nystrom.hpp"
#include "support/catalog.hpp"

using namespace nystrom;

namespace {

/// The exact value of a working number as a wide MPFR number (all components added exactly).
bigfloat exact_value(double x) { return bigfloat(x); }
bigfloat exact_value(const float128& x) {
  const __float128 v = x.backend().value();
  const double hi = static_cast<double>(v);
  const __float128 r = v - hi;  // exact
  const double mid = static_cast<double>(r);
  const double lo = static_cast<double>(r - mid);
  bigfloat s(hi);
  s += bigfloat(mid);
  s += bigfloat(lo);
  return s;
}
bigfloat exact_value(const double_double& x) {
  bigfloat s(x.x[0]);
  s += bigfloat(x.x[1]);
  return s;
}
bigfloat exact_value(const quad_double& x) {
  bigfloat s(x.x[0]);
  for (int k = 1; k < 4; ++k) s += bigfloat(x.x[k]);
  return s;
}
bigfloat exact_value(const mpfr_real& x) { return x; }

/// Runs fn(type_tag<T>) for each extended precision, by name (mpfr at 256 bits).
template <class Fn>
void for_each_extended(Fn fn) {
  for (const std::string name : {"float128", "dd", "qd", "mpfr:256"}) {
    SCOPED_TRACE(name);
    dispatch_precision(name, [&](auto tag) {
      fn(tag, name);
      return 0;
    });
  }
}

}  // namespace

TEST(Precision, NamesAndBits) {
  EXPECT_EQ(dispatch_precision("float128", [](auto t) { return scalar_traits<typename decltype(t)::type>::bits(); }),
            113);
  EXPECT_EQ(dispatch_precision("dd", [](auto t) { return scalar_traits<typename decltype(t)::type>::bits(); }), 105);
  EXPECT_EQ(dispatch_precision("qd", [](auto t) { return scalar_traits<typename decltype(t)::type>::bits(); }), 210);
  // Boost 1.74 keeps the MPFR precision in decimal digits: mpfr:256 is 77 digits = 257 bits.
  EXPECT_EQ(dispatch_precision("mpfr:256", [](auto t) { return scalar_traits<typename decltype(t)::type>::bits(); }),
            257);
  EXPECT_EQ(dispatch_precision("mpfr:1000", [](auto t) { return scalar_traits<typename decltype(t)::type>::bits(); }),
            1001);  // 301 digits: Boost allocates 301 * 1000 / 301 + 1 bits
  for (const std::string name : {"float128", "dd", "qd", "mpfr:256"})
    EXPECT_EQ(dispatch_precision(name, [](auto t) { return scalar_traits<typename decltype(t)::type>::name(); }), name);
  EXPECT_EQ(dispatch_precision("quadruple", [](auto t) { return scalar_traits<typename decltype(t)::type>::name(); }),
            "float128");
  EXPECT_EQ(
      dispatch_precision("double-double", [](auto t) { return scalar_traits<typename decltype(t)::type>::name(); }),
      "dd");
  EXPECT_EQ(dispatch_precision("quad-double", [](auto t) { return scalar_traits<typename decltype(t)::type>::name(); }),
            "qd");
}

TEST(Precision, EffectiveMpfrBitsAreAtLeastTheRequestAndStable) {
  for (long bits = MpfrPrecision::min_bits; bits <= 2000; ++bits) {
    const unsigned d = MpfrPrecision::digits10_for(bits);
    const auto eff = boost::multiprecision::detail::digits10_2_2(d);
    ASSERT_GE(eff, static_cast<unsigned long>(bits));
    ASSERT_LE(eff, static_cast<unsigned long>(bits) + 4) << bits;            // no coarser than Boost's digits10 grid
    ASSERT_EQ(boost::multiprecision::detail::digits2_2_10(eff), d) << bits;  // results keep it (no drift)
  }
}

TEST(Precision, UnknownOrMalformedPrecisionIsAClearError) {
  auto fails = [](const std::string& name, const std::string& fragment) {
    try {
      dispatch_precision(name, [](auto) { return 0; });
      ADD_FAILURE() << "no error for '" << name << "'";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  fails("float129", "unknown precision 'float129'");
  fails("", "unknown precision");
  fails("mpfr", "mpfr:BITS");
  fails("mpfr:", "malformed MPFR precision");
  fails("mpfr:abc", "malformed MPFR precision");
  fails("mpfr:256x", "malformed MPFR precision");
  fails("mpfr:-256", "malformed MPFR precision");
  fails("mpfr:2.5e2", "malformed MPFR precision");
  fails("mpfr:12", "out of range");
  fails("mpfr:99999999", "out of range");
  fails("mpfr:123456789012345", "malformed MPFR precision");
  EXPECT_THROW(MpfrPrecision(10), std::invalid_argument);
  EXPECT_THROW(MpfrPrecision(MpfrPrecision::max_bits + 1), std::invalid_argument);
}

// Reference values reach the working type correctly rounded (within half an ulp of the type), not
// through double: this is what makes rational and closed-form coefficients exact to the precision.
TEST(Precision, ConversionFromReferenceIsExactToTheWorkingPrecision) {
  for_each_extended([](auto tag, const std::string&) {
    using T = typename decltype(tag)::type;
    const long p = scalar_traits<T>::bits();
    const long ref = reference_bits(p);
    BigPrecision guard(static_cast<unsigned>(ref + 200));  // exact_value sums need more than p bits
    for (const std::string text : {"1/3", "-2/7", "355/113", "1/1000000007", "123456789/1024", "-0.1"}) {
      bigfloat x;
      {
        BigPrecision at_ref(ref);
        x = big(text);
      }
      const T y = to_real<T>(x);
      const bigfloat err = abs(exact_value(y) - x);
      const bigfloat half_ulp = ldexp(abs(x), static_cast<int>(-p));  // 2^-p |x| >= half an ulp
      EXPECT_LE(err, half_ulp) << text << " error " << err << " > " << half_ulp;
    }
    const bigfloat sqrt2 = [&] {
      BigPrecision at_ref(ref);
      return bigfloat(sqrt(bigfloat(2)));
    }();
    EXPECT_LE(abs(exact_value(to_real<T>(sqrt2)) - sqrt2), ldexp(bigfloat(2), static_cast<int>(-p)));
  });
}

TEST(Precision, EpsilonIsTwoToOneMinusBits) {
  EXPECT_TRUE(epsilon_of<float128>() == std::numeric_limits<float128>::epsilon());
  // libqd's own epsilons are decimal literals, 2^-104 and 2^-209 to 15 digits
  EXPECT_NEAR(as_double(epsilon_of<double_double>()) / std::numeric_limits<::dd_real>::epsilon(), 1.0, 1e-14);
  EXPECT_NEAR(as_double(epsilon_of<quad_double>()) / std::numeric_limits<::qd_real>::epsilon(), 1.0, 1e-14);
  EXPECT_EQ(as_double(epsilon_of<double_double>()), std::ldexp(1.0, -104));
  EXPECT_EQ(as_double(epsilon_of<quad_double>()), std::ldexp(1.0, -209));
  {
    const float128 one(1), e = epsilon_of<float128>();
    EXPECT_TRUE(one + e != one);
    EXPECT_TRUE(one + e / 2 == one);
  }
  for (const long bits : {256L, 1000L, 3000L}) {
    SCOPED_TRACE(bits);
    MpfrPrecision scope(bits);
    const mpfr_real one(1), e = epsilon_of<mpfr_real>();
    EXPECT_TRUE(one + e != one);
    EXPECT_TRUE(one + e / 2 == one);  // ties to even
    EXPECT_EQ(static_cast<long>(mpfr_get_prec(e.backend().data())), MpfrPrecision::effective());
  }
}

// libqd accepts only int and double; the wrappers make T(long) exact and unambiguous.
TEST(Precision, IntegerConstructionIsExact) {
  const long big_odd = (1L << 60) + 1;
  EXPECT_TRUE(double_double(big_odd) - double_double(1L << 60) == double_double(1));
  EXPECT_TRUE(quad_double(big_odd) - quad_double(1L << 60) == quad_double(1));
  EXPECT_TRUE(double_double(-big_odd) + double_double(big_odd) == double_double(0));
  EXPECT_TRUE(double_double(3UL) == double_double(3));
  EXPECT_TRUE(quad_double(static_cast<long long>(-7)) == quad_double(-7.0));
  // Results of libqd arithmetic have the wrapper type, so a conditional mixes them freely.
  const double_double x(2);
  const double_double y = x > double_double(0) ? x : -x;
  EXPECT_TRUE(y == x);
}

// The wrapper's double-double products are libqd's code with a forced-inline two_prod: bitwise what
// libqd's operators give, including beyond libqd's splitting threshold (2^996), where split scales.
TEST(Precision, DoubleDoubleProductsAreBitwiseLibqds) {
  std::mt19937_64 gen(7);
  std::uniform_real_distribution<double> u(-1, 1);
  auto same = [](const ::dd_real& x, const ::dd_real& y) { return x.x[0] == y.x[0] && x.x[1] == y.x[1]; };
  for (int k = 0; k < 2000; ++k) {
    const bool huge = k % 50 == 0;  // a beyond the threshold, b small enough for a finite product
    const int ea = static_cast<int>(u(gen) * 500) + (huge ? 500 : 0),
              eb = static_cast<int>(u(gen) * 400) - (huge ? 500 : 0);
    const double a0 = std::ldexp(u(gen), ea), b0 = std::ldexp(u(gen), eb), d = std::ldexp(u(gen), eb);
    const double_double a = double_double(a0) + std::ldexp(u(gen), ea - 54);
    const double_double b = double_double(b0) + std::ldexp(u(gen), eb - 54);
    SCOPED_TRACE(k);
    EXPECT_TRUE(same(a * b, a.base() * b.base()));
    EXPECT_TRUE(same(a * d, a.base() * d));
    EXPECT_TRUE(same(d * a, d * a.base()));
    double_double x = a;
    x *= b;
    ::dd_real y = a.base();
    y *= b.base();
    EXPECT_TRUE(same(x, y));
    x = a;
    x *= d;
    y = a.base();
    y *= d;
    EXPECT_TRUE(same(x, y));
  }
}

// inv_r3(r2) = r2^(-3/2), the Kepler force's 1/r^3: the generic formula is exactly 1 / (r2 sqrt(r2))
// (so double's force is unchanged bit for bit); double-double and quad-double compute it without
// libqd's square root and division, and must be as accurate: within 3 machine epsilons of the exact
// value on these inputs (libqd's own formula reaches 2.1 in dd and 1.3 in qd on them; ours 1.6 and 1.8),
// and in double-double within 0.175 epsilon on average over them (measured: 0.148; without the correction's
// term z e_lo, of order 2^-105, 0.203). r2 over many decades, with full-precision low components,
// powers of 4 (where the double seed is exact) and the ranges beyond 2^-600 and 2^600 where the generic
// formula takes over.
TEST(Precision, InverseCubeOfTheRadiusIsAccurate) {
  for (const double x : {1.0, 0.81, 2.0, 3.7e-5, 1e20}) EXPECT_EQ(-inv_r3(x), -1.0 / (x * std::sqrt(x))) << x;
  BigPrecision wide(700);
  std::mt19937_64 gen(11);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<std::array<double, 4>> inputs;  // the components of r2, decreasing
  for (int k = 0; k < 3000; ++k) {
    const int e =
        k < 2800 ? static_cast<int>(u(gen) * 1200) - 600 : (k % 2 ? 1 : -1) * (601 + static_cast<int>(u(gen) * 10));
    const double m = k % 10 == 0 ? 1.0 : 1 + 3 * u(gen);  // every tenth a power of 2 (or 4)
    const bool lows = k % 20 != 0;
    inputs.push_back({std::ldexp(m, e), lows ? std::ldexp(u(gen) - 0.5, e - 53) : 0.0,
                      lows ? std::ldexp(u(gen) - 0.5, e - 107) : 0.0, lows ? std::ldexp(u(gen) - 0.5, e - 160) : 0.0});
  }
  for (int k = -20; k <= 20; ++k) inputs.push_back({std::ldexp(1.0, 2 * k), 0.0, 0.0, 0.0});
  int checked = 0, dd_count = 0;
  double dd_sum = 0;
  auto check = [&](auto r2, long p) {
    const bigfloat x = exact_value(r2);
    const bigfloat exact = 1 / (x * sqrt(x));
    // Only where the type carries its full precision (last component normal) in the result and in
    // r2^(3/2), the generic formula's intermediate: both above 2^(p - 1021).
    const bigfloat tiny = ldexp(bigfloat(1), static_cast<int>(p - 1021));
    if (exact < tiny || 1 / exact < tiny) return;
    ++checked;
    const bigfloat rel = abs(exact_value(inv_r3(r2)) - exact) / exact;
    EXPECT_LE(rel, ldexp(bigfloat(3), static_cast<int>(1 - p))) << "r2 = " << x.str(20);
    if constexpr (std::is_same_v<decltype(r2), double_double>) {
      dd_sum += static_cast<double>(bigfloat(ldexp(rel, static_cast<int>(p - 1))));
      ++dd_count;
    }
  };
  for (const auto& c : inputs) {
    double hi, lo;
    hi = qd::two_sum(c[0], c[1], lo);  // a normalised double-double
    check(double_double(hi, lo), scalar_traits<double_double>::bits());
    check(quad_double(::qd_real(c[0]) + c[1] + c[2] + c[3]), scalar_traits<quad_double>::bits());
  }
  EXPECT_GT(checked, 5000);
  ASSERT_GT(dd_count, 2500);
  std::printf("double-double inv_r3: mean relative error %.3f eps over %d inputs\n", dd_sum / dd_count, dd_count);
  EXPECT_LT(dd_sum / dd_count, 0.175);
}

// mpfr:BITS fixes the precision of every working value, including coefficients converted while the
// catalog's wider reference precision is active, and results of arithmetic on them.
TEST(Precision, MpfrWorkingPrecisionIsKeptThroughoutARun) {
  const unsigned before = mpfr_real::default_precision();
  {
    const MpfrPrecision scope(parse_mpfr_bits("300"));
    using T = mpfr_real;
    const long eff = scalar_traits<T>::bits();
    EXPECT_GE(eff, 300);
    auto prec = [](const T& x) { return static_cast<long>(mpfr_get_prec(x.backend().data())); };
    EXPECT_EQ(prec(T(1)), eff);
    {
      BigPrecision wide(reference_bits(eff));
      EXPECT_EQ(prec(to_real<T>(big("1/3"))), eff);
    }
    auto integ = make_integrator<std::array<T, 2>>(resolve_method("M8"), KeplerForce{});
    const KeplerProblem<T> prob(T(0.5));
    auto s = prob.initial_state();
    integ.integrate(s, T(1) / T(10), 20);
    for (const auto& x : {s.q[0], s.q[1], s.v[0], s.v[1]}) EXPECT_EQ(prec(x), eff);
    auto split = make_integrator<std::array<T, 2>>(resolve_method("FR"), KeplerForce{});
    split.integrate(s, T(1) / T(10), 20);
    for (const auto& x : {s.q[0], s.q[1], s.v[0], s.v[1]}) EXPECT_EQ(prec(x), eff);
  }
  EXPECT_EQ(mpfr_real::default_precision(), before);
}

// Very wide MPFR: MPE coefficients, epsilon and the Kepler solution work beyond double's exponent range
// (2^-1074), and the result agrees with quad-double to quad-double's precision.
TEST(Precision, VeryWideMpfrRuns) {
  const auto def = resolve_method("M8");
  const auto wide = dispatch_precision("mpfr:2000", [&](auto tag) {
    using T = typename decltype(tag)::type;
    return run_kepler<T>(def, 0.5, 64, 1);
  });
  const auto qd = run_kepler<quad_double>(def, 0.5, 64, 1);
  EXPECT_EQ(wide.precision, "mpfr:2000");
  EXPECT_GT(std::abs(qd.precession_per_period), 1e-12);                      // a visible method error ...
  EXPECT_NEAR(wide.precession_per_period, qd.precession_per_period, 1e-40);  // ... identical in both
  EXPECT_NEAR(wide.energy_error, qd.energy_error, 1e-40);
}

// std::complex<T> (complex sqrt in the Kepler force) is accurate to T's precision: compared with the
// same computation at 600 bits.
TEST(Precision, ComplexKeplerForceIsAccurate) {
  using R = std::complex<mpfr_real>;
  const std::array<std::array<std::string, 2>, 3> qs{{{"0.7", "0.3"}, {"-1.1", "0.05"}, {"0.2", "-1.9"}}};
  const std::array<std::string, 3> imag{"0.01", "-0.2", "0.003"};
  std::vector<std::array<R, 2>> ref;
  {
    MpfrPrecision wide(600);
    for (std::size_t k = 0; k < qs.size(); ++k) {
      std::array<R, 2> q{R(big(qs[k][0]), big(imag[k])), R(big(qs[k][1]), big("1/7"))}, a;
      KeplerForce{}(q, a);
      ref.push_back(a);
    }
  }
  for_each_extended([&](auto tag, const std::string&) {
    using T = typename decltype(tag)::type;
    using C = std::complex<T>;
    const long p = scalar_traits<T>::bits();
    for (std::size_t k = 0; k < qs.size(); ++k) {
      std::array<C, 2> q, a;
      {
        BigPrecision wide(700);
        q = {C(to_real<T>(big(qs[k][0])), to_real<T>(big(imag[k]))),
             C(to_real<T>(big(qs[k][1])), to_real<T>(big("1/7")))};
      }
      KeplerForce{}(q, a);  // at the working precision
      BigPrecision wide(700);
      for (int i = 0; i < 2; ++i) {
        const bigfloat dre = exact_value(a[i].real()) - ref[k][i].real();
        const bigfloat dim = exact_value(a[i].imag()) - ref[k][i].imag();
        const bigfloat size = abs(ref[k][i].real()) + abs(ref[k][i].imag());
        // the inputs are rounded to T, and the force amplifies that a little: 64 ulps of T
        EXPECT_LE(sqrt(dre * dre + dim * dim), ldexp(size, static_cast<int>(6 - p))) << "point " << k << " i " << i;
      }
    }
  });
}

// Complex-coefficient methods (Chambers' third-order splitting, a closed form; Gürkan's AC1, a decimal
// table refined to each precision) run on the complexified state in every precision, and all of them
// agree far beyond double precision.
TEST(Precision, ComplexMethodsAgreeAcrossPrecisions) {
  for (const std::string method : {"Chambers", "AC1"}) {
    SCOPED_TRACE(method);
    const auto def = resolve_method(method);
    ASSERT_TRUE(def.info.complex);
    const auto qd = run_kepler<quad_double>(def, 0.5, 400, 2);
    const auto dbl = run_kepler<double>(def, 0.5, 400, 2);
    EXPECT_GT(std::abs(qd.position_error), 1e-16);  // a visible method error
    EXPECT_NEAR(dbl.position_error, qd.position_error, 1e-13);
    for_each_extended([&](auto tag, const std::string& name) {
      using T = typename decltype(tag)::type;
      const auto r = run_kepler<T>(def, 0.5, 400, 2);
      EXPECT_EQ(r.precision, name);
      // float128 and dd carry about 32 digits; the errors are 1e-7 (Chambers) and 1e-13 (AC1)
      EXPECT_NEAR(r.position_error, qd.position_error, 1e-28);
      EXPECT_NEAR(r.precession_per_period, qd.precession_per_period, 1e-28);
    });
  }
}

// Chin (2010), Fig. 3: "the highest order considered is 16 because quadruple precision is inadequate
// for precision below 1e-30". M16 at e = 0.9, 3000 steps per period (108 000 force evaluations):
// method error 4.4e-30 per period, round-off 3e-31 in float128 and 2e-29 in dd.
TEST(Precision, M16ReachesBelow1e28PerPeriodAtE09) {
  const auto def = resolve_method("M16");
  for_each_extended([&](auto tag, const std::string&) {
    using T = typename decltype(tag)::type;
    const auto r = run_kepler<T>(def, 0.9, 3000, 1);
    EXPECT_LT(std::abs(r.precession_per_period), 1e-28);
    EXPECT_LT(r.energy_error, 1e-27);
  });
  // Double stops at its round-off floor, many orders of magnitude above.
  EXPECT_GT(std::abs(run_kepler<double>(def, 0.9, 3000, 1).precession_per_period), 1e-20);
}

// DP12 (Dormand, El-Mikkawy & Prince; exact rationals), the other curve of Fig. 3 below 1e-28:
// 11000 steps per period (187 000 force evaluations), method error about 2e-29.
TEST(Precision, DP12ReachesBelow1e28PerPeriodAtE09) {
  const auto def = resolve_method("DP12");
  for_each_extended([&](auto tag, const std::string&) {
    using T = typename decltype(tag)::type;
    const auto r = run_kepler<T>(def, 0.9, 11000, 1);
    EXPECT_LT(std::abs(r.precession_per_period), 1e-28);
    EXPECT_LT(r.energy_error, 1e-27);
  });
}

// Decimal coefficients are refined to the working precision: SS10's 26 published digits leave an
// error floor of 1e-25 in quadruple precision that the refined set does not have.
TEST(Precision, RefinedCoefficientsRemoveThePublishedDigitsFloor) {
  const auto def = resolve_method("SS10");
  ASSERT_EQ(def.info.published_digits, 26);
  auto as_published = def;
  as_published.info.published_digits = 0;  // pretend the 26 digits were exact: no refinement
  const auto refined = run_kepler<float128>(def, 0.5, 2000, 1);
  const auto published = run_kepler<float128>(as_published, 0.5, 2000, 1);
  EXPECT_GT(published.position_error, 1e-26);  // the floor of the published digits
  EXPECT_LT(refined.position_error, 1e-27);    // the method's own error, 1.4e-28
  // In double the published digits are more than enough and are used as they are.
  EXPECT_DOUBLE_EQ(run_kepler<double>(def, 0.5, 200, 1).position_error,
                   run_kepler<double>(as_published, 0.5, 200, 1).position_error);
}

// Asking for a precision that a method's coefficients cannot reach, and cannot be refined to, is a
// clear error (here: an RKN tableau printed with 16 digits).
TEST(Precision, PrecisionBeyondUnrefinableCoefficientsIsAClearError) {
  const MethodDef n4 = test::decimal_n4();
  EXPECT_NO_THROW(run_kepler<double>(n4, 0.5, 100, 1));
  for_each_extended([&](auto tag, const std::string& name) {
    using T = typename decltype(tag)::type;
    try {
      run_kepler<T>(n4, 0.5, 100, 1);
      ADD_FAILURE() << "no error";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("published with 16 digits, too few for " + name), std::string::npos)
          << e.what();
    }
  });
}
