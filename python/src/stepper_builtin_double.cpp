// Steppers of the built-in problems in double: real and complex coefficients, fixed and adaptive steps.
#include <array>
#include <complex>
#include <vector>

#include "nystrom/problems/kepler.hpp"
#include "nystrom/problems/nbody.hpp"
#include "stepper.hpp"

namespace nystrom::python {

namespace {

/// The stepper of force F on state container V<double> (or V<complex<double>> for complex methods).
template <class VReal, class F>
std::unique_ptr<Stepper> build(F force, std::size_t n, const MethodDef& def, const StepperOptions& o) {
  if (def.info.complex) {
    using VC = rebind_vector_t<VReal, std::complex<double>>;
    return std::make_unique<StepperImpl<VC, F>>(def, std::move(force), n, o, false);
  }
  return std::make_unique<StepperImpl<VReal, F>>(def, std::move(force), n, o, false);
}

}  // namespace

std::unique_ptr<Stepper> make_builtin_stepper_double(const std::string& problem, const std::vector<double>& params,
                                                     std::size_t n, const MethodDef& def, const StepperOptions& o) {
  if (problem == "kepler") return build<std::array<double, 2>>(KeplerForce{}, n, def, o);
  if (problem == "henon_heiles") return build<std::array<double, 2>>(HenonHeilesForce{}, n, def, o);
  if (problem == "harmonic") return build<std::vector<double>>(HarmonicForce{params.at(0)}, n, def, o);
  if (problem == "nbody") {
    std::vector<double> gm(params.begin() + 1, params.end());
    if (gm.size() * 3 != n) throw std::invalid_argument("N-body state must hold 3 coordinates per particle");
    return build<std::vector<double>>(NBodyForce<double>(std::move(gm), params.at(0)), n, def, o);
  }
  throw std::invalid_argument("unknown built-in problem '" + problem + "'");
}

}  // namespace nystrom::python
