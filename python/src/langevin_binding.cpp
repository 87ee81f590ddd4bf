// nystrom._core.langevin: Langevin path ensembles of the built-in one-dimensional problems
// (nystrom/stochastic/potentials.hpp), the solver of `nystrom langevin`. The paths run in blocks with the GIL
// released; between blocks Python checks for Ctrl-C and reports progress. A block is a whole number of chunks
// of paths, so the result is bitwise that of one run (nystrom/stochastic/langevin.hpp). Every check of the
// input is the library's (nystrom::invalid_input reaches Python as ValueError with its one-line message).
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "langevin_binding.hpp"
#include "nystrom/stochastic/potentials.hpp"

namespace nystrom::python {

namespace py = pybind11;
namespace st = nystrom::stochastic;

namespace {

py::dict estimate(const st::Estimate& e) {
  py::dict d;
  d["value"] = e.value;
  d["stderr"] = e.stderr_;
  return d;
}

py::dict langevin(const std::string& potential, double omega, double gamma, double kT, double q0, double v0,
                  const std::string& method, double h, double t_end, long paths, std::uint64_t seed,
                  const std::vector<long>& extrapolate, int threads, long first_path, const py::object& progress) {
  st::LangevinOptions o;
  o.method = method;
  o.h = h;
  o.paths = paths;
  o.seed = seed;
  o.extrapolate = extrapolate;
  o.threads = threads;
  const auto problem = st::builtin_problem_1d(potential, gamma, kT, t_end, q0, v0, omega);
  st::check_langevin(problem, o);
  st::LangevinPartial all;
  // blocks of about a tenth of a second of work for small problems: at least one chunk per thread
  const double steps = t_end / h;
  double members = 0;
  for (long k : extrapolate) members += static_cast<double>(k);
  const long per_block =
      std::max<long>(st::chunk_paths * std::max(1, threads),
                     static_cast<long>(2e7 / std::max(1.0, steps * members)) / st::chunk_paths * st::chunk_paths);
  for (long done = 0; done < paths;) {
    const long n = std::min(per_block, paths - done);
    st::LangevinPartial part;
    {
      py::gil_scoped_release free;
      part = st::run_langevin_paths(problem, o, first_path + done, n);
    }
    all.merge(part);
    done += n;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    if (!progress.is_none()) progress(done, paths);
  }
  const st::LangevinResult r = st::finish_langevin(problem, o, all);
  py::dict d, averages, finals;
  py::list members_list;
  for (const auto& ob : r.observables) {
    averages[py::str(ob.name)] = estimate(ob.average);
    finals[py::str(ob.name)] = estimate(ob.final);
  }
  for (std::size_t i = 0; i < r.extrapolate.size(); ++i) {
    py::dict m, ma, mf;
    m["k"] = r.extrapolate[i];
    m["h"] = r.h / static_cast<double>(r.extrapolate[i]);
    for (const auto& ob : r.observables) {
      ma[py::str(ob.name)] = estimate(ob.member_average[i]);
      mf[py::str(ob.name)] = estimate(ob.member_final[i]);
    }
    m["averages"] = ma;
    m["final"] = mf;
    members_list.append(m);
  }
  d["method"] = r.method;
  d["h"] = r.h;
  d["t_end"] = r.t_end;
  d["steps"] = r.steps;
  d["window"] = py::make_tuple(r.window_start, r.t_end);
  d["paths"] = r.paths;
  d["seed"] = seed;
  d["extrapolate"] = r.extrapolate;
  d["coefficients"] = r.coefficients;
  d["order"] = r.order;
  d["force_evaluations"] = r.force_evaluations;
  d["averages"] = averages;
  d["final"] = finals;
  d["members"] = members_list;
  return d;
}

}  // namespace

void register_langevin(py::module_& m) {
  m.def("langevin", &langevin, py::arg("potential"), py::arg("omega"), py::arg("gamma"), py::arg("kT"), py::arg("q0"),
        py::arg("v0"), py::arg("method"), py::arg("h"), py::arg("t_end"), py::arg("paths"), py::arg("seed"),
        py::arg("extrapolate"), py::arg("threads"), py::arg("first_path"), py::arg("progress"),
        "Langevin paths of a built-in problem (nystrom.langevin checks the arguments and wraps the result)");
}

}  // namespace nystrom::python
