// Dispatch of the extended precisions to their translation units.
#include "stepper_extended.hpp"

#include "nystrom/core/precision.hpp"

namespace nystrom::python {

std::unique_ptr<Stepper> make_builtin_stepper_extended(const std::string& problem, const std::vector<double>& params,
                                                       std::size_t n, const MethodDef& def, const StepperOptions& o,
                                                       const std::string& precision) {
  if (def.info.complex)
    throw std::invalid_argument("complex-coefficient methods run in double only from Python (method '" + def.info.name +
                                "')");
  if (precision.rfind("mpfr", 0) == 0)
    throw std::invalid_argument("precision '" + precision +
                                "' is not available from Python (long-double, float128, dd and qd are)");
  return dispatch_precision(precision, [&](auto tag) -> std::unique_ptr<Stepper> {
    using T = typename decltype(tag)::type;
    if constexpr (std::is_same_v<T, long double>) {
      return make_extended_stepper_long_double(problem, params, n, def, o);
    } else if constexpr (std::is_same_v<T, float128>) {
      return make_extended_stepper_float128(problem, params, n, def, o);
    } else if constexpr (std::is_same_v<T, double_double>) {
      return make_extended_stepper_dd(problem, params, n, def, o);
    } else if constexpr (std::is_same_v<T, quad_double>) {
      return make_extended_stepper_qd(problem, params, n, def, o);
    } else {
      throw std::invalid_argument("precision '" + precision + "' is not an extended precision");
    }
  });
}

}  // namespace nystrom::python
