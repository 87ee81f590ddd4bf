// The quantum solver's binding (quantum_binding.cpp, compiled only with FFTW: NYSTROM_PYTHON_QUANTUM).
#pragma once

#include <pybind11/pybind11.h>

namespace nystrom::python {

/// Adds _core.quantum to the module.
void register_quantum(pybind11::module_& m);

}  // namespace nystrom::python
