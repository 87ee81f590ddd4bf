// Run-time choice of the scalar type: `--precision NAME` maps to a C++ type through dispatch_precision.
// Every engine is a template; this is the one place where a run-time name becomes a type.
#pragma once

#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "nystrom/core/scalar.hpp"

namespace nystrom {

template <class T>
struct type_tag {
  using type = T;
};

/// Names accepted by dispatch_precision.
inline std::vector<std::string> precision_names() { return {"double", "long-double"}; }

/// Calls fn(type_tag<T>{}) with the scalar type named by `name`. Throws std::invalid_argument.
template <class Fn>
decltype(auto) dispatch_precision(const std::string& name, Fn&& fn) {
  if (name == "double") return fn(type_tag<double>{});
  if (name == "long-double" || name == "long double" || name == "ld") return fn(type_tag<long double>{});
  std::string known;
  for (const auto& n : precision_names()) known += (known.empty() ? "" : ", ") + n;
  throw std::invalid_argument("unknown precision '" + name + "' (known: " + known + ")");
}

}  // namespace nystrom
