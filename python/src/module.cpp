// nystrom._core: the compiled part of the Python package. The catalog (methods, coeffs) and the
// steppers the pure-Python driver (nystrom/_solve.py) advances. Library errors (std::invalid_argument)
// reach Python as ValueError with the library's one-line message.
#include <pybind11/complex.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <iomanip>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "nystrom/analysis/bch.hpp"
#include "nystrom/analysis/method_file.hpp"  // installs the reader of "file:" method specifications
#include "nystrom/engines/mpe.hpp"
#include "nystrom/experiments/kepler.hpp"
#include "nystrom/methods/catalog.hpp"
#include "nystrom/problems/plummer.hpp"
#include "stepper.hpp"

namespace py = pybind11;
using namespace nystrom;
using namespace nystrom::python;

namespace {

py::dict info_dict(const MethodInfo& m) {
  py::dict d;
  d["name"] = m.name;
  d["family"] = m.family;
  d["order"] = m.order;
  d["stages"] = m.stages;
  d["forces_per_step"] = m.forces_per_step;
  d["fsal"] = m.fsal;
  d["symmetric"] = m.symmetric;
  d["symplectic"] = m.symplectic;
  d["complex"] = m.complex;
  d["adaptive"] = m.adaptive;
  d["published_digits"] = m.published_digits;
  d["aliases"] = m.aliases;
  d["source"] = m.source;
  d["description"] = m.description;
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
  validate_mpe_sequence(k);
  const auto m = mpe_coefficients(k);
  long sum = 0;
  for (long x : k) sum += x;
  py::list c;
  for (const auto& x : m.c) c.append(x.get_str());
  py::dict d;
  d["family"] = "mpe";
  d["sequence"] = k;
  d["order"] = m.order();
  d["coefficients"] = c;
  d["error_coefficient"] = m.error.get_str();
  d["amplification"] = mpe_amplification(m);
  d["force_evals_pv"] = sum;
  d["force_evals_vv"] = sum + 1;
  return d;
}

py::dict method_coeffs(const std::string& spec, int digits) {
  if (digits < 1 || digits > 1000) throw std::invalid_argument("digits must be between 1 and 1000");
  const auto def = resolve_method(spec);
  BigPrecision guard(static_cast<unsigned>(digits * 3.33 + 64));
  const auto data = def.build();
  py::dict j;
  j["method"] = def.info.name;
  j["order"] = def.info.order;
  j["source"] = def.info.source;
  auto vec = [&](const std::vector<bigcomplex>& v) {
    py::list a;
    for (const auto& x : v) a.append(show(x, digits));
    return a;
  };
  if (const auto* sp = std::get_if<SplittingScheme<bigcomplex>>(&data)) {
    j["family"] = "splitting";
    py::list steps;
    for (const auto& s : sp->steps) {
      py::dict st;
      st["flow"] = s.flow == Flow::drift ? "drift" : "kick";
      st["re"] = show(s.coef.re, digits);
      st["im"] = show(s.coef.im, digits);
      steps.append(st);
    }
    j["steps"] = steps;
  } else if (const auto* t = std::get_if<RknTableau<bigcomplex>>(&data)) {
    j["family"] = "rkn";
    j["c"] = vec(t->c);
    j["b"] = vec(t->b);
    j["B"] = vec(t->B);
    py::list a;
    for (const auto& row : t->a) a.append(vec(row));
    j["a"] = a;
  } else {
    const auto& m = std::get<MpeDef>(data);
    const auto mc = mpe_coefficients(m.k);
    j["family"] = "mpe";
    j["sequence"] = m.k;
    j["base"] = m.base_name;
    py::list c;
    for (const auto& x : mc.c) c.append(x.get_str());
    j["coefficients"] = c;
    j["error_coefficient"] = mc.error.get_str();
  }
  return j;
}

/// The BCH analysis of a splitting method, as `nystrom bch --json` gives it.
py::dict bch(const std::string& method, int degree, const std::string& basis, const std::string& algebra, unsigned bits,
             double tolerance) {
  namespace an = nystrom::analysis;
  an::check_degree(degree);
  if (bits < 64 || bits > 4096) throw std::invalid_argument("bits must be between 64 and 4096");
  if (!(tolerance >= 0)) throw std::invalid_argument("tolerance must be >= 0");
  an::AnalysisOptions opt;
  opt.degree = degree;
  opt.basis = an::parse_basis(basis);
  opt.algebra = an::parse_algebra(algebra);
  opt.precision_bits = bits;
  opt.tolerance = tolerance;
  const an::MethodAnalysis a = an::analyze_method(resolve_method(method), opt);
  auto terms = [](const an::DegreeTerms& d) {
    py::list out;
    for (const auto& t : d.terms) {
      py::dict x;
      x["name"] = t.name;
      x["definition"] = t.definition;
      x["bracket"] = t.bracket;
      x["value"] = t.value;
      x["exact"] = t.exact;
      out.append(x);
    }
    return out;
  };
  py::dict j;
  j["method"] = a.method;
  j["degree"] = a.degree;
  j["basis"] = an::to_string(a.basis);
  j["algebra"] = an::to_string(a.algebra);
  j["exact"] = a.exact;
  j["precision_bits"] = a.precision_bits;
  j["tolerance"] = a.tolerance;
  j["declared_order"] = a.declared_order;
  j["order"] = a.order;
  j["order_is_lower_bound"] = a.order_is_lower_bound;
  py::list degs;
  for (const auto& d : a.degrees) {
    py::dict x;
    x["degree"] = d.degree;
    x["vanishes"] = d.vanishes;
    x["norm"] = d.norm;
    x["terms"] = terms(d);
    degs.append(x);
  }
  j["degrees"] = degs;
  if (const auto* l = a.leading()) {
    py::dict x;
    x["degree"] = l->degree;
    x["norm"] = l->norm;
    x["terms"] = terms(*l);
    j["leading"] = x;
  } else {
    j["leading"] = py::none();
  }
  return j;
}

/// A stepper as Python sees it.
struct PyStepper {
  std::unique_ptr<Stepper> s;
};

using DArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

const double* checked(const DArray& a, std::size_t n, const char* what) {
  if (static_cast<std::size_t>(a.size()) != n)
    throw std::invalid_argument(std::string(what) + " has " + std::to_string(a.size()) + " values, expected " +
                                std::to_string(n));
  return a.data();
}

py::dict status_dict(const AdvanceStatus& st, Record* rec, std::size_t n) {
  py::dict d;
  d["steps"] = st.steps;
  d["rejected"] = st.rejected;
  d["failed"] = st.failed;
  d["message"] = st.message;
  if (rec) {
    const auto m = static_cast<py::ssize_t>(rec->t.size());
    const auto dn = static_cast<py::ssize_t>(n);
    d["t"] = py::array_t<double>(m, rec->t.data());
    d["q"] = py::array_t<double>({m, dn}, rec->q.data());
    d["v"] = py::array_t<double>({m, dn}, rec->v.data());
  }
  return d;
}

StepperOptions options(double tol, double h0, double h_max, long max_steps, bool keep_complex) {
  if (!(tol >= 0) || !std::isfinite(tol)) throw std::invalid_argument("tolerance must be a positive finite number");
  StepperOptions o;
  o.tol = tol;
  o.h0 = h0;
  o.h_max = h_max;
  o.max_steps = max_steps;
  o.keep_complex = keep_complex;
  return o;
}

}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "Compiled core of nystrom: the method catalog and the integrators (use the nystrom package).";

  m.def(
      "methods",
      [] {
        py::list out;
        for (const auto& d : catalog()) out.append(info_dict(d.info));
        return out;
      },
      "Every method in the catalog, as a list of dicts.");
  m.def(
      "method_info", [](const std::string& spec) { return info_dict(resolve_method(spec).info); }, py::arg("spec"),
      "The catalog record of a method specification (a name, M<2n>, mpe:1,2,3, ...).");
  m.def("mpe_coeffs", &mpe_coeffs, py::arg("sequence"), "Exact multi-product coefficients of a sequence.");
  m.def(
      "optimal_mpe_sequence", [](int n, long sum) { return optimal_mpe_sequence(n, sum); }, py::arg("n"),
      py::arg("sum"));
  m.def("bch", &bch, py::arg("method"), py::arg("degree") = 7, py::arg("basis") = "hall", py::arg("algebra") = "rkn",
        py::arg("bits") = 192u, py::arg("tolerance") = 0.0,
        "BCH series of a splitting method: coefficients of H - Z per degree, order, leading error terms.");
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
        const MethodDef def = resolve_method(method);
        py::gil_scoped_release free;
        const auto r = run_kepler<double>(def, e, steps_per_period, periods);
        return std::make_tuple(r.seconds, r.force_evals, r.position_error);
      },
      py::arg("method"), py::arg("e"), py::arg("steps_per_period"), py::arg("periods"),
      "For benchmarks: the C++ library's own fixed-step Kepler run (experiments/kepler.hpp) without the Python "
      "driver: (seconds, force evaluations, final position error).");

  py::class_<PyStepper>(m, "Stepper")
      .def_property_readonly("dim", [](const PyStepper& p) { return p.s->dim(); })
      .def_property_readonly("adaptive", [](const PyStepper& p) { return p.s->adaptive(); })
      .def_property_readonly("python_force", [](const PyStepper& p) { return p.s->python_force(); })
      .def_property_readonly("force_evals", [](const PyStepper& p) { return p.s->force_evals(); })
      .def("set_state",
           [](PyStepper& p, const DArray& q, const DArray& v) {
             const std::size_t n = p.s->dim();
             p.s->set_state(checked(q, n, "q0"), checked(v, n, "v0"));
           })
      .def("state",
           [](const PyStepper& p) {
             const auto n = static_cast<py::ssize_t>(p.s->dim());
             py::array_t<double> q(n), v(n);
             p.s->get_state(q.mutable_data(), v.mutable_data());
             return py::make_tuple(q, v);
           })
      .def("state_strings", [](const PyStepper& p) { return p.s->state_strings(); })
      .def("acceleration",
           [](PyStepper& p, const DArray& q) {
             const std::size_t n = p.s->dim();
             py::array_t<double> a(static_cast<py::ssize_t>(n));
             p.s->acceleration(checked(q, n, "q"), a.mutable_data());
             return a;
           })
      .def(
          "advance_fixed",
          [](PyStepper& p, double t0, double t1, long n, long every, py::object progress) {
            Record rec;
            Record* r = every > 0 ? &rec : nullptr;
            Heartbeat hb{std::move(progress), !p.s->python_force()};
            AdvanceStatus st;
            if (hb.release_gil) {
              py::gil_scoped_release free;
              st = p.s->advance_fixed(t0, t1, n, every, r, hb);
            } else {
              st = p.s->advance_fixed(t0, t1, n, every, r, hb);
            }
            return status_dict(st, r, p.s->dim());
          },
          py::arg("t0"), py::arg("t1"), py::arg("n"), py::arg("every") = 0, py::arg("progress") = py::none())
      .def(
          "advance_adaptive",
          [](PyStepper& p, double t0, double t1, bool record, py::object progress) {
            Record rec;
            Record* r = record ? &rec : nullptr;
            Heartbeat hb{std::move(progress), !p.s->python_force()};
            AdvanceStatus st;
            if (hb.release_gil) {
              py::gil_scoped_release free;
              st = p.s->advance_adaptive(t0, t1, r, hb);
            } else {
              st = p.s->advance_adaptive(t0, t1, r, hb);
            }
            return status_dict(st, r, p.s->dim());
          },
          py::arg("t0"), py::arg("t1"), py::arg("record") = false, py::arg("progress") = py::none());

  m.def(
      "builtin_stepper",
      [](const std::string& problem, const std::vector<double>& params, std::size_t n, const std::string& method,
         const std::string& precision, double tol, double h0, double h_max, long max_steps, bool keep_complex) {
        const MethodDef def = resolve_method(method);
        const StepperOptions o = options(tol, h0, h_max, max_steps, keep_complex);
        PyStepper p;
        if (precision == "double")
          p.s = make_builtin_stepper_double(problem, params, n, def, o);
        else
          p.s = make_builtin_stepper_extended(problem, params, n, def, o, precision);
        return p;
      },
      py::arg("problem"), py::arg("params"), py::arg("n"), py::arg("method"), py::arg("precision") = "double",
      py::arg("tol") = 0.0, py::arg("h0") = 0.0, py::arg("h_max") = 0.0, py::arg("max_steps") = 10000000L,
      py::arg("keep_complex") = false);
  m.def(
      "python_stepper",
      [](py::object fn, std::vector<py::ssize_t> shape, const std::string& method, double tol, double h0, double h_max,
         long max_steps, bool keep_complex) {
        const MethodDef def = resolve_method(method);
        const StepperOptions o = options(tol, h0, h_max, max_steps, keep_complex);
        std::size_t n = 1;
        for (auto s : shape) n *= static_cast<std::size_t>(s);
        PyStepper p;
        std::shared_ptr<double> time_slot;  // the force's time, set by the stepper at every stage
        p.s = make_python_stepper(std::move(fn), std::move(shape), n, def, o, time_slot);
        return p;
      },
      py::arg("force"), py::arg("shape"), py::arg("method"), py::arg("tol") = 0.0, py::arg("h0") = 0.0,
      py::arg("h_max") = 0.0, py::arg("max_steps") = 10000000L, py::arg("keep_complex") = false);
}
