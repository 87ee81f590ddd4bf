// nystrom._core.flows: velocity::solve_builtin() (nystrom/velocity/solve.hpp) run with the GIL released. Every
// parameter left as None keeps the library's default (velocity::BuiltinSetup, which the CLI's `nystrom flows`
// shares); every check of the input is the library's (nystrom::invalid_input reaches Python as ValueError with
// its one-line message).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "flows_binding.hpp"
#include "nystrom/velocity/solve.hpp"

namespace nystrom::python {

namespace py = pybind11;

namespace {

py::array_t<double> array(const std::vector<double>& x) {
  return py::array_t<double>(static_cast<py::ssize_t>(x.size()), x.data());
}

py::dict to_dict(const velocity::FlowResult& r) {
  py::dict d;
  d["method"] = r.method;
  d["order"] = r.order;
  d["symplectic"] = r.symplectic;
  d["dt"] = r.dt;
  d["time"] = r.time;
  d["steps"] = r.steps;
  d["q"] = array(r.q);
  d["v"] = array(r.v);
  d["force_evals"] = r.force_evals;
  d["flows"] = r.flows;
  d["invariant_name"] = r.invariant_name.empty() ? py::object(py::none()) : py::object(py::str(r.invariant_name));
  d["invariant0"] = r.invariant0;
  d["invariant"] = r.invariant;
  d["invariant_error"] = r.invariant_error;
  d["position_error"] = r.position_error;
  d["velocity_error"] = r.velocity_error;
  d["return_error"] = r.return_error;
  d["periods"] = r.periods;
  d["seconds"] = r.seconds;
  const auto n = static_cast<py::ssize_t>(r.samples.size());
  const auto dims = static_cast<py::ssize_t>(r.q.size());
  py::array_t<double> t(n), inv(n), q({n, dims}), v({n, dims});
  for (py::ssize_t i = 0; i < n; ++i) {
    const auto& s = r.samples[static_cast<std::size_t>(i)];
    t.mutable_at(i) = s.time;
    inv.mutable_at(i) = s.invariant;
    for (py::ssize_t a = 0; a < dims; ++a) {
      q.mutable_at(i, a) = s.q.at(static_cast<std::size_t>(a));
      v.mutable_at(i, a) = s.v.at(static_cast<std::size_t>(a));
    }
  }
  d["sample_times"] = t;
  d["sample_q"] = q;
  d["sample_v"] = v;
  d["sample_invariant"] = inv;
  return d;
}

/// f(q) or f(t, q) from Python as a vector of n components; the GIL is held (the run keeps it).
std::vector<double> call_field(const py::object& f, const char* what, std::size_t n, const double* q, std::size_t nq,
                               std::optional<double> t) {
  py::array_t<double> qa(static_cast<py::ssize_t>(nq), q);
  py::object out = t ? f(*t, qa) : f(qa);
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(out);
  if (!a || a.ndim() > 1 || static_cast<std::size_t>(a.size()) != n)
    throw invalid_input(std::string(what) + " must return " + std::to_string(n) + " numbers");
  std::vector<double> r(a.data(), a.data() + n);
  for (double x : r)
    if (!std::isfinite(x)) throw invalid_input(std::string(what) + " returned a value that is not finite");
  return r;
}

velocity::Vec3<double> vec3(const std::vector<double>& x, const char* what) {
  if (x.size() != 3) throw invalid_input(std::string(what) + " needs 3 components, got " + std::to_string(x.size()));
  return {x[0], x[1], x[2]};
}

}  // namespace

void register_flows(py::module_& m) {
  m.def(
      "flows_custom",
      [](const std::string& family, std::vector<double> axis, double gamma, std::vector<double> q0,
         std::vector<double> v0, double t0, py::object force, py::object potential, const std::string& method,
         double dt, long steps, long samples) {
        velocity::FlowResult r;
        const bool has_force = !force.is_none(), has_potential = !potential.is_none();
        if (family == "rotating" || family == "magnetic") {
          auto field = [force](const char* what) {
            return [force, what](const velocity::Vec3<double>& q, velocity::Vec3<double>& out) {
              const auto a = call_field(force, what, 3, q.data(), 3, std::nullopt);
              out = {a[0], a[1], a[2]};
            };
          };
          auto pot = [potential](const velocity::Vec3<double>& q) {
            const double u = py::cast<double>(potential(py::array_t<double>(3, q.data())));
            if (!std::isfinite(u)) throw invalid_input("the potential returned a value that is not finite");
            return u;
          };
          if (family == "rotating") {
            if (!has_force) throw invalid_input("a rotating frame needs the gradient of its potential");
            velocity::RotatingFrameProblem<double> p;
            p.omega = vec3(axis, "omega");
            p.q0 = vec3(q0, "q0");
            p.v0 = vec3(v0, "v0");
            p.gradient = field("the gradient");
            if (has_potential) p.potential = pot;
            r = velocity::solve(p, method, dt, steps, samples);
          } else {
            velocity::MagneticProblem<double> p;
            p.b = vec3(axis, "b");
            p.q0 = vec3(q0, "q0");
            p.v0 = vec3(v0, "v0");
            if (has_force) p.force = field("the force");
            if (has_potential) p.potential = pot;
            r = velocity::solve(p, method, dt, steps, samples);
          }
        } else if (family == "damped") {
          velocity::DampedProblem<double> p;
          p.gamma = gamma;
          p.q0 = q0;
          p.v0 = v0;
          p.t0 = t0;
          if (has_force)
            p.force = [force](double t, const std::vector<double>& q, std::vector<double>& out) {
              out = call_field(force, "the force", q.size(), q.data(), q.size(), t);
            };
          r = velocity::solve(p, method, dt, steps, samples);
        } else {
          throw invalid_input("unknown family '" + family + "' (rotating, magnetic, damped)");
        }
        py::dict d = to_dict(r);
        d["problem"] = family;
        d["precision"] = "double";
        return d;
      },
      py::arg("family"), py::arg("axis"), py::arg("gamma"), py::arg("q0"), py::arg("v0"), py::arg("t0"),
      py::arg("force"), py::arg("potential"), py::arg("method"), py::arg("dt"), py::arg("steps"), py::arg("samples"),
      "velocity::solve() (nystrom/velocity/solve.hpp) on a RotatingFrameProblem, MagneticProblem or DampedProblem "
      "with forces from Python (the GIL is held: the forces are Python calls); nystrom.rotating_frame, "
      "nystrom.magnetic and nystrom.damped wrap the result.");

  m.def(
      "flows",
      [](const std::string& problem, std::optional<std::string> method, std::optional<double> periods,
         std::optional<long> steps_per_period, std::optional<long> samples, std::optional<double> mu,
         std::optional<std::vector<double>> b, std::optional<std::vector<double>> e, std::optional<double> kappa,
         std::optional<double> gamma, std::optional<double> omega0, std::optional<double> drive,
         std::optional<double> drive_frequency, std::optional<std::vector<double>> q0,
         std::optional<std::vector<double>> v0, const std::string& precision) {
        velocity::BuiltinSetup s;
        s.problem = problem;
        if (method) s.method = *method;
        if (periods) s.periods = *periods;
        if (steps_per_period) s.steps_per_period = *steps_per_period;
        if (samples) s.samples = *samples;
        if (mu) s.mu = *mu;
        if (b) s.b = *b;
        if (e) s.e = *e;
        if (kappa) s.kappa = *kappa;
        if (gamma) s.gamma = *gamma;
        if (omega0) s.omega0 = *omega0;
        if (drive) s.drive = *drive;
        if (drive_frequency) s.drive_frequency = *drive_frequency;
        if (q0) s.q0 = *q0;
        if (v0) s.v0 = *v0;
        if (precision != "double" && precision != "long-double")
          throw std::invalid_argument("precision must be 'double' or 'long-double', got '" + precision + "'");
        velocity::FlowResult r;
        {
          py::gil_scoped_release free;
          r = precision == "double" ? velocity::solve_builtin<double>(s) : velocity::solve_builtin<long double>(s);
        }
        py::dict d = to_dict(r);
        d["problem"] = problem;
        d["precision"] = precision;
        return d;
      },
      py::arg("problem"), py::arg("method"), py::arg("periods"), py::arg("steps_per_period"), py::arg("samples"),
      py::arg("mu"), py::arg("b"), py::arg("e"), py::arg("kappa"), py::arg("gamma"), py::arg("omega0"),
      py::arg("drive"), py::arg("drive_frequency"), py::arg("q0"), py::arg("v0"), py::arg("precision"),
      "velocity::solve_builtin() (nystrom/velocity/solve.hpp) with the GIL released; nystrom.flows wraps the "
      "result.");
}

}  // namespace nystrom::python
