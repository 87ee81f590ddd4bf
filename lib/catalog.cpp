// Definitions of the catalog (declared in methods/catalog.hpp): every coefficient table, the registry and
// the specification parser, compiled once in libnystrom.
#include <algorithm>
#include <atomic>
#include <cctype>
#include <cmath>
#include <map>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "nystrom/core/error.hpp"
#include "nystrom/methods/blanes_moan2002.hpp"
#include "nystrom/methods/catalog.hpp"
#include "nystrom/methods/chin2010.hpp"
#include "nystrom/methods/compositions.hpp"
#include "nystrom/methods/dop853.hpp"
#include "nystrom/methods/dormand_prince1987.hpp"
#include "nystrom/methods/fine1987.hpp"
#include "nystrom/methods/gurkan.hpp"
#include "nystrom/methods/method.hpp"

namespace nystrom {

namespace detail {

inline bool any_complex(const std::vector<bigcomplex>& v) {
  return std::any_of(v.begin(), v.end(), [](const bigcomplex& x) { return !x.is_real(); });
}

/// Every adaptive method carries the values its controller uses, so that the listings (nystrom methods,
/// nystrom.methods()) read them as they are: gamma 1 (plain control) where none was measured, and the engines'
/// default anchor, 1e-15 (adaptive_detail::kToleranceAnchor).
void controller_defaults(MethodInfo& in) {
  if (!in.adaptive) return;
  if (in.tolerance_exponent == 0) in.tolerance_exponent = 1;
  if (in.tolerance_anchor == 0) in.tolerance_anchor = 1e-15;
}

/// Fills the fields of MethodInfo that follow from the coefficients.
void finalize_info(MethodDef& d) {
  BigPrecision guard(128);
  const MethodData data = d.build();
  MethodInfo& in = d.info;
  if (const auto* sp = std::get_if<SplittingScheme<bigcomplex>>(&data)) {
    const auto s = normalized(*sp);
    in.stages = 0;
    for (const auto& st : s.steps) in.stages += st.flow == Flow::kick;
    in.forces_per_step = s.forces_per_step();
    in.fsal = s.fsal();
    in.complex = std::any_of(s.steps.begin(), s.steps.end(), [](const auto& x) { return !x.coef.is_real(); });
    if (in.complex) in.symplectic = false;  // imaginary parts are dropped after each step
    if (in.complex && in.fsal) {            // ... so the last force, taken at a complex position, is not reusable
      in.fsal = false;
      ++in.forces_per_step;
    }
  } else if (const auto* t = std::get_if<RknTableau<bigcomplex>>(&data)) {
    in.stages = static_cast<int>(t->stages());
    in.forces_per_step = t->forces_per_step();
    in.fsal = t->fsal();
    in.complex = any_complex(t->c) || any_complex(t->b) || any_complex(t->B);
    in.adaptive = in.adaptive || !t->bhat.empty();
    in.velocity = in.velocity || t->general();
  } else if (const auto* m = std::get_if<MpeDef>(&data)) {
    long sum = 0;
    for (long k : m->k) sum += k;
    in.stages = static_cast<int>(sum);
    const bool kick_first = m->base.steps.front().flow == Flow::kick;
    in.forces_per_step = static_cast<int>(sum) * m->base.forces_per_step() + (kick_first ? 1 : 0);
    in.fsal = false;
    in.complex = false;
    // The adaptive multi-product expansion's global error grows as tol^(1/gamma), gamma = (p - 1) / (p + 1) (the
    // estimate's order over one more than the method's): measured within 0.03 for p = 6..16, tol^1.59 for p = 4
    // (Kepler e = 0.5 and 0.9, outer solar system; engines/step_control.hpp, controlled_tolerance). The anchor:
    // where the plain controller's error on the outer solar system falls to about the tolerance, 1e-10 for p = 4,
    // beyond the tightest tolerance in double (1e-15) from p = 6 on: 10^-min(15, 2.5 p).
    if (in.adaptive) {
      in.tolerance_exponent = static_cast<double>(in.order - 1) / (in.order + 1);
      in.tolerance_anchor = std::pow(10.0, -std::min(15.0, 2.5 * in.order));
    }
  }
  controller_defaults(in);
}

inline std::string lower(std::string s) {
  for (auto& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace detail

/// All named methods, with derived fields filled in. Built once.
const std::vector<MethodDef>& catalog() {
  static const std::vector<MethodDef> all = [] {
    std::vector<MethodDef> v;
    auto add = [&v](std::vector<MethodDef> more) {
      for (auto& d : more) v.push_back(std::move(d));
    };
    add(methods::chin2010());
    add(methods::chin2010_mpe());
    add(methods::compositions());
    add(methods::blanes_moan2002());
    add(methods::gurkan());
    add(methods::dormand_prince1987());
    add(methods::dop853_methods());
    add(methods::fine1987_methods());
    for (auto& d : v) detail::finalize_info(d);
    return v;
  }();
  return all;
}

namespace detail {
std::atomic<MethodFileReader>& method_file_reader() {
  static std::atomic<MethodFileReader> reader{nullptr};
  return reader;
}
}  // namespace detail

void set_method_file_reader(MethodFileReader reader) { detail::method_file_reader().store(reader); }

namespace {
MethodDef resolve_spec(const std::string& spec) {
  if (spec.empty()) throw std::invalid_argument("empty method name");
  for (const auto& d : catalog()) {
    if (d.info.name == spec) return d;
  }
  const std::string ls = detail::lower(spec);
  for (const auto& d : catalog()) {
    if (detail::lower(d.info.name) == ls) return d;
    for (const auto& a : d.info.aliases)
      if (detail::lower(a) == ls) return d;
  }
  auto finalize = [](MethodDef d) {
    detail::finalize_info(d);
    return d;
  };
  // Adaptive multi-product methods (engines/adaptive_mpe.hpp): M<2n>-adaptive, mpe-adaptive:K, mpe-vv-adaptive:K.
  auto adaptive_mpe = [&finalize](const std::vector<long>& k, const std::string& base, const std::string& name) {
    if (k.size() < 2)
      throw std::invalid_argument("an adaptive MPE needs at least two products (the error estimate drops one): '" +
                                  name + "'");
    MethodDef d = methods::mpe_method(k, base, name);
    d.info.adaptive = true;
    d.info.description += ", adaptive step (embedded estimate: the products without the largest k)";
    return finalize(d);
  };
  if (ls.rfind("mpe-adaptive-max:", 0) == 0) {
    const std::string o = spec.substr(17);
    if (o.empty() || o.size() > 2 || !std::all_of(o.begin(), o.end(), ::isdigit))
      throw std::invalid_argument("the largest order of '" + spec + "' must be an even number from 4 to 16");
    return finalize(methods::mpe_order_control_method(std::stoi(o), "MPE-adaptive-max:" + o));
  }
  if (ls.rfind("mpe-adaptive:", 0) == 0) return adaptive_mpe(parse_sequence(spec.substr(13)), "PV", spec);
  if (ls.rfind("mpe-pv-adaptive:", 0) == 0) return adaptive_mpe(parse_sequence(spec.substr(16)), "PV", spec);
  if (ls.rfind("mpe-vv-adaptive:", 0) == 0) return adaptive_mpe(parse_sequence(spec.substr(16)), "VV", spec);
  if (ls.size() > 10 && ls.size() < 20 && ls[0] == 'm' && ls.substr(ls.size() - 9) == "-adaptive" &&
      std::all_of(ls.begin() + 1, ls.end() - 9, ::isdigit)) {
    const long order = std::stol(ls.substr(1, ls.size() - 10));
    if (order < 4 || order % 2 != 0 || order > 400)
      throw std::invalid_argument("adaptive MPE order must be an even number between 4 and 400, got '" + spec + "'");
    std::vector<long> k;
    for (long i = 1; i <= order / 2; ++i) k.push_back(i);
    return adaptive_mpe(k, "PV", "M" + std::to_string(order) + "-adaptive");
  }
  if (ls.rfind("mpe:", 0) == 0) return finalize(methods::mpe_method(parse_sequence(spec.substr(4)), "PV", spec));
  if (ls.rfind("mpe-pv:", 0) == 0) return finalize(methods::mpe_method(parse_sequence(spec.substr(7)), "PV", spec));
  if (ls.rfind("mpe-vv:", 0) == 0) return finalize(methods::mpe_method(parse_sequence(spec.substr(7)), "VV", spec));
  if (ls.size() >= 2 && ls[0] == 'm' && std::all_of(ls.begin() + 1, ls.end(), ::isdigit)) {
    if (ls.size() > 10)
      throw std::invalid_argument("MPE order must be an even number between 2 and 400, got '" + spec + "'");
    const long order = std::stol(ls.substr(1));
    if (order < 2 || order % 2 != 0 || order > 400)
      throw std::invalid_argument("MPE order must be an even number between 2 and 400, got '" + spec + "'");
    std::vector<long> k;
    for (long i = 1; i <= order / 2; ++i) k.push_back(i);
    return finalize(methods::mpe_method(k, "PV", "M" + std::to_string(order)));
  }
  for (const auto& [prefix, base] :
       {std::pair<std::string, std::string>{"triplejump:", "PV"}, {"triplejump-pv:", "PV"}, {"triplejump-vv:", "VV"}})
    if (ls.rfind(prefix, 0) == 0)
      return finalize(
          methods::triple_jump_method(methods::parse_composition_order(spec.substr(prefix.size()), spec), base, ls));
  for (const auto& [prefix, base] :
       {std::pair<std::string, std::string>{"suzuki:", "PV"}, {"suzuki-pv:", "PV"}, {"suzuki-vv:", "VV"}})
    if (ls.rfind(prefix, 0) == 0)
      return finalize(
          methods::suzuki_method(methods::parse_composition_order(spec.substr(prefix.size()), spec), base, ls));
  if (ls.rfind("file:", 0) == 0) {
    const MethodFileReader reader = detail::method_file_reader().load();
    if (!reader)
      throw std::invalid_argument(
          "method files need the method-file reader (include nystrom/analysis/method_file.hpp)");
    return finalize(reader(spec.substr(5)));
  }
  if (ls.rfind("adjoint:", 0) == 0) {
    // Nested adjoints are peeled off in a loop (a recursive descent overflowed the stack at a few thousand
    // levels); the adjoint is an involution, so only the parity of the nesting changes the method.
    std::size_t depth = 0, pos = 0;
    while (ls.compare(pos, 8, "adjoint:") == 0) pos += 8, ++depth;
    MethodDef base = resolve_method(spec.substr(pos));
    auto build = base.build;
    if (!std::holds_alternative<SplittingScheme<bigcomplex>>(build()))
      throw std::invalid_argument("adjoint: is defined here for splitting methods only, not '" + base.info.name + "'");
    if (depth % 2 == 0) return base;
    MethodDef d = base;
    d.info.name = "adjoint:" + base.info.name;
    d.info.aliases.clear();
    d.info.description = "adjoint of " + base.info.name;
    d.build = [build] { return MethodData{adjoint(std::get<SplittingScheme<bigcomplex>>(build()))}; };
    return finalize(d);
  }
  throw std::invalid_argument("unknown method '" + spec + "' (see `nystrom methods`)");
}

}  // namespace

/// Resolves a method specification (see methods/catalog.hpp); every refusal is an invalid_input.
MethodDef resolve_method(const std::string& spec) {
  try {
    return resolve_spec(spec);
  } catch (const std::invalid_argument& e) {
    throw invalid_input(e.what());
  }
}

MethodDef gbs_method_def(const GbsDef& gbs) {
  if (gbs.max_columns < 3 || gbs.max_columns > 20)
    throw invalid_input("GBS: the columns must be an integer between 3 and 20 (GBS:SEQUENCE:COLUMNS)");
  static const char* const names[] = {"harmonic", "romberg", "bulirsch"};
  const GbsDef defaults{};
  MethodDef d;
  d.info.name = "GBS";
  if (gbs.sequence != defaults.sequence || gbs.max_columns != defaults.max_columns)
    d.info.name += std::string(":") + names[static_cast<int>(gbs.sequence)] +
                   (gbs.max_columns != defaults.max_columns ? ":" + std::to_string(gbs.max_columns) : "");
  d.info.family = "extrapolation";
  d.info.order = 2 * gbs.max_columns;
  d.info.symmetric = true;  // the modified midpoint rule that it extrapolates
  d.info.adaptive = true;
  d.info.velocity = true;
  d.info.source = "Gragg (1965); Bulirsch & Stoer (1966); Hairer, Norsett & Wanner I, sec. II.9/II.14 (ODEX2)";
  d.info.description = std::string("Gragg-Bulirsch-Stoer extrapolation, adaptive step and order up to ") +
                       std::to_string(2 * gbs.max_columns) + ", " + names[static_cast<int>(gbs.sequence)] +
                       " step numbers";
  detail::controller_defaults(d.info);
  d.build = [gbs]() -> MethodData { return gbs; };
  return d;
}

namespace {

/// "GBS", "GBS:SEQUENCE" or "GBS:SEQUENCE:COLUMNS" (case-insensitive); nullopt for any other spec.
std::optional<MethodDef> gbs_spec(const std::string& spec) {
  const std::string ls = detail::lower(spec);
  if (ls != "gbs" && ls.rfind("gbs:", 0) != 0) return std::nullopt;
  GbsDef g;
  if (ls == "gbs") return gbs_method_def(g);
  const std::string rest = ls.substr(4);
  const auto colon = rest.find(':');
  const std::string seq = rest.substr(0, colon);
  if (seq == "harmonic")
    g.sequence = GbsSequence::harmonic;
  else if (seq == "romberg")
    g.sequence = GbsSequence::romberg;
  else if (seq == "bulirsch")
    g.sequence = GbsSequence::bulirsch;
  else
    throw invalid_input("GBS: unknown step-number sequence '" + seq.substr(0, 40) +
                        "' (known: harmonic, romberg, bulirsch; GBS:SEQUENCE:COLUMNS)");
  if (colon != std::string::npos) {
    const std::string cols = rest.substr(colon + 1);
    if (cols.empty() || cols.size() > 2 || cols.find_first_not_of("0123456789") != std::string::npos)
      throw invalid_input("GBS: the columns must be an integer between 3 and 20 (GBS:SEQUENCE:COLUMNS)");
    g.max_columns = std::stoi(cols);
  }
  return gbs_method_def(g);
}

}  // namespace

MethodDef midpoint_mpe_method_def(const std::vector<long>& k, const std::string& name, bool adaptive) {
  try {
    validate_mpe_sequence(k);
  } catch (const std::invalid_argument& e) {
    throw invalid_input(e.what());
  }
  if (adaptive && k.size() < 2)
    throw invalid_input("an adaptive MPE needs at least two products (the error estimate drops one): '" + name + "'");
  MethodDef d;
  d.info.name = name;
  d.info.family = "mpe-midpoint";
  d.info.order = 2 * static_cast<int>(k.size());
  long evals = 1;
  for (long x : k) evals += 2 * x - 1;
  d.info.stages = static_cast<int>(evals);
  d.info.forces_per_step = static_cast<int>(evals);
  d.info.velocity = true;
  d.info.source = "Gragg (1965); Hairer, Norsett & Wanner I, sec. II.9; Chin (2010) eq (14)";
  d.info.adaptive = adaptive;
  d.info.description =
      std::string("multi-product expansion over Gragg's modified midpoint rule (2k substeps), ") +
      (adaptive ? "adaptive step (embedded estimate: the products without the largest k)" : "fixed step");
  detail::controller_defaults(d.info);
  d.build = [k]() -> MethodData { return MpeDef{k, "GM", {}, false}; };
  return d;
}

std::string verlet_mpe_counterpart(const MethodDef& midpoint) {
  const std::string& name = midpoint.info.name;
  return (midpoint.info.adaptive ? "mpe-adaptive:" : "mpe:") + name.substr(name.find(':') + 1);
}

std::vector<MethodDef> listed_methods() {
  std::vector<MethodDef> out = catalog();
  out.push_back(gbs_method_def());
  return out;
}

std::vector<std::string> velocity_methods() {
  std::vector<std::string> out;
  for (const auto& d : catalog())
    if (d.info.velocity) out.push_back(d.info.name);
  out.push_back(gbs_method_def().info.name);
  out.push_back("mpe-midpoint:K1,K2,...");
  out.push_back("mpe-midpoint-adaptive:K1,K2,...");
  return out;
}

namespace {
std::string velocity_list() {
  std::string list;
  for (const auto& m : velocity_methods()) list += (list.empty() ? "" : ", ") + m;
  return list;
}
}  // namespace

std::string velocity_refusal(const std::string& name) {
  return "method '" + name +
         "' does not support velocity-dependent forces a(t, q, v); methods that do: " + velocity_list();
}

std::string first_order_refusal(const std::string& name) {
  return "method '" + name +
         "' does not integrate first-order systems y' = f(t, y); methods that do: " + velocity_list();
}

void require_first_order(const MethodDef& method) {
  if (!method.info.velocity) throw invalid_input(first_order_refusal(method.info.name));
}

void require_first_order(const std::string& method) { require_first_order(resolve_solve_method(method)); }

MethodDef resolve_solve_method(const std::string& spec) {
  if (auto g = gbs_spec(spec)) return *g;
  for (const bool adaptive : {false, true}) {
    const std::string prefix = adaptive ? "mpe-midpoint-adaptive:" : "mpe-midpoint:";
    if (detail::lower(spec).rfind(prefix, 0) != 0) continue;
    std::vector<long> k;
    try {
      k = parse_sequence(spec.substr(prefix.size()));
    } catch (const std::invalid_argument& e) {
      throw invalid_input(e.what());
    }
    std::string name = prefix;
    for (std::size_t i = 0; i < k.size(); ++i) name += (i ? "," : "") + std::to_string(k[i]);
    return midpoint_mpe_method_def(k, name, adaptive);
  }
  return resolve_method(spec);
}

}  // namespace nystrom
