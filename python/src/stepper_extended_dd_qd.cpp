// Built-in problems in double-double and quad-double.
#include "stepper_extended.hpp"

namespace nystrom::python {

std::unique_ptr<Stepper> make_extended_stepper_dd(const std::string& problem, const std::vector<double>& params,
                                                  std::size_t n, const MethodDef& def, const StepperOptions& o) {
  return make_extended_stepper<double_double>(problem, params, n, def, o);
}

std::unique_ptr<Stepper> make_extended_stepper_qd(const std::string& problem, const std::vector<double>& params,
                                                  std::size_t n, const MethodDef& def, const StepperOptions& o) {
  return make_extended_stepper<quad_double>(problem, params, n, def, o);
}

}  // namespace nystrom::python
