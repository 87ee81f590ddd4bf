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
// Boost's default precision is one variable per process, so an MpfrPrecision scope holds the same lock as
// BigPrecision (mpfr_default_precision_mutex, core/bignum.hpp) for its lifetime: there is one MPFR working
// precision per process at a time, and a thread that opens a scope (or builds coefficients) while another
// thread's scope is open waits until that scope ends. Scopes and BigPrecision guards nest in one thread. In a
// multi-threaded program, compute with mpfr_real only inside a scope.
#pragma once

#include <algorithm>
#include <cmath>
#include <complex>
#include <concepts>
#include <limits>
#include <mutex>
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

// Inlining of libqd's double-double arithmetic. libqd declares its operations inline, but GCC leaves
// its exact product qd::two_prod (Dekker's splitting, about 20 instructions without FMA) and the
// products built on it out of line in the engines' loops, and every call spills the caller's live
// registers: calls of operator* and two_prod took a fifth to a quarter of an M8 step in dd. For dd_real
// the operations are forced inline; the products are libqd's own code (qd/inline.h, qd/dd_inline.h)
// repeated here with a forced-inline two_prod, operation for operation, so the results are bitwise
// libqd's. Quad-double's operations, several times larger, are left to the compiler to inline or not.
#if defined(__GNUC__) || defined(__clang__)
#define NYSTROM_QD_FORCE_INLINE __attribute__((always_inline))
#define NYSTROM_QD_NOINLINE __attribute__((noinline))
#else
#define NYSTROM_QD_FORCE_INLINE
#define NYSTROM_QD_NOINLINE
#endif

namespace detail {

/// libqd's qd::two_prod (with its qd::split), forced inline: a b = p + err exactly.
NYSTROM_QD_FORCE_INLINE inline double dd_two_prod(double a, double b, double& err) {
#ifdef QD_FMS
  const double p = a * b;
  err = QD_FMS(a, b, p);
  return p;
#else
  auto split = [](double x, double& hi, double& lo) NYSTROM_QD_FORCE_INLINE {
    double temp;
    if (x > _QD_SPLIT_THRESH || x < -_QD_SPLIT_THRESH) {
      x *= 3.7252902984619140625e-09;  // 2^-28
      temp = _QD_SPLITTER * x;
      hi = temp - (temp - x);
      lo = x - hi;
      hi *= 268435456.0;  // 2^28
      lo *= 268435456.0;
    } else {
      temp = _QD_SPLITTER * x;
      hi = temp - (temp - x);
      lo = x - hi;
    }
  };
  double a_hi, a_lo, b_hi, b_lo;
  const double p = a * b;
  split(a, a_hi, a_lo);
  split(b, b_hi, b_lo);
  err = ((a_hi * b_hi - p) + a_hi * b_lo + a_lo * b_hi) + a_lo * b_lo;
  return p;
#endif
}

#define NYSTROM_QD_ADD_SUB(ATTR)                              \
  ATTR static B add(const B& a, const B& b) { return a + b; } \
  ATTR static B add(const B& a, double b) { return a + b; }   \
  ATTR static B add(double a, const B& b) { return a + b; }   \
  ATTR static B sub(const B& a, const B& b) { return a - b; } \
  ATTR static B sub(const B& a, double b) { return a - b; }   \
  ATTR static B sub(double a, const B& b) { return a - b; }   \
  ATTR static B neg(const B& a) { return -a; }                \
  ATTR static void add_to(B& a, const B& b) { a += b; }       \
  ATTR static void add_to(B& a, double b) { a += b; }         \
  ATTR static void sub_from(B& a, const B& b) { a -= b; }     \
  ATTR static void sub_from(B& a, double b) { a -= b; }

/// libqd's addition, subtraction and multiplication of B (see above).
template <class Base>
struct qd_arith {
  using B = Base;
  NYSTROM_QD_ADD_SUB()
  static B mul(const B& a, const B& b) { return a * b; }
  static B mul(const B& a, double b) { return a * b; }
  static B mul(double a, const B& b) { return a * b; }
  static void mul_by(B& a, const B& b) { a *= b; }
  static void mul_by(B& a, double b) { a *= b; }
};

template <>
struct qd_arith<::dd_real> {
  using B = ::dd_real;
  NYSTROM_QD_ADD_SUB(NYSTROM_QD_FORCE_INLINE)
  // dd_inline.h's operator*(dd_real, dd_real), operator*(dd_real, double), operator*=, with dd_two_prod
  NYSTROM_QD_FORCE_INLINE static B mul(const B& a, const B& b) {
    double p1, p2;
    p1 = dd_two_prod(a.x[0], b.x[0], p2);
    p2 += (a.x[0] * b.x[1] + a.x[1] * b.x[0]);
    p1 = qd::quick_two_sum(p1, p2, p2);
    return B(p1, p2);
  }
  NYSTROM_QD_FORCE_INLINE static B mul(const B& a, double b) {
    double p1, p2;
    p1 = dd_two_prod(a.x[0], b, p2);
    p2 += (a.x[1] * b);
    p1 = qd::quick_two_sum(p1, p2, p2);
    return B(p1, p2);
  }
  NYSTROM_QD_FORCE_INLINE static B mul(double a, const B& b) { return mul(b, a); }
  NYSTROM_QD_FORCE_INLINE static void mul_by(B& x, const B& a) {
    double p1, p2;
    p1 = dd_two_prod(x.x[0], a.x[0], p2);
    p2 += a.x[1] * x.x[0];
    p2 += a.x[0] * x.x[1];
    x.x[0] = qd::quick_two_sum(p1, p2, x.x[1]);
  }
  NYSTROM_QD_FORCE_INLINE static void mul_by(B& x, double a) {
    double p1, p2;
    p1 = dd_two_prod(x.x[0], a, p2);
    p2 += x.x[1] * a;
    x.x[0] = qd::quick_two_sum(p1, p2, x.x[1]);
  }
};
#undef NYSTROM_QD_ADD_SUB

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
  requires(!std::same_as<I, int> && !std::same_as<I, bool>) qd_number(I v)
      : B(0.0) {  // NOLINT: implicit like the int constructor
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

  using arith = detail::qd_arith<B>;
  NYSTROM_QD_FORCE_INLINE qd_number operator-() const { return arith::neg(base()); }
  NYSTROM_QD_FORCE_INLINE qd_number& operator+=(const qd_number& o) {
    arith::add_to(*this, o.base());
    return *this;
  }
  NYSTROM_QD_FORCE_INLINE qd_number& operator-=(const qd_number& o) {
    arith::sub_from(*this, o.base());
    return *this;
  }
  NYSTROM_QD_FORCE_INLINE qd_number& operator*=(const qd_number& o) {
    arith::mul_by(*this, o.base());
    return *this;
  }
  qd_number& operator/=(const qd_number& o) {
    B::operator/=(o.base());
    return *this;
  }
  NYSTROM_QD_FORCE_INLINE qd_number& operator+=(double o) {
    arith::add_to(*this, o);
    return *this;
  }
  NYSTROM_QD_FORCE_INLINE qd_number& operator-=(double o) {
    arith::sub_from(*this, o);
    return *this;
  }
  NYSTROM_QD_FORCE_INLINE qd_number& operator*=(double o) {
    arith::mul_by(*this, o);
    return *this;
  }
  qd_number& operator/=(double o) {
    B::operator/=(o);
    return *this;
  }

#define NYSTROM_QD_BINARY(op, f)                                                                                      \
  [[gnu::always_inline]] friend qd_number operator op(const qd_number& a, const qd_number& b) {                       \
    return arith::f(a.base(), b.base());                                                                              \
  }                                                                                                                   \
  [[gnu::always_inline]] friend qd_number operator op(const qd_number& a, double b) { return arith::f(a.base(), b); } \
  [[gnu::always_inline]] friend qd_number operator op(double a, const qd_number& b) { return arith::f(a, b.base()); }
  NYSTROM_QD_BINARY(+, add)
  NYSTROM_QD_BINARY(-, sub)
  NYSTROM_QD_BINARY(*, mul)
#undef NYSTROM_QD_BINARY
  friend qd_number operator/(const qd_number& a, const qd_number& b) { return a.base() / b.base(); }
  friend qd_number operator/(const qd_number& a, double b) { return a.base() / b; }
  friend qd_number operator/(double a, const qd_number& b) { return a / b.base(); }

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

// ---- r2^(-3/2) for inverse-square forces (scalar.hpp's inv_r3) -------------------------------
//
// libqd's sqrt is compiled in libqd (not inlined) and its division costs two double divisions and a
// product; the Kepler force needs neither. From a double seed y = 1/sqrt(r2) (error about 2^-52),
// e = 1 - r2 y^2 is formed to about 2^-106 (y^2 and the leading product exact, 1 - s exact by Sterbenz)
// and
//     r2^(-3/2) = y^3 (1 - e)^(-3/2) = y^3 (1 + 3/2 e + 15/8 e^2 + O(e^3)),   |e| < 2^-50,
// with y^3 exact to about 2^-106 (two exact products): one correction takes the seed's 53 bits to
// double-double accuracy. Quad-double takes the double-double value of r2^(-1/2) as its seed and
// applies the same correction in quad-double (|e| about 2^-104). tests/core/test_precision.cpp checks
// both against MPFR. Outside 2^-600 <= r2 <= 2^600 (and for 0, negative, infinite or NaN r2) they
// fall back to the generic formula, where the seed's powers could leave the range of double.

namespace detail {

inline bool inv_r3_in_range(double a) { return a >= 0x1p-600 && a <= 0x1p600; }

/// The generic formula, out of line (the rare case).
template <class T>
NYSTROM_QD_NOINLINE T inv_r3_generic(const T& r2) {
  return T(1) / (r2 * sqrt(r2));
}

/// The seed y = 1/sqrt(a) of r2 = a + b (a in range), y^2 = p + p_lo exactly, and e + e_lo = 1 - r2 y^2
/// to about 2^-106 (a p = s + s_lo exactly, 1 - s exact; b p_lo, below 2^-106, dropped).
struct InvSqrtSeed {
  double y, p, p_lo, e, e_lo;
};
NYSTROM_QD_FORCE_INLINE inline InvSqrtSeed inv_sqrt_seed(double a, double b) {
  InvSqrtSeed r;
  r.y = 1.0 / std::sqrt(a);
  r.p = dd_two_prod(r.y, r.y, r.p_lo);
  double s_lo;
  const double s = dd_two_prod(a, r.p, s_lo);
  r.e = qd::two_diff(1.0 - s, s_lo + (a * r.p_lo + b * r.p), r.e_lo);
  return r;
}

}  // namespace detail

/// r2^(-3/2) in double-double without division or square root of double-doubles (see above).
NYSTROM_QD_FORCE_INLINE inline double_double inv_r3(const double_double& r2) {
  const double a = r2.x[0], b = r2.x[1];
  if (!detail::inv_r3_in_range(a)) [[unlikely]]
    return detail::inv_r3_generic(r2);
  const auto [y, p, p_lo, e, e_lo] = detail::inv_sqrt_seed(a, b);
  double z_lo, w_lo, h1_lo, h2_lo, lo_out;
  const double z = detail::dd_two_prod(p, y, z_lo);  // y^3 = z + t to about 2^-106
  const double t = z_lo + p_lo * y;
  // (z + t)(1 + 3/2 (e + e_lo) + 15/8 e^2): z + w + w/2 exactly with w = z e (exact), the rest in lo
  const double w = detail::dd_two_prod(z, e, w_lo);
  const double h1 = qd::two_sum(z, w, h1_lo);
  const double h2 = qd::two_sum(h1, 0.5 * w, h2_lo);
  const double lo = (h1_lo + h2_lo) + (t + (1.5 * (w_lo + z * e_lo) + (1.5 * t + 1.875 * w) * e));
  const double hi_out = qd::quick_two_sum(h2, lo, lo_out);
  return double_double(hi_out, lo_out);
}

/// r2^(-3/2) in quad-double: the double-double r2^(-1/2) as seed, one correction in quad-double.
inline quad_double inv_r3(const quad_double& r2) {
  const double a = r2.x[0];
  if (!detail::inv_r3_in_range(a)) [[unlikely]]
    return detail::inv_r3_generic(r2);
  // y = r2^(-1/2) (1 + e0/2 + 3/8 e0^2) as a double-double, to about 2^-104
  const auto [y0, p, p_lo, e0, e0_lo] = detail::inv_sqrt_seed(a, r2.x[1]);
  double y_lo;
  const double y_hi = qd::quick_two_sum(y0, y0 * (e0 * (0.5 + 0.375 * e0)), y_lo);
  const ::qd_real y(y_hi, y_lo, 0.0, 0.0);
  const ::qd_real y2 = sqr(y);
  const ::qd_real d = 1.0 - r2.base() * y2;   // e = 1 - r2 y^2, |e| about 2^-104
  const ::dd_real e(d.x[0], d.x[1]);          // to about 2^-210 absolute
  const ::dd_real c = e * (1.5 + 1.875 * e);  // (1 - e)^(-3/2) - 1 (e^3 below 2^-300)
  // (libqd 2.3's qd_real * dd_real misses the product a[3] b_hi: quad-double products only)
  const ::qd_real z = y2 * y;  // y^3
  return z + z * ::qd_real(c.x[0], c.x[1], 0.0, 0.0);
}

// ---- run-time MPFR precision ------------------------------------------------------------------

/// The working precision of mpfr_real for the lifetime of the scope (see the top of this file). Holds
/// mpfr_default_precision_mutex() meanwhile: a scope in another thread waits until this one ends.
class MpfrPrecision {
 public:
  static constexpr long min_bits = 53;     // below double precision there is nothing to gain
  static constexpr long max_bits = 65536;  // about 19 700 digits; keeps the catalog build bounded

  /// Throws std::invalid_argument unless min_bits <= bits <= max_bits.
  explicit MpfrPrecision(long bits)
      : lock_(mpfr_default_precision_mutex()), saved_(state()), saved_default_(mpfr_real::default_precision()) {
    if (bits < min_bits || bits > max_bits)
      throw std::invalid_argument("MPFR precision must be between " + std::to_string(min_bits) + " and " +
                                  std::to_string(max_bits) + " bits, got " + std::to_string(bits));
    const unsigned d10 = digits10_for(bits);
    state() = {bits, static_cast<long>(boost::multiprecision::detail::digits10_2_2(d10)), d10};
    mpfr_real::default_precision(d10);
  }
  ~MpfrPrecision() {  // lock_ is released after the restore
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
  std::unique_lock<std::recursive_mutex> lock_;  // declared first: taken before saved_ is read
  State saved_;
  unsigned saved_default_;
};

/// Parses the BITS of "mpfr:BITS" (the text after the colon). Throws std::invalid_argument.
inline long parse_mpfr_bits(const std::string& text) {
  const std::string what = "malformed MPFR precision 'mpfr:" + text +
                           "': expected mpfr:BITS with BITS a whole number between " +
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

// ---- compiled in libnystrom (solve/compiled.hpp) -----------------------------------------------

template <>
struct is_compiled_scalar<float128> : std::true_type {};
template <>
struct is_compiled_scalar<double_double> : std::true_type {};
template <>
struct is_compiled_scalar<quad_double> : std::true_type {};
template <>
struct is_compiled_scalar<mpfr_real> : std::true_type {};

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
