// solve() on a Python force(t, q) in double, for real and complex coefficients.
//
// The state carries the time as one more coordinate, the last (velocity 1, acceleration 0): every method
// integrates it exactly (drifts move it by c h, RKN stages by c_i h, the multi-product combination has
// coefficients summing to 1), and the force gets the time of each stage. A complex-coefficient method
// passes complex arrays to the force.
#include <complex>
#include <vector>

#include "solve_binding.hpp"

namespace nystrom::python {

namespace {

/// force(t, q) called once per force evaluation with q shaped like the user's q0 (the first n
/// coordinates) and t from coordinate n.
struct PyForce {
  py::object fn;
  std::vector<py::ssize_t> shape;
  std::size_t n = 0;

  template <class W>
  requires(std::is_same_v<typename W::value_type, double> ||
           std::is_same_v<typename W::value_type, std::complex<double>>) void
  operator()(const W& q, W& a) const {
    using S = typename W::value_type;
    py::array_t<S> arr(shape);
    S* dst = arr.mutable_data();
    for (std::size_t i = 0; i < n; ++i) dst[i] = q[i];
    py::object r = fn(to_double(q[n]), arr);
    using Arr = py::array_t<S, py::array::c_style | py::array::forcecast>;
    if (!py::isinstance<py::array>(r) && !py::isinstance<py::sequence>(r))
      throw py::type_error("force(t, q) must return an array of numbers, got " +
                           std::string(py::str(py::type::of(r).attr("__name__"))));
    Arr res = Arr::ensure(r);
    if (!res) throw py::type_error("force(t, q) must return an array of numbers");
    if (static_cast<std::size_t>(res.size()) != n)
      throw py::value_error("force(t, q) returned " + std::to_string(res.size()) + " values for a state of " +
                            std::to_string(n) + " coordinates");
    const S* src = res.data();
    for (std::size_t i = 0; i < n; ++i) a[i] = src[i];
    a[n] = S(0);
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  }
};

}  // namespace

py::dict solve_python_force(py::object force, std::vector<py::ssize_t> shape, const SolveRequest& r) {
  SolveRequest req = r;
  req.options.engine.mpe_schedule = MpeSchedule::sequential;  // one thread: the force holds the GIL
  const std::size_t n = r.q0.size();
  return run_solve<std::vector<double>>(PyForce{std::move(force), std::move(shape), n}, req, true, true);
}

}  // namespace nystrom::python
