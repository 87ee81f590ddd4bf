// Work-precision comparison of nystrom against Boost.Odeint on the planar Kepler problem.
//
// Every run integrates KeplerProblem (e = 0.5, 0.9; q0 at apocentre) over `periods` orbits and
// measures the final position error |q - q_exact| against the exact orbit of the start as rounded
// to double, evaluated in quad-double at the time reached (problems/reference.hpp), the number of force
// evaluations (counted by one functor shared by both libraries, CountingKepler) and the wall time of
// the integration alone (steppers are built outside the clock; the minimum over repetitions is kept).
//
// Boost.Odeint is used as a library (header-only, Debian's libboost-dev): its symplectic RKN steppers
// and velocity Verlet on a (q, p) pair of std::array<double, 2>, Runge-Kutta-Fehlberg 7(8) (fixed step),
// Dormand-Prince 5(4) and Bulirsch-Stoer (adaptive) on the first-order system y = (q, v) in
// std::array<double, 4>, with absolute = relative tolerance.
//
// Fixed-step methods are swept over steps per period (geometric), adaptive ones over tolerances. A
// sweep stops at a force-evaluation cap, or when the error has reached its round-off floor.
#pragma once

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <boost/numeric/odeint.hpp>
#include <boost/numeric/odeint/stepper/symplectic_rkn_sb3a_m4_mclachlan.hpp>

#include "nystrom/core/state.hpp"
#include "nystrom/engines/adaptive_mpe.hpp"
#include "nystrom/engines/adaptive_rkn.hpp"
#include "nystrom/engines/gbs.hpp"
#include "nystrom/engines/integrator.hpp"
#include "nystrom/methods/catalog.hpp"
#include "nystrom/problems/counting_force.hpp"
#include "nystrom/problems/kepler.hpp"
#include "nystrom/problems/reference.hpp"

namespace nystrom::peers {

using Vec2 = std::array<double, 2>;
using Vec4 = std::array<double, 4>;

/// Thrown by CountingKepler when a run exceeds its force-evaluation budget (adaptive runs at
/// tolerances a method cannot reach in reasonable work).
struct BudgetExceeded {};

struct ForceCounter {
  long calls = 0;
  long cap = std::numeric_limits<long>::max();
  /// One more call (CountingForce), BudgetExceeded past the cap.
  ForceCounter& operator++() {
    if (++calls > cap) throw BudgetExceeded{};
    return *this;
  }
};

/// a = -q/|q|^3, counting its calls. Copies share the counter, so the count is right whatever the
/// integrator does with the functor it is given.
using CountingKepler = CountingForce<KeplerForce, ForceCounter>;

/// The same force as the first-order system y' = (v, a(q)) of odeint's Runge-Kutta steppers.
struct CountingKeplerSystem {
  CountingKepler f;
  void operator()(const Vec4& y, Vec4& dy, double /*t*/) const {
    Vec2 a;
    f(Vec2{y[0], y[1]}, a);
    dy[0] = y[2];
    dy[1] = y[3];
    dy[2] = a[0];
    dy[3] = a[1];
  }
};

/// The same force as odeint's velocity Verlet wants it: sys(q, v, a, t).
struct CountingKeplerVerlet {
  CountingKepler f;
  void operator()(const Vec2& q, const Vec2& /*v*/, Vec2& a, double /*t*/) const { f(q, a); }
};

/// One timed run.
struct Outcome {
  long steps = 0;
  long forces = 0;
  double seconds = 0;
  double error = std::numeric_limits<double>::infinity();  // inf: failed (budget, step-size failure, NaN)
  bool ok = false;                                         // finished with a finite error
  bool budget = false;                                     // stopped by the force-evaluation cap
};

/// The time a run reached: n steps of h (fixed steps, h n exactly), or the end of the span (h = t_end, n = 1).
struct EndTime {
  double h = 0;
  long n = 1;
};
/// One run: integrate from the start, fill the final state, the steps taken and the time reached.
/// It may be called repeatedly (each call starts afresh from copies of prepared steppers).
using Run = std::function<void(State<Vec2>& s, long& steps, EndTime& end)>;
/// Prepares a run at one parameter (steps per period, or tolerance) outside the clock.
using Prepare = std::function<Run(double param)>;

struct MethodSpec {
  std::string library;  // "nystrom" or "odeint"
  std::string name;     // catalog name or odeint class name
  std::string label;    // legend / table label
  bool adaptive = false;
  int order = 0;            // declared order (adaptive: the higher order of the pair; GBS: 0)
  int forces_per_step = 0;  // fixed-step: forces per step in a long run
  int forces_extra = 0;     // fixed-step: forces of the first step beyond forces_per_step (FSAL start)
  bool compensated = true;  // nystrom: compensated summation (the default for double)
  bool reference = true;    // counts for "the best of its library" (the uncompensated variants do not)
  std::function<Prepare(ForceCounter*)> make{};  // builds what does not depend on the parameter
};

struct PeerRun {
  std::string library, method, label;
  bool adaptive = false, compensated = true, reference = true;
  int order = 0, forces_per_step = 0, forces_extra = 0;
  double ecc = 0;
  double param = 0;  // steps per period (fixed) or tolerance (adaptive)
  long steps = 0, forces = 0;
  double seconds = 0, error = 0;
  int reps = 0;
  bool ok = false;
};

struct PeerConfig {
  std::vector<double> eccs{0.5, 0.9};
  long periods = 100;
  double spp_ratio = std::pow(2.0, 0.25);   // steps-per-period ratio of consecutive fixed-step runs
  double tol_ratio = std::pow(10.0, 0.25);  // tolerance ratio of consecutive adaptive runs (both libraries)
  double tol_max = 1e-3, tol_min = 1e-15;
  long force_cap = 30'000'000;      // per run
  double min_time = 0.2;            // repeat a run until this much time has been spent ...
  int min_reps = 3, max_reps = 20;  // ... at least min_reps times (1 for runs above long_run), at most max_reps
  double long_run = 0.5;
  double floor_error = 3e-16;  // stop a sweep once the error is below this
};

inline PeerConfig quick_config() {
  PeerConfig c;
  c.spp_ratio = std::sqrt(2.0);
  c.tol_ratio = 10.0;
  c.tol_min = 1e-14;
  c.force_cap = 3'000'000;
  c.min_time = 0.0;
  c.min_reps = 1;
  c.max_reps = 1;
  return c;
}

namespace detail {

inline State<Vec2> start(double ecc) { return KeplerProblem<double>(ecc).initial_state(); }

inline double position_error(double ecc, const State<Vec2>& s, const EndTime& end) {
  // The exact orbit of the start as rounded to double, in quad-double, at the time the integrator
  // actually reached (problems/reference.hpp).
  if (!std::isfinite(s.q[0]) || !std::isfinite(s.q[1]) || !std::isfinite(s.v[0]) || !std::isfinite(s.v[1]))
    return std::numeric_limits<double>::infinity();
  const double err = kepler_reference_errors(start(ecc), s, end.h, end.n).position;
  return std::isfinite(err) ? err : std::numeric_limits<double>::infinity();
}

inline double period() { return KeplerProblem<double>::period(); }

// ---- nystrom -------------------------------------------------------------------------------------

inline MethodSpec nystrom_fixed(const std::string& name, double ecc, long periods,
                                Compensation compensation = Compensation::on) {
  const bool compensated = compensation != Compensation::off;
  const MethodDef def = resolve_method(name);
  MethodSpec m;
  m.library = "nystrom";
  m.name = name;
  m.label = compensated ? name : name + " (no comp.)";
  m.order = def.info.order;
  m.forces_per_step = def.info.forces_per_step;
  m.forces_extra = def.info.fsal ? 1 : 0;
  m.compensated = compensated;
  m.reference = compensated;
  m.make = [def, ecc, periods, compensated](ForceCounter* c) -> Prepare {
    EngineOptions opt;
    opt.compensated = compensated ? Compensation::on : Compensation::off;
    auto proto = std::make_shared<Integrator<Vec2, CountingKepler>>(make_integrator<Vec2>(def, CountingKepler{c}, opt));
    return [proto, ecc, periods](double spp) -> Run {
      const long n = static_cast<long>(spp) * periods;
      const double h = period() / static_cast<double>(static_cast<long>(spp));
      return [proto, ecc, n, h](State<Vec2>& s, long& steps, EndTime& end) {
        auto integ = *proto;  // a fresh copy: no force cache from an earlier repetition
        s = start(ecc);
        integ.integrate(s, h, n);
        steps = n;
        end = {h, n};
      };
    };
  };
  return m;
}

inline MethodSpec nystrom_adaptive(const std::string& name, double ecc, long periods) {
  const MethodDef def = resolve_method(name);
  MethodSpec m;
  m.library = "nystrom";
  m.name = name;
  m.label = name;
  m.adaptive = true;
  m.order = def.info.order;
  m.make = [def, ecc, periods](ForceCounter* c) -> Prepare {
    return [def, ecc, periods, c](double tol) -> Run {
      AdaptiveOptions opt;
      opt.rtol = tol;
      opt.h0 = 1e-3;
      auto proto = std::make_shared<AdaptiveRknIntegrator<Vec2, CountingKepler>>(
          make_adaptive_integrator<Vec2>(def, CountingKepler{c}, opt));
      return [proto, ecc, periods](State<Vec2>& s, long& steps, EndTime& end) {
        auto integ = *proto;
        s = start(ecc);
        const double t_end = period() * static_cast<double>(periods);
        end = {t_end, 1};
        const AdaptiveStats st = integ.integrate_to(s, 0.0, t_end);
        steps = st.accepted;
      };
    };
  };
  return m;
}

/// An adaptive multi-product method (engines/adaptive_mpe.hpp), e.g. "M12-adaptive": products in
/// lockstep, the same start step as DP12-adaptive; compensated summation (the default for double) or
/// not (then a variant "(no comp.)" that does not count as the library's reference configuration).
inline MethodSpec nystrom_adaptive_mpe(const std::string& name, double ecc, long periods,
                                       Compensation compensation = Compensation::on) {
  const bool compensated = compensation != Compensation::off;
  const MethodDef def = resolve_method(name);
  MethodSpec m;
  m.library = "nystrom";
  m.name = name;
  m.label = compensated ? name : name + " (no comp.)";
  m.adaptive = true;
  m.order = def.info.order;
  m.compensated = compensated;
  m.reference = compensated;
  m.make = [def, ecc, periods, compensated](ForceCounter* c) -> Prepare {
    return [def, ecc, periods, c, compensated](double tol) -> Run {
      AdaptiveOptions opt;
      opt.rtol = tol;
      opt.h0 = 1e-3;
      EngineOptions eo;
      eo.compensated = compensated ? Compensation::on : Compensation::off;
      auto proto = std::make_shared<AdaptiveMpeIntegrator<Vec2, CountingKepler>>(
          make_adaptive_mpe_integrator<Vec2>(def, CountingKepler{c}, opt, eo));
      return [proto, ecc, periods](State<Vec2>& s, long& steps, EndTime& end) {
        auto integ = *proto;
        s = start(ecc);
        const double t_end = period() * static_cast<double>(periods);
        end = {t_end, 1};
        const AdaptiveStats st = integ.integrate_to(s, 0.0, t_end);
        steps = st.accepted;
      };
    };
  };
  return m;
}

inline MethodSpec nystrom_gbs(double ecc, long periods) {
  MethodSpec m;
  m.library = "nystrom";
  m.name = "GBS";
  m.label = "GBS";
  m.adaptive = true;
  m.make = [ecc, periods](ForceCounter* c) -> Prepare {
    return [ecc, periods, c](double tol) -> Run {
      GbsOptions opt;
      opt.rtol = opt.atol = tol;
      auto proto = std::make_shared<GbsIntegrator<Vec2, CountingKepler>>(CountingKepler{c}, opt);
      return [proto, ecc, periods](State<Vec2>& s, long& steps, EndTime& end) {
        auto integ = *proto;
        s = start(ecc);
        const double t_end = period() * static_cast<double>(periods);
        end = {t_end, 1};
        integ.integrate_to(s, t_end);
        steps = integ.steps();
      };
    };
  };
  return m;
}

// ---- Boost.Odeint --------------------------------------------------------------------------------

namespace oi = boost::numeric::odeint;

/// A fixed-step odeint run: `n` calls of stepper.do_step(sys, x, t, h) on a new stepper (cheap to build;
/// copying odeint's steppers copies uninitialised buffers), with the state converted from and to (q, v)
/// by `in` and `out`.
template <class Stepper, class Sys, class X, class In, class Out>
Run odeint_fixed_run(Sys sys, In in, Out out, double ecc, long n, double h) {
  return [sys, in, out, ecc, n, h](State<Vec2>& s, long& steps, EndTime& end) {
    Stepper stepper;
    X x = in(start(ecc));
    double t = 0;
    for (long i = 0; i < n; ++i, t += h) stepper.do_step(sys, x, t, h);
    s = out(x);
    steps = n;
    end = {h, n};
  };
}

inline std::pair<Vec2, Vec2> to_pair(const State<Vec2>& s) { return {s.q, s.v}; }
inline State<Vec2> from_pair(const std::pair<Vec2, Vec2>& x) { return {x.first, x.second}; }
inline Vec4 to_vec4(const State<Vec2>& s) { return {s.q[0], s.q[1], s.v[0], s.v[1]}; }
inline State<Vec2> from_vec4(const Vec4& y) { return {{y[0], y[1]}, {y[2], y[3]}}; }

/// odeint's symplectic RKN steppers on the (q, p) pair; the system is the momentum function alone
/// (odeint then takes dq/dt = p).
template <class Stepper>
MethodSpec odeint_symplectic(const std::string& name, const std::string& label, int order, int forces_per_step,
                             double ecc, long periods) {
  MethodSpec m{.library = "odeint", .name = name, .label = label, .order = order, .forces_per_step = forces_per_step};
  m.make = [ecc, periods](ForceCounter* c) -> Prepare {
    return [ecc, periods, c](double spp) -> Run {
      const long k = static_cast<long>(spp);
      return odeint_fixed_run<Stepper, CountingKepler, std::pair<Vec2, Vec2>>(
          CountingKepler{c}, to_pair, from_pair, ecc, k * periods, period() / static_cast<double>(k));
    };
  };
  return m;
}

inline MethodSpec odeint_verlet(double ecc, long periods) {
  MethodSpec m{.library = "odeint",
               .name = "velocity_verlet",
               .label = "odeint velocity_verlet",
               .order = 2,
               .forces_per_step = 1,
               .forces_extra = 1};
  m.make = [ecc, periods](ForceCounter* c) -> Prepare {
    return [ecc, periods, c](double spp) -> Run {
      const long k = static_cast<long>(spp);
      using Stepper = oi::velocity_verlet<Vec2>;
      return odeint_fixed_run<Stepper, CountingKeplerVerlet, std::pair<Vec2, Vec2>>(
          CountingKeplerVerlet{CountingKepler{c}}, to_pair, from_pair, ecc, k * periods,
          period() / static_cast<double>(k));
    };
  };
  return m;
}

inline MethodSpec odeint_rkf78(double ecc, long periods) {
  MethodSpec m{.library = "odeint",
               .name = "runge_kutta_fehlberg78",
               .label = "odeint rkf78",
               .order = 8,
               .forces_per_step = 13};
  m.make = [ecc, periods](ForceCounter* c) -> Prepare {
    return [ecc, periods, c](double spp) -> Run {
      const long k = static_cast<long>(spp);
      using Stepper = oi::runge_kutta_fehlberg78<Vec4>;
      return odeint_fixed_run<Stepper, CountingKeplerSystem, Vec4>(CountingKeplerSystem{CountingKepler{c}}, to_vec4,
                                                                   from_vec4, ecc, k * periods,
                                                                   period() / static_cast<double>(k));
    };
  };
  return m;
}

/// An adaptive odeint run: integrate_adaptive(stepper, sys, y, 0, t_end, 1e-3) on a new stepper from
/// `make_stepper`.
template <class MakeStepper>
Run odeint_adaptive_run(MakeStepper make_stepper, ForceCounter* c, double ecc, long periods) {
  return [make_stepper, c, ecc, periods](State<Vec2>& s, long& steps, EndTime& end) {
    auto stepper = make_stepper();
    Vec4 y = to_vec4(start(ecc));
    const double t_end = period() * static_cast<double>(periods);
    end = {t_end, 1};
    steps = static_cast<long>(
        oi::integrate_adaptive(stepper, CountingKeplerSystem{CountingKepler{c}}, y, 0.0, t_end, 1e-3));
    s = from_vec4(y);
  };
}

inline MethodSpec odeint_dopri5(double ecc, long periods) {
  MethodSpec m{
      .library = "odeint", .name = "runge_kutta_dopri5", .label = "odeint dopri5", .adaptive = true, .order = 5};
  m.make = [ecc, periods](ForceCounter* c) -> Prepare {
    return [ecc, periods, c](double tol) -> Run {
      return odeint_adaptive_run([tol] { return oi::make_controlled(tol, tol, oi::runge_kutta_dopri5<Vec4>()); }, c,
                                 ecc, periods);
    };
  };
  return m;
}

inline MethodSpec odeint_bs(double ecc, long periods) {
  MethodSpec m{.library = "odeint", .name = "bulirsch_stoer", .label = "odeint bulirsch_stoer", .adaptive = true};
  m.make = [ecc, periods](ForceCounter* c) -> Prepare {
    return [ecc, periods, c](double tol) -> Run {
      return odeint_adaptive_run([tol] { return oi::bulirsch_stoer<Vec4>(tol, tol); }, c, ecc, periods);
    };
  };
  return m;
}

}  // namespace detail

/// The methods compared, for one eccentricity.
inline std::vector<MethodSpec> peer_methods(double ecc, long periods) {
  using namespace detail;
  std::vector<MethodSpec> m;
  for (const char* name : {"VV", "M4", "M6", "M6-5F", "A6", "M8", "KL8", "M10", "SS10", "M12", "DP12"})
    m.push_back(nystrom_fixed(name, ecc, periods));
  m.push_back(nystrom_adaptive("DP12-adaptive", ecc, periods));
  for (const char* name : {"M10-adaptive", "M12-adaptive", "M14-adaptive", "M16-adaptive", "MPE-adaptive"})
    m.push_back(nystrom_adaptive_mpe(name, ecc, periods));
  m.push_back(nystrom_adaptive_mpe("M12-adaptive", ecc, periods, Compensation::off));
  m.push_back(nystrom_gbs(ecc, periods));
  for (const char* name : {"M8", "SS10", "DP12"}) m.push_back(nystrom_fixed(name, ecc, periods, Compensation::off));
  m.push_back(odeint_verlet(ecc, periods));
  m.push_back(odeint_symplectic<oi::symplectic_rkn_sb3a_mclachlan<Vec2>>("symplectic_rkn_sb3a_mclachlan",
                                                                         "odeint sb3a_mclachlan", 4, 6, ecc, periods));
  m.push_back(odeint_symplectic<oi::symplectic_rkn_sb3a_m4_mclachlan<Vec2>>(
      "symplectic_rkn_sb3a_m4_mclachlan", "odeint sb3a_m4_mclachlan", 4, 5, ecc, periods));
  m.push_back(odeint_rkf78(ecc, periods));
  m.push_back(odeint_dopri5(ecc, periods));
  m.push_back(odeint_bs(ecc, periods));
  return m;
}

/// Runs `run` repeatedly (the config's repetition rule) and returns the fastest repetition.
inline Outcome timed(const Run& run, ForceCounter& counter, double ecc, const PeerConfig& cfg, int& reps) {
  Outcome best;
  double spent = 0;
  reps = 0;
  while (true) {
    counter.calls = 0;
    State<Vec2> s;
    long steps = 0;
    EndTime end;
    Outcome o;
    const auto t0 = std::chrono::steady_clock::now();
    try {
      run(s, steps, end);
      o.ok = true;
    } catch (const BudgetExceeded&) {
      o.ok = false;
      o.budget = true;
    } catch (const std::exception&) {  // odeint: step size adjustment failed; nystrom: max_steps
      o.ok = false;
    }
    const auto t1 = std::chrono::steady_clock::now();
    o.seconds = std::chrono::duration<double>(t1 - t0).count();
    o.forces = counter.calls;
    ++reps;
    if (!o.ok) return o;  // failures are not repeated
    o.steps = steps;
    o.error = detail::position_error(ecc, s, end);
    if (!std::isfinite(o.error)) {
      o.ok = false;  // diverged (NaN or infinite): a failure, not repeated
      return o;
    }
    if (reps == 1 || o.seconds < best.seconds) best = o;
    spent += o.seconds;
    if (reps >= cfg.max_reps) break;
    if (o.seconds >= cfg.long_run) break;
    if (reps >= cfg.min_reps && spent >= cfg.min_time) break;
  }
  return best;
}

/// Two runs timed alternately, `pairs` times each (a, b, a, b, ...), the fastest repetition of each:
/// both see the same state of the machine, so their ratio does not move with the load of a shared
/// host the way two sweeps minutes apart do. The runs are rebuilt from their specifications and
/// parameters (with fresh counters); failures and errors are checked as in timed().
inline std::pair<Outcome, Outcome> interleaved(const MethodSpec& ma, double pa, const MethodSpec& mb, double pb,
                                               double ecc, int pairs) {
  ForceCounter ca, cb;
  const Run ra = ma.make(&ca)(pa), rb = mb.make(&cb)(pb);
  PeerConfig once;
  once.min_reps = once.max_reps = 1;
  once.min_time = 0;
  Outcome best_a, best_b;
  for (int i = 0; i < pairs; ++i) {
    int reps = 0;
    const Outcome a = timed(ra, ca, ecc, once, reps);
    const Outcome b = timed(rb, cb, ecc, once, reps);
    if (i == 0 || a.seconds < best_a.seconds) best_a = a;
    if (i == 0 || b.seconds < best_b.seconds) best_b = b;
    if (!a.ok || !b.ok) break;
  }
  return {best_a, best_b};
}

/// Steps per period of a fixed-step sweep: geometric from `from`, integers, strictly increasing.
inline std::vector<long> spp_values(double from, double ratio, long up_to) {
  std::vector<long> v;
  for (double x = from; x <= static_cast<double>(up_to); x *= ratio) {
    const long n = std::lround(x);
    if (v.empty() || n > v.back()) v.push_back(n);
  }
  return v;
}

/// Runs one method's sweep at one eccentricity. `progress` is called after each run.
inline std::vector<PeerRun> sweep_method(const MethodSpec& m, double ecc, const PeerConfig& cfg,
                                         const std::function<void()>& progress = {}) {
  std::vector<PeerRun> out;
  ForceCounter counter;
  counter.cap = m.adaptive ? cfg.force_cap : std::numeric_limits<long>::max();
  const Prepare prepare = m.make(&counter);
  auto record = [&](double param, const Outcome& o, int reps) {
    PeerRun r;
    r.library = m.library;
    r.method = m.name;
    r.label = m.label;
    r.adaptive = m.adaptive;
    r.compensated = m.compensated;
    r.reference = m.reference;
    r.order = m.order;
    r.forces_per_step = m.forces_per_step;
    r.forces_extra = m.forces_extra;
    r.ecc = ecc;
    r.param = param;
    r.steps = o.steps;
    r.forces = o.forces;
    r.seconds = o.seconds;
    r.error = o.error;
    r.reps = reps;
    r.ok = o.ok;
    out.push_back(r);
    if (progress) progress();
  };
  // Stop once the error has reached the floor, or has not improved on its best for 1.5 decades of
  // tolerance (adaptive) or two octaves of steps (fixed step), at least three runs, while already
  // small: the round-off plateau, on which errors scatter by 10x between neighbouring runs (a shorter
  // rule would stop odeint's rkf78 at e = 0.5 before its 1448 steps/period run, 2.2e-13).
  double best = std::numeric_limits<double>::infinity();
  int stale = 0;
  const int stale_max = std::max(
      3, static_cast<int>(std::lround(m.adaptive ? 1.5 / std::log10(cfg.tol_ratio) : 2.0 / std::log2(cfg.spp_ratio))));
  auto done = [&](double err) {
    if (err < best * 0.7) {
      best = err;
      stale = 0;
    } else if (best < 1e-9) {
      ++stale;
    }
    return err < cfg.floor_error || stale >= stale_max;
  };
  if (m.adaptive) {
    for (double tol = cfg.tol_max; tol >= cfg.tol_min * 0.999; tol /= cfg.tol_ratio) {
      Run run;
      try {
        run = prepare(tol);
      } catch (const std::invalid_argument&) {
        continue;  // a tolerance the integrator refuses (below 10 eps)
      }
      int reps = 0;
      const Outcome o = timed(run, counter, ecc, cfg, reps);
      record(tol, o, reps);
      if (o.budget || (o.ok && done(o.error))) break;
    }
  } else {
    // Start where the coarsest step still resolves the pericentre of e = 0.9 somewhat.
    const double from = ecc > 0.7 ? 64.0 : 16.0;
    const long fps = std::max(1, m.forces_per_step);
    const long spp_cap = std::max<long>(1, cfg.force_cap / (fps * cfg.periods));
    for (long spp : spp_values(from, cfg.spp_ratio, spp_cap)) {
      int reps = 0;
      const Outcome o = timed(prepare(static_cast<double>(spp)), counter, ecc, cfg, reps);
      record(static_cast<double>(spp), o, reps);
      if (o.ok && done(o.error)) break;
    }
  }
  return out;
}

// ---- summaries -----------------------------------------------------------------------------------

/// The fastest successful run of `library` at eccentricity `ecc` with error <= target (reference
/// configurations only, unless reference_only is false); nullptr if none.
inline const PeerRun* cheapest(const std::vector<PeerRun>& runs, const std::string& library, double ecc, double target,
                               bool reference_only = true) {
  const PeerRun* best = nullptr;
  for (const auto& r : runs)
    if (r.ok && (r.reference || !reference_only) && r.library == library && r.ecc == ecc && r.error <= target &&
        (!best || r.seconds < best->seconds))
      best = &r;
  return best;
}

/// The smallest error of one method (by label) at `ecc`.
inline double min_error(const std::vector<PeerRun>& runs, const std::string& label, double ecc) {
  double e = std::numeric_limits<double>::infinity();
  for (const auto& r : runs)
    if (r.ok && r.label == label && r.ecc == ecc) e = std::min(e, r.error);
  return e;
}

/// Observed order of a fixed-step method: minus the least-squares slope of log(error) against
/// log(steps per period) over its runs with error in [lo, hi] (the asymptotic range above the round-off
/// floor); NaN with fewer than three such runs.
inline double observed_order(const std::vector<PeerRun>& runs, const std::string& label, double ecc, double lo = 1e-11,
                             double hi = 1e-2) {
  std::vector<double> x, y;
  for (const auto& r : runs)
    if (r.ok && !r.adaptive && r.label == label && r.ecc == ecc && r.error >= lo && r.error <= hi) {
      x.push_back(std::log(r.param));
      y.push_back(std::log(r.error));
    }
  if (x.size() < 3) return std::numeric_limits<double>::quiet_NaN();
  double mx = 0, my = 0;
  for (std::size_t i = 0; i < x.size(); ++i) mx += x[i], my += y[i];
  mx /= static_cast<double>(x.size());
  my /= static_cast<double>(x.size());
  double sxy = 0, sxx = 0;
  for (std::size_t i = 0; i < x.size(); ++i) sxy += (x[i] - mx) * (y[i] - my), sxx += (x[i] - mx) * (x[i] - mx);
  return -sxy / sxx;
}

}  // namespace nystrom::peers
