// Steppers of a Python force in double (real and complex coefficients, fixed and adaptive steps).
//
// The engines integrate autonomous systems, so the time is carried as one more coordinate, the last one
// (velocity 1, acceleration 0): every method integrates it exactly (drifts move it by c h, RKN stages by
// c_i h, the multi-product combination has coefficients summing to 1), and the force gets the time of
// each stage.
#include <complex>
#include <vector>

#include "stepper.hpp"

namespace nystrom::python {

namespace {

/// PyForce on the first n coordinates, with the time taken from coordinate n.
template <class S>
struct TimedPyForce {
  PyForce<S> f;
  std::size_t n = 0;
  mutable std::vector<S> qu, au;  // the user's coordinates (scratch)

  template <class V>
  void operator()(const V& q, V& a) const {
    qu.assign(q.begin(), q.begin() + static_cast<std::ptrdiff_t>(n));
    au.resize(n);
    *f.t = to_double(q[n]);
    f(qu, au);
    for (std::size_t i = 0; i < n; ++i) a[i] = au[i];
    a[n] = S(0);
  }
};

}  // namespace

std::unique_ptr<Stepper> make_python_stepper(py::object fn, std::vector<py::ssize_t> shape, std::size_t n,
                                             const MethodDef& def, const StepperOptions& o,
                                             std::shared_ptr<double>& time_slot) {
  if (def.info.complex) {
    using C = std::complex<double>;
    TimedPyForce<C> f{PyForce<C>{std::move(fn), std::move(shape)}, n, {}, {}};
    time_slot = f.f.t;
    return std::make_unique<StepperImpl<std::vector<C>, TimedPyForce<C>>>(def, std::move(f), n + 1, o, true);
  }
  TimedPyForce<double> f{PyForce<double>{std::move(fn), std::move(shape)}, n, {}, {}};
  time_slot = f.f.t;
  return std::make_unique<StepperImpl<std::vector<double>, TimedPyForce<double>>>(def, std::move(f), n + 1, o, true);
}

}  // namespace nystrom::python
