// The steppers of the small built-in problems in one extended precision T (stepper_extended_*.cpp).
#pragma once

#include <array>
#include <vector>

#include "nystrom/core/extended.hpp"
#include "nystrom/problems/kepler.hpp"
#include "stepper.hpp"

namespace nystrom::python {

template <class T>
std::unique_ptr<Stepper> make_extended_stepper(const std::string& problem, const std::vector<double>& params,
                                               std::size_t n, const MethodDef& def, const StepperOptions& o) {
  // Kepler only: each problem adds five engines per precision to the compile time.
  (void)params;
  if (problem == "kepler")
    return std::make_unique<StepperImpl<std::array<T, 2>, KeplerForce>>(def, KeplerForce{}, n, o, false);
  throw std::invalid_argument("problem '" + problem + "' runs in double only (extended precisions: Kepler)");
}

std::unique_ptr<Stepper> make_extended_stepper_long_double(const std::string&, const std::vector<double>&, std::size_t,
                                                           const MethodDef&, const StepperOptions&);
std::unique_ptr<Stepper> make_extended_stepper_float128(const std::string&, const std::vector<double>&, std::size_t,
                                                        const MethodDef&, const StepperOptions&);
std::unique_ptr<Stepper> make_extended_stepper_dd(const std::string&, const std::vector<double>&, std::size_t,
                                                  const MethodDef&, const StepperOptions&);
std::unique_ptr<Stepper> make_extended_stepper_qd(const std::string&, const std::vector<double>&, std::size_t,
                                                  const MethodDef&, const StepperOptions&);

}  // namespace nystrom::python
