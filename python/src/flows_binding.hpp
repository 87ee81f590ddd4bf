// The velocity-dependent flows' binding (flows_binding.cpp): nystrom/velocity/solve.hpp's built-in problems.
#pragma once

#include <pybind11/pybind11.h>

namespace nystrom::python {

/// Adds _core.flows to the module.
void register_flows(pybind11::module_& m);

}  // namespace nystrom::python
