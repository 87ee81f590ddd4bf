// Built-in problems in long double and float128.
#include "stepper_extended.hpp"

namespace nystrom::python {

std::unique_ptr<Stepper> make_extended_stepper_long_double(const std::string& problem,
                                                           const std::vector<double>& params, std::size_t n,
                                                           const MethodDef& def, const StepperOptions& o) {
  return make_extended_stepper<long double>(problem, params, n, def, o);
}

std::unique_ptr<Stepper> make_extended_stepper_float128(const std::string& problem, const std::vector<double>& params,
                                                        std::size_t n, const MethodDef& def, const StepperOptions& o) {
  return make_extended_stepper<float128>(problem, params, n, def, o);
}

}  // namespace nystrom::python
