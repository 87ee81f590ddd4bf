// Definition of method_record (declared in methods/method_record.hpp).
#include "nystrom/methods/method_record.hpp"

namespace nystrom {

MethodRecord method_record(const MethodInfo& m) {
  // the exponent and the anchor of the controller's tolerance (engines/step_control.hpp); null for fixed steps
  const auto if_adaptive = [&](double x) { return m.adaptive ? RecordValue(x) : RecordValue(std::monostate{}); };
  return {{"name", m.name},
          {"family", m.family},
          {"order", m.order},
          {"stages", m.stages},
          {"force_evals_per_step", m.forces_per_step},
          {"forces_per_step", m.forces_per_step},
          {"fsal", m.fsal},
          {"symmetric", m.symmetric},
          {"symplectic", m.symplectic},
          {"complex", m.complex},
          {"adaptive", m.adaptive},
          {"order_control", m.order_control},
          {"velocity_dependent", m.velocity},
          {"velocity", m.velocity},
          {"published_digits", m.published_digits},
          {"tolerance_exponent", if_adaptive(m.tolerance_exponent)},
          {"tolerance_anchor", if_adaptive(m.tolerance_anchor)},
          {"aliases", m.aliases},
          {"source", m.source},
          {"description", m.description}};
}

}  // namespace nystrom
