// nystrom._core.smoluchowski and nystrom._core.thermal: quantum::smoluchowski() (nystrom/quantum/smoluchowski.hpp)
// and quantum::thermal() (nystrom/quantum/thermal.hpp) in double, run with the GIL released. Every check of the
// input is the library's (std::invalid_argument reaches Python as ValueError with its one-line message).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <optional>
#include <string>
#include <vector>

#include "diffusion_binding.hpp"
#include "nystrom/quantum/smoluchowski.hpp"
#include "nystrom/quantum/thermal.hpp"

namespace nystrom::python {

namespace py = pybind11;

namespace {

using DArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

std::vector<double> to_vector(const std::optional<DArray>& a) {
  std::vector<double> v;
  if (a) v.assign(a->data(), a->data() + a->size());
  return v;
}

py::array_t<double> to_array(const std::vector<double>& v) {
  return py::array_t<double>(static_cast<py::ssize_t>(v.size()), v.data());
}

}  // namespace

void register_diffusion(py::module_& m) {
  m.def(
      "smoluchowski",
      [](const std::string& potential, std::optional<DArray> values, std::optional<DArray> initial, int dims, int grid,
         double box, double diffusion, double beta, std::vector<double> x0, double width, const std::string& method,
         double dt, long steps, int rates, int threads) {
        if (threads < 1) throw std::invalid_argument("threads must be positive");
        quantum::SmoluchowskiProblem<double> p;
        p.potential = potential;
        p.values = to_vector(values);
        p.initial = to_vector(initial);
        p.dims = dims;
        p.grid = grid;
        p.box = box;
        p.diffusion = diffusion;
        p.beta = beta;
        p.x0 = std::move(x0);
        p.width = width;
        p.rates = rates;
        p.fft.threads = threads;
        p.keep_density = true;
        quantum::SmoluchowskiResult r;
        {
          py::gil_scoped_release free;
          r = quantum::smoluchowski(p, method, dt, steps);
        }
        py::dict d;
        d["method"] = r.method;
        d["order"] = r.order;
        d["dt"] = r.dt;
        d["time"] = r.time;
        d["steps"] = r.steps;
        d["mass"] = r.mass;
        d["mass_drift"] = r.mass_drift;
        d["min_density"] = r.min_density;
        d["negative_mass"] = r.negative_mass;
        d["imaginary_part"] = r.imaginary_part;
        d["mean"] = to_array(r.mean);
        d["variance"] = to_array(r.variance);
        d["boltzmann_distance"] = r.boltzmann_distance;
        d["exact_error"] = r.exact_error;
        d["exact_solution"] = r.exact_solution.empty() ? py::object(py::none()) : py::object(py::str(r.exact_solution));
        d["rates"] = to_array(r.rates);
        d["rate_residuals"] = to_array(r.rate_residuals);
        d["kramers_rate"] = r.kramers_rate;
        d["fft_count"] = r.fft_count;
        d["seconds"] = r.seconds;
        std::vector<py::ssize_t> shape(static_cast<std::size_t>(dims), static_cast<py::ssize_t>(grid));
        py::array_t<double> rho(shape), rho_b(shape);
        std::copy(r.density.begin(), r.density.end(), rho.mutable_data());
        std::copy(r.boltzmann.begin(), r.boltzmann.end(), rho_b.mutable_data());
        d["density"] = rho;
        d["boltzmann"] = rho_b;
        return d;
      },
      py::arg("potential"), py::arg("values"), py::arg("initial"), py::arg("dims"), py::arg("grid"), py::arg("box"),
      py::arg("diffusion"), py::arg("beta"), py::arg("x0"), py::arg("width"), py::arg("method"), py::arg("dt"),
      py::arg("steps"), py::arg("rates"), py::arg("threads"),
      "quantum::smoluchowski() with the GIL released; nystrom.smoluchowski wraps the result.");
  m.def(
      "thermal",
      [](const std::string& potential, std::optional<DArray> values, int grid, double box, double beta,
         std::vector<long> beads, std::vector<long> extrapolate) {
        quantum::ThermalProblem<double> p;
        p.potential = potential;
        p.values = to_vector(values);
        p.grid = grid;
        p.box = box;
        p.beta = beta;
        p.beads = std::move(beads);
        p.extrapolate = std::move(extrapolate);
        quantum::ThermalResult r;
        {
          py::gil_scoped_release free;
          r = quantum::thermal(p);
        }
        py::dict d;
        d["beta"] = r.beta;
        d["extrapolate"] = r.extrapolate;
        d["order"] = r.order;
        d["z_exact"] = r.z_exact;
        d["energy_exact"] = r.energy_exact;
        d["levels"] = to_array(r.levels);
        std::vector<long> b;
        std::vector<double> zp, ep, zx, ex;
        for (const auto& row : r.rows) {
          b.push_back(row.beads);
          zp.push_back(row.z_primitive);
          ep.push_back(row.energy_primitive);
          zx.push_back(row.z_extrapolated);
          ex.push_back(row.energy_extrapolated);
        }
        d["beads"] = py::array_t<long>(static_cast<py::ssize_t>(b.size()), b.data());
        d["z_primitive"] = to_array(zp);
        d["energy_primitive"] = to_array(ep);
        d["z_extrapolated"] = to_array(zx);
        d["energy_extrapolated"] = to_array(ex);
        d["seconds"] = r.seconds;
        return d;
      },
      py::arg("potential"), py::arg("values"), py::arg("grid"), py::arg("box"), py::arg("beta"), py::arg("beads"),
      py::arg("extrapolate"), "quantum::thermal() with the GIL released; nystrom.thermal wraps the result.");
}

}  // namespace nystrom::python
