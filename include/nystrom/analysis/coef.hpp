// Coefficient types of the Lie-algebra analysis (nystrom/analysis/*).
//
// The BCH machinery is generic in its coefficient field K. It needs +, -, *, += and a conversion from an
// exact rational (the structure constants of the algebra are rationals). Provided here:
//   mpq_class                       exact rationals (methods with rational coefficients)
//   std::complex<double>, std::complex<long double>
//   bigcomplex                      MPFR complex at the current BigPrecision (nystrom/core/bignum.hpp)
//   Dual<C, N>                      forward-mode derivatives (holomorphic in C), for Newton and Gauss-Newton
// plus the few complex helpers the solvers need for bigcomplex (division, modulus, negation).
#pragma once

#include <array>
#include <cmath>
#include <complex>
#include <cstddef>
#include <string>

#include <gmpxx.h>
#include <mpfr.h>

#include "nystrom/core/bignum.hpp"

namespace nystrom::analysis {

/// Forward-mode dual number: value v and N partial derivatives d[k] (all in C). Used with complex C
/// for holomorphic functions (the BCH coefficients and the order conditions are polynomials).
template <class C, std::size_t N>
struct Dual {
  C v{};
  std::array<C, N> d{};

  Dual() = default;
  Dual(C value) : v(std::move(value)) {}  // NOLINT: constants convert implicitly
  static Dual variable(C value, std::size_t k) {
    Dual x(std::move(value));
    x.d[k] = C(1);
    return x;
  }
  friend Dual operator+(const Dual& a, const Dual& b) {
    Dual r;
    r.v = a.v + b.v;
    for (std::size_t k = 0; k < N; ++k) r.d[k] = a.d[k] + b.d[k];
    return r;
  }
  friend Dual operator-(const Dual& a, const Dual& b) {
    Dual r;
    r.v = a.v - b.v;
    for (std::size_t k = 0; k < N; ++k) r.d[k] = a.d[k] - b.d[k];
    return r;
  }
  friend Dual operator*(const Dual& a, const Dual& b) {
    Dual r;
    r.v = a.v * b.v;
    for (std::size_t k = 0; k < N; ++k) r.d[k] = a.d[k] * b.v + a.v * b.d[k];
    return r;
  }
  Dual& operator+=(const Dual& b) {
    v += b.v;
    for (std::size_t k = 0; k < N; ++k) d[k] += b.d[k];
    return *this;
  }
};

/// Conversion from exact rationals and a magnitude for tolerance checks.
template <class K>
struct coef_traits;

template <>
struct coef_traits<mpq_class> {
  static mpq_class from_rational(const mpq_class& q) { return q; }
  static double magnitude(const mpq_class& x) { return std::abs(x.get_d()); }
  static constexpr bool exact() { return true; }
};

template <class T>
struct coef_traits<std::complex<T>> {
  static std::complex<T> from_rational(const mpq_class& q) {
    mpfr_t x;
    mpfr_init2(x, 128);
    mpfr_set_q(x, q.get_mpq_t(), MPFR_RNDN);
    T r;
    if constexpr (std::is_same_v<T, double>) {
      r = mpfr_get_d(x, MPFR_RNDN);
    } else {
      r = static_cast<T>(mpfr_get_ld(x, MPFR_RNDN));
    }
    mpfr_clear(x);
    return {r, T(0)};
  }
  static double magnitude(const std::complex<T>& x) { return static_cast<double>(std::abs(x)); }
  static constexpr bool exact() { return false; }
};

template <>
struct coef_traits<bigcomplex> {
  static bigcomplex from_rational(const mpq_class& q) {
    bigfloat x;
    mpfr_set_q(x.backend().data(), q.get_mpq_t(), MPFR_RNDN);
    return bigcomplex(x);
  }
  static double magnitude(const bigcomplex& x) {
    return static_cast<double>(boost::multiprecision::sqrt(x.re * x.re + x.im * x.im));
  }
  static constexpr bool exact() { return false; }
};

template <class C, std::size_t N>
struct coef_traits<Dual<C, N>> {
  static Dual<C, N> from_rational(const mpq_class& q) { return Dual<C, N>(coef_traits<C>::from_rational(q)); }
  static double magnitude(const Dual<C, N>& x) { return coef_traits<C>::magnitude(x.v); }
  static constexpr bool exact() { return false; }
};

template <class K>
K from_rational(const mpq_class& q) {
  return coef_traits<K>::from_rational(q);
}
template <class K>
double magnitude_of(const K& x) {
  return coef_traits<K>::magnitude(x);
}

// ---- complex helpers shared by std::complex and bigcomplex ----------------------------------------

inline double re_d(const std::complex<double>& z) { return z.real(); }
inline double im_d(const std::complex<double>& z) { return z.imag(); }
inline double re_d(const std::complex<long double>& z) { return static_cast<double>(z.real()); }
inline double im_d(const std::complex<long double>& z) { return static_cast<double>(z.imag()); }
inline double re_d(const bigcomplex& z) { return static_cast<double>(z.re); }
inline double im_d(const bigcomplex& z) { return static_cast<double>(z.im); }
inline std::complex<double> to_cd(const std::complex<double>& z) { return z; }
inline std::complex<double> to_cd(const std::complex<long double>& z) {
  return {static_cast<double>(z.real()), static_cast<double>(z.imag())};
}
inline std::complex<double> to_cd(const bigcomplex& z) { return {re_d(z), im_d(z)}; }
inline std::complex<double> to_cd(const mpq_class& q) { return {q.get_d(), 0.0}; }

inline bigcomplex neg(const bigcomplex& z) { return {-z.re, -z.im}; }
inline bigcomplex cdiv(const bigcomplex& a, const bigcomplex& b) {
  const bigfloat den = b.re * b.re + b.im * b.im;
  return {(a.re * b.re + a.im * b.im) / den, (a.im * b.re - a.re * b.im) / den};
}
inline bigcomplex conj_of(const bigcomplex& z) { return z.conj(); }
inline bigfloat abs_big(const bigcomplex& z) { return boost::multiprecision::sqrt(z.re * z.re + z.im * z.im); }

/// Decimal text of a real with `digits` significant digits (scientific when small or large).
inline std::string big_str(const bigfloat& x, int digits) { return x.str(digits, std::ios_base::fmtflags(0)); }

}  // namespace nystrom::analysis
