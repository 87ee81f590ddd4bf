// What a method in the catalog is: its descriptive record (MethodInfo) and its coefficients as
// data (MethodData), built in high precision on demand.
#pragma once

#include <functional>
#include <initializer_list>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "nystrom/core/bignum.hpp"
#include "nystrom/methods/gbs_def.hpp"
#include "nystrom/methods/mpe_coefficients.hpp"
#include "nystrom/methods/rkn_tableau.hpp"
#include "nystrom/methods/splitting_scheme.hpp"

namespace nystrom {

struct MethodInfo {
  std::string name;
  std::string family;  // "splitting", "composition", "rkn", "mpe"
  int order = 0;
  int stages = 0;           // force stages of one step (kicks, RKN stages, or T_2 applications)
  int forces_per_step = 0;  // force evaluations per step in a long run (FSAL accounted)
  bool fsal = false;
  bool symmetric = false;
  bool symplectic = false;
  bool complex = false;
  bool adaptive = false;       // embedded pair with step-size control
  bool order_control = false;  // adaptive multi-product expansion choosing its order per step (MpeDef::order_control)
  bool velocity = false;       // integrates velocity-dependent forces a(t, q, v) (y'' = f(t, y, y'))
  int published_digits = 0;    // 0: exact (rational or closed form); else digits of the published table
  std::string source;          // the publication the coefficients come from
  std::string description;
  std::vector<std::string> aliases;
  // Adaptive methods: the exponent gamma and the anchor of the controller's tolerance (engines/step_control.hpp,
  // controlled_tolerance); gamma is the inverse of the measured growth of the global error with the tolerance
  // (error ~ tol^(1/gamma) under plain error-per-step control). 0: none (gamma 1), the default anchor 1e-15.
  double tolerance_exponent = 0;
  double tolerance_anchor = 0;
};

/// A multi-product method: the sequence {k_i} and the symmetric second-order base T_2. order_control: the
/// adaptive engine chooses per step how many of the products (a prefix of the natural sequence k) to run.
struct MpeDef {
  std::vector<long> k;
  std::string base_name;
  SplittingScheme<bigcomplex> base;
  bool order_control = false;
};

/// A method: a splitting scheme, an RKN tableau, a multi-product expansion, or Gragg-Bulirsch-Stoer
/// extrapolation (GbsDef: adaptive step and order; solve() runs it, the fixed-step engines refuse it).
using MethodData = std::variant<SplittingScheme<bigcomplex>, RknTableau<bigcomplex>, MpeDef, GbsDef>;

struct MethodDef {
  MethodInfo info;
  /// Builds the coefficients at the current reference precision (see BigPrecision).
  std::function<MethodData()> build;
};

// ---- helpers for writing tables ---------------------------------------------------------------

inline SubStep<bigcomplex> drift(bigcomplex c) { return {Flow::drift, std::move(c)}; }
inline SubStep<bigcomplex> kick(bigcomplex c) { return {Flow::kick, std::move(c)}; }

inline SplittingScheme<bigcomplex> scheme(std::initializer_list<SubStep<bigcomplex>> steps) {
  SplittingScheme<bigcomplex> s;
  s.steps.assign(steps.begin(), steps.end());
  return s;
}

/// Velocity Verlet, eq (25): kick h/2, drift h, kick h/2.
inline SplittingScheme<bigcomplex> velocity_verlet_scheme() {
  return scheme({kick(big("1/2")), drift(big("1")), kick(big("1/2"))});
}
/// Position Verlet, eq (26): drift h/2, kick h, drift h/2.
inline SplittingScheme<bigcomplex> position_verlet_scheme() {
  return scheme({drift(big("1/2")), kick(big("1")), drift(big("1/2"))});
}

/// Composition prod_i S(w_i h) of a symmetric base S (weights in order of application); adjacent
/// half-steps of the base merge.
inline SplittingScheme<bigcomplex> compose(const SplittingScheme<bigcomplex>& base, const std::vector<bigcomplex>& w) {
  SplittingScheme<bigcomplex> out;
  for (const auto& wi : w)
    for (const auto& s : base.steps) out.steps.push_back({s.flow, s.coef * wi});
  return normalized(out);
}

/// The length of a palindrome completed from its first half w_1..w_m: odd, w_1..w_{m-1} w_m w_{m-1}..w_1 (the
/// last given weight is the central one), or even, w_1..w_m w_m..w_1.
enum class PalindromeLength : unsigned char { odd, even };

/// Symmetric weights from the first half w_1..w_m (see PalindromeLength).
inline std::vector<bigcomplex> palindrome(const std::vector<bigcomplex>& half, PalindromeLength length) {
  std::vector<bigcomplex> w = half;
  for (std::size_t i = half.size() - (length == PalindromeLength::odd ? 1 : 0); i-- > 0;) w.push_back(half[i]);
  return w;
}

/// RKN tableau from rows written as strings (exact rationals or decimals).
inline RknTableau<bigcomplex> tableau(const std::vector<std::string>& c, const std::vector<std::vector<std::string>>& a,
                                      const std::vector<std::string>& b, const std::vector<std::string>& B) {
  RknTableau<bigcomplex> t;
  const std::size_t s = c.size();
  for (const auto& x : c) t.c.push_back(big(x));
  t.a.assign(s, std::vector<bigcomplex>(s, bigcomplex(big("0"))));
  for (std::size_t i = 0; i < a.size() && i < s; ++i)
    for (std::size_t j = 0; j < a[i].size() && j < s; ++j) t.a[i][j] = big(a[i][j]);
  for (const auto& x : b) t.b.push_back(big(x));
  for (const auto& x : B) t.B.push_back(big(x));
  return t;
}

}  // namespace nystrom
