// Scalar types: real and complex, double through arbitrary precision.
//
// Every engine is a template on its scalar type. This header defines the small set of
// customisation points the engines and the catalog need:
//   * real_t<S>            the real type underlying S (S itself, or T for std::complex<T>)
//   * is_complex_v<S>
//   * scalar_traits<T>     name, mantissa bits (and, for the extended types, from_mpfr: see from_mpfr_as
//                          in core/bignum.hpp)
//   * real_part(x)         projection used by complex-coefficient methods
//   * inv_r3(r2)           r2^(-3/2), the r^-3 of inverse-square forces (overloaded for dd and qd)
// double and long double are defined here; extended types (float128, dd_real, qd_real,
// mpfr_float) add their specialisations in nystrom/core/precision.hpp.
#pragma once

#include <cmath>
#include <complex>
#include <limits>
#include <string>
#include <type_traits>

namespace nystrom {

template <class S>
struct is_complex : std::false_type {};
template <class T>
struct is_complex<std::complex<T>> : std::true_type {};
template <class S>
inline constexpr bool is_complex_v = is_complex<S>::value;

template <class S>
struct real_of {
  using type = S;
};
template <class T>
struct real_of<std::complex<T>> {
  using type = T;
};
template <class S>
using real_t = typename real_of<S>::type;

/// Traits of a real scalar type. Specialise for every supported precision.
template <class T>
struct scalar_traits;

template <>
struct scalar_traits<double> {
  static std::string name() { return "double"; }
  static long bits() { return std::numeric_limits<double>::digits; }
};

template <>
struct scalar_traits<long double> {
  static std::string name() { return "long-double"; }
  static long bits() { return std::numeric_limits<long double>::digits; }
};

/// The real scalar types for which libnystrom compiles solve() on std::vector states (solve/compiled.hpp):
/// double and long double here, the extended types in core/extended.hpp. Others run on the inline path
/// (nystrom/solve_inline.hpp).
template <class T>
struct is_compiled_scalar : std::bool_constant<std::is_same_v<T, double> || std::is_same_v<T, long double>> {};

/// Machine epsilon of a real scalar type, 2^(1-bits).
template <class T>
T epsilon_of() {
  return static_cast<T>(std::ldexp(1.0L, static_cast<int>(1 - scalar_traits<T>::bits())));
}

/// Conversion to double for reporting (types without an explicit conversion overload this).
template <class T>
double as_double(const T& x) {
  return static_cast<double>(x);
}

template <class S>
S real_part(const S& x) {
  return x;
}
template <class T>
std::complex<T> real_part(const std::complex<T>& x) {
  return std::complex<T>(x.real(), T(0));
}

/// r2^(-3/2): the 1/r^3 of an inverse-square force from r2 = |q|^2 (Kepler). The generic version is
/// exactly S(1) / (r2 * sqrt(r2)), so double and the other hardware and MPFR types keep their
/// arithmetic bit for bit. Double-double and quad-double overload it (core/extended.hpp) without
/// libqd's square root (out of line) and division: a double seed and one correction.
template <class S>
S inv_r3(const S& r2) {
  using std::sqrt;
  return S(1) / (r2 * sqrt(r2));
}

/// |x| for real or complex scalars, as a real.
template <class S>
real_t<S> magnitude(const S& x) {
  using std::abs;
  return abs(x);
}

/// True when a real or complex value is finite.
template <class S>
bool is_finite_scalar(const S& x) {
  if constexpr (is_complex_v<S>) {
    return is_finite_scalar(x.real()) && is_finite_scalar(x.imag());
  } else {
    using std::isfinite;
    return isfinite(x);
  }
}

}  // namespace nystrom
