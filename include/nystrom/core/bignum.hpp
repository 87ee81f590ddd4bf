// High-precision reference numbers for method coefficients.
//
// The catalog builds every coefficient in MPFR (through Boost.Multiprecision) at a precision a
// little above the working precision, and only then converts to the working scalar type:
// rational coefficients are therefore correctly rounded, closed forms (Forest-Ruth, Suzuki)
// are evaluated in the working precision, and decimal tables carry exactly their published digits.
#pragma once

#include <algorithm>
#include <complex>
#include <mutex>
#include <stdexcept>
#include <string>
#include <type_traits>

#include <boost/multiprecision/mpfr.hpp>

#include "nystrom/core/scalar.hpp"

namespace nystrom {

// Expression templates off: values convert implicitly and read like ordinary arithmetic.
using bigfloat =
    boost::multiprecision::number<boost::multiprecision::mpfr_float_backend<0>, boost::multiprecision::et_off>;

struct bigcomplex {
  bigfloat re{0};
  bigfloat im{0};
  bigcomplex() = default;
  bigcomplex(bigfloat r) : re(std::move(r)), im(0) {}  // NOLINT: implicit on purpose (real -> complex)
  bigcomplex(bigfloat r, bigfloat i) : re(std::move(r)), im(std::move(i)) {}
  bool is_real() const { return im == 0; }
  friend bool operator==(const bigcomplex& a, const bigcomplex& b) { return a.re == b.re && a.im == b.im; }
  friend bigcomplex operator+(const bigcomplex& a, const bigcomplex& b) { return {a.re + b.re, a.im + b.im}; }
  friend bigcomplex operator-(const bigcomplex& a, const bigcomplex& b) { return {a.re - b.re, a.im - b.im}; }
  friend bigcomplex operator*(const bigcomplex& a, const bigcomplex& b) {
    return {a.re * b.re - a.im * b.im, a.re * b.im + a.im * b.re};
  }
  bigcomplex& operator+=(const bigcomplex& b) {
    re += b.re;
    im += b.im;
    return *this;
  }
  bigcomplex conj() const { return {re, -im}; }
};

/// Bits of the reference precision used to build coefficients for a working type of `bits`.
inline unsigned reference_bits(long working_bits) {
  return static_cast<unsigned>(std::max<long>(256, working_bits + 64));
}

/// The lock held by every scope that sets Boost's process-wide MPFR default precision: BigPrecision (the
/// reference precision of coefficients) and MpfrPrecision (core/extended.hpp, the working precision of
/// mpfr_real). Recursive, so that the scopes nest in one thread; one mutex per process (a function-local
/// static of an inline function is shared by all translation units).
inline std::recursive_mutex& mpfr_default_precision_mutex() {
  static std::recursive_mutex m;
  return m;
}

/// Sets the MPFR default precision of bigfloat (in bits) for the lifetime of the guard.
///
/// Boost 1.74 keeps that precision in one process-wide variable (a function-local static of
/// mpfr_float_backend<0>, atomic but not thread_local), and every bigfloat created or computed reads it.
/// Two threads building coefficients at different precisions would race on it (a race of logic, not a data
/// race, so ThreadSanitizer is silent about it): one thread's coefficients could be rounded at the other's
/// precision, and interleaved save/restore pairs could leave the wrong default behind. The guard therefore also holds
/// mpfr_default_precision_mutex() for its lifetime: a guard (or an MpfrPrecision scope) in another thread waits until
/// this one ends, and guards nested in one thread nest. Coefficients are built once per integrator, outside the hot
/// loop, so serialising their construction costs no speed where it matters. In a multi-threaded program, compute with
/// bigfloat only inside a guard.
class BigPrecision {
 public:
  explicit BigPrecision(unsigned bits) : lock_(mpfr_default_precision_mutex()), saved_(bigfloat::default_precision()) {
    bigfloat::default_precision(bits_to_digits10(bits));
  }
  ~BigPrecision() { bigfloat::default_precision(saved_); }  // lock_ is released after the restore
  BigPrecision(const BigPrecision&) = delete;
  BigPrecision& operator=(const BigPrecision&) = delete;
  static unsigned bits_to_digits10(unsigned bits) { return bits * 30103u / 100000u + 2u; }

 private:
  std::unique_lock<std::recursive_mutex> lock_;  // declared first: taken before saved_ is read
  unsigned saved_;
};

/// Parses an exact rational "p/q", an integer, or a decimal "0.123e-4" at the current precision.
inline bigfloat big(const std::string& text) {
  const auto slash = text.find('/');
  try {
    if (slash != std::string::npos) {
      bigfloat p(text.substr(0, slash));
      bigfloat q(text.substr(slash + 1));
      if (q == 0) throw std::invalid_argument("zero denominator");
      return p / q;
    }
    return bigfloat(text);
  } catch (const std::exception&) {
    throw std::invalid_argument("malformed number '" + text + "'");
  }
}

inline bigcomplex bigc(const std::string& re, const std::string& im = "0") { return {big(re), big(im)}; }

/// An MPFR value rounded to a real working type T: MPFR's own conversions for double and long double,
/// scalar_traits<T>::from_mpfr for the others (core/extended.hpp).
template <class T>
T from_mpfr_as(mpfr_srcptr x) {
  if constexpr (std::is_same_v<T, double>) {
    return mpfr_get_d(x, MPFR_RNDN);
  } else if constexpr (std::is_same_v<T, long double>) {
    return mpfr_get_ld(x, MPFR_RNDN);
  } else {
    return scalar_traits<T>::from_mpfr(x);
  }
}

/// Converts a reference value to a real working type (correct rounding where MPFR provides it).
template <class T>
T to_real(const bigfloat& x) {
  return from_mpfr_as<T>(x.backend().data());
}

/// Converts a reference complex value to a working scalar S (real or std::complex).
/// Throws if S is real but the value has an imaginary part.
template <class S>
S to_scalar(const bigcomplex& x) {
  if constexpr (is_complex_v<S>) {
    using T = real_t<S>;
    return S(to_real<T>(x.re), to_real<T>(x.im));
  } else {
    if (!(x.im == 0)) throw std::invalid_argument("complex coefficient used with a real scalar type");
    return to_real<S>(x.re);
  }
}

/// The rounding residual of a real reference value rounded to the working type S (exact minus rounded,
/// rounded = to_scalar<S>(exact)): the low part of the double-word that carries the exact coefficient.
template <class S>
S rounding_residual(const bigcomplex& exact, const S& rounded) {
  return to_scalar<S>(exact - bigcomplex(bigfloat(rounded)));
}

}  // namespace nystrom
