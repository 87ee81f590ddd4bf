// The Smoluchowski and thermal solvers' binding (diffusion_binding.cpp, compiled only with FFTW:
// NYSTROM_PYTHON_QUANTUM).
#pragma once

#include <pybind11/pybind11.h>

namespace nystrom::python {

/// Adds _core.smoluchowski and _core.thermal to the module.
void register_diffusion(pybind11::module_& m);

}  // namespace nystrom::python
