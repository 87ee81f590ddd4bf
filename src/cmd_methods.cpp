// `nystrom methods [--json]`: the catalog.
#include <cstdio>
#include <iostream>
#include <memory>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "nystrom/methods/catalog.hpp"

namespace {

nlohmann::json info_json(const nystrom::MethodInfo& m) {
  return {{"name", m.name},
          {"family", m.family},
          {"order", m.order},
          {"stages", m.stages},
          {"force_evals_per_step", m.forces_per_step},
          {"fsal", m.fsal},
          {"symmetric", m.symmetric},
          {"symplectic", m.symplectic},
          {"complex", m.complex},
          {"adaptive", m.adaptive},
          {"published_digits", m.published_digits},
          {"aliases", m.aliases},
          {"source", m.source},
          {"description", m.description}};
}

nystrom::cli::Registrar reg("methods", "List every method in the catalog", [](CLI::App& app) {
  auto json = std::make_shared<bool>(false);
  app.add_flag("--json", *json, "Print one JSON array");
  return [json]() {
    const auto& cat = nystrom::catalog();
    if (*json) {
      nlohmann::json arr = nlohmann::json::array();
      for (const auto& d : cat) arr.push_back(info_json(d.info));
      std::cout << arr.dump(2) << "\n";
      return 0;
    }
    fmt::print("{:<12} {:<12} {:>5} {:>6} {:>6} {:>4} {:>4} {:>5} {:>4}  {}\n", "name", "family", "order", "stages",
               "forces", "fsal", "sym", "sympl", "cplx", "source");
    for (const auto& d : cat) {
      const auto& m = d.info;
      auto yn = [](bool b) { return b ? "yes" : "-"; };
      fmt::print("{:<12} {:<12} {:>5} {:>6} {:>6} {:>4} {:>4} {:>5} {:>4}  {}\n", m.name, m.family, m.order, m.stages,
                 m.forces_per_step, yn(m.fsal), yn(m.symmetric), yn(m.symplectic), yn(m.complex), m.source);
    }
    fmt::print("\nAlso: M<2n> (any even order), mpe:K1,K2,... (PV base), mpe-vv:K1,K2,..., adjoint:NAME.\n");
    return 0;
  };
});

}  // namespace
