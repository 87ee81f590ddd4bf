// Extended and arbitrary precision scalar types.
//
//   float128        IEEE quadruple (113-bit significand): Boost.Multiprecision float128 over GCC's
//                   __float128 and libquadmath.
//   double_double   libqd's dd_real (an unevaluated sum of two doubles, about 106 bits; Hida, Li and
//                   Bailey, "Library for double-double and quad-double arithmetic", 2000) in a thin
//                   wrapper, qd_number<dd_real>, that completes it as a scalar type for generic code
//                   (dd_real itself accepts only int and double, so T(long) would be ambiguous).
//   quad_double     libqd's qd_real (four doubles, about 212 bits), likewise qd_number<qd_real>.
//   mpfr_real       MPFR through Boost.Multiprecision (mpfr_float_backend<0>, expression templates
//                   off), with a precision chosen at run time by an MpfrPrecision scope.
//
// Every type has scalar_traits (name, bits, exact conversion from an MPFR reference value) and the
// math functions the library calls unqualified (sqrt, abs, sin, cos, acos, atan2, floor, ldexp,
// isfinite) reachable by argument-dependent lookup. std::complex<T> of each works for the
// complex-coefficient methods (libstdc++'s generic complex code calls those same functions).
//
// "bits" is the significand precision p with epsilon_of<T>() = 2^(1-p) the library's own machine
// epsilon: 113 for float128, 105 for dd (dd_real::_eps = 2^-104), 210 for qd (qd_real::_eps = 2^-209).
//
// Run-time MPFR precision. Boost 1.74 keeps one process-wide default precision for every
// mpfr_float_backend<0> number (shared with bigfloat, the catalog's reference type), stores it in
// decimal digits, and gives the result of an operation the largest precision of its operands.
// MpfrPrecision therefore fixes the precision of every working value:
//   * it sets Boost's default precision, so values made from builtins (T(2), T(0.9)) have it;
//   * from_mpfr creates values with exactly that precision, whatever the default is at the time
//     (the catalog builds coefficients under a wider BigPrecision);
//   * "mpfr:BITS" asks for at least BITS bits; the effective precision is the smallest one Boost
//     can represent from a digits10 setting (e.g. 257 for 256), reported by scalar_traits::bits().
// Not thread-safe, like Boost's default precision itself: one working precision per process at a time.
#pragma once

#include <algorithm>
#include <cmath>
#include <complex>
#include <concepts>
#include <limits>
#include <stdexcept>
#include <string>

#include <boost/multiprecision/float128.hpp>
#include <boost/multiprecision/mpfr.hpp>

// Hardware fused multiply-add for libqd's error-free products when the target has it (e.g. built with
// -march=native, CMake option NYSTROM_NATIVE): two_prod becomes p = a b, e = fma(a, b, -p) instead of
// Dekker's 17-flop splitting, the same exact result about twice as fast for double-double. libqd's
// configuration leaves these macros for the user to define; its compiled functions (sqrt, sin, ...)
// are unaffected. qd headers must not be included before this one (the inline functions would differ).
#if defined(__FMA__) && !defined(QD_FMA) && !defined(QD_FMS) && !defined(_QD_DD_REAL_H)
#define QD_FMA(a, b, c) __builtin_fma(a, b, c)
#define QD_FMS(a, b, c) __builtin_fma(a, b, -(c))
#endif
#include <qd/dd_real.h>
#include <qd/qd_real.h>

#include "nystrom/core/bignum.hpp"
#include "nystrom/core/scalar.hpp"

namespace nystrom {

using float128 = boost::multiprecision::float128;
/// The MPFR working type: the same C++ type as bigfloat, at the precision of the active MpfrPrecision.
using mpfr_real = bigfloat;

namespace detail {

/// Splits a finite MPFR value into N doubles x = d[0] + d[1] + ... with |d[k+1]| <= ulp(d[k]) / 2:
/// each d[k] is the nearest double to what remains, the subtraction is exact in MPFR (the remainder
/// of rounding x to 53 bits needs fewer bits than x), so only the last component is rounded.
template <int N>
void split_doubles(mpfr_srcptr x, double (&d)[N]) {
  if (!mpfr_number_p(x) || mpfr_zero_p(x)) {
    d[0] = mpfr_get_d(x, MPFR_RNDN);
    for (int k = 1; k < N; ++k) d[k] = 0.0;
    return;
  }
  mpfr_t r;
  mpfr_init2(r, std::max<mpfr_prec_t>(mpfr_get_prec(x), 64));
  mpfr_set(r, x, MPFR_RNDN);
  for (int k = 0; k < N; ++k) {
    d[k] = mpfr_get_d(r, MPFR_RNDN);
    mpfr_sub_d(r, r, d[k], MPFR_RNDN);
  }
  mpfr_clear(r);
}

/// Exact split of an integer of up to 64 bits into a non-overlapping pair of doubles.
template <std::integral I>
void split_integer(I v, double& hi, double& lo) {
  const long double x = static_cast<long double>(v);  // exact: 64-bit significand
  hi = static_cast<double>(x);
  lo = static_cast<double>(x - static_cast<long double>(hi));
}

}  // namespace detail

/// A libqd number (B = dd_real or qd_real) that behaves as a complete scalar type in generic code:
/// constructors from every integer type and from long double (exact; libqd accepts only int and
/// double, so T(long) would be ambiguous), explicit conversions to float, double and long double,
/// and arithmetic and math functions that return the same type (so `c ? x : -x` and std::complex<T>
/// work). All the arithmetic is libqd's; this adds none of its own.
template <class B>
struct qd_number : B {
  using B::B;
  qd_number() = default;
  qd_number(const B& v) : B(v) {}  // NOLINT: implicit, results of libqd functions
  template <std::integral I>
    requires(!std::same_as<I, int> && !std::same_as<I, bool>)
  qd_number(I v) : B(0.0) {  // NOLINT: implicit like the int constructor
    detail::split_integer(v, this->x[0], this->x[1]);
  }

  /// From long double, exactly (libqd has no such constructor, so T(1.0L) would be ambiguous).
  qd_number(long double v) : B(0.0) {  // NOLINT: implicit like the double constructor
    this->x[0] = static_cast<double>(v);
    this->x[1] = static_cast<double>(v - static_cast<long double>(this->x[0]));
  }

  const B& base() const { return *this; }
  /// Nearest double (the leading component of a normalised libqd number).
  explicit operator double() const { return this->x[0]; }
  explicit operator long double() const {
    long double s = 0;
    for (int k = static_cast<int>(sizeof(this->x) / sizeof(double)); k-- > 0;) s += this->x[k];
    return s;
  }
  explicit operator float() const { return static_cast<float>(this->x[0]); }

  qd_number operator-() const { return -base(); }
  qd_number& operator+=(const qd_number& o) { B::operator+=(o.base()); return *this; }
  qd_number& operator-=(const qd_number& o) { B::operator-=(o.base()); return *this; }
  qd_number& operator*=(const qd_number& o) { B::operator*=(o.base()); return *this; }
  qd_number& operator/=(const qd_number& o) { B::operator/=(o.base()); return *this; }
  qd_number& operator+=(double o) { B::operator+=(o); return *this; }
  qd_number& operator-=(double o) { B::operator-=(o); return *this; }
  qd_number& operator*=(double o) { B::operator*=(o); return *this; }
  qd_number& operator/=(double o) { B::operator/=(o); return *this; }

#define NYSTROM_QD_BINARY(op)                                                                                        \
  friend qd_number operator op(const qd_number& a, const qd_number& b) { return a.base() op b.base(); }               \
  friend qd_number operator op(const qd_number& a, double b) { return a.base() op b; }                                \
  friend qd_number operator op(double a, const qd_number& b) { return a op b.base(); }
  NYSTROM_QD_BINARY(+)
  NYSTROM_QD_BINARY(-)
  NYSTROM_QD_BINARY(*)
  NYSTROM_QD_BINARY(/)
#undef NYSTROM_QD_BINARY

#define NYSTROM_QD_UNARY(f) \
  friend qd_number f(const qd_number& a) { return ::f(a.base()); }
  NYSTROM_QD_UNARY(sqrt)
  NYSTROM_QD_UNARY(abs)
  NYSTROM_QD_UNARY(fabs)
  NYSTROM_QD_UNARY(floor)
  NYSTROM_QD_UNARY(ceil)
  NYSTROM_QD_UNARY(exp)
  NYSTROM_QD_UNARY(log)
  NYSTROM_QD_UNARY(log10)
  NYSTROM_QD_UNARY(sin)
  NYSTROM_QD_UNARY(cos)
  NYSTROM_QD_UNARY(tan)
  NYSTROM_QD_UNARY(asin)
  NYSTROM_QD_UNARY(acos)
  NYSTROM_QD_UNARY(atan)
  NYSTROM_QD_UNARY(sinh)
  NYSTROM_QD_UNARY(cosh)
  NYSTROM_QD_UNARY(tanh)
#undef NYSTROM_QD_UNARY
  friend qd_number atan2(const qd_number& y, const qd_number& x) { return ::atan2(y.base(), x.base()); }
  friend qd_number pow(const qd_number& a, const qd_number& b) { return ::pow(a.base(), b.base()); }
  friend qd_number pow(const qd_number& a, int n) { return ::pow(a.base(), n); }
  friend qd_number fmod(const qd_number& a, const qd_number& b) { return ::fmod(a.base(), b.base()); }
  friend qd_number ldexp(const qd_number& a, int e) { return ::ldexp(a.base(), e); }
  friend qd_number cbrt(const qd_number& a) { return ::nroot(a.base(), 3); }
  friend bool isfinite(const qd_number& a) { return a.isfinite(); }
  friend bool isnan(const qd_number& a) { return a.isnan(); }
  friend bool isinf(const qd_number& a) { return a.isinf(); }
  friend std::ostream& operator<<(std::ostream& os, const qd_number& a) { return os << a.base(); }
};

/// libqd's double-double (about 106 bits).
using double_double = qd_number<::dd_real>;
/// libqd's quad-double (about 212 bits).
using quad_double = qd_number<::qd_real>;

// ---- run-time MPFR precision ------------------------------------------------------------------

/// The working precision of mpfr_real for the lifetime of the scope (see the top of this file).
class MpfrPrecision {
 public:
  static constexpr long min_bits = 53;     // below double precision there is nothing to gain
  static constexpr long max_bits = 65536;  // about 19 700 digits; keeps the catalog build bounded

  /// Throws std::invalid_argument unless min_bits <= bits <= max_bits.
  explicit MpfrPrecision(long bits) : saved_(state()), saved_default_(mpfr_real::default_precision()) {
    if (bits < min_bits || bits > max_bits)
      throw std::invalid_argument("MPFR precision must be between " + std::to_string(min_bits) + " and " +
                                  std::to_string(max_bits) + " bits, got " + std::to_string(bits));
    const unsigned d10 = digits10_for(bits);
    state() = {bits, static_cast<long>(boost::multiprecision::detail::digits10_2_2(d10)), d10};
    mpfr_real::default_precision(d10);
  }
  ~MpfrPrecision() {
    state() = saved_;
    mpfr_real::default_precision(saved_default_);
  }
  MpfrPrecision(const MpfrPrecision&) = delete;
  MpfrPrecision& operator=(const MpfrPrecision&) = delete;

  /// Bits asked for by the innermost active scope (0 if none).
  static long requested() { return state().requested; }
  /// Bits of every mpfr_real working value: the active scope's effective precision, or (outside any
  /// scope) the precision of Boost's current default.
  static long effective() {
    if (state().requested > 0) return state().effective;
    return static_cast<long>(boost::multiprecision::detail::digits10_2_2(mpfr_real::default_precision()));
  }

  /// The smallest Boost digits10 setting whose precision in bits is at least `bits`.
  static unsigned digits10_for(long bits) {
    unsigned d = static_cast<unsigned>(bits * 301 / 1000);
    while (d > 1 && boost::multiprecision::detail::digits10_2_2(d - 1) >= static_cast<unsigned long>(bits)) --d;
    while (boost::multiprecision::detail::digits10_2_2(d) < static_cast<unsigned long>(bits)) ++d;
    return d;
  }

 private:
  struct State {
    long requested = 0;
    long effective = 0;
    unsigned digits10 = 0;
  };
  static State& state() {
    static State s;
    return s;
  }
  State saved_;
  unsigned saved_default_;
};

/// Parses the BITS of "mpfr:BITS" (the text after the colon). Throws std::invalid_argument.
inline long parse_mpfr_bits(const std::string& text) {
  const std::string what = "malformed MPFR precision 'mpfr:" + text + "': expected mpfr:BITS with BITS a whole number between " +
                           std::to_string(MpfrPrecision::min_bits) + " and " + std::to_string(MpfrPrecision::max_bits);
  if (text.empty() || text.size() > 9) throw std::invalid_argument(what);
  for (char c : text)
    if (c < '0' || c > '9') throw std::invalid_argument(what);
  const long bits = std::stol(text);
  if (bits < MpfrPrecision::min_bits || bits > MpfrPrecision::max_bits)
    throw std::invalid_argument("MPFR precision out of range: mpfr:" + text + " (BITS must be between " +
                                std::to_string(MpfrPrecision::min_bits) + " and " +
                                std::to_string(MpfrPrecision::max_bits) + ")");
  return bits;
}

// ---- scalar_traits ----------------------------------------------------------------------------

template <>
struct scalar_traits<float128> {
  static std::string name() { return "float128"; }
  static long bits() { return 113; }
  /// Correctly rounded to 113 bits, then an exact sum of three doubles.
  static float128 from_mpfr(mpfr_srcptr x) {
    mpfr_t r;
    mpfr_init2(r, 113);
    mpfr_set(r, x, MPFR_RNDN);
    double d[3];
    detail::split_doubles(r, d);
    mpfr_clear(r);
    __float128 v = d[0];
    v += d[1];  // exact: partial sums of a 113-bit value split at 53-bit boundaries
    v += d[2];
    return float128(v);
  }
};

template <>
struct scalar_traits<double_double> {
  static std::string name() { return "dd"; }
  static long bits() { return 105; }
  static double_double from_mpfr(mpfr_srcptr x) {
    double d[2];
    detail::split_doubles(x, d);
    return double_double(d[0], d[1]);
  }
};

template <>
struct scalar_traits<quad_double> {
  static std::string name() { return "qd"; }
  static long bits() { return 210; }
  static quad_double from_mpfr(mpfr_srcptr x) {
    double d[4];
    detail::split_doubles(x, d);
    return quad_double(d[0], d[1], d[2], d[3]);
  }
};

template <>
struct scalar_traits<mpfr_real> {
  static std::string name() {
    const long r = MpfrPrecision::requested();
    return "mpfr:" + std::to_string(r > 0 ? r : MpfrPrecision::effective());
  }
  static long bits() { return MpfrPrecision::effective(); }
  /// Exactly the working precision (not the current default, which a BigPrecision may have raised).
  static mpfr_real from_mpfr(mpfr_srcptr x) {
    mpfr_real r;
    mpfr_set_prec(r.backend().data(), static_cast<mpfr_prec_t>(bits()));
    mpfr_set(r.backend().data(), x, MPFR_RNDN);
    return r;
  }
};

// ---- epsilon_of (scalar.hpp) for these types ---------------------------------------------

template <>
inline double_double epsilon_of<double_double>() {
  return double_double(std::ldexp(1.0, 1 - 105));
}
template <>
inline quad_double epsilon_of<quad_double>() {
  return quad_double(std::ldexp(1.0, 1 - 210));
}
template <>
inline float128 epsilon_of<float128>() {
  return std::numeric_limits<float128>::epsilon();
}
template <>
inline mpfr_real epsilon_of<mpfr_real>() {
  mpfr_real one(1);
  return ldexp(one, static_cast<int>(1 - MpfrPrecision::effective()));
}

}  // namespace nystrom

namespace std {
template <class B>
class numeric_limits<nystrom::qd_number<B>> : public numeric_limits<B> {};
}  // namespace std
