// Steppers of a Python force in double (real and complex coefficients, fixed and adaptive steps).
#include <complex>
#include <vector>

#include "stepper.hpp"

namespace nystrom::python {

std::unique_ptr<Stepper> make_python_stepper(py::object fn, std::vector<py::ssize_t> shape, std::size_t n,
                                             const MethodDef& def, const StepperOptions& o,
                                             std::shared_ptr<double>& time_slot) {
  if (def.info.complex) {
    using C = std::complex<double>;
    PyForce<C> f{std::move(fn), std::move(shape)};
    time_slot = f.t;
    return std::make_unique<StepperImpl<std::vector<C>, PyForce<C>>>(def, std::move(f), n, o, true);
  }
  PyForce<double> f{std::move(fn), std::move(shape)};
  time_slot = f.t;
  return std::make_unique<StepperImpl<std::vector<double>, PyForce<double>>>(def, std::move(f), n, o, true);
}

}  // namespace nystrom::python
