// Wisdom-Holman maps: the splitting H = H_Kepler + H_interaction of a planetary system in Jacobi coordinates
// as operator flows (operators/flows.hpp), so that every real splitting and multi-product method of the
// catalog runs over them.
//
// J. Wisdom and M. Holman, "Symplectic maps for the N-body problem", AJ 102 (1991) 1528:
//   H_Kepler      = sum_{i>=1} m'_i (|v'_i|^2 / 2 - mu_i / r'_i),   mu_i = G m_0 eta_i / eta_{i-1},
//   H_interaction = sum_{i>=1} G m_0 m_i (1 / r'_i - 1 / r_0i) - sum_{1<=i<j} G m_i m_j / r_ij,
// (system.hpp for the Jacobi coordinates); the centre of mass x'_0 moves freely with H_Kepler.
// H_interaction depends on positions only, so its flow is a kick of the Jacobi velocities:
//   v'_i += dt (a'_i + mu_i x'_i / r'_i^3),
// where a'_i are the Jacobi components of the Newtonian accelerations (the Jacobi map applied to the inertial
// accelerations: it is the gradient in Jacobi coordinates divided by m'_i, since the kinetic energy is
// diagonal there) and the second term removes the Kepler part. This is the construction of WHFast (Rein &
// Tamayo, MNRAS 452 (2015) 376). Flow A is the Kepler drift (kepler_drift.hpp) of every Jacobi coordinate,
// flow B this kick. The pair satisfies [B,[B,[A,B]]] = 0 (B is a function of positions, A quadratic in the
// velocities), so methods built for q'' = a(q) keep their order.
//
// Methods (resolve_wh_method):
//   WH                the map itself: Kepler drift h/2, kick h, Kepler drift h/2 (the catalog's PV scheme);
//   WH-<catalog name> any real splitting or multi-product method of the catalog over these flows, e.g. WH-M8 =
//                     Chin's multi-product expansion of order 8 over the WH map (the natural sequence 1..4),
//                     WH-KL8 = Kahan-Li's composition of WH maps, WH-mpe:1,2,3,4,5 (any sequence);
//   SABA1..4, SBAB1..4 Laskar & Robutel's maps (methods/laskar_robutel2001.hpp);
//   SABA(10,6,4), SABA(8,6,4), SABA(10,4), SABAH(8,4,4), SABAH(8,6,4), SABAH(10,6,4)  the methods of generalized
//                     order of Blanes, Casas, Farres, Laskar, Makazaga & Murua (methods/blanes_et_al2013.hpp;
//                     aliases SABA1064, ...): error O(eps h^10 + eps^2 h^6 + eps^3 h^4) for SABA(10,6,4);
//   WHC3, WHC5, WHC7, WHC11, WHC17  the map with the symplectic corrector of that order (Wisdom, Holman &
//                     Touma 1996; methods/wisdom_holman_touma1996.hpp): C before the first step, C^{-1} applied
//                     to a copy at every output, error O(eps h^{n+1} + eps^2 h^2).
// Complex coefficients are refused: a Kepler drift over a complex time has no meaning for the orbits.
//
//   WHD, WHD-<name>   the map in democratic heliocentric coordinates (planetary/democratic.hpp) and any
//                     splitting or multi-product method of the catalog over it whose kicks never meet (WHD-M8).
#pragma once

#include <algorithm>
#include <complex>
#include <cstddef>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "nystrom/core/scalar.hpp"
#include "nystrom/core/state.hpp"  // Compensation, use_compensation
#include "nystrom/methods/blanes_et_al2013.hpp"
#include "nystrom/methods/laskar_robutel2001.hpp"
#include "nystrom/methods/wisdom_holman_touma1996.hpp"
#include "nystrom/operators/flow_methods.hpp"
#include "nystrom/planetary/democratic.hpp"
#include "nystrom/planetary/kepler_drift.hpp"
#include "nystrom/planetary/system.hpp"

namespace nystrom::planetary {

/// The Kepler drifts (A) and interaction kicks (B) of a planetary system over its flat Jacobi state.
template <class R>
class JacobiFlows {
 public:
  using state_type = std::vector<R>;
  using real_type = R;

  JacobiFlows(R G, std::vector<R> mass)
      : G_(G), mass_(std::move(mass)), mu_(jacobi_kepler_mu(G_, mass_)), eta_(detail::interior_masses(mass_)) {}

  std::size_t bodies() const { return mass_.size(); }
  const std::vector<R>& masses() const { return mass_; }
  R G() const { return G_; }
  long kepler_drifts() const { return drifts_; }  // applications of flow A
  long kicks() const { return kicks_; }           // applications of flow B (one force evaluation each)

  /// Compensated summation of every drift's and kick's increments over one state of `size` values, whose carries
  /// (carry()) the flows keep: for a run that applies the flows to that one state only (a splitting; propagate()
  /// with PropagateOptions::compensated), off (the default) where the flows act on several states (multi-product
  /// expansions). Switching it on zeroes the carries; the caller keeps the state and the carries paired.
  void set_compensated(bool on, std::size_t size) {
    compensated_ = on;
    carry_.assign(on ? size : 0, R(0));
  }
  bool compensated() const { return compensated_; }
  const std::vector<R>& carry() const { return carry_; }
  /// While paused, the increments are added plainly and the carries kept (another state passes through the flows:
  /// the inverse corrector's copy at an output).
  void pause_compensation(bool paused) { paused_ = paused; }

  void apply_a(state_type& s, std::complex<R> z) {
    detail::kepler_drift_bodies(
        s, mass_.size(), detail::real_step(z, "a Kepler drift"), [this](std::size_t i) { return mu_[i]; },
        carry_for(s));
    ++drifts_;
  }

  void apply_b(state_type& s, std::complex<R> z) {
    using std::sqrt;
    const R dt = detail::real_step(z, "an interaction kick");
    const std::size_t n = mass_.size();
    R* x = s.data();
    R* v = s.data() + 3 * n;
    R* cv = carry_for(s) ? carry_.data() + 3 * n : nullptr;
    pos_.resize(n);
    detail::jacobi_to_inertial<R>(
        mass_, eta_, n,
        [&](std::size_t i) {
          return i == 0 ? Vec3<R>{0, 0, 0} : Vec3<R>{x[3 * i], x[3 * i + 1], x[3 * i + 2]};
        },
        [&](std::size_t i, const Vec3<R>& xi) { pos_[i] = xi; });
    accelerations(G_, mass_, pos_, acc_);
    detail::inertial_to_jacobi<R>(
        mass_, n, [&](std::size_t i) { return acc_[i]; },
        [&](std::size_t i, const Vec3<R>& a) {
          if (i == 0) return;  // the centre of mass is not accelerated
          const R xx = x[3 * i], xy = x[3 * i + 1], xz = x[3 * i + 2];
          const R r2 = xx * xx + xy * xy + xz * xz;
          const R k = mu_[i] / (r2 * sqrt(r2));
          detail::add_increment(v[3 * i], dt * (a[0] + k * xx), cv ? cv + 3 * i : nullptr);
          detail::add_increment(v[3 * i + 1], dt * (a[1] + k * xy), cv ? cv + 3 * i + 1 : nullptr);
          detail::add_increment(v[3 * i + 2], dt * (a[2] + k * xz), cv ? cv + 3 * i + 2 : nullptr);
        });
    ++kicks_;
  }

  void assign(state_type& d, const state_type& s) { d = s; }
  void scale(state_type& s, R r) {
    for (R& a : s) a *= r;
  }
  void axpy(state_type& d, R r, const state_type& s) {
    for (std::size_t i = 0; i < d.size(); ++i) d[i] += r * s[i];
  }

 private:
  /// The carries of s, or nullptr when compensation is off.
  R* carry_for(const state_type& s) {
    if (!compensated_ || paused_) return nullptr;
    if (carry_.size() != s.size())
      throw std::invalid_argument("Wisdom-Holman flows: the carries are for another state");
    return carry_.data();
  }

  R G_;
  std::vector<R> mass_, mu_, eta_;  // eta_: interior masses m_0 + ... + m_i
  std::vector<Vec3<R>> pos_, acc_;  // scratch of the kick (allocated by the first one)
  std::vector<R> carry_;            // compensated summation's carries of the one state (set_compensated)
  bool compensated_ = false, paused_ = false;
  long drifts_ = 0, kicks_ = 0;
};

/// The order of the symplectic corrector a method name asks for (WHC3 -> 3), 0 for a method without one.
/// Throws std::invalid_argument for WHC<n> with no published corrector of order n.
inline int wh_corrector_order(const std::string& spec) {
  if (spec.rfind("WHC", 0) != 0 || spec.size() < 4 || spec.size() > 5) return 0;
  for (int n : methods::wh_corrector_orders())
    if (spec == "WHC" + std::to_string(n)) return n;
  throw std::invalid_argument("unknown planetary method '" + spec + "': the symplectic correctors are WHC3, WHC5, " +
                              "WHC7, WHC11 and WHC17");
}

/// Whether a method name asks for democratic heliocentric coordinates (WHD, WHD-<catalog method>).
inline bool is_democratic(const std::string& spec) { return spec == "WHD" || spec.rfind("WHD-", 0) == 0; }

/// Resolves a Wisdom-Holman method name (see the top of this file) with coefficients for a working type of
/// `bits` bits. Throws std::invalid_argument for unknown names and for methods that do not apply.
inline operators::FlowMethod resolve_wh_method(const std::string& spec, long bits, const std::string& type_name) {
  const MethodInfo wh{.name = "WH",
                      .family = "splitting",
                      .order = 2,
                      .stages = 1,
                      .forces_per_step = 1,
                      .symmetric = true,
                      .symplectic = true,
                      .source = "Wisdom & Holman, AJ 102 (1991) 1528",
                      .description = "Wisdom-Holman map: Kepler drift h/2, interaction kick h, Kepler drift h/2",
                      .aliases = {}};
  if (spec == "WH") return {wh, position_verlet_scheme()};
  if (const int n = wh_corrector_order(spec); n > 0) {
    MethodInfo info = wh;
    info.name = spec;
    info.source = "Wisdom, Holman & Touma, Fields Inst. Commun. 10 (1996) 217; Rein & Tamayo, MNRAS 452 (2015) 376";
    info.description = "Wisdom-Holman map with the symplectic corrector of order " + std::to_string(n) +
                       ": error O(eps h^" + std::to_string(n + 1) + " + eps^2 h^2) for H = A + eps B";
    return {info, position_verlet_scheme()};
  }
  std::vector<MethodDef> named = methods::laskar_robutel2001();
  for (MethodDef& def : methods::blanes_et_al2013()) named.push_back(std::move(def));
  for (const MethodDef& def : named)
    if (def.info.name == spec ||
        std::find(def.info.aliases.begin(), def.info.aliases.end(), spec) != def.info.aliases.end()) {
      auto sc = std::get<SplittingScheme<bigcomplex>>(method_data_for(def, bits, type_name));
      MethodInfo info = def.info;
      info.forces_per_step = info.stages = normalized(sc).forces_per_step();
      info.fsal = normalized(sc).fsal();
      return {info, std::move(sc)};
    }
  if (is_democratic(spec)) {
    operators::FlowMethod m =
        spec == "WHD"
            ? operators::FlowMethod{wh, position_verlet_scheme()}
            : operators::resolve_flow_method(spec.substr(4), operators::OperatorStructure::general, bits, type_name);
    const SplittingScheme<bigcomplex>* sc = std::get_if<SplittingScheme<bigcomplex>>(&m.data);
    if (const auto* mpe = std::get_if<operators::FlowMpeDef>(&m.data)) sc = &mpe->base;
    if (m.info.complex || !sc || sc->steps.empty() || sc->steps.front().flow != Flow::drift ||
        sc->steps.back().flow != Flow::drift)
      throw std::invalid_argument("'" + spec + "': democratic heliocentric coordinates take real splittings and " +
                                  "multi-product expansions that begin and end with a Kepler drift (over the " +
                                  "position-Verlet base)");
    m.info.name = spec;
    m.info.source = m.info.source + "; Duncan, Levison & Lee, AJ 116 (1998) 2067";
    m.info.description = spec == "WHD" ? "Wisdom-Holman map in democratic heliocentric coordinates: Kepler drift "
                                         "h/2, jump h/2, interaction kick h, jump h/2, Kepler drift h/2"
                                       : m.info.description + ", over the democratic heliocentric map";
    return m;
  }
  if (spec.rfind("WH-", 0) == 0 && spec.size() > 3) {
    operators::FlowMethod m =
        operators::resolve_flow_method(spec.substr(3), operators::OperatorStructure::rkn, bits, type_name);
    if (m.info.complex)
      throw std::invalid_argument("'" + spec +
                                  "' has complex coefficients: a Kepler drift over a complex time does not apply");
    m.info.description = m.info.description + ", over the Wisdom-Holman splitting";
    m.info.name = spec;
    return m;
  }
  throw std::invalid_argument(
      "unknown planetary method '" + spec +
      "': use WH, WH-<catalog method> (e.g. WH-M8), WHC3..WHC17, SABA1..SABA4, SBAB1..SBAB4, " +
      "SABA(10,6,4), SABA(8,6,4), SABA(10,4), SABAH(8,4,4), SABAH(8,6,4), SABAH(10,6,4), WHD or WHD-<catalog method>");
}

/// What a run observes: called before the first step and after every `every` steps (and after the last).
template <class R>
struct PropagateOptions {
  long every = 0;  // 0: no observation
  std::function<void(long step, const std::vector<R>& jacobi)> observer;
  /// Compensated summation of the drifts' and kicks' increments (JacobiFlows::set_compensated) for the splittings in
  /// Jacobi coordinates (the expansions and the democratic heliocentric maps add plainly): off by default; on (or
  /// automatic: on in double and float) removes the random walk of the state's rounding, 8x lower energy errors
  /// over 1e3 Jupiter periods for SABA(10,6,4) on the outer solar system, at about 1.15x the cost per step. Over
  /// 1e5 periods and more the Kepler solver's own energy bias (about -7e-20 per drift, the same sign every time)
  /// catches up with the plain map's random walk (docs/performance.md, "Long runs").
  Compensation compensated = Compensation::off;
};

template <class R>
struct PropagateResult {
  PlanetarySystem<R> system;  // the final state, in the frame of the initial one
  MethodInfo method;
  long kepler_drifts = 0, kicks = 0;
};

namespace detail {

/// Runs `fm` over flows F from the flat state s (C^{-1} of the outputs when a corrector is given); `jacobi`
/// maps a state of F to the Jacobi state the observer receives, `inertial` to inertial positions and velocities.
template <class F, class R, class ToJacobi, class ToInertial>
PropagateResult<R> run_flows(const PlanetarySystem<R>& sys, const operators::FlowMethod& fm, int corrector_order,
                             std::vector<R> s, R h, long steps, const PropagateOptions<R>& opt, ToJacobi jacobi,
                             ToInertial inertial) {
  F flows(sys.G, sys.mass);
  operators::FlowIntegrator<F> integ(fm);
  // compensated summation where asked and the flows act on the one state s (a splitting, not an expansion)
  constexpr bool can_compensate = requires { flows.set_compensated(true, std::size_t{0}); };
  if constexpr (can_compensate)
    if (!integ.is_mpe() && use_compensation<R>(opt.compensated)) flows.set_compensated(true, s.size());
  auto compensating = [&] {
    if constexpr (can_compensate)
      return flows.compensated();
    else
      return false;
  };
  // the state with its carries folded in (the outputs)
  auto with_carries = [&](std::vector<R>& x) {
    if constexpr (can_compensate)
      if (flows.compensated())
        for (std::size_t i = 0; i < x.size(); ++i) x[i] += flows.carry()[i];
  };
  // a symplectic corrector: C before the first step; the outputs are C^{-1} of the state, on a copy
  using Stepper = operators::SplittingFlowStepper<F>;
  std::optional<Stepper> corrector, inverse;
  if (corrector_order > 0) {
    SplittingScheme<std::complex<R>> c;
    {
      const BigPrecision guard(reference_bits(scalar_traits<R>::bits()));
      c = convert_scheme<std::complex<R>>(methods::wh_corrector_scheme(corrector_order),
                                          [](const bigcomplex& x) { return to_scalar<std::complex<R>>(x); });
    }
    SplittingScheme<std::complex<R>> ci = adjoint(c);
    for (auto& st : ci.steps) st.coef = -st.coef;
    corrector.emplace(c);
    inverse.emplace(ci);
    corrector->apply_once(flows, s, h);
  }
  std::vector<R> out;
  auto output = [&]() -> const std::vector<R>& {
    if (!inverse && !compensating()) return s;
    out = s;
    with_carries(out);
    if (inverse) {
      // the inverse corrector acts on the copy: its increments are added plainly, the run's carries kept
      if constexpr (can_compensate) flows.pause_compensation(true);
      inverse->apply_once(flows, out, h);
      if constexpr (can_compensate) flows.pause_compensation(false);
    }
    return out;
  };
  if (opt.every > 0 && opt.observer) {
    opt.observer(0, jacobi(output()));
    for (long done = 0; done < steps;) {
      const long chunk = std::min(opt.every, steps - done);
      integ.integrate(flows, s, h, chunk);
      done += chunk;
      opt.observer(done, jacobi(output()));
    }
  } else {
    integ.integrate(flows, s, h, steps);
  }
  PropagateResult<R> r;
  r.system = sys;
  inertial(output(), r.system.x, r.system.v);
  r.method = fm.info;
  r.kepler_drifts = flows.kepler_drifts();
  r.kicks = flows.kicks();
  return r;
}

}  // namespace detail

/// Advances a planetary system by `steps` steps of size h with a Wisdom-Holman method (in Jacobi coordinates, or
/// in democratic heliocentric ones for the WHD methods). The observer receives the Jacobi state either way.
template <class R>
PropagateResult<R> propagate(const PlanetarySystem<R>& sys, const std::string& method, R h, long steps,
                             const PropagateOptions<R>& opt = {}) {
  sys.validate();
  if (!(h > 0) || !std::isfinite(static_cast<double>(h)))
    throw std::invalid_argument("the step must be positive and finite");
  if (steps < 0) throw std::invalid_argument("the number of steps must not be negative");
  const operators::FlowMethod fm = resolve_wh_method(method, scalar_traits<R>::bits(), scalar_traits<R>::name());
  if (is_democratic(method)) {
    PlanetarySystem<R> tmp = sys;
    auto inertial = [&](const std::vector<R>& st, std::vector<Vec3<R>>& x, std::vector<Vec3<R>>& v) {
      from_democratic(sys.mass, st, x, v);
    };
    std::vector<R> j;
    auto jacobi = [&](const std::vector<R>& st) -> const std::vector<R>& {
      from_democratic(sys.mass, st, tmp.x, tmp.v);
      j = to_jacobi(tmp);
      return j;
    };
    return detail::run_flows<DemocraticHeliocentricFlows<R>>(sys, fm, 0, to_democratic(sys), h, steps, opt, jacobi,
                                                             inertial);
  }
  auto inertial = [&](const std::vector<R>& st, std::vector<Vec3<R>>& x, std::vector<Vec3<R>>& v) {
    from_jacobi(sys.mass, st, x, v);
  };
  auto jacobi = [](const std::vector<R>& st) -> const std::vector<R>& { return st; };
  return detail::run_flows<JacobiFlows<R>>(sys, fm, wh_corrector_order(method), to_jacobi(sys), h, steps, opt, jacobi,
                                           inertial);
}

}  // namespace nystrom::planetary
