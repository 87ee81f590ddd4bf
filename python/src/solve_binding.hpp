// The Python module's binding of solve() (nystrom/solve.hpp; compiled in libnystrom for std::vector states): the one
// driver runs every integration that nystrom.solve asks for. This header converts a request built from Python arguments
// into a SecondOrderProblem, events and SolveOptions, runs solve() with the GIL released and converts the Solution
// back: arrays of doubles, the final state in full working precision as decimal strings, and sol(t) kept as a
// DenseSolution.
//
// Python callables (the force, events, progress) take the GIL for their call only; an exception they raise
// travels through solve() as py::error_already_set and reaches the caller as the original Python exception.
// The run itself holds no GIL, so that the library locks it takes (method_data_for, MPFR precision) are
// never waited for with the GIL held.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <array>
#include <chrono>
#include <cmath>
#include <complex>
#include <cstddef>
#include <cstdio>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "nystrom/core/extended.hpp"
#include "nystrom/methods/method.hpp"
#include "nystrom/solve.hpp"

namespace nystrom::python {

namespace py = pybind11;

/// An event function of the Python side: g(t, q, v) -> float on flat arrays of the library's layout.
struct PyEvent {
  py::object g;
  int direction = 0;
  bool terminal = false;
  std::string name;
};

/// What nystrom.solve asks for, with the initial state flat in the library's layout.
struct SolveRequest {
  MethodDef method;
  std::vector<double> q0, v0;
  double t0 = 0, t1 = 0;
  SolveOptions options;  // h or steps, rtol and atol, t_eval, dense, max_steps, engine options
  std::vector<PyEvent> events;
  py::object progress = py::none();  // None or progress(t)
  /// Checkpoint (solve/checkpoint.hpp): written to checkpoint_file at the first step boundary at or after
  /// checkpoint_at while the run goes on; restart_file: continue from such a file. checkpoint_problem: what
  /// a checkpoint must match besides the method.
  double checkpoint_at = std::numeric_limits<double>::quiet_NaN();
  std::string checkpoint_problem, checkpoint_file, restart_file;
};

/// sol(t) of a finished run, whatever its state type: flat states of n coordinates as doubles.
class DenseSolution {
 public:
  virtual ~DenseSolution() = default;
  virtual std::size_t dim() const = 0;
  virtual double t_first() const = 0;
  virtual double t_last() const = 0;
  /// The state at t into q[0..dim) and v[0..dim) (invalid_input outside the integrated span).
  virtual void eval(double t, double* q, double* v) const = 0;
};

// ---- scalar conversions -----------------------------------------------------------------------------

template <class S>
double to_double(const S& x) {
  if constexpr (is_complex_v<S>) {
    return as_double(x.real());
  } else {
    return as_double(x);
  }
}

/// x in decimal with enough digits to identify it in type T. MPFR numbers print themselves; the other
/// extended types are sums of doubles, added exactly in MPFR and printed from there.
template <class T>
std::string full_string(const T& x) {
  const int digits = static_cast<int>(std::ceil(static_cast<double>(scalar_traits<T>::bits()) * 0.30103)) + 2;
  if constexpr (std::is_same_v<T, double>) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.17g", x);
    return buf;
  } else if constexpr (std::is_same_v<T, mpfr_real>) {
    return x.str(digits, std::ios_base::scientific);
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
    char* out = nullptr;
    mpfr_asprintf(&out, "%.*Rg", digits, acc);
    std::string s = out ? out : "nan";
    mpfr_free_str(out);
    mpfr_clear(acc);
    return s;
  }
}

// ---- the run ---------------------------------------------------------------------------------------------

/// The first n coordinates of x as doubles, appended to out.
template <class V>
void append_doubles(const V& x, std::size_t n, std::vector<double>& out) {
  for (std::size_t i = 0; i < n; ++i) out.push_back(to_double(x[i]));
}

inline py::array_t<double> rows_array(const std::vector<double>& flat, std::size_t rows, std::size_t n) {
  py::array_t<double> a({static_cast<py::ssize_t>(rows), static_cast<py::ssize_t>(n)});
  std::copy(flat.begin(), flat.end(), a.mutable_data());
  return a;
}

/// sol(t) of a Solution<V> with n coordinates.
/// mpfr_bits > 0: the MPFR working precision of the run, set again around every evaluation.
template <class V>
class DenseSolutionOf final : public DenseSolution {
 public:
  using R = real_t<typename V::value_type>;
  DenseSolutionOf(Solution<V> sol, std::size_t n, long mpfr_bits)
      : sol_(std::move(sol)), n_(n), mpfr_bits_(mpfr_bits) {}
  std::size_t dim() const override { return n_; }
  double t_first() const override { return as_double(sol_.dense.times().front()); }
  double t_last() const override { return as_double(sol_.dense.times().back()); }
  void eval(double t, double* q, double* v) const override {
    std::optional<MpfrPrecision> scope;
    if (mpfr_bits_ > 0) scope.emplace(mpfr_bits_);
    const State<V> s = sol_(R(t));
    for (std::size_t i = 0; i < n_; ++i) {
      q[i] = to_double(s.q[i]);
      v[i] = to_double(s.v[i]);
    }
  }

 private:
  Solution<V> sol_;
  std::size_t n_;
  long mpfr_bits_;
};

/// Runs solve() for state type V and force F (python_force: a Python callable, called with the GIL).
template <class V, class F>
py::dict run_solve(F force, const SolveRequest& r, bool python_force, long mpfr_bits = 0) {
  using R = real_t<typename V::value_type>;
  const std::size_t n = r.q0.size();
  V q0{}, v0{};
  if constexpr (requires { q0.resize(n); }) {
    q0.resize(n);
    v0.resize(n);
  }
  if (q0.size() != n)
    throw invalid_input("the state has " + std::to_string(n) + " coordinates, this problem " +
                        std::to_string(q0.size()));
  for (std::size_t i = 0; i < n; ++i) {
    q0[i] = R(r.q0[i]);
    v0[i] = R(r.v0[i]);
  }
  const SecondOrderProblem<V, F> prob(std::move(force), std::move(q0), std::move(v0), R(r.t0), R(r.t1));

  std::vector<Event<V>> events;
  for (const auto& e : r.events) {
    // fn is borrowed from the request (alive for the run): copies of g touch no reference count.
    auto g = [fn = py::handle(e.g), n](const R& t, const V& q, const V& v) -> R {
      py::gil_scoped_acquire hold;
      py::array_t<double> qa(static_cast<py::ssize_t>(n)), va(static_cast<py::ssize_t>(n));
      for (std::size_t i = 0; i < n; ++i) {
        qa.mutable_at(i) = to_double(q[i]);
        va.mutable_at(i) = to_double(v[i]);
      }
      return R(py::float_(fn(to_double(t), qa, va)).cast<double>());
    };
    events.push_back({e.name, std::move(g), e.direction, e.terminal});
  }

  // The GIL is released for the whole run; Python runs at every step with a Python force or events, or the
  // steps are slow (MPFR).
  const bool python_every_step = python_force || !events.empty() || mpfr_bits != 0;
  SolveOptions opt = r.options;
  opt.partial_on_failure = true;  // a failed run returns the states it reached, with status -1
  // Interruption checks (Ctrl-C) and progress every on_step_every steps: about 2^22 coordinate updates apart,
  // or every 64 steps when Python runs at every step anyway.
  const long work = static_cast<long>(n) * std::max(1, r.method.info.forces_per_step);
  opt.on_step_every = python_every_step ? 64 : std::max(1L, (1L << 22) / std::max(1L, work));
  opt.on_step = [&](double t) {
    py::gil_scoped_acquire hold;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    if (!r.progress.is_none()) r.progress(t);
  };

  opt.checkpoint_at = r.checkpoint_at;
  opt.checkpoint_problem = r.checkpoint_problem;
  std::optional<Checkpoint<R>> from;
  if constexpr (checkpoint_detail::exact_text<R>) {
    if (!r.checkpoint_file.empty())
      opt.on_checkpoint = [file = r.checkpoint_file](const std::string& text) {
        try {
          write_checkpoint_text(file, text);
        } catch (const nystrom::error& e) {  // a bad path is bad input, not a failure of the integration
          throw invalid_input(e.what());
        }
      };
    if (!r.restart_file.empty()) {
      from = read_checkpoint<R>(r.restart_file);
      if (prob.t1 >= prob.t0 ? from->t > prob.t1 : from->t < prob.t1)
        throw invalid_input("the checkpoint lies after the end of the span");
    }
  } else {
    if (!r.checkpoint_file.empty() || !r.restart_file.empty())
      throw invalid_input("checkpoints are written for double and long double states");
  }

  Solution<V> sol;
  int status = 0;
  std::string message;
  const auto start = std::chrono::steady_clock::now();
  auto run = [&] { return from ? resume(prob, r.method, *from, opt, events) : solve(prob, r.method, opt, events); };
  {
    py::gil_scoped_release free;
    sol = run();
  }
  if (sol.status == SolveStatus::terminated_by_event) {
    status = 1;
    message = sol.message;
  } else if (sol.status == SolveStatus::failed) {  // step size underflow, too many steps, NaN
    status = -1;
    message = sol.message;
  } else {
    message = "The solver successfully reached the end of the integration interval.";
  }

  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  py::dict d;
  d["solve_seconds"] = seconds;
  // The saved states, written once, straight into the arrays returned (every-step output: one per step).
  const bool terminal_state =  // the terminal event ends the output
      status == 1 && (sol.t.empty() || as_double(sol.t.back()) != as_double(sol.t_final));
  const std::size_t rows = sol.t.size() + (terminal_state ? 1 : 0);
  const auto nr = static_cast<py::ssize_t>(rows), nc = static_cast<py::ssize_t>(n);
  py::array_t<double> ta(nr), qa({nr, nc}), va({nr, nc});
  double* tp = ta.mutable_data();
  double* qp = qa.mutable_data();
  double* vp = va.mutable_data();
  auto put = [&](std::size_t k, const auto& t, const V& q, const V& v) {
    tp[k] = as_double(t);
    for (std::size_t i = 0; i < n; ++i) {
      qp[k * n + i] = to_double(q[i]);
      vp[k * n + i] = to_double(v[i]);
    }
  };
  for (std::size_t k = 0; k < sol.t.size(); ++k) put(k, sol.t[k], sol.q[k], sol.v[k]);
  if (terminal_state) put(rows - 1, sol.t_final, sol.q_final, sol.v_final);
  d["t"] = ta;
  d["q"] = qa;
  d["v"] = va;
  py::list hits;
  for (const auto& h : sol.events) {
    std::vector<double> hq, hv;
    append_doubles(h.q, n, hq);
    append_doubles(h.v, n, hv);
    hits.append(py::make_tuple(h.index, as_double(h.t), rows_array(hq, 1, n), rows_array(hv, 1, n)));
  }
  d["events"] = hits;
  py::list q_str, v_str;
  if (status >= 0) {
    for (std::size_t i = 0; i < n; ++i) q_str.append(full_string(sol.q_final[i]));
    for (std::size_t i = 0; i < n; ++i) v_str.append(full_string(sol.v_final[i]));
  }
  d["q_str"] = q_str;
  d["v_str"] = v_str;
  d["force_evals"] = sol.force_evals;
  d["output_force_evals"] = sol.output_force_evals;
  d["steps"] = sol.accepted;
  d["rejected"] = sol.rejected;
  d["precise_products"] = sol.precise_products;
  d["status"] = status;
  d["message"] = message;
  d["checkpoint_t"] = sol.checkpoint ? py::object(py::float_(as_double(sol.checkpoint->t))) : py::object(py::none());
  // The checkpoint a restarted run continued from, as read: a pickled dense output repeats the run from these
  // bytes, not from the file (which may have changed or gone since).
  d["restart_text"] = py::none();
  if constexpr (checkpoint_detail::exact_text<R>) {
    if (from) d["restart_text"] = to_text(*from);
  }
  if (opt.dense && status >= 0 && !sol.dense.empty())
    d["sol"] = py::cast(std::unique_ptr<DenseSolution>(new DenseSolutionOf<V>(std::move(sol), n, mpfr_bits)));
  else
    d["sol"] = py::none();
  return d;
}

// ---- forces -----------------------------------------------------------------------------------------------

/// The small built-in problems on std::vector states, one force type for all of them (one instantiation
/// of solve() per precision): Kepler a = -q/|q|^3 (2 coordinates), Hénon-Heiles V = (x^2 + y^2)/2 + x^2 y
/// - y^3/3, a = (-x - 2xy, -y - x^2 + y^2) (2 coordinates), and the harmonic oscillator a = -omega^2 q
/// (any number). Real scalars, and complex double for complex-coefficient methods in double.
struct SmallProblemForce {
  enum class Kind { kepler, henon_heiles, harmonic };
  Kind kind = Kind::kepler;
  double omega2 = 1;

  template <class W>
  requires(!is_complex_v<typename W::value_type> || std::is_same_v<typename W::value_type, std::complex<double>>) void
  operator()(const W& q, W& a) const {
    using S = typename W::value_type;
    switch (kind) {
      case Kind::kepler: {
        const S r2 = q[0] * q[0] + q[1] * q[1];
        S minv;
        if constexpr (is_complex_v<S>) {
          using std::sqrt;
          minv = S(-1) / (r2 * sqrt(r2));
        } else {
          minv = S(-inv_r3(r2));
        }
        a[0] = minv * q[0];
        a[1] = minv * q[1];
        break;
      }
      case Kind::henon_heiles:
        a[0] = -q[0] - S(2) * q[0] * q[1];
        a[1] = -q[1] - q[0] * q[0] + q[1] * q[1];
        break;
      case Kind::harmonic:
        for (std::size_t i = 0; i < q.size(); ++i) a[i] = -S(omega2) * q[i];
        break;
    }
  }

  /// The force of a built-in problem name; params: omega^2 for "harmonic".
  static SmallProblemForce of(const std::string& problem, const std::vector<double>& params, std::size_t n) {
    if (problem == "kepler" || problem == "henon_heiles") {
      if (n != 2) throw invalid_input("problem '" + problem + "' has 2 coordinates, got " + std::to_string(n));
      return {problem == "kepler" ? Kind::kepler : Kind::henon_heiles, 1};
    }
    if (problem == "harmonic") return {Kind::harmonic, params.at(0)};
    throw invalid_input("problem '" + problem +
                        "' runs in double only (extended precisions: Kepler, "
                        "HarmonicOscillator, HenonHeiles)");
  }
};

// ---- the entry points (one translation unit each, so that they compile in parallel) -----------------------

/// A Python force(t, q) in double (real and complex coefficients), or force(t, q, v) when `velocity`.
py::dict solve_python_force(py::object force, std::vector<py::ssize_t> shape, const SolveRequest& r,
                            bool velocity = false);
/// Whether a built-in problem runs its compensated force (Kepler(e, compensated=True), NBody(..., compensated=True)):
/// in double only, for the methods that take it (methods/compensated_force.hpp).
inline bool is_compensated_problem(const std::string& problem) {
  return problem == "kepler_compensated" || problem == "nbody_compensated";
}
/// A built-in problem in double: "kepler", "henon_heiles", "harmonic" (params: omega^2), "nbody" (params:
/// eps^2, then G m_i; the structure-of-arrays layout of nbody.hpp), and "kepler_compensated", "nbody_compensated".
py::dict solve_builtin_double(const std::string& problem, const std::vector<double>& params, const SolveRequest& r);
/// "kepler", "henon_heiles" or "harmonic" in an extended precision (long-double, float128, dd, qd, mpfr:BITS).
py::dict solve_builtin_extended(const std::string& problem, const std::vector<double>& params, const SolveRequest& r,
                                const std::string& precision);

}  // namespace nystrom::python
