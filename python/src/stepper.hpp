// The engine side of the Python module: a type-erased stepper that owns one integrator (fixed-step,
// adaptive RKN or adaptive MPE) of the library, its force and its state, and advances in steps the
// Python driver (nystrom/_solve.py) asks for. Built-in problems run here with the GIL released; Python
// forces (PyForce) call back into the interpreter, so they run with the GIL held.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <array>
#include <cmath>
#include <complex>
#include <cstddef>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "nystrom/engines/adaptive_mpe.hpp"
#include "nystrom/engines/adaptive_rkn.hpp"
#include "nystrom/engines/integrator.hpp"
#include "nystrom/methods/catalog.hpp"

namespace nystrom::python {

namespace py = pybind11;

/// States recorded during an advance: times and the flattened positions and velocities (row i of q is
/// the state at t[i]).
struct Record {
  std::vector<double> t, q, v;
};

/// How far one advance() got.
struct AdvanceStatus {
  long steps = 0;       // accepted steps
  long rejected = 0;    // rejected steps (adaptive)
  bool failed = false;  // the adaptive controller gave up (step size underflow, too many steps)
  std::string message;
};

/// Options of a stepper fixed at construction.
struct StepperOptions {
  bool keep_complex = false;  // complex-coefficient methods: keep the complexified state
  double tol = 0;             // > 0: adaptive step control with this tolerance
  double h0 = 0;              // adaptive: first step (0: automatic)
  double h_max = 0;           // adaptive: largest step (0: the span of each call)
  long max_steps = 10000000;  // adaptive: steps per advance
};

/// Called between chunks with the GIL held: interrupt checks (Ctrl-C) and the progress callback.
/// Throws py::error_already_set when a signal handler raised (KeyboardInterrupt).
struct Heartbeat {
  py::object progress;  // None or a callable progress(t)
  bool release_gil = false;

  void operator()(double t) const {
    auto beat = [&] {
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
      if (!progress.is_none()) progress(t);
    };
    if (release_gil) {
      py::gil_scoped_acquire hold;
      beat();
    } else {
      beat();
    }
  }
};

class Stepper {
 public:
  virtual ~Stepper() = default;
  virtual std::size_t dim() const = 0;
  virtual bool adaptive() const = 0;
  /// Whether the force calls into Python (then the GIL must stay held while advancing).
  virtual bool python_force() const = 0;
  virtual void set_state(const double* q, const double* v) = 0;
  virtual void get_state(double* q, double* v) const = 0;
  /// The state in full working precision, as decimal strings (q then v).
  virtual std::vector<std::string> state_strings() const = 0;
  /// n steps of size (t1 - t0) / n from t0, recording every `every` steps (every <= 0: nothing recorded).
  virtual AdvanceStatus advance_fixed(double t0, double t1, long n, long every, Record* rec, const Heartbeat& hb) = 0;
  /// Adaptive steps from t0 to t1 (lands on t1), recording every accepted step when rec is given.
  virtual AdvanceStatus advance_adaptive(double t0, double t1, Record* rec, const Heartbeat& hb) = 0;
  /// Force evaluations of the integration so far.
  virtual long force_evals() const = 0;
  /// a(q) in double for the dense-output interpolant (not counted in force_evals).
  virtual void acceleration(const double* q, double* a) = 0;
};

// ---- scalar conversions -----------------------------------------------------------------------------

/// x in decimal with enough digits to identify it in type T: the exact sum of its leading doubles (every
/// extended type here is such a sum), printed by MPFR.
template <class T>
std::string full_string(const T& x) {
  if constexpr (std::is_same_v<T, double>) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.17g", x);
    return buf;
  } else {
    mpfr_t acc;
    mpfr_init2(acc, 2200);
    mpfr_set_d(acc, 0.0, MPFR_RNDN);
    T r = x;
    for (int i = 0; i < 6; ++i) {
      const double d = as_double(r);
      if (d == 0 || !std::isfinite(d)) {
        if (!std::isfinite(d)) mpfr_set_d(acc, d, MPFR_RNDN);
        break;
      }
      mpfr_add_d(acc, acc, d, MPFR_RNDN);
      r = r - T(d);
    }
    const int digits = static_cast<int>(std::ceil(static_cast<double>(scalar_traits<T>::bits()) * 0.30103)) + 2;
    char* out = nullptr;
    mpfr_asprintf(&out, "%.*Rg", digits, acc);
    std::string s = out ? out : "nan";
    mpfr_free_str(out);
    mpfr_clear(acc);
    return s;
  }
}

template <class S>
double to_double(const S& x) {
  if constexpr (is_complex_v<S>) {
    return as_double(x.real());
  } else {
    return as_double(x);
  }
}

// ---- forces ------------------------------------------------------------------------------------------

/// The Hénon-Heiles potential V = (x^2 + y^2)/2 + x^2 y - y^3/3: a = (-x - 2xy, -y - x^2 + y^2).
struct HenonHeilesForce {
  template <class S>
  void operator()(const std::array<S, 2>& q, std::array<S, 2>& a) const {
    a[0] = -q[0] - S(2) * q[0] * q[1];
    a[1] = -q[1] - q[0] * q[0] + q[1] * q[1];
  }
};

/// A Python callable force(t, q) -> array, called once per force evaluation with q shaped like the
/// user's q0 and the time in the slot t (set per stage from the time coordinate, stepper_python.cpp).
/// Exceptions raised by the callable propagate
/// unchanged (py::error_already_set carries the original Python exception through the engine).
template <class S>
struct PyForce {
  py::object fn;
  std::vector<py::ssize_t> shape;
  std::shared_ptr<double> t = std::make_shared<double>(0.0);

  template <class V>
  void operator()(const V& q, V& a) const {
    py::array_t<S> arr(shape);
    S* dst = arr.mutable_data();
    for (std::size_t i = 0; i < q.size(); ++i) dst[i] = q[i];
    py::object r = fn(*t, arr);
    using Arr = py::array_t<S, py::array::c_style | py::array::forcecast>;
    if (!py::isinstance<py::array>(r) && !py::isinstance<py::sequence>(r))
      throw py::type_error("force(t, q) must return an array of numbers, got " +
                           std::string(py::str(py::type::of(r).attr("__name__"))));
    Arr res = Arr::ensure(r);
    if (!res) throw py::type_error("force(t, q) must return an array of numbers");
    if (static_cast<std::size_t>(res.size()) != q.size())
      throw py::value_error("force(t, q) returned " + std::to_string(res.size()) + " values for a state of " +
                            std::to_string(q.size()) + " coordinates");
    const S* src = res.data();
    for (std::size_t i = 0; i < q.size(); ++i) a[i] = src[i];
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  }
};

// ---- the stepper over one integrator -----------------------------------------------------------------

template <class V>
void resize_to(V& x, std::size_t n) {
  if constexpr (is_std_array<V>::value) {
    if (x.size() != n) throw std::invalid_argument("state has the wrong size for this problem");
  } else {
    x.assign(n, typename V::value_type(0));
  }
}

/// Steps per chunk between heartbeats: a fixed count (chunk boundaries change the rounding of merged
/// sub-steps, so they must not depend on timing), about 2^22 coordinate updates.
inline long chunk_steps(std::size_t dim, int forces_per_step) {
  const long work = static_cast<long>(dim) * std::max(1, forces_per_step);
  return std::max(1L, (1L << 22) / std::max(1L, work));
}

/// V: the engine's state type (complex for complex-coefficient methods), F: its force.
template <class V, class F>
class StepperImpl final : public Stepper {
 public:
  using S = typename V::value_type;
  using T = real_t<S>;
  using RealV = rebind_vector_t<V, T>;

  StepperImpl(const MethodDef& def, F force, std::size_t n, const StepperOptions& o, bool python)
      : def_(def), force_(force), n_(n), python_(python) {
    resize_to(s_.q, n);
    resize_to(s_.v, n);
    if (o.tol > 0) {
      if constexpr (is_complex_v<S>) {
        throw std::invalid_argument("adaptive steps need a method with real coefficients");
      } else {
        AdaptiveOptions ao;
        ao.tol = o.tol;
        ao.h0 = o.h0;
        ao.h_max = o.h_max;
        ao.max_steps = o.max_steps;
        const bool mpe = std::holds_alternative<MpeDef>(def.build());
        if (mpe)
          engine_.template emplace<3>(make_adaptive_mpe_integrator<V>(def, force, ao));
        else
          engine_.template emplace<2>(make_adaptive_integrator<V>(def, force, ao));
      }
    } else {
      engine_.template emplace<1>(make_integrator<V>(def, force, EngineOptions{o.keep_complex}));
    }
  }

  std::size_t dim() const override { return n_; }
  bool adaptive() const override { return engine_.index() >= 2; }
  bool python_force() const override { return python_; }

  void set_state(const double* q, const double* v) override {
    for (std::size_t i = 0; i < n_; ++i) {
      s_.q[i] = S(T(q[i]));
      s_.v[i] = S(T(v[i]));
    }
    validate_state(s_);
  }
  void get_state(double* q, double* v) const override {
    for (std::size_t i = 0; i < n_; ++i) {
      q[i] = to_double(s_.q[i]);
      v[i] = to_double(s_.v[i]);
    }
  }
  std::vector<std::string> state_strings() const override {
    std::vector<std::string> out;
    for (const auto& x : s_.q) out.push_back(full_string(real_of_s(x)));
    for (const auto& x : s_.v) out.push_back(full_string(real_of_s(x)));
    return out;
  }

  AdvanceStatus advance_fixed(double t0, double t1, long n, long every, Record* rec, const Heartbeat& hb) override {
    if (engine_.index() != 1) throw std::invalid_argument("this stepper was built for adaptive steps");
    if (n <= 0) throw std::invalid_argument("the number of steps must be positive");
    auto& integ = std::get<1>(engine_);
    const T ta(t0), tb(t1);
    const T h = (tb - ta) / T(n);
    if (!(h > T(0))) throw std::invalid_argument("the time span must be increasing and non-empty");
    const long chunk = chunk_steps(n_, def_.info.forces_per_step);
    const long block = every > 0 ? every : chunk;
    long done = 0;
    long since_beat = 0;
    AdvanceStatus st;
    while (done < n) {
      const long m = std::min(block, n - done);
      integ.integrate(s_, h, m);
      done += m;
      since_beat += m;
      if (!all_finite(s_.q) || !all_finite(s_.v)) {
        st.steps = done;
        st.failed = true;
        st.message = "the solution became NaN or infinite at t = " + std::to_string(t0 + (t1 - t0) * done / n);
        if (rec) record(*rec, done == n ? tb : ta + h * T(done));
        return st;
      }
      if (rec && every > 0) record(*rec, done == n ? tb : ta + h * T(done));
      if (since_beat >= chunk && done < n) {
        hb(to_double(ta + h * T(done)));
        since_beat = 0;
      }
    }
    st.steps = n;
    return st;
  }

  AdvanceStatus advance_adaptive(double t0, double t1, Record* rec, const Heartbeat& hb) override {
    AdvanceStatus st;
    if constexpr (is_complex_v<S>) {
      throw std::invalid_argument("adaptive steps need a method with real coefficients");
    } else {
      if (engine_.index() < 2) throw std::invalid_argument("this stepper was built for fixed steps");
      const long chunk = chunk_steps(n_, def_.info.forces_per_step * 4);
      long count = 0;
      bool first = true;
      auto obs = [&](const T& t, const State<V>& s) {
        if (first) {  // the observer sees t0 first
          first = false;
          return;
        }
        if (rec) {
          rec->t.push_back(to_double(t));
          for (const auto& x : s.q) rec->q.push_back(to_double(x));
          for (const auto& x : s.v) rec->v.push_back(to_double(x));
        }
        if (++count % chunk == 0) hb(to_double(t));
      };
      try {
        AdaptiveStats a = std::visit(
            [&](auto& e) -> AdaptiveStats {
              if constexpr (std::is_same_v<std::decay_t<decltype(e)>, std::monostate>) {
                return {};
              } else if constexpr (requires { e.integrate_to(s_, T(t0), T(t1), obs); }) {
                return e.integrate_to(s_, T(t0), T(t1), obs);
              } else {
                return {};
              }
            },
            engine_);
        st.steps = a.accepted;
        st.rejected = a.rejected;
      } catch (const StepSizeUnderflow& e) {
        st.failed = true;
        st.message = e.what();
        st.steps = count;
      } catch (const TooManySteps& e) {
        st.failed = true;
        st.message = e.what();
        st.steps = count;
      }
    }
    return st;
  }

  long force_evals() const override {
    return std::visit(
        [](const auto& e) -> long {
          if constexpr (std::is_same_v<std::decay_t<decltype(e)>, std::monostate>) {
            return 0;
          } else if constexpr (requires { e.total(); }) {
            return e.total().force_evals;
          } else {
            return e.force_evals();
          }
        },
        engine_);
  }

  void acceleration(const double* q, double* a) override {
    V x, ax;
    resize_to(x, n_);
    resize_to(ax, n_);
    for (std::size_t i = 0; i < n_; ++i) x[i] = S(T(q[i]));
    force_(x, ax);
    for (std::size_t i = 0; i < n_; ++i) a[i] = to_double(ax[i]);
  }

 private:
  static T real_of_s(const S& x) {
    if constexpr (is_complex_v<S>) {
      return x.real();
    } else {
      return x;
    }
  }
  void record(Record& r, const T& t) const {
    r.t.push_back(to_double(t));
    for (const auto& x : s_.q) r.q.push_back(to_double(x));
    for (const auto& x : s_.v) r.v.push_back(to_double(x));
  }

  using Fixed = Integrator<V, F>;
  template <class W>
  struct AdaptiveTypes {
    using Rkn = std::monostate;
    using Mpe = std::monostate;
  };
  template <class W>
  requires(!is_complex_v<typename W::value_type>) struct AdaptiveTypes<W> {
    using Rkn = AdaptiveRknIntegrator<W, F>;
    using Mpe = AdaptiveMpeIntegrator<W, F>;
  };
  // Index 1: fixed steps; 2: adaptive RKN (embedded pair); 3: adaptive MPE. The monostates (index 0
  // before construction; 2 and 3 for complex states, which have no adaptive engine) are never run.
  using Engine = std::variant<std::monostate, Fixed, typename AdaptiveTypes<V>::Rkn, typename AdaptiveTypes<V>::Mpe>;

  MethodDef def_;
  F force_;
  std::size_t n_;
  bool python_;
  State<V> s_;
  Engine engine_;
};

// ---- factories (one translation unit each, so that they compile in parallel) -------------------------

/// Built-in problems in double: "kepler", "henon_heiles" (2 coordinates), "harmonic" (omega^2 = params[0],
/// any number of coordinates), "nbody" (params: eps^2, then G m_i; SoA layout of nbody.hpp).
std::unique_ptr<Stepper> make_builtin_stepper_double(const std::string& problem, const std::vector<double>& params,
                                                     std::size_t n, const MethodDef& def, const StepperOptions& o);
/// Built-in problems "kepler", "henon_heiles" and "harmonic" in an extended precision (long-double, float128,
/// dd, qd); real coefficients only.
std::unique_ptr<Stepper> make_builtin_stepper_extended(const std::string& problem, const std::vector<double>& params,
                                                       std::size_t n, const MethodDef& def, const StepperOptions& o,
                                                       const std::string& precision);
/// A Python force in double.
std::unique_ptr<Stepper> make_python_stepper(py::object fn, std::vector<py::ssize_t> shape, std::size_t n,
                                             const MethodDef& def, const StepperOptions& o,
                                             std::shared_ptr<double>& time_slot);

}  // namespace nystrom::python
