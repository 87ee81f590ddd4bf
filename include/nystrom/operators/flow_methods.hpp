// Methods over operator flows: which catalog methods apply to a problem, their coefficients, and one
// integrator that runs any of them over flows F (operators/flows.hpp).
//
// Specifications: everything resolve_method() accepts (`M8`, `mpe:1,2,4`, `mpe-vv:1,2,3`, `KL8`, `AC1`,
// `adjoint:FR`, ...), plus the multi-product expansion over a higher-order symmetric base:
//   mpe4:1,2,3          over Forest-Ruth (fourth order);
//   mpe-over:NAME:1,2   over any symmetric catalog splitting NAME of even order p.
// For a symmetric base T_p of order p, T_p^k(h/k) = e^{h(A+B)} + sum_{m = p, p+2, ...} k^{-m} h^{m+1} E_m
// + ..., so the c_i that solve sum c_i = 1, sum c_i k_i^{-m} = 0 (m = p, ..., p + 2(n-2)) give order
// p + 2(n-1). For p = 2 these are Chin's eq (14); for p = 4 and {1, 2} his eq (27),
// T_6 = -T_4(h)/15 + 16 T_4^2(h/2)/15 (S. A. Chin, "Multi-product splitting and Runge-Kutta-Nystrom
// integrators", Celest. Mech. Dyn. Astron. 106 (2010) 391).
#pragma once

#include <algorithm>
#include <cmath>
#include <complex>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include <gmpxx.h>

#include "nystrom/core/bignum.hpp"
#include "nystrom/engines/integrator.hpp"  // mpe_coefficients_as (coefficient data only)
#include "nystrom/engines/mpe.hpp"         // mpe_coefficients, parse_sequence
#include "nystrom/methods/catalog.hpp"
#include "nystrom/methods/method_data.hpp"
#include "nystrom/operators/flows.hpp"

namespace nystrom::operators {

/// What is known about the pair (A, B) a method is run on.
enum class OperatorStructure {
  general,  // any A, B (matrices, stochastic generators): only the free-Lie-algebra order conditions hold
  rkn,      // [B,[B,[A,B]]] = 0: A kinetic, B a potential (q'' = a(q); Schrödinger T + V, Gross-Pitaevskii)
};

/// A multi-product expansion over a symmetric base of even order p.
struct FlowMpeDef {
  std::vector<long> k;
  std::string base_name;
  int base_order = 2;
  SplittingScheme<bigcomplex> base;
  std::vector<mpq_class> c;
};

/// A splitting whose kick sub-steps carry gradient coefficients c_j: e^{h b_j B + h^3 c_j [B,[A,B]]}.
struct GradientSplitting {
  SplittingScheme<bigcomplex> scheme;
  std::vector<bigcomplex> gradient;  // one per sub-step, 0 for the drifts and plain kicks
};

struct FlowMethod {
  MethodInfo info;
  std::variant<SplittingScheme<bigcomplex>, FlowMpeDef, GradientSplitting> data;
};

/// Chin's forward fourth-order method 4A with the exact gradient term, every coefficient positive:
/// e^{hB/6} e^{hA/2} e^{2h B~/3} e^{hA/2} e^{hB/6}, B~ = B + (h^2/48)[B,[A,B]] (S. A. Chin, "Symplectic
/// integrators from composite operator factorizations", Phys. Lett. A 226 (1997) 344; for the Schrodinger
/// equation, where [V,[T,V]] = |grad V|^2/m, S. A. Chin and C. R. Chen, J. Chem. Phys. 114 (2001) 7338). The
/// middle kick's gradient coefficient is (2/3)(1/48) = 1/72. It needs flows with apply_b_gradient().
inline FlowMethod chin_forward_4a(long bits) {
  const BigPrecision guard(reference_bits(bits));
  GradientSplitting d{
      scheme({kick(big("1/6")), drift(big("1/2")), kick(big("2/3")), drift(big("1/2")), kick(big("1/6"))}),
      {big("0"), big("0"), big("1/72"), big("0"), big("0")}};
  MethodInfo info{.name = "4A",
                  .family = "splitting",
                  .order = 4,
                  .stages = 3,
                  .forces_per_step = 2,
                  .fsal = true,
                  .symmetric = true,
                  .symplectic = true,
                  .source = "Chin, Phys. Lett. A 226 (1997) 344; Chin & Chen, J. Chem. Phys. 114 (2001) 7338",
                  .description = "Chin's forward 4th-order 4A with the gradient potential [B,[A,B]]",
                  .aliases = {"chin-4a"}};
  return {info, d};
}

/// Exact extrapolation coefficients for a symmetric base of even order p (see the top of this file).
inline std::vector<mpq_class> extrapolation_coefficients(const std::vector<long>& k, int p) {
  validate_mpe_sequence(k);
  if (p < 2 || p % 2 != 0) throw std::invalid_argument("the base of a multi-product expansion must have even order");
  const std::size_t n = k.size();
  std::vector<std::vector<mpq_class>> a(n, std::vector<mpq_class>(n + 1));
  for (std::size_t i = 0; i < n; ++i) a[0][i] = 1;
  a[0][n] = 1;
  for (std::size_t j = 1; j < n; ++j)
    for (std::size_t i = 0; i < n; ++i) {
      mpz_class pw;
      mpz_pow_ui(pw.get_mpz_t(), mpz_class(k[i]).get_mpz_t(), static_cast<unsigned long>(p + 2 * (j - 1)));
      a[j][i] = mpq_class(1) / mpq_class(pw);
    }
  for (std::size_t col = 0; col < n; ++col) {  // exact Gaussian elimination (the Vandermonde matrix is regular)
    std::size_t piv = col;
    while (a[piv][col] == 0) ++piv;
    std::swap(a[piv], a[col]);
    for (std::size_t r = 0; r < n; ++r) {
      if (r == col || a[r][col] == 0) continue;
      const mpq_class f = a[r][col] / a[col][col];
      for (std::size_t c = col; c <= n; ++c) a[r][c] -= f * a[col][c];
    }
  }
  std::vector<mpq_class> c(n);
  for (std::size_t i = 0; i < n; ++i) c[i] = a[i][n] / a[i][i];
  return c;
}

/// Whether a splitting method's declared order holds for general operators. Compositions of a symmetric
/// second-order method (Forest-Ruth, Yoshida, Suzuki, Kahan-Li, Sofroniou-Spaletta) and methods of order
/// <= 3 do; the splittings designed for q'' = a(q) (Blanes-Moan's RKN splittings, Gürkan's fifth-order
/// methods, method files from `discover`) use [B,[B,[A,B]]] = 0 in their order conditions.
inline bool order_holds_for_general_operators(const MethodInfo& info) {
  if (info.family == "composition" || info.family == "mpe" || info.order <= 3) return true;
  std::string name = info.name;
  if (name.rfind("adjoint:", 0) == 0) name = name.substr(8);
  return name == "FR" || name == "FR-V";
}

/// The one place that decides whether a method runs over operator flows of the given structure; throws
/// std::invalid_argument with the reason when it does not.
inline void check_applicable(const MethodInfo& info, const MethodData& data, OperatorStructure structure) {
  if (std::holds_alternative<RknTableau<bigcomplex>>(data))
    throw std::invalid_argument("'" + info.name +
                                "' is a Runge-Kutta-Nystrom tableau with consolidated forces: it solves q'' = a(q) "
                                "only, not a product of operator flows (use a splitting or MPE method)");
  if (info.adaptive)
    throw std::invalid_argument("'" + info.name + "' is adaptive: adaptive steps run on q'' = a(q) only");
  if (structure == OperatorStructure::general && !order_holds_for_general_operators(info))
    throw std::invalid_argument("'" + info.name + "' reaches order " + std::to_string(info.order) +
                                " only when [B,[B,[A,B]]] = 0 (q'' = a(q), Schrodinger T + V), not for general "
                                "operators");
}

namespace detail {

inline bool is_palindrome(const SplittingScheme<bigcomplex>& s) {
  const auto n = normalized(s);
  for (std::size_t i = 0, j = n.steps.size(); i < j--; ++i) {
    if (n.steps[i].flow != n.steps[j].flow) return false;
    const double dr = std::abs((n.steps[i].coef.re - n.steps[j].coef.re).convert_to<double>());
    const double di = std::abs((n.steps[i].coef.im - n.steps[j].coef.im).convert_to<double>());
    if (dr > 1e-25 || di > 1e-25) return false;
  }
  return true;
}

inline FlowMethod mpe_over(const std::string& spec, const std::string& base_spec, const std::string& seq, long bits,
                           const std::string& type_name, OperatorStructure structure) {
  const std::vector<long> k = parse_sequence(seq);
  const MethodDef base = resolve_method(base_spec);
  const MethodData bd = method_data_for(base, bits, type_name);
  check_applicable(base.info, bd, structure);
  const auto* sp = std::get_if<SplittingScheme<bigcomplex>>(&bd);
  if (!sp || !is_palindrome(*sp) || base.info.order % 2 != 0)
    throw std::invalid_argument("'" + spec + "': the base of a multi-product expansion must be a symmetric splitting " +
                                "of even order, not '" + base.info.name + "'");
  FlowMpeDef m{k, base.info.name, base.info.order, *sp, extrapolation_coefficients(k, base.info.order)};
  MethodInfo info{
      .name = spec,
      .family = "mpe",
      .order = base.info.order + 2 * (static_cast<int>(k.size()) - 1),
      .symmetric = false,
      .symplectic = false,
      .complex = base.info.complex,
      .source = "Chin (2010) eq (27), extrapolation of a symmetric order-" + std::to_string(base.info.order) + " base",
      .description = "multi-product expansion {" + seq + "} over " + base.info.name,
      .aliases = {}};
  return {info, m};
}

}  // namespace detail

/// Resolves `spec` for operator flows of the given structure, with coefficients at the reference precision
/// of a working type of `bits` bits. Throws std::invalid_argument for unknown or inapplicable methods.
inline FlowMethod resolve_flow_method(const std::string& spec, OperatorStructure structure, long bits,
                                      const std::string& type_name) {
  if (spec == "4A" || spec == "chin-4a") {
    if (structure == OperatorStructure::general)
      throw std::invalid_argument("'" + spec +
                                  "' needs the gradient term [B,[A,B]] of a potential (Schrodinger "
                                  "T + V), not general operators");
    return chin_forward_4a(bits);
  }
  if (spec.rfind("mpe4:", 0) == 0) return detail::mpe_over(spec, "FR", spec.substr(5), bits, type_name, structure);
  if (spec.rfind("mpe-over:", 0) == 0) {
    const std::string rest = spec.substr(9);
    const auto colon = rest.rfind(':');
    if (colon == std::string::npos || colon == 0)
      throw std::invalid_argument("'" + spec + "' must read mpe-over:NAME:k1,k2,...");
    return detail::mpe_over(spec, rest.substr(0, colon), rest.substr(colon + 1), bits, type_name, structure);
  }
  const MethodDef def = resolve_method(spec);
  check_applicable(def.info, def.build(), structure);  // before any refinement of published digits
  const MethodData data = method_data_for(def, bits, type_name);
  check_applicable(def.info, data, structure);
  if (const auto* m = std::get_if<MpeDef>(&data)) {
    const MpeCoefficients mc = mpe_coefficients(m->k);
    return {def.info, FlowMpeDef{m->k, m->base_name, 2, m->base, mc.c}};
  }
  return {def.info, std::get<SplittingScheme<bigcomplex>>(data)};
}

/// A sub-step that runs a flow backwards: its coefficient has a real part that is not positive (or, for a
/// gradient sub-step, the gradient coefficient has a negative real part).
struct BackwardSubStep {
  Flow flow;
  std::complex<double> coefficient;
  bool gradient = false;  // the gradient coefficient of a GradientSplitting sub-step
};

/// The first sub-step of `m` that runs a flow backwards, decided from the coefficients: the sub-steps of a
/// splitting, the gradient coefficients of a forward gradient method, the base of a multi-product expansion
/// (whose combination coefficients are not flows). None: every flow runs forward, as diffusion-type problems
/// (imaginary time, heat equations) need: a backward diffusion sub-step amplifies the highest modes.
inline std::optional<BackwardSubStep> backward_sub_step(const FlowMethod& m) {
  auto first = [](const SplittingScheme<bigcomplex>& s) -> std::optional<BackwardSubStep> {
    for (const auto& st : normalized(s).steps)
      if (!(st.coef.re > 0))
        return BackwardSubStep{st.flow, {st.coef.re.convert_to<double>(), st.coef.im.convert_to<double>()}};
    return std::nullopt;
  };
  if (const auto* sp = std::get_if<SplittingScheme<bigcomplex>>(&m.data)) return first(*sp);
  if (const auto* mp = std::get_if<FlowMpeDef>(&m.data)) return first(mp->base);
  const auto& g = std::get<GradientSplitting>(m.data);
  if (auto b = first(g.scheme)) return b;
  for (const auto& w : g.gradient)
    if (w.re < 0) return BackwardSubStep{Flow::kick, {w.re.convert_to<double>(), w.im.convert_to<double>()}, true};
  return std::nullopt;
}

inline bool runs_forward(const FlowMethod& m) { return !backward_sub_step(m).has_value(); }

/// The catalog's forward methods of order 3 and above for flows of the given structure, decided from their
/// coefficients, as a list for messages: "multi-product M4..M16 or mpe:K1,K2,..., Chin's 4A, Gurkan's AC1, ...
/// (complex)". `gradient`: include 4A (it needs the gradient of the potential).
inline std::string forward_alternatives(OperatorStructure structure, bool gradient) {
  std::vector<std::string> mpe, complex, real;
  for (const auto& def : catalog()) {
    if (def.info.adaptive || def.info.order < 3) continue;
    const MethodData d = def.build();
    if (std::holds_alternative<RknTableau<bigcomplex>>(d)) continue;
    if (structure == OperatorStructure::general && !order_holds_for_general_operators(def.info)) continue;
    const FlowMethod fm = std::holds_alternative<MpeDef>(d)
                              ? FlowMethod{def.info, FlowMpeDef{{}, "", 2, std::get<MpeDef>(d).base, {}}}
                              : FlowMethod{def.info, std::get<SplittingScheme<bigcomplex>>(d)};
    if (!runs_forward(fm)) continue;
    (def.info.family == "mpe" ? mpe : def.info.complex ? complex : real).push_back(def.info.name);
  }
  std::vector<std::string> parts;
  if (!mpe.empty())
    parts.push_back("multi-product " + (mpe.size() > 2 ? mpe.front() + ".." + mpe.back() : mpe.front()) +
                    " or mpe:K1,K2,...");
  if (gradient && structure == OperatorStructure::rkn && runs_forward(chin_forward_4a(64)))
    parts.push_back("Chin's 4A");
  auto join = [](const std::vector<std::string>& v) {
    std::string s;
    for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
    return s;
  };
  if (!real.empty()) parts.push_back(join(real));
  if (!complex.empty()) parts.push_back(join(complex) + " (complex, positive real parts)");
  return join(parts);
}

/// Any splitting or multi-product method over flows F; chosen at run time, one dispatch per integrate().
template <OperatorFlows F>
class FlowIntegrator {
 public:
  using state_type = typename F::state_type;
  using real_type = typename F::real_type;
  using complex_type = std::complex<real_type>;

  /// compensated: the multi-product expansions' compensated summation (MpeFlowStepper); splittings ignore it.
  explicit FlowIntegrator(const FlowMethod& m, Compensation compensated = Compensation::automatic)
      : info_(m.info), impl_(make(m, compensated)) {}

  const MethodInfo& info() const { return info_; }
  bool is_mpe() const { return impl_.index() == 1; }

  void integrate(F& f, state_type& s, real_type h, long n) {
    std::visit([&](auto& e) { e.integrate(f, s, h, n); }, impl_);
  }
  void step(F& f, state_type& s, real_type h) { integrate(f, s, h, 1); }

  /// Applications of the A and B flows in n steps of integrate().
  std::pair<long, long> applications(const F& f, long n) const {
    if (const auto* sp = std::get_if<0>(&impl_)) return sp->applications(f, n);
    const auto [a, b] = std::get<1>(impl_).applications(f);
    return {a * n, b * n};
  }

 private:
  using Impl = std::variant<SplittingFlowStepper<F>, MpeFlowStepper<F>>;  // a GradientSplitting runs on the first

  static SplittingScheme<complex_type> convert(const SplittingScheme<bigcomplex>& s) {
    return convert_scheme<complex_type>(s, [](const bigcomplex& x) { return to_scalar<complex_type>(x); });
  }

  static Impl make(const FlowMethod& m, Compensation compensated) {
    if (const auto* sp = std::get_if<SplittingScheme<bigcomplex>>(&m.data))
      return Impl(std::in_place_index<0>, convert(*sp));
    if (const auto* gp = std::get_if<GradientSplitting>(&m.data)) {
      std::vector<complex_type> c;
      for (const auto& x : gp->gradient) c.push_back(to_scalar<complex_type>(x));
      return Impl(std::in_place_index<0>, convert(gp->scheme), std::move(c));
    }
    const auto& d = std::get<FlowMpeDef>(m.data);
    MpeCoefficients mc;
    mc.k = d.k;
    mc.c = d.c;
    return Impl(std::in_place_index<1>, d.k, mpe_coefficients_as<real_type>(mc), convert(d.base), compensated);
  }

  MethodInfo info_;
  Impl impl_;
};

}  // namespace nystrom::operators
