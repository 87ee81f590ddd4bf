// nystrom._core: the compiled part of the Python package. The catalog (methods, coeffs, bch) and solve()
// (nystrom/solve.hpp) on a Python force or a built-in problem (solve_binding.hpp); nystrom/_solve.py checks
// the arguments and wraps the result. Library errors (std::invalid_argument, nystrom::invalid_input) reach
// Python as ValueError with the library's one-line message.
//
// Lock discipline: the library's locks (the process-wide MPFR precision mutex of BigPrecision and
// MpfrPrecision, the caches of method_data_for) are never waited for while the GIL is held. Every call that
// may take one (method resolution, coefficient tables, BCH series, runs, MPFR dense output) runs with the GIL
// released; the Python objects are built from its C++ result afterwards.
#include <pybind11/complex.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <iomanip>
#include <optional>
#include <sstream>
#include <string>
#include <tuple>
#include <type_traits>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

#include "experiments/kepler.hpp"
#include "flows_binding.hpp"
#include "langevin_binding.hpp"
#include "nystrom/analysis/bch.hpp"
#include "nystrom/analysis/bch_report.hpp"
#include "nystrom/analysis/method_file.hpp"
#include "nystrom/methods/catalog.hpp"
#include "nystrom/methods/method_record.hpp"
#include "nystrom/methods/mpe_coefficients.hpp"
#include "nystrom/problems/plummer.hpp"
#include "solve_binding.hpp"
#ifdef NYSTROM_PYTHON_QUANTUM
#include "diffusion_binding.hpp"
#include "quantum_binding.hpp"
#endif

namespace py = pybind11;
using namespace nystrom;
using namespace nystrom::python;

#ifndef NYSTROM_VERSION
#error "NYSTROM_VERSION (the CMake project version) must be defined by the build"
#endif

namespace {

/// f() with the GIL released (f touches no Python object).
template <class F>
auto released(F&& f) {
  py::gil_scoped_release free;
  return f();
}

// The library's record (methods/method_record.hpp) as a dict, null as None.
py::dict info_dict(const MethodInfo& m) {
  py::dict d;
  for (const auto& [key, value] : method_record(m))
    d[py::str(key)] = std::visit(
        [](const auto& v) -> py::object {
          if constexpr (std::is_same_v<std::decay_t<decltype(v)>, std::monostate>)
            return py::none();
          else
            return py::cast(v);
        },
        value);
  return d;
}

std::string show(const bigfloat& x, int digits) {
  std::ostringstream s;
  s << std::setprecision(digits) << x;
  return s.str();
}
std::string show(const bigcomplex& x, int digits) {
  if (x.is_real()) return show(x.re, digits);
  return show(x.re, digits) + (x.im < 0 ? " - " : " + ") + show(boost::multiprecision::abs(x.im), digits) + "i";
}

py::dict mpe_coeffs(std::vector<long> k) {
  std::vector<std::string> coefficients;
  std::string error;
  int order = 0;
  double amplification = 0;
  released([&] {
    validate_mpe_sequence(k);
    const auto m = mpe_coefficients(k);
    for (const auto& x : m.c) coefficients.push_back(x.get_str());
    error = m.error.get_str();
    order = m.order();
    amplification = mpe_amplification(m);
    return 0;
  });
  long sum = 0;
  for (long x : k) sum += x;
  py::dict d;
  d["family"] = "mpe";
  d["sequence"] = k;
  d["order"] = order;
  d["coefficients"] = coefficients;
  d["error_coefficient"] = error;
  d["amplification"] = amplification;
  d["force_evals_pv"] = sum;
  d["force_evals_vv"] = sum + 1;
  return d;
}

/// The coefficient table of a catalog method as JSON text (digits decimal digits), built without the GIL.
std::string method_coeffs_json(const std::string& spec, int digits) {
  if (digits < 1 || digits > 1000) throw std::invalid_argument("digits must be between 1 and 1000");
  py::gil_scoped_release free;
  const auto def = resolve_method(spec);
  BigPrecision guard(static_cast<unsigned>(digits * 3.33 + 64));
  const auto data = def.build();
  nlohmann::json j;
  j["method"] = def.info.name;
  j["order"] = def.info.order;
  j["source"] = def.info.source;
  auto vec = [&](const std::vector<bigcomplex>& v) {
    auto a = nlohmann::json::array();
    for (const auto& x : v) a.push_back(show(x, digits));
    return a;
  };
  if (const auto* sp = std::get_if<SplittingScheme<bigcomplex>>(&data)) {
    j["family"] = "splitting";
    auto steps = nlohmann::json::array();
    for (const auto& s : sp->steps)
      steps.push_back({{"flow", s.flow == Flow::drift ? "drift" : "kick"},
                       {"re", show(s.coef.re, digits)},
                       {"im", show(s.coef.im, digits)}});
    j["steps"] = steps;
  } else if (const auto* t = std::get_if<RknTableau<bigcomplex>>(&data)) {
    j["family"] = "rkn";
    j["c"] = vec(t->c);
    j["b"] = vec(t->b);
    j["B"] = vec(t->B);
    auto a = nlohmann::json::array();
    for (const auto& row : t->a) a.push_back(vec(row));
    j["a"] = a;
  } else {
    const auto& m = std::get<MpeDef>(data);
    const auto mc = mpe_coefficients(m.k);
    j["family"] = "mpe";
    j["sequence"] = m.k;
    j["base"] = m.base_name;
    auto c = nlohmann::json::array();
    for (const auto& x : mc.c) c.push_back(x.get_str());
    j["coefficients"] = c;
    j["error_coefficient"] = mc.error.get_str();
  }
  return j.dump();
}

py::object method_coeffs(const std::string& spec, int digits) {
  return py::module_::import("json").attr("loads")(method_coeffs_json(spec, digits));
}

/// The BCH analysis of a splitting method as JSON text, the document `nystrom bch --json` prints.
std::string bch_json(const std::string& method, int degree, const std::string& basis, const std::string& algebra,
                     unsigned bits, double tolerance) {
  namespace an = nystrom::analysis;
  an::check_degree(degree);
  if (bits < 64 || bits > 4096) throw std::invalid_argument("bits must be between 64 and 4096");
  if (!(tolerance >= 0) || !std::isfinite(tolerance) || tolerance >= 1)
    throw std::invalid_argument("tolerance must be >= 0 and below 1");
  an::AnalysisOptions opt;
  opt.degree = degree;
  opt.basis = an::parse_basis(basis);
  opt.algebra = an::parse_algebra(algebra);
  opt.precision_bits = bits;
  opt.tolerance = tolerance;
  py::gil_scoped_release free;
  return an::bch_report_json<nlohmann::json>(an::analyze_method(resolve_method(method), opt)).dump();
}

/// The method solve() runs: resolve_solve_method(spec); with a tolerance, a multi-product method of
/// fixed steps becomes its adaptive form (M<2n> -> M<2n>-adaptive, mpe:K -> mpe-pv-adaptive:K,
/// mpe-midpoint:K -> mpe-midpoint-adaptive:K).
MethodDef solve_method(const std::string& spec, bool tolerance) {
  MethodDef def = resolve_solve_method(spec);
  if (!tolerance || def.info.adaptive) return def;
  const std::string& name = def.info.name;
  if (def.info.family == "mpe-midpoint")
    return resolve_solve_method("mpe-midpoint-adaptive:" + name.substr(name.find(':') + 1));
  if (def.info.family != "mpe") return def;
  const auto data = def.build();
  const auto& m = std::get<MpeDef>(data);
  const bool m_order =
      name.size() > 1 && name[0] == 'M' && name.find_first_not_of("0123456789", 1) == std::string::npos;
  if (m_order) return resolve_method(name + "-adaptive");
  std::string seq;
  for (long k : m.k) seq += (seq.empty() ? "" : ",") + std::to_string(k);
  return resolve_method(std::string(m.base_name == "VV" ? "mpe-vv" : "mpe-pv") + "-adaptive:" + seq);
}

using DArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

std::vector<double> flat(const DArray& a) { return std::vector<double>(a.data(), a.data() + a.size()); }

}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "Compiled core of nystrom: the method catalog and the integrators (use the nystrom package).";
  nystrom::analysis::register_method_file_reader();  // `file:PATH` method specifications
  m.attr("__version__") = NYSTROM_VERSION;
  m.attr("max_lie_degree") = nystrom::analysis::max_lie_degree;

  m.def(
      "methods",
      [] {
        // The catalog is built at its first use, which takes the precision lock: without the GIL.
        const auto infos = released([] {
          std::vector<MethodInfo> v;
          for (const auto& d : listed_methods()) v.push_back(d.info);
          return v;
        });
        py::list out;
        for (const auto& info : infos) out.append(info_dict(info));
        return out;
      },
      "Every method in the catalog, then GBS, as a list of dicts.");
  m.def(
      "method_info",
      [](const std::string& spec) { return info_dict(released([&] { return resolve_solve_method(spec).info; })); },
      py::arg("spec"), "The catalog record of a method specification (a name, M<2n>, mpe:1,2,3, ...).");
  m.def("mpe_coeffs", &mpe_coeffs, py::arg("sequence"), "Exact multi-product coefficients of a sequence.");
  m.def(
      "optimal_mpe_sequence", [](int n, long sum) { return optimal_mpe_sequence(n, sum); }, py::arg("n"),
      py::arg("sum"));
  m.def("bch_json", &bch_json, py::arg("method"), py::arg("degree") = 7, py::arg("basis") = "hall",
        py::arg("algebra") = "rkn", py::arg("bits") = 192u, py::arg("tolerance") = 0.0,
        "BCH series of a splitting method as the JSON text of `nystrom bch --json`.");
  m.def("method_coeffs", &method_coeffs, py::arg("spec"), py::arg("digits") = 20,
        "The coefficients of a catalog method, as decimal strings.");

  m.def(
      "plummer",
      [](std::size_t n, std::uint64_t seed) {
        const auto p = plummer_sphere<double>(n, seed);
        const auto N = static_cast<py::ssize_t>(n);
        py::array_t<double> mass(N), q({N, py::ssize_t(3)}), v({N, py::ssize_t(3)});
        for (std::size_t i = 0; i < n; ++i) {
          mass.mutable_at(i) = p.m[i];
          for (std::size_t c = 0; c < 3; ++c) {  // the library's layout is structure of arrays
            q.mutable_at(i, c) = p.s.q[c * n + i];
            v.mutable_at(i, c) = p.s.v[c * n + i];
          }
        }
        return py::make_tuple(mass, q, v);
      },
      py::arg("n"), py::arg("seed"), "A Plummer sphere (masses, positions (n, 3), velocities (n, 3)), E = -1/4.");

  m.def(
      "library_kepler_seconds",
      [](const std::string& method, double e, long steps_per_period, long periods) {
        py::gil_scoped_release free;
        const MethodDef def = resolve_method(method);
        const auto r = run_kepler<double>(def, e, steps_per_period, periods);
        return std::make_tuple(r.seconds, r.force_evals, r.position_error);
      },
      py::arg("method"), py::arg("e"), py::arg("steps_per_period"), py::arg("periods"),
      "For benchmarks: the C++ library's own fixed-step Kepler run (experiments/kepler.hpp) without the Python "
      "driver: (seconds, force evaluations, final position error).");

  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const nystrom::invalid_input& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    }
  });

  m.def(
      "solve_method_info",
      [](const std::string& spec, bool tolerance) {
        return info_dict(released([&] { return solve_method(spec, tolerance).info; }));
      },
      py::arg("spec"), py::arg("tolerance"),
      "The catalog record of the method solve() runs for spec (with a tolerance: the adaptive form of a "
      "multi-product method).");

  py::class_<DenseSolution>(m, "DenseSolution")
      .def_property_readonly("t_first", &DenseSolution::t_first)
      .def_property_readonly("t_last", &DenseSolution::t_last)
      .def("__call__", [](const DenseSolution& s, const DArray& ts) {
        const auto k = static_cast<py::ssize_t>(ts.size());
        const auto n = static_cast<py::ssize_t>(s.dim());
        py::array_t<double> q({k, n}), v({k, n});
        const double* t = ts.data();
        double* qd = q.mutable_data();
        double* vd = v.mutable_data();
        {
          py::gil_scoped_release free;  // an MPFR solution takes the precision lock around every evaluation
          for (py::ssize_t i = 0; i < k; ++i) s.eval(t[i], qd + i * n, vd + i * n);
        }
        return py::make_tuple(q, v);
      });

  m.def(
      "solve",
      [](const std::string& problem, const std::vector<double>& params, py::object force,
         std::vector<py::ssize_t> shape, const DArray& q0, const DArray& v0, double t0, double t1,
         const std::string& method, const std::string& precision, double h, long steps, double rtol, double atol,
         std::optional<std::vector<double>> t_eval, const py::list& events, bool dense, bool keep_complex,
         long max_steps, py::object progress, double checkpoint_at, std::string checkpoint_problem,
         std::string checkpoint_file, std::string restart_file, bool velocity) {
        SolveRequest r;
        r.method = released([&] { return solve_method(method, rtol > 0 || atol > 0); });
        r.q0 = flat(q0);
        r.v0 = flat(v0);
        if (r.q0.size() != r.v0.size()) throw invalid_input("q0 and v0 differ in size");
        r.t0 = t0;
        r.t1 = t1;
        r.options.h = h;
        r.options.steps = steps;
        r.options.rtol = rtol;
        r.options.atol = atol;
        if (t_eval) r.options.t_eval = *t_eval;
        r.options.dense = dense;
        r.options.max_steps = max_steps;
        r.options.keep_complex = keep_complex;
        for (const auto& e : events) {
          const auto t = e.cast<py::tuple>();
          r.events.push_back({t[0], t[1].cast<int>(), t[2].cast<bool>(), t[3].cast<std::string>()});
        }
        r.progress = std::move(progress);
        r.checkpoint_at = checkpoint_at;
        r.checkpoint_problem = std::move(checkpoint_problem);
        r.checkpoint_file = std::move(checkpoint_file);
        r.restart_file = std::move(restart_file);
        if (problem.empty()) {
          if (precision != "double")
            throw invalid_input("precision '" + precision + "' is available for built-in problems only");
          return solve_python_force(std::move(force), std::move(shape), r, velocity);
        }
        if (precision == "double") return solve_builtin_double(problem, params, r);
        if (is_compensated_problem(problem))
          throw invalid_input("compensated=True runs in double precision, not '" + precision + "'");
        return solve_builtin_extended(problem, params, r, precision);
      },
      py::arg("problem"), py::arg("params"), py::arg("force"), py::arg("shape"), py::arg("q0"), py::arg("v0"),
      py::arg("t0"), py::arg("t1"), py::arg("method"), py::arg("precision"), py::arg("h"), py::arg("steps"),
      py::arg("rtol"), py::arg("atol"), py::arg("t_eval"), py::arg("events"), py::arg("dense"), py::arg("keep_complex"),
      py::arg("max_steps"), py::arg("progress"), py::arg("checkpoint_at"), py::arg("checkpoint_problem"),
      py::arg("checkpoint_file"), py::arg("restart_file"), py::arg("velocity") = false,
      "solve() (nystrom/solve.hpp) on a built-in problem (problem: its name) or a Python force(t, q) "
      "(problem: ''; velocity: force(t, q, v)); nystrom.solve checks the arguments and wraps the result.");
  m.def("velocity_refusal", &velocity_refusal, py::arg("method"),
        "The one-line refusal of a method for a velocity-dependent force (the text of the C++ solve()).");
  m.def("first_order_refusal", &first_order_refusal, py::arg("method"),
        "The one-line refusal of a method for a first-order system (the text of the C++ solve()).");

  register_flows(m);
  register_langevin(m);
#ifdef NYSTROM_PYTHON_QUANTUM
  register_quantum(m);
  register_diffusion(m);
#endif
}
