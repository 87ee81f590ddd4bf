// Run-time choice of the scalar type: `--precision NAME` maps to a C++ type through dispatch_precision.
// Every engine is a template; this is the one place where a run-time name becomes a type.
//
//   double | long-double | float128 | dd | qd | mpfr:BITS
//
// mpfr:BITS sets the MPFR working precision (an MpfrPrecision scope, nystrom/core/extended.hpp) for
// the duration of the call, so states and coefficients created inside fn have it.
#pragma once

#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "nystrom/core/extended.hpp"
#include "nystrom/core/scalar.hpp"

namespace nystrom {

template <class T>
struct type_tag {
  using type = T;
};

/// Names accepted by dispatch_precision (mpfr:BITS with BITS a number of bits).
inline std::vector<std::string> precision_names() {
  return {"double", "long-double", "float128", "dd", "qd", "mpfr:BITS"};
}

/// Calls fn(type_tag<T>{}) with the scalar type named by `name`. Throws std::invalid_argument.
/// Aliases: "long double"/"ld", "quad"/"quadruple"/"__float128", "double-double", "quad-double".
template <class Fn>
decltype(auto) dispatch_precision(const std::string& name, Fn&& fn) {
  if (name == "double") return fn(type_tag<double>{});
  if (name == "long-double" || name == "long double" || name == "ld") return fn(type_tag<long double>{});
  if (name == "float128" || name == "quad" || name == "quadruple" || name == "__float128")
    return fn(type_tag<float128>{});
  if (name == "dd" || name == "double-double") return fn(type_tag<double_double>{});
  if (name == "qd" || name == "quad-double") return fn(type_tag<quad_double>{});
  if (name.rfind("mpfr:", 0) == 0) {
    const MpfrPrecision scope(parse_mpfr_bits(name.substr(5)));
    return fn(type_tag<mpfr_real>{});
  }
  if (name == "mpfr") throw std::invalid_argument("precision 'mpfr' needs a number of bits: mpfr:BITS, e.g. mpfr:256");
  std::string known;
  for (const auto& n : precision_names()) known += (known.empty() ? "" : ", ") + n;
  throw std::invalid_argument("unknown precision '" + name + "' (known: " + known + ")");
}

}  // namespace nystrom
