// nystrom._core.quantum: the quantum layer's solve() (nystrom/quantum/solve.hpp) on one process, run with the
// GIL released. Every check of the input is the library's (std::invalid_argument reaches Python as ValueError
// with its one-line message); Python runs only in the heartbeat, which checks for Ctrl-C and reports progress.
#include <pybind11/complex.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <complex>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "nystrom/quantum/solve.hpp"
#include "quantum_binding.hpp"

namespace nystrom::python {

namespace py = pybind11;

namespace {

using DArray = py::array_t<double, py::array::c_style | py::array::forcecast>;
using CArray = py::array_t<std::complex<double>, py::array::c_style | py::array::forcecast>;

/// The arguments of nystrom.quantum, checked by the library.
struct QuantumRequest {
  std::string potential;
  std::optional<DArray> values;
  std::optional<CArray> initial;
  int dims = 1, grid = 256;
  double box = 20;
  std::string method;
  double dt = 0.05;
  long steps = 200;
  bool imaginary = false;
  std::vector<double> x0, p0;
  double width = 1, g = 0;
  int states = 1;
  bool autocorrelation = false;
  long samples = 0;
  int threads = 1;
  double converge = 0;
  bool allow_negative = false;
  py::object progress;  // None or progress(done, total)
};

/// Steps between heartbeats: about 2^20 grid points updated (a few milliseconds of FFTs), so that Ctrl-C
/// answers promptly while a small run (fewer steps than that) is one call of the integrator, as in the tool.
long heartbeat_steps(int dims, int grid) {
  double points = 1;
  for (int i = 0; i < dims; ++i) points *= std::max(1, grid);
  return std::max(1L, static_cast<long>(static_cast<double>(1L << 20) / points));
}

template <class R>
py::dict run(const QuantumRequest& q) {
  quantum::QuantumProblem<R> p;
  p.dims = q.dims;
  p.grid = q.grid;
  p.box = static_cast<R>(q.box);
  p.potential = q.potential;
  if (q.values)
    for (py::ssize_t i = 0; i < q.values->size(); ++i) p.values.push_back(static_cast<R>(q.values->data()[i]));
  if (q.initial)
    for (py::ssize_t i = 0; i < q.initial->size(); ++i) {
      const std::complex<double> z = q.initial->data()[i];
      p.initial.emplace_back(static_cast<R>(z.real()), static_cast<R>(z.imag()));
    }
  p.converge = q.converge;
  p.allow_negative_coefficients = q.allow_negative;
  p.g = static_cast<R>(q.g);
  p.time = q.imaginary ? quantum::TimeKind::imaginary : quantum::TimeKind::real;
  for (double x : q.x0) p.x0.push_back(static_cast<R>(x));
  for (double x : q.p0) p.p0.push_back(static_cast<R>(x));
  p.width = static_cast<R>(q.width);
  p.fft.threads = q.threads;
  p.states = q.states;
  p.autocorrelation = q.autocorrelation;
  p.keep_state = true;
  p.heartbeat_steps = heartbeat_steps(q.dims, q.grid);
  p.heartbeat = [&q](long done, long total) {
    py::gil_scoped_acquire hold;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    if (!q.progress.is_none()) q.progress(done, total);
  };
  quantum::QuantumResult r;
  {
    py::gil_scoped_release free;
    r = quantum::solve(p, q.method, static_cast<R>(q.dt), q.steps, q.samples);
  }

  py::dict d;
  d["method"] = r.method;
  d["order"] = r.order;
  d["dt"] = r.dt;
  d["time"] = r.time;
  d["steps"] = r.steps;
  d["steps_taken"] = r.steps_taken;
  d["converged"] = r.converged;
  d["norm"] = r.norm;
  d["norm_drift"] = r.norm_drift;
  d["energy"] = r.energy;
  d["chemical_potential"] = r.chemical_potential;
  d["mean_position"] = py::array_t<double>(static_cast<py::ssize_t>(r.mean_x.size()), r.mean_x.data());
  d["mean_momentum"] = py::array_t<double>(static_cast<py::ssize_t>(r.mean_p.size()), r.mean_p.data());
  d["energies"] = py::array_t<double>(static_cast<py::ssize_t>(r.energies.size()), r.energies.data());
  d["exact_error"] = r.exact_error;
  d["exact_solution"] = r.exact_solution.empty() ? py::object(py::none()) : py::object(py::str(r.exact_solution));
  d["fft_count"] = r.fft_count;
  d["seconds"] = r.seconds;
  d["final_autocorrelation"] = r.autocorrelation;

  const auto n = static_cast<py::ssize_t>(r.samples.size());
  const auto dims = static_cast<py::ssize_t>(q.dims);
  py::array_t<double> times(n), norms(n), energies(n), mean_x({n, dims});
  py::array_t<std::complex<double>> c(n);
  for (py::ssize_t i = 0; i < n; ++i) {
    const auto& s = r.samples[static_cast<std::size_t>(i)];
    times.mutable_at(i) = s.time;
    norms.mutable_at(i) = s.norm;
    energies.mutable_at(i) = s.energy;
    for (py::ssize_t a = 0; a < dims; ++a) mean_x.mutable_at(i, a) = s.mean_x.at(static_cast<std::size_t>(a));
    c.mutable_at(i) = s.autocorrelation;
  }
  d["sample_times"] = times;
  d["sample_norms"] = norms;
  d["sample_energies"] = energies;
  d["sample_mean_position"] = mean_x;
  d["sample_autocorrelation"] = c;

  std::vector<py::ssize_t> shape(static_cast<std::size_t>(q.dims), static_cast<py::ssize_t>(q.grid));
  py::array_t<std::complex<double>> psi(shape);
  std::copy(r.psi.begin(), r.psi.end(), psi.mutable_data());
  d["psi"] = psi;
  return d;
}

}  // namespace

void register_quantum(py::module_& m) {
  m.def(
      "quantum",
      [](const std::string& potential, std::optional<DArray> values, std::optional<CArray> initial, int dims, int grid,
         double box, const std::string& method, double dt, long steps, bool imaginary, std::vector<double> x0,
         std::vector<double> p0, double width, double g, int states, const std::string& precision, bool autocorrelation,
         long samples, int threads, double converge, bool allow_negative, py::object progress) {
        if (threads < 1) throw std::invalid_argument("threads must be positive");
        if (samples < 0) throw std::invalid_argument("samples must not be negative");
        QuantumRequest q{potential,
                         std::move(values),
                         std::move(initial),
                         dims,
                         grid,
                         box,
                         method,
                         dt,
                         steps,
                         imaginary,
                         x0,
                         p0,
                         width,
                         g,
                         states,
                         autocorrelation,
                         samples,
                         threads,
                         converge,
                         allow_negative,
                         std::move(progress)};
        if (precision == "double") return run<double>(q);
        if (precision == "long-double") return run<long double>(q);
        throw std::invalid_argument("precision must be 'double' or 'long-double', got '" + precision + "'");
      },
      py::arg("potential"), py::arg("values"), py::arg("initial"), py::arg("dims"), py::arg("grid"), py::arg("box"),
      py::arg("method"), py::arg("dt"), py::arg("steps"), py::arg("imaginary"), py::arg("x0"), py::arg("p0"),
      py::arg("width"), py::arg("g"), py::arg("states"), py::arg("precision"), py::arg("autocorrelation"),
      py::arg("samples"), py::arg("threads"), py::arg("converge"), py::arg("allow_negative_coefficients"),
      py::arg("progress"),
      "quantum::solve() (nystrom/quantum/solve.hpp) with the GIL released; nystrom.quantum wraps the result.");
}

}  // namespace nystrom::python
