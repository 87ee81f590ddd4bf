// The catalog as test parameters: the names of its entries for INSTANTIATE_TEST_SUITE_P, an entry by name,
// GoogleTest parameter names made of them; and a method outside the catalog that tests of precision share.
#pragma once

#include <gtest/gtest.h>

#include <cctype>
#include <stdexcept>
#include <string>
#include <vector>

#include "nystrom/methods/catalog.hpp"

namespace nystrom::test {

/// The name of every catalog entry, in catalog order.
inline std::vector<std::string> catalog_names() {
  std::vector<std::string> names;
  for (const auto& d : catalog()) names.push_back(d.info.name);
  return names;
}

/// The catalog entry named `name` (not a specification that resolve_method would build).
inline const MethodDef& find_in_catalog(const std::string& name) {
  for (const auto& d : catalog())
    if (d.info.name == name) return d;
  throw std::invalid_argument("no catalog entry '" + name + "'");
}

/// A GoogleTest parameter name for a method name or specification: only [A-Za-z0-9_] are allowed, so other
/// characters become '_'; the index keeps the names unique.
inline std::string param_name(const testing::TestParamInfo<std::string>& info) {
  std::string s;
  for (char c : info.param) s += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return s + "_" + std::to_string(info.index);
}

/// An RKN tableau printed with 16 digits, which cannot be refined: Nystrom's fourth-order method (the catalog's
/// N4) with its weights rounded to 16 decimals, named N4-decimal (published_digits 16).
inline MethodDef decimal_n4() {
  MethodDef n4 = resolve_method("N4");
  n4.info.name = "N4-decimal";
  n4.info.published_digits = 16;
  n4.build = [] {
    return MethodData{tableau({"0", "0.5", "1"}, {{}, {"0.125"}, {"0", "0.5"}},
                              {"0.1666666666666667", "0.3333333333333333", "0"},
                              {"0.1666666666666667", "0.6666666666666667", "0.1666666666666667"})};
  };
  return n4;
}

}  // namespace nystrom::test
