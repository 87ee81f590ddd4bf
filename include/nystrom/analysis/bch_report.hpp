// The BCH analysis of a method as a JSON document: what `nystrom bch --json` prints and nystrom.bch()
// returns in Python. Json is a JSON value type with nlohmann::json's interface (operator[], array(),
// push_back, initializer lists); the library itself does not depend on one.
#pragma once

#include <complex>

#include "nystrom/analysis/bch.hpp"

namespace nystrom::analysis {

/// One error term: its basis element, its definition, its bracket in T and V, its value (re, im, abs) and,
/// when computed exactly, the rational.
template <class Json>
Json error_term_json(const ErrorTerm& t) {
  Json j{{"name", t.name},       {"definition", t.definition}, {"bracket", t.bracket},
         {"re", t.value.real()}, {"im", t.value.imag()},       {"abs", std::abs(t.value)}};
  if (!t.exact.empty()) j["exact"] = t.exact;
  return j;
}

/// The whole analysis: options, orders, the terms of every degree and the leading (first non-vanishing)
/// degree, null when every degree vanishes.
template <class Json>
Json bch_report_json(const MethodAnalysis& a) {
  Json j;
  j["method"] = a.method;
  j["degree"] = a.degree;
  j["basis"] = to_string(a.basis);
  j["algebra"] = to_string(a.algebra);
  j["exact"] = a.exact;
  j["precision_bits"] = a.precision_bits;
  j["tolerance"] = a.tolerance;
  j["declared_order"] = a.declared_order;
  j["order"] = a.order;
  j["order_is_lower_bound"] = a.order_is_lower_bound;
  j["order_confirmed"] = a.declared_order_confirmed();
  auto terms_of = [](const DegreeTerms& d) {
    Json terms = Json::array();
    for (const auto& t : d.terms) terms.push_back(error_term_json<Json>(t));
    return terms;
  };
  Json degs = Json::array();
  for (const auto& d : a.degrees)
    degs.push_back({{"degree", d.degree}, {"vanishes", d.vanishes}, {"norm", d.norm}, {"terms", terms_of(d)}});
  j["degrees"] = degs;
  if (const auto* l = a.leading())
    j["leading"] = {{"degree", l->degree}, {"norm", l->norm}, {"terms", terms_of(*l)}};
  else
    j["leading"] = nullptr;
  return j;
}

}  // namespace nystrom::analysis
