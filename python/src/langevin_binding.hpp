// The Langevin binding (langevin_binding.cpp): nystrom._core.langevin.
#pragma once

#include <pybind11/pybind11.h>

namespace nystrom::python {

/// Adds _core.langevin to the module.
void register_langevin(pybind11::module_& m);

}  // namespace nystrom::python
