// solve() on a Python force(t, q) in double, for real and complex coefficients, and on a velocity-dependent
// force(t, q, v).
//
// solve() gives the force the time of each stage (it integrates the time exactly, as one more coordinate). A
// complex-coefficient method passes complex arrays and a complex time to the force.
#include <algorithm>
#include <complex>
#include <string>
#include <vector>

#include "solve_binding.hpp"

namespace nystrom::python {

namespace {

std::string shape_text(const py::ssize_t* dims, std::size_t ndim) {
  std::string s = "(";
  for (std::size_t i = 0; i < ndim; ++i) s += (i ? ", " : "") + std::to_string(dims[i]);
  return s + (ndim == 1 ? ",)" : ")");
}

/// force(t, q) called once per force evaluation with q shaped like the user's q0. The run goes on without
/// the GIL: each call takes it for the call only (fn is borrowed from the caller, who keeps it alive, so that
/// copies of this functor touch no reference count).
struct PyForce {
  py::handle fn;
  std::vector<py::ssize_t> shape;
  std::size_t n = 0;

  /// Real (double) or complex (std::complex<double>) time and states.
  template <class S>
  requires(std::is_same_v<S, double> || std::is_same_v<S, std::complex<double>>) void operator()(
      const S& t, const std::vector<S>& q, std::vector<S>& a) const {
    py::gil_scoped_acquire hold;
    py::array_t<S> arr(shape);
    S* dst = arr.mutable_data();
    for (std::size_t i = 0; i < n; ++i) dst[i] = q[i];
    read<S>(fn(t, arr), "force(t, q)", a);
  }

  /// The result r of the call `what` into a[0..n): exactly q's shape.
  template <class S, class W>
  void read(const py::object& r, const char* what, W& a) const {
    using Arr = py::array_t<S, py::array::c_style | py::array::forcecast>;
    if (!py::isinstance<py::array>(r) && !py::isinstance<py::sequence>(r))
      throw py::type_error(std::string(what) + " must return an array of numbers, got " +
                           std::string(py::str(py::type::of(r).attr("__name__"))));
    Arr res = Arr::ensure(r);
    if (!res) throw py::type_error(std::string(what) + " must return an array of numbers");
    // The exact shape of q: an array of the right size and another shape (q.T, a flattened q) is a
    // mistake that would mix the coordinates up.
    const bool same =
        static_cast<std::size_t>(res.ndim()) == shape.size() && std::equal(shape.begin(), shape.end(), res.shape());
    if (!same)
      throw py::value_error(std::string(what) + " returned an array of shape " +
                            shape_text(res.shape(), static_cast<std::size_t>(res.ndim())) + " for q of shape " +
                            shape_text(shape.data(), shape.size()) + ": it must return q's shape");
    const S* src = res.data();
    for (std::size_t i = 0; i < n; ++i) a[i] = src[i];
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  }
};

/// force(t, q, v): the same with the velocity.
struct PyVelocityForce {
  PyForce base;
  void operator()(const double& t, const std::vector<double>& q, const std::vector<double>& v,
                  std::vector<double>& a) const {
    py::gil_scoped_acquire hold;
    py::array_t<double> qa(base.shape), va(base.shape);
    double* qd = qa.mutable_data();
    double* vd = va.mutable_data();
    for (std::size_t i = 0; i < base.n; ++i) {
      qd[i] = q[i];
      vd[i] = v[i];
    }
    base.read<double>(base.fn(t, qa, va), "force(t, q, v)", a);
  }
};

}  // namespace

py::dict solve_python_force(py::object force, std::vector<py::ssize_t> shape, const SolveRequest& r, bool velocity) {
  SolveRequest req = r;
  req.options.mpe_schedule = MpeSchedule::sequential;  // one thread calls the force
  const std::size_t n = r.q0.size();
  if (velocity) return run_solve<std::vector<double>>(PyVelocityForce{{force, shape, n}}, req, true);
  return run_solve<std::vector<double>>(PyForce{force, std::move(shape), n}, req, true);
}

}  // namespace nystrom::python
