// The drivers of solve() (the inline path, nystrom/solve_inline.hpp): solve_impl integrates a
// SecondOrderProblem with any catalog method and returns a Solution.
//
//   auto prob = nystrom::SecondOrderProblem(force, q0, v0, 0.0, 20.0);       // force(q, a) or force(t, q, a)
//   auto sol  = nystrom::solve(prob, "M8", {.steps = 2000});                  // fixed step (or .h = 0.01)
//   auto sol  = nystrom::solve(prob, "DP12-adaptive", {.rtol = 1e-12});       // adaptive (also M10-adaptive, ...)
//   auto sol  = nystrom::solve(prob, "GBS", {.rtol = 1e-12});                 // Gragg-Bulirsch-Stoer
//   sol.t, sol.q, sol.v         saved times and states (options.t_eval, or every step end)
//   sol(t)                      the state at any t of the span (dense output, solve/dense.hpp)
//   sol.events                  located events (Event: g(t, q, v) = 0, direction, terminal)
//   sol.force_evals, sol.accepted, sol.rejected, sol.status, sol.message
//   sol.precise_products        adaptive multi-product methods: the products carried their own rounding
//
// solve() chooses the engine from the method once: splitting, RKN and multi-product methods with fixed
// steps; adaptive RKN pairs and adaptive multi-product methods with a tolerance; GBS. Complex-coefficient
// methods run on the complexified state and drop the imaginary parts after every step (the force must
// then accept complex states: a generic lambda or a template operator()). Backward integration (t1 < t0)
// integrates the time-reversed problem (v -> -v, t -> -t), so that every engine steps forward. A
// time-dependent force a(t, q) runs as an autonomous one with t as one more coordinate (velocity 1,
// acceleration 0): every method integrates it exactly (drifts move it by c h, RKN stages by c_i h), and a
// time-independent force costs nothing more.
//
// Fixed steps: one engine call per step (Integrator::integrate(s, h, n) with n > 1 joins the last
// sub-step of a step with the first of the next, which changes the rounding), so that the steps are the
// same with or without outputs, events and checkpoints, and a restarted run is bitwise the
// uninterrupted one.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <cstddef>
#include <exception>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "nystrom/core/error.hpp"
#include "nystrom/core/state.hpp"
#include "nystrom/engines/adaptive_mpe.hpp"
#include "nystrom/engines/adaptive_rkn.hpp"
#include "nystrom/engines/gbs.hpp"
#include "nystrom/engines/integrator.hpp"
#include "nystrom/engines/mpe_midpoint.hpp"
#include "nystrom/methods/catalog.hpp"
#include "nystrom/problems/counting_force.hpp"
#include "nystrom/solve/checkpoint.hpp"
#include "nystrom/solve/dense.hpp"
#include "nystrom/solve/erased_force.hpp"  // erased_detail::resized
#include "nystrom/solve/options.hpp"
#include "nystrom/solve/problem.hpp"
#include "nystrom/solve/recorder.hpp"
#include "nystrom/solve/solution.hpp"

namespace nystrom {

namespace solve_detail {

/// The vector the engines integrate: V (or its complex counterpart) with one more coordinate for t
/// when the force is time-dependent.
template <class V, bool Extend>
struct extended;
template <class V>
struct extended<V, false> {
  using type = V;
};
template <class S, std::size_t N>
struct extended<std::array<S, N>, true> {
  using type = std::array<S, N + 1>;
};
template <class S, class A>
struct extended<std::vector<S, A>, true> {
  using type = std::vector<S>;
};

/// The user's time from the time coordinate tau of the engine's vector: real, or complex for a
/// complex-coefficient method (its stages lie at complex times, as its positions are complex).
template <class R, class S>
auto user_time(int dir, const S& tau) {
  using T = std::conditional_t<is_complex_v<S>, S, R>;
  const T t = T(tau);
  return dir > 0 ? t : T(-t);
}

/// The user's state type V with the scalar of the engine's vector VE: V itself, or its complex counterpart
/// for a complex-coefficient method.
template <class V, class VE>
using engine_user_vector_t =
    std::conditional_t<is_complex_v<typename VE::value_type> && !is_complex_v<typename V::value_type>,
                       rebind_vector_t<V, typename VE::value_type>, V>;

/// The force on the engine's vector: the user's force, time-reversed for backward integration
/// (dir = -1: t = -tau, and the user's velocity is -dq/dtau) and with t read from the extra coordinate when
/// it is time-dependent (a complex time for a complex-coefficient method). A velocity-dependent force is
/// called as force(q, v, a) by the engine (GBS's midpoint base).
template <class V, class VE, class F, bool TD>
struct EngineForce {
  static constexpr bool VD = VelocityForce<F, V>;
  using W = engine_user_vector_t<V, VE>;
  F f;
  int dir = 1;
  std::size_t n = 0;
  W qb{}, ab{}, vb{};
  void operator()(const VE& q, VE& a) requires(!VD) {
    if constexpr (!TD) {
      f(q, a);
      check_size(a, q.size());
    } else {
      using R = real_t<typename V::value_type>;
      resize_like_n(qb, n);
      resize_like_n(ab, n);
      for (std::size_t i = 0; i < n; ++i) qb[i] = q[i];
      f(user_time<R>(dir, q[n]), static_cast<const W&>(qb), ab);
      check_size(ab, n);
      for (std::size_t i = 0; i < n; ++i) a[i] = ab[i];
      a[n] = typename VE::value_type(0);
    }
  }
  // A compensated force (takes_carry_v) keeps its form for the engines that take its low parts.
  void operator()(const VE& q, const VE& cq, VE& a, VE& alo) requires(!VD && !TD && takes_carry_v<F, VE>) {
    f(q, cq, a, alo);
    check_size(a, q.size());
    check_size(alo, q.size());
  }
  void operator()(const VE& q, const VE& v, VE& a) requires(VD) {
    if constexpr (!TD) {
      if (dir > 0) {
        f(q, v, a);
      } else {
        resize_like_n(vb, n);
        for (std::size_t i = 0; i < n; ++i) vb[i] = -v[i];
        f(q, static_cast<const W&>(vb), a);
      }
      check_size(a, q.size());
    } else {
      resize_like_n(qb, n);
      resize_like_n(vb, n);
      resize_like_n(ab, n);
      for (std::size_t i = 0; i < n; ++i) {
        qb[i] = q[i];
        vb[i] = dir > 0 ? v[i] : -v[i];
      }
      f(user_time<real_t<typename V::value_type>>(dir, q[n]), static_cast<const W&>(qb), static_cast<const W&>(vb), ab);
      check_size(ab, n);
      for (std::size_t i = 0; i < n; ++i) a[i] = ab[i];
      a[n] = typename VE::value_type(0);
    }
  }
  // A force that assigned a vector of another size to its output (a = V{...}) is refused before the engine
  // reads past its end (on the compiled path ErasedForce checks the same).
  template <class X>
  static void check_size(const X& a, std::size_t want) {
    if constexpr (!is_std_array<X>::value) {
      if (a.size() != want) erased_detail::resized(a.size(), want);
    } else {
      (void)a, (void)want;
    }
  }
  static void resize_like_n(W& x, std::size_t m) {
    if constexpr (!is_std_array<W>::value) {
      if (x.size() != m) x.resize(m);
    } else {
      (void)x, (void)m;
    }
  }
};

template <class VE>
VE make_vector(std::size_t m) {
  VE x{};
  if constexpr (!is_std_array<VE>::value) x.resize(m);
  return x;
}

template <class T>
T sgn_mul(int dir, const T& x) {
  return dir > 0 ? x : T(-x);
}

/// Flattens an engine vector of real or complex scalars into reals.
template <class T, class VE>
void flatten(const VE& x, std::vector<T>& out) {
  for (const auto& e : x) {
    if constexpr (is_complex_v<std::decay_t<decltype(e)>>) {
      out.push_back(e.real());
      out.push_back(e.imag());
    } else {
      out.push_back(e);
    }
  }
}
template <class T, class VE>
std::size_t unflatten(const std::vector<T>& in, std::size_t pos, VE& x) {
  for (auto& e : x) {
    if (pos >= in.size()) throw invalid_input("checkpoint: the state has the wrong size for this problem");
    if constexpr (is_complex_v<std::decay_t<decltype(e)>>) {
      if (pos + 1 >= in.size()) throw invalid_input("checkpoint: the state has the wrong size for this problem");
      e = typename VE::value_type(in[pos], in[pos + 1]);
      pos += 2;
    } else {
      e = in[pos++];
    }
  }
  return pos;
}

/// Whether a run from t_start (t0, or the time of the checkpoint it resumes from) to t1 needs the method's
/// partial steps: for the dense output, events, or an output time other than t_start and t1 (the recorder
/// saves those two from the step ends). Without them the recorder keeps no copy of the method.
template <class V, class R>
bool needs_partial_steps(const SolveOptions& opt, const std::vector<Event<V>>& events, const R& t_start, const R& t1) {
  if (opt.dense || !events.empty()) return true;
  return std::any_of(opt.t_eval.begin(), opt.t_eval.end(), [&](double t) { return R(t) != t_start && R(t) != t1; });
}

/// Conversions between the user's state (time t, q, v) and the engine's (time-reversed for backward
/// integration, complexified for complex-coefficient methods, with t as one more coordinate when the
/// force depends on time).
template <class V, class VE, bool TD>
struct Conversion {
  using R = real_t<typename V::value_type>;
  using S = typename VE::value_type;
  int dir = 1;
  std::size_t n = 0;

  State<VE> to_engine(const R& t, const V& q, const V& v) const {
    State<VE> s{make_vector<VE>(n + (TD ? 1 : 0)), make_vector<VE>(n + (TD ? 1 : 0))};
    for (std::size_t i = 0; i < n; ++i) {
      s.q[i] = S(q[i]);
      s.v[i] = S(sgn_mul(dir, v[i]));
    }
    if constexpr (TD) {
      s.q[n] = S(sgn_mul(dir, t));
      s.v[n] = S(1);
    } else {
      (void)t;
    }
    return s;
  }
  void from_engine(const State<VE>& s, V& q, V& v) const {
    if constexpr (!is_std_array<V>::value) {
      q.resize(n);
      v.resize(n);
    }
    for (std::size_t i = 0; i < n; ++i) {
      if constexpr (is_complex_v<S>) {
        q[i] = s.q[i].real();
        v[i] = sgn_mul(dir, R(s.v[i].real()));
      } else {
        q[i] = s.q[i];
        v[i] = sgn_mul(dir, s.v[i]);
      }
    }
  }
};

template <class E>
struct is_gbs : std::false_type {};
template <class VE, class F>
struct is_gbs<GbsIntegrator<VE, F>> : std::true_type {};

/// The partial step of a solution's dense output (DenseOutput::PartialStep): one step of the method
/// from a step end, on a copy of the engine that the solution keeps (with its copy of the force) after
/// solve() returns. A fixed-step Integrator takes one step with its compensation restarted; GBS runs a
/// fresh copy of the extrapolation integrator over the interval. A mutex makes concurrent calls safe.
template <class V, class VE, bool TD, class Engine>
class PartialStepper {
 public:
  using R = real_t<typename V::value_type>;

  PartialStepper(Conversion<V, VE, TD> conv, Engine engine) : p_(std::make_shared<Shared>(conv, std::move(engine))) {}

  long operator()(const R& t0, const V& q0, const V& v0, const R& t, V& q, V& v) const {
    Shared& p = *p_;
    std::lock_guard<std::mutex> lock(p.m);
    State<VE> s = p.conv.to_engine(t0, q0, v0);
    const R h = sgn_mul(p.conv.dir, R(t - t0));
    long evals = 0;
    if (h > R(0)) {
      if constexpr (is_gbs<Engine>::value) {
        Engine g = p.engine;
        g.integrate_to(s, h);
        evals = g.force_evals() - p.engine.force_evals();
      } else {
        const long e0 = p.engine.force_evals();
        p.engine.compensator().valid = false;  // no carry from an earlier call
        p.engine.integrate(s, h, 1);
        evals = p.engine.force_evals() - e0;
      }
    }
    p.conv.from_engine(s, q, v);
    return evals;
  }

 private:
  struct Shared {
    Shared(Conversion<V, VE, TD> c, Engine e) : conv(c), engine(std::move(e)) {}
    std::mutex m;
    Conversion<V, VE, TD> conv;
    Engine engine;
  };
  std::shared_ptr<Shared> p_;
};

/// Common state of a run: problem, options, direction, conversions between the user's state and the
/// engine's.
template <class V, class F, class VE>
struct Run {
  using R = real_t<typename V::value_type>;
  static constexpr bool td = SecondOrderProblem<V, F>::time_dependent;
  using Force = EngineForce<V, VE, F, td>;

  SecondOrderProblem<V, F>& prob;
  const SolveOptions& opt;
  int dir;
  std::size_t n;
  std::string method;

  /// Completes a checkpoint just taken and hands it to the solution and the options' callback.
  void take(Checkpoint<R>& c, Solution<V>& sol) const {
    c.method = method;
    c.problem = opt.checkpoint_problem;
    if constexpr (checkpoint_detail::exact_text<R>) {
      if (opt.on_checkpoint) opt.on_checkpoint(to_text(c));
    }
    sol.checkpoint = c;
  }

  Conversion<V, VE, td> conversion() const { return {dir, n}; }
  State<VE> to_engine(const R& t, const V& q, const V& v) const { return conversion().to_engine(t, q, v); }
  void from_engine(const State<VE>& s, V& q, V& v) const { conversion().from_engine(s, q, v); }
  Force force() const { return {prob.force, dir, n, {}, {}, {}}; }
  /// The dense output's partial step with `engine` (a copy the solution keeps).
  template <class Engine>
  typename DenseOutput<V>::PartialStep partial_step(Engine engine) const {
    return PartialStepper<V, VE, td, Engine>(conversion(), std::move(engine));
  }
  /// The fixed-step method that the adaptive engines propagate (the high-order weights of an RKN pair,
  /// the whole multi-product expansion of an adaptive one), for the partial steps.
  typename DenseOutput<V>::PartialStep propagated_method(const MethodDef& def) const {
    using T = real_t<typename VE::value_type>;
    const auto shared = shared_method_data_for(def, scalar_traits<T>::bits(), scalar_traits<T>::name());
    const MethodData& data = *shared;
    if constexpr (Force::VD) {
      // A velocity-dependent force: the multi-product expansion over the midpoint rule of an adaptive one, or
      // the general RKN pair, whose integrate() propagates the main weights.
      if (const auto* m = std::get_if<MpeDef>(&data))
        return partial_step(MidpointMpeIntegrator<VE, Force>(m->k, mpe_coefficients_as<T>(mpe_coefficients(m->k)),
                                                             force(), detail::engine_options(opt)));
      auto conv = [](const bigcomplex& x) { return to_scalar<typename VE::value_type>(x); };
      return partial_step(
          RknStepper<VE, Force>(convert_tableau<typename VE::value_type>(std::get<RknTableau<bigcomplex>>(data), conv),
                                force(), detail::engine_options(opt)));
    } else {
      return partial_step(Integrator<VE, Force>(data, force(), detail::engine_options(opt)));
    }
  }
  void check_finite(const V& q, const V& v, const R& ta, const R& tb) const {
    if (!all_finite(q) || !all_finite(v)) throw not_finite(ta, tb);
  }
  /// Whether the user's coordinates of engine state s (the real parts) are finite: check_finite without
  /// the conversion.
  bool finite_in_engine(const State<VE>& s) const {
    for (std::size_t i = 0; i < n; ++i) {
      if constexpr (is_complex_v<typename VE::value_type>) {
        if (!is_finite_scalar(s.q[i].real()) || !is_finite_scalar(s.v[i].real())) return false;
      } else {
        if (!is_finite_scalar(s.q[i]) || !is_finite_scalar(s.v[i])) return false;
      }
    }
    return true;
  }
  static error not_finite(const R& ta, const R& tb) {
    return error("the state became NaN or infinite in the step from t = " + adaptive_detail::sci(as_double(ta)) +
                 " to t = " + adaptive_detail::sci(as_double(tb)) + " (the force returned NaN or infinity)");
  }
  /// Restores the state of a checkpoint into s.
  void restore(const Checkpoint<R>& c, State<VE>& s) const {
    std::size_t pos = unflatten(c.state, 0, s.q);
    pos = unflatten(c.state, pos, s.v);
    if (pos != c.state.size()) throw invalid_input("checkpoint: the state has the wrong size for this problem");
  }
  /// And its compensation carries into the engine's compensator.
  void restore(const Checkpoint<R>& c, State<VE>& s, Compensator<VE>& comp) const {
    restore(c, s);
    if (!c.carry.empty()) {
      VE cq = s.q, cv = s.v;
      std::size_t p2 = unflatten(c.carry, 0, cq);
      p2 = unflatten(c.carry, p2, cv);
      if (p2 != c.carry.size()) throw invalid_input("checkpoint: the carries have the wrong size");
      comp.restore(cq, cv, s);
    }
  }
};

/// The observer of the adaptive and GBS engines: records every accepted step end and stops the engine
/// for a terminal event or where the checkpoint is due.
template <class V, class F, class VE>
struct StepEnds {
  using R = real_t<typename V::value_type>;
  const Run<V, F, VE>& run;
  Recorder<V, SecondOrderProblem<V, F>>& rec;
  V q{}, v{};
  R tprev{};
  bool taken = false, terminal = false, want_checkpoint = false;

  StepEnds(const Run<V, F, VE>& r, Recorder<V, SecondOrderProblem<V, F>>& rc, const R& t_start, const State<VE>& s)
      : run(r), rec(rc), tprev(t_start), taken(!std::isfinite(r.opt.checkpoint_at)) {
    run.from_engine(s, q, v);
    rec.start(t_start, q, v);
  }
  /// A step ended at user time t with engine state st: true to stop the engine there.
  bool operator()(const R& t, const State<VE>& st) {
    run.from_engine(st, q, v);
    run.check_finite(q, v, tprev, t);
    tprev = t;
    if (rec.step(t, q, v)) {
      terminal = true;
      return true;
    }
    // Not at the end of the span: the engine keeps no resume point there (as the fixed-step driver, which
    // takes none in its last step).
    if (!taken && t != run.prob.t1 && run.dir * as_double(t) >= run.dir * run.opt.checkpoint_at) {
      taken = true;
      want_checkpoint = true;
      return true;
    }
    return false;
  }
  void finish(Solution<V>& sol) const {
    if (sol.status == SolveStatus::success) {
      sol.t_final = run.prob.t1;
      sol.q_final = q;
      sol.v_final = v;
    }
  }
};

/// Runs an adaptive or GBS engine from engine state s (user time t_start) to the end or a terminal
/// event, recording every accepted step end. advance(obs) runs the engine from where it stands to the
/// end under the observer obs(te, st) (te: engine time), which user_time(te) maps to the user's time
/// (std::nullopt: a time not to record, the start that the engine reports again). Where the run stopped
/// for the checkpoint, fill(c) completes the checkpoint c (and sets where the engine goes on), and
/// the engine goes on from its resume point: the same steps as without the stop.
template <class V, class F, class VE, class UserTime, class Advance, class Fill>
void drive_engine(const Run<V, F, VE>& run, Recorder<V, SecondOrderProblem<V, F>>& rec, Solution<V>& sol,
                  const real_t<typename V::value_type>& t_start, const State<VE>& s, UserTime&& user_time,
                  Advance&& advance, Fill&& fill) {
  using R = real_t<typename V::value_type>;
  StepEnds<V, F, VE> ends(run, rec, t_start, s);
  auto obs = [&](const R& te, const State<VE>& st) -> bool {
    const std::optional<R> t = user_time(te);
    return t ? ends(*t, st) : false;
  };
  for (;;) {
    ends.want_checkpoint = false;
    advance(obs);
    if (ends.terminal || !ends.want_checkpoint) break;
    Checkpoint<R> c;
    fill(c);
    c.output_force_evals = sol.output_force_evals;
    run.take(c, sol);
  }
  ends.finish(sol);
}

/// The engine of a fixed-step method: the catalog's Integrator, or for a velocity-dependent force the
/// multi-product expansion over Gragg's midpoint rule (the one fixed-step family for such forces).
template <class VE, class V, class F>
auto make_fixed_engine(const Run<V, F, VE>& run, const MethodDef& def, const EngineOptions& eo) {
  if constexpr (Run<V, F, VE>::Force::VD) {
    using T = real_t<typename VE::value_type>;
    const MethodData data = def.build();
    const auto* m = std::get_if<MpeDef>(&data);
    if (!m || def.info.family != "mpe-midpoint") throw invalid_input(velocity_refusal(def.info.name));
    return MidpointMpeIntegrator<VE, typename Run<V, F, VE>::Force>(
        m->k, mpe_coefficients_as<T>(mpe_coefficients(m->k)), run.force(), eo);
  } else {
    return make_integrator<VE>(def, run.force(), eo);
  }
}

template <class VE, class V, class F>
void run_fixed(SecondOrderProblem<V, F>& prob, const MethodDef& def, const SolveOptions& opt,
               const std::vector<Event<V>>& events, Solution<V>& sol, int dir,
               const Checkpoint<real_t<typename V::value_type>>* resume) {
  using R = real_t<typename V::value_type>;
  Run<V, F, VE> run{prob, opt, dir, prob.q0.size(), def.info.name};
  const R span = prob.t1 - prob.t0;
  const R aspan = dir > 0 ? span : R(-span);
  long n;
  R h;
  if (opt.steps > 0 && opt.h != 0) throw invalid_input("give either h or steps, not both");
  if (opt.steps > 0) {
    n = opt.steps;
    h = aspan / R(n);
  } else {
    if (!(opt.h > 0) || !std::isfinite(opt.h))
      throw invalid_input("a fixed-step method needs a positive step size h or a number of steps");
    h = R(opt.h);
    const double nd = std::ceil(as_double(aspan) / opt.h * (1 - 1e-12));
    if (nd > 1e15) throw invalid_input("the step size is too small for the span");
    n = std::max(1L, static_cast<long>(nd));
  }
  if (n > opt.max_steps) throw too_many_steps("the span needs " + std::to_string(n) + " steps, more than max_steps");
  auto integ = make_fixed_engine<VE>(run, def, detail::engine_options(opt));
  using Engine = decltype(integ);
  const R tau0 = sgn_mul(dir, prob.t0), tau1 = sgn_mul(dir, prob.t1);
  State<VE> s = run.to_engine(prob.t0, prob.q0, prob.v0);
  long k0 = 0;
  long evals0 = 0;
  Recorder<V, SecondOrderProblem<V, F>> rec(
      prob, opt, events, sol, dir,
      needs_partial_steps(opt, events, resume ? resume->t : prob.t0, prob.t1) ? run.partial_step(integ) : nullptr);
  if (resume) {
    if (resume->engine != "fixed") throw invalid_input("checkpoint of another engine (" + resume->engine + ")");
    k0 = resume->step_index;
    if (k0 < 0 || k0 > n) throw invalid_input("checkpoint step index outside the run");
    run.restore(*resume, s, integ.compensator());
    evals0 = resume->force_evals;
    sol.output_force_evals = resume->output_force_evals;
  }
  V q, v;
  run.from_engine(s, q, v);
  const R tstart = resume ? resume->t : prob.t0;
  rec.start(tstart, q, v);
  bool taken = !std::isfinite(opt.checkpoint_at);
  R tprev = tstart;
  // The user's time at the end of the j-th step (the last one ends on t1).
  auto step_end = [&](long j) -> R { return j == n ? prob.t1 : sgn_mul(dir, R(tau0 + h * R(j))); };
  if (resume && resume->t != step_end(k0)) throw invalid_input("checkpoint: its time is not that of its step index");
  // A failed run reports the forces evaluated up to the failure.
  struct CountOnExit {
    Solution<V>& sol;
    const Engine& engine;
    long evals0;
    ~CountOnExit() { sol.force_evals = evals0 + engine.force_evals(); }
  } count_on_exit{sol, integ, evals0};
  for (long k = k0; k < n; ++k) {
    // Steps with nothing to record (Recorder::quiet_steps; none while a checkpoint is due) run as bare
    // engine steps, the same engine calls as below: the loop costs what a hand-written loop of them costs.
    if (const long m = taken ? rec.quiet_steps(k, n - 1, step_end, as_double(h)) : 0; m > 0) {
      for (const long stop = k + m; k < stop; ++k) {
        integ.integrate(s, h, 1);
        if (!run.finite_in_engine(s)) {
          sol.accepted = k;
          throw run.not_finite(step_end(k), step_end(k + 1));
        }
      }
      tprev = step_end(k);
      run.from_engine(s, q, v);
      sol.accepted = k;
      rec.quiet(m, tprev, q, v);
    }
    // The last step of a given h ends on t1.
    const R hk = (opt.steps <= 0 && k == n - 1) ? R((tau1 - tau0) - h * R(n - 1)) : h;
    integ.integrate(s, hk, 1);
    const R t = step_end(k + 1);
    run.from_engine(s, q, v);
    run.check_finite(q, v, tprev, t);
    sol.accepted = k + 1;
    if (rec.step(t, q, v)) break;
    tprev = t;
    if (!taken && dir * as_double(t) >= dir * opt.checkpoint_at && k + 1 < n) {
      taken = true;
      Checkpoint<R> c;
      c.engine = "fixed";
      c.t = t;
      c.step_index = k + 1;
      flatten(s.q, c.state);
      flatten(s.v, c.state);
      if (use_compensation<typename VE::value_type>(opt.compensated)) {
        flatten(integ.compensator().cq, c.carry);
        flatten(integ.compensator().cv, c.carry);
      }
      c.force_evals = evals0 + integ.force_evals();
      c.output_force_evals = sol.output_force_evals;
      c.accepted = k + 1;
      run.take(c, sol);
    }
  }
  if (sol.status == SolveStatus::success) {
    sol.t_final = prob.t1;
    sol.q_final = q;
    sol.v_final = v;
  }
}

/// Adaptive RKN or MPE (Engine: AdaptiveRknIntegrator or AdaptiveMpeIntegrator on VE, its force counting
/// its calls in `calls`: the engines add up their own counts when a call returns, a failed run reports these).
template <class VE, class V, class F, class Engine>
void run_adaptive(Run<V, F, VE>& run, Engine& engine, const long& calls, const char* name, const MethodDef& def,
                  Solution<V>& sol, const std::vector<Event<V>>& events,
                  const Checkpoint<real_t<typename V::value_type>>* resume) {
  using R = real_t<typename V::value_type>;
  auto& prob = run.prob;
  const int dir = run.dir;
  const R tau0 = sgn_mul(dir, prob.t0), tau1 = sgn_mul(dir, prob.t1);
  State<VE> s = run.to_engine(prob.t0, prob.q0, prob.v0);
  long evals0 = 0, acc0 = 0, rej0 = 0;
  R tau = tau0;
  if (resume) {
    if (resume->engine != name)
      throw invalid_input(std::string("checkpoint of another engine (") + resume->engine + ")");
    if constexpr (requires { engine.compensator(); })
      run.restore(*resume, s, engine.compensator());
    else
      run.restore(*resume, s);
    tau = sgn_mul(dir, resume->t);
    engine.set_resume_point(
        {tau, resume->h_want, resume->hmax, resume->last_rejected, resume->q_prev, resume->h_prev, true});
    evals0 = resume->force_evals;
    acc0 = resume->accepted;
    rej0 = resume->rejected;
    sol.output_force_evals = resume->output_force_evals;
  }
  if constexpr (requires { engine.precise_products(); }) sol.precise_products = engine.precise_products();
  Recorder<V, SecondOrderProblem<V, F>> rec(prob, run.opt, events, sol, dir,
                                            needs_partial_steps(run.opt, events, resume ? resume->t : prob.t0, prob.t1)
                                                ? run.propagated_method(def)
                                                : nullptr);
  struct CountOnFailure {
    Solution<V>& sol;
    const Recorder<V, SecondOrderProblem<V, F>>& rec;
    const long& calls;
    long evals0, acc0;
    ~CountOnFailure() {
      if (std::uncaught_exceptions() == 0) return;
      sol.force_evals = evals0 + calls;
      sol.accepted = acc0 + rec.steps();
    }
  } count_on_failure{sol, rec, calls, evals0, acc0};
  drive_engine(
      run, rec, sol, sgn_mul(dir, tau), s,
      [&](const R& tt) -> std::optional<R> {
        if (tt == tau) return std::nullopt;  // the start
        return tt == tau1 ? prob.t1 : sgn_mul(dir, tt);
      },
      [&](auto& obs) { engine.integrate_to(s, tau, tau1, obs); },
      [&](Checkpoint<R>& c) {
        const auto& rp = engine.resume_point();
        c.engine = name;
        c.t = sgn_mul(dir, rp.t);
        flatten(s.q, c.state);
        flatten(s.v, c.state);
        if constexpr (requires { engine.compensator(); }) {
          if (use_compensation<typename VE::value_type>(run.opt.compensated)) {
            flatten(engine.compensator().cq, c.carry);
            flatten(engine.compensator().cv, c.carry);
          }
        }
        c.h_want = rp.h_want;
        c.hmax = rp.hmax;
        c.last_rejected = rp.last_rejected;
        c.q_prev = rp.q_prev;
        c.h_prev = rp.h_prev;
        c.force_evals = evals0 + engine.total().force_evals;
        c.accepted = acc0 + engine.total().accepted;
        c.rejected = rej0 + engine.total().rejected;
        tau = rp.t;  // go on from the resume point
      });
  sol.force_evals = evals0 + engine.total().force_evals;
  sol.accepted = acc0 + engine.total().accepted;
  sol.rejected = rej0 + engine.total().rejected;
}

template <class VE, class V, class F>
void run_gbs(Run<V, F, VE>& run, const MethodDef& def, Solution<V>& sol, const std::vector<Event<V>>& events,
             const Checkpoint<real_t<typename V::value_type>>* resume) {
  using R = real_t<typename V::value_type>;
  auto& prob = run.prob;
  const int dir = run.dir;
  GbsOptions go;
  const MethodData data = def.build();
  const auto& gd = std::get<GbsDef>(data);
  go.sequence = gd.sequence;
  go.max_columns = gd.max_columns;
  go.initial_step = run.opt.h0;
  go.rtol = run.opt.rtol;
  go.atol = run.opt.atol > 0 ? run.opt.atol : run.opt.rtol;
  go.max_steps = run.opt.max_steps;
  GbsIntegrator<VE, typename Run<V, F, VE>::Force> g(run.force(), go);
  if constexpr (Run<V, F, VE>::td) g.set_clock(run.n, sgn_mul(dir, prob.t1));  // t exact, never past t1
  const R tau0 = sgn_mul(dir, prob.t0);
  const R span = sgn_mul(dir, R(prob.t1 - prob.t0));
  State<VE> s = run.to_engine(prob.t0, prob.q0, prob.v0);
  R t_start = prob.t0;
  // The partial steps run a fresh copy of the integrator (its controller in the initial state) at a
  // tolerance 1000 times smaller (bounded by rounding): GBS's accepted steps are usually far more
  // accurate than its tolerance (the estimate is that of the column before the accepted one), and a
  // partial step must not be less accurate than the steps it lies between.
  auto partial_step = [&] {
    GbsOptions gp = go;
    gp.rtol = std::max(go.rtol * 1e-3, 100 * as_double(epsilon_of<R>()));
    gp.atol = std::max(go.atol * 1e-3, 100 * as_double(epsilon_of<R>()));
    GbsIntegrator<VE, typename Run<V, F, VE>::Force> gpart(run.force(), gp);
    if constexpr (Run<V, F, VE>::td) gpart.set_clock(run.n, sgn_mul(dir, prob.t1));
    return run.partial_step(std::move(gpart));
  };
  Recorder<V, SecondOrderProblem<V, F>> rec(
      prob, run.opt, events, sol, dir,
      needs_partial_steps(run.opt, events, resume ? resume->t : prob.t0, prob.t1) ? partial_step() : nullptr);
  if (resume) {
    if (resume->engine != "gbs") throw invalid_input("checkpoint of another engine (" + resume->engine + ")");
    run.restore(*resume, s);
    g.set_resume_point({resume->span, span, resume->h_want, resume->columns, resume->last_rejected, true});
    g.set_counters(resume->force_evals, resume->accepted, resume->rejected);
    t_start = resume->t;
    sol.output_force_evals = resume->output_force_evals;
  }
  struct CountOnExit {  // also a failed run: the counts up to the failure
    Solution<V>& sol;
    const GbsIntegrator<VE, typename Run<V, F, VE>::Force>& g;
    ~CountOnExit() {
      sol.force_evals = g.force_evals();
      sol.accepted = g.steps();
      sol.rejected = g.rejected();
    }
  } count_on_exit{sol, g};
  drive_engine(
      run, rec, sol, t_start, s,
      [&](const R& trel) -> std::optional<R> { return trel == span ? prob.t1 : sgn_mul(dir, R(tau0 + trel)); },
      [&](auto& obs) { g.integrate_to(s, span, obs); },
      [&](Checkpoint<R>& c) {
        const auto& rp = g.resume_point();
        c.engine = "gbs";
        c.t = sgn_mul(dir, R(tau0 + rp.t));
        c.span = rp.t;
        flatten(s.q, c.state);
        flatten(s.v, c.state);
        c.h_want = rp.H;
        c.columns = rp.k;
        c.last_rejected = rp.last_rejected;
        c.force_evals = g.force_evals();
        c.accepted = g.steps();
        c.rejected = g.rejected();
      });
}

/// Throws invalid_input unless the options give a tolerance (adaptive methods and GBS).
inline void check_tolerances(const MethodDef& def, const SolveOptions& opt) {
  if (!(opt.rtol >= 0) || !std::isfinite(opt.rtol)) throw invalid_input("rtol must be finite and >= 0");
  if (!(opt.atol >= 0) || !std::isfinite(opt.atol)) throw invalid_input("atol must be finite and >= 0");
  if (opt.rtol == 0 && opt.atol == 0)
    throw invalid_input("method '" + def.info.name + "' needs a tolerance (rtol > 0 or atol > 0)");
}

/// Throws invalid_input when an option of the step control is set for a method that has no use for it
/// (instead of ignoring it): h0 applies to the adaptive methods and GBS, h_max, safety, fac_min, fac_max,
/// predictive, error_order, tolerance_exponent and tolerance_anchor to the adaptive RKN and MPE methods.
inline void check_step_control(const MethodDef& def, const SolveOptions& opt, bool gbs) {
  const SolveOptions d{};
  const bool controller = opt.h_max != d.h_max || opt.safety != d.safety || opt.fac_min != d.fac_min ||
                          opt.fac_max != d.fac_max || opt.predictive != d.predictive ||
                          opt.error_order != d.error_order || opt.tolerance_exponent != d.tolerance_exponent ||
                          opt.tolerance_anchor != d.tolerance_anchor;
  const bool adaptive = def.info.adaptive && !gbs;
  if (controller && !adaptive)
    throw invalid_input(
        "h_max, safety, fac_min, fac_max, predictive, error_order, tolerance_exponent and tolerance_anchor apply "
        "to the adaptive RKN and MPE methods, not to '" +
        def.info.name + "'");
  if (opt.h0 != d.h0 && !adaptive && !gbs)
    throw invalid_input("h0 (the first step) applies to adaptive methods and GBS; '" + def.info.name +
                        "' runs with fixed steps (give h or steps)");
  if (!std::isfinite(opt.h0) || opt.h0 < 0) throw invalid_input("h0 must be finite and >= 0");
}

/// The run of solve_impl with the method's engine, into sol.
template <class V, class F, class VE>
void run_method(SecondOrderProblem<V, F>& prob, const MethodDef& def, const SolveOptions& opt,
                const std::vector<Event<V>>& events, Solution<V>& sol, int dir,
                const Checkpoint<real_t<typename V::value_type>>* resume, bool gbs) {
  using R = real_t<typename V::value_type>;
  constexpr bool td = SecondOrderProblem<V, F>::time_dependent;
  if constexpr (SecondOrderProblem<V, F>::velocity_dependent) {
    // Only the methods for y'' = f(t, y, y') are instantiated (solve_impl refused the others).
    const bool midpoint = def.info.family == "mpe-midpoint";
    if (midpoint && !def.info.adaptive) {
      run_fixed<VE>(prob, def, opt, events, sol, dir, resume);
      return;
    }
    if (!gbs && !def.info.adaptive) throw invalid_input(velocity_refusal(def.info.name));
    check_tolerances(def, opt);
    Run<V, F, VE> run{prob, opt, dir, prob.q0.size(), def.info.name};
    long calls = 0;
    using Counted = CountingForce<typename Run<V, F, VE>::Force>;
    if (gbs) {
      run_gbs<VE>(run, def, sol, events, resume);
    } else if (midpoint) {  // the adaptive multi-product expansion over the midpoint rule
      using T = real_t<typename VE::value_type>;
      const AdaptiveMpeCoefficients ac = adaptive_mpe_coefficients(std::get<MpeDef>(def.build()).k);
      AdaptiveMidpointMpeIntegrator<VE, Counted> engine(
          ac.high.k, mpe_coefficients_as<T>(ac.high), mpe_coefficients_as<T>(ac.error()), Counted{&calls, run.force()},
          detail::adaptive_options(opt), detail::engine_options(opt));
      run_adaptive<VE>(run, engine, calls, "adaptive-mpe-midpoint", def, sol, events, resume);
    } else {  // a general (RKNG) pair
      auto engine = make_adaptive_integrator<VE>(def, Counted{&calls, run.force()}, detail::adaptive_options(opt),
                                                 detail::engine_options(opt));
      run_adaptive<VE>(run, engine, calls, "adaptive-rkn", def, sol, events, resume);
    }
  } else if (gbs || def.info.adaptive) {
    check_tolerances(def, opt);
    Run<V, F, VE> run{prob, opt, dir, prob.q0.size(), def.info.name};
    if (gbs) {
      run_gbs<VE>(run, def, sol, events, resume);
    } else {
      const AdaptiveOptions ao = detail::adaptive_options(opt);
      long calls = 0;
      using Counted = CountingForce<typename Run<V, F, VE>::Force>;
      if (std::holds_alternative<MpeDef>(def.build())) {
        auto engine =
            make_adaptive_mpe_integrator<VE>(def, Counted{&calls, run.force()}, ao, detail::engine_options(opt));
        run_adaptive<VE>(run, engine, calls, "adaptive-mpe", def, sol, events, resume);
      } else {
        auto engine = make_adaptive_integrator<VE>(def, Counted{&calls, run.force()}, ao, detail::engine_options(opt));
        run_adaptive<VE>(run, engine, calls, "adaptive-rkn", def, sol, events, resume);
      }
    }
  } else if (def.info.complex) {
    using C = std::complex<R>;
    using VC = rebind_vector_t<V, C>;
    constexpr bool accepts_complex =
        td ? std::is_invocable_v<F&, const C&, const VC&, VC&> : std::is_invocable_v<F&, const VC&, VC&>;
    if constexpr (accepts_complex) {
      run_fixed<typename extended<VC, td>::type>(prob, def, opt, events, sol, dir, resume);
    } else {
      throw invalid_input("method '" + def.info.name +
                          "' has complex coefficients: its force must accept complex states (and a complex time "
                          "if it depends on time: a generic lambda or a template operator())");
    }
  } else {
    run_fixed<VE>(prob, def, opt, events, sol, dir, resume);
  }
}

template <class V, class F>
Solution<V> solve_impl(const SecondOrderProblem<V, F>& problem, const MethodDef& def, const SolveOptions& opt,
                       const std::vector<Event<V>>& events, const Checkpoint<real_t<typename V::value_type>>* resume) {
  using R = real_t<typename V::value_type>;
  using P = SecondOrderProblem<V, F>;
  constexpr bool td = P::time_dependent;
  problem.validate();
  if constexpr (P::velocity_dependent) {
    if (!def.info.velocity) throw invalid_input(velocity_refusal(def.info.name));
  } else {
    if (def.info.family == "mpe-midpoint")
      throw invalid_input("method '" + def.info.name +
                          "' is for velocity-dependent forces and first-order systems; for a(t, q) run its "
                          "multi-product expansion over Verlet, " +
                          verlet_mpe_counterpart(def));
  }
  if (opt.max_steps <= 0) throw invalid_input("max_steps must be positive");
  P prob = problem;
  const int dir = prob.t1 >= prob.t0 ? 1 : -1;
  // Output times: within the span and monotone in the direction of integration.
  for (std::size_t i = 0; i < opt.t_eval.size(); ++i) {
    const double te = opt.t_eval[i];
    if (!std::isfinite(te)) throw invalid_input("output times must be finite");
    if (sgn_mul(dir, R(te)) < sgn_mul(dir, prob.t0))
      throw invalid_input("output time " + adaptive_detail::sci(te) + " lies before t0");
    if (sgn_mul(dir, R(te)) > sgn_mul(dir, prob.t1))
      throw invalid_input("output time " + adaptive_detail::sci(te) + " lies after t1");
    if (i > 0 && dir * te < dir * opt.t_eval[i - 1])
      throw invalid_input("output times must be ordered in the direction of integration");
  }
  if (!std::isnan(opt.checkpoint_at) && !std::isfinite(opt.checkpoint_at))
    throw invalid_input("the checkpoint time must be finite");
  Solution<V> sol;
  if (resume && resume->problem != opt.checkpoint_problem)
    throw invalid_input("the checkpoint was taken for another problem ('" + resume->problem + "', not '" +
                        opt.checkpoint_problem + "')");
  if (resume && resume->method != def.info.name)
    throw invalid_input("the checkpoint was taken with method '" + resume->method + "', not '" + def.info.name + "'");
  // A resumed run starts at the checkpoint's time: it has no state for an output time before it.
  if (resume && !opt.t_eval.empty() && sgn_mul(dir, R(opt.t_eval.front())) < sgn_mul(dir, resume->t))
    throw invalid_input("output time " + adaptive_detail::sci(opt.t_eval.front()) +
                        " lies before the checkpoint's time " + adaptive_detail::sci(as_double(resume->t)) +
                        ", where the resumed run starts");
  if (prob.t1 == prob.t0) {
    Recorder<V, P> rec(prob, opt, events, sol, dir, {});
    rec.start(prob.t0, prob.q0, prob.v0);
    sol.t_final = prob.t0;
    sol.q_final = prob.q0;
    sol.v_final = prob.v0;
    return sol;
  }
  using VE = typename extended<V, td>::type;
  const bool gbs = def.info.family == "extrapolation";
  try {
    check_step_control(def, opt, gbs);
    run_method<V, F, VE>(prob, def, opt, events, sol, dir, resume, gbs);
  } catch (const invalid_input&) {
    throw;
  } catch (const std::invalid_argument& e) {  // an engine's or the coefficients' refusal: one error type
    throw invalid_input(e.what());
  } catch (const error& e) {
    if (!opt.partial_on_failure) throw;
    sol.status = SolveStatus::failed;
    sol.message = e.what();
    if (!sol.t.empty()) {
      sol.t_final = sol.t.back();
      sol.q_final = sol.q.back();
      sol.v_final = sol.v.back();
    }
  }
  return sol;
}

}  // namespace solve_detail
}  // namespace nystrom
