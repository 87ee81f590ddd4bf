// Order conditions of explicit Runge-Kutta-Nystrom methods for q'' = f(q), by special Nystrom trees.
//
// Theory (Hairer, Norsett & Wanner, Solving ODEs I, sec. II.14). For the special second-order
// equation q'' = f(q) the elementary differentials are indexed by SN-trees: rooted trees with "fat"
// vertices (f and its derivatives) and "meagre" vertices (the velocity v), where
//   * the root is fat,
//   * every son of a fat vertex is meagre,
//   * a meagre vertex has no son (it is v) or exactly one son, which is fat (v' = f).
// rho(t) counts all vertices; gamma(t) is the density of t read as an ordinary rooted tree
// (gamma = rho * product of the gammas of the subtrees). For a tableau in form (2.1) of Gurkan
// (see methods/rkn_tableau.hpp) the stage weights are
//   Phi_i(t) = prod over the meagre sons m of the root of phi_i(m),
//   phi_i(leaf) = c_i,   phi_i(meagre over fat u) = sum_j a_ij Phi_j(u),
// and the method has order p iff
//   position:  sum_i b_i Phi_i(t) = 1 / ((rho(t) + 1) gamma(t))   for all t with rho(t) <= p - 1,
//   velocity:  sum_i B_i Phi_i(t) = 1 / gamma(t)                   for all t with rho(t) <= p.
// "The conditions of order n" below are the position conditions with rho = n - 1 together with the
// velocity conditions with rho = n (the terms h^(n+1) of q and h^n of v of the local error).
// Numbers of SN-trees with rho = 1, 2, ...: 1, 1, 2, 3, 6, 10, 20, 36, 72, 137, 275, ... (HNW I,
// Table II.14.3, special case y'' = f(y)).
//
// API (all in namespace nystrom; C is the coefficient type of the tableau: double, long double,
// bigfloat, std::complex<T>, bigcomplex, or any field type with +, -, * and construction from int
// plus a rkn_rational_value overload, e.g. a dual number for derivatives):
//   sn_trees(max_order)                  the SN-trees with rho <= max_order (shared, immutable; index
//                                        = position in the list, ordered by rho); sn_tree_count(n).
//   rkn_conditions(order)                descriptions of all conditions of orders 1..order, in the
//                                        fixed order used by rkn_residual_vector.
//   rkn_residuals(tableau, n)            the residuals of the conditions of order n (signed, with tree).
//   rkn_residual_vector(tableau, order)  all residuals of orders 1..order, signed, as std::vector<C>
//                                        (the function F(x) = 0 to solve by Newton's method when
//                                        refining decimal coefficients in MPFR: set a BigPrecision
//                                        guard, build the tableau in bigfloat, call this).
//   max_residual_of_order(tableau, n)    max |residual| of the conditions of order n.
//   max_residual(tableau, order)         max |residual| over all conditions of orders 1..order.
//   rkn_order(tableau, tol, max_order)   the highest p <= max_order such that every condition of
//                                        orders 1..p holds to |residual| <= tol.
//   embedded_tableau(tableau)            the tableau with (b, B) replaced by the embedded (bhat, Bhat).
//   to_rkn_tableau(scheme)               any splitting scheme (drifts/kicks in order of application)
//                                        as an RKN tableau: c_i = drift accumulated before kick i,
//                                        B_i = kick coefficient, b_i = B_i (1 - c_i),
//                                        a_ij = B_j (c_i - c_j), j < i (Gurkan eqs 2.2-2.3, 3.5).
// For many orders of one tableau use the class RknOrderConditions<C>, which keeps the stage
// weights between calls. bigfloat arithmetic runs at the MPFR default precision: hold a
// BigPrecision guard around the construction of the tableau and the calls.
// Residuals are absolute: with exact rational coefficients they are rounding-level (~1e-70 at 256
// bits); with coefficients published to d digits expect ~10^-d times the size of the coefficients.
#pragma once

#include <algorithm>
#include <complex>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "nystrom/core/bignum.hpp"
#include "nystrom/core/scalar.hpp"
#include "nystrom/methods/rkn_tableau.hpp"
#include "nystrom/methods/splitting_scheme.hpp"

namespace nystrom {

/// Largest rho supported (gamma and (rho+1) gamma fit in 64 bits far beyond; the tree count does not
/// stay small: about 75 000 trees up to rho = 18).
inline constexpr int kMaxSnOrder = 18;

/// A special Nystrom tree. `sons` lists the meagre sons of the fat root: -1 for a meagre leaf (v),
/// k >= 0 for a meagre vertex whose fat son is the tree with index k. Sorted in decreasing order.
struct SnTree {
  int order = 0;            // rho(t): number of vertices, fat and meagre
  std::uint64_t gamma = 1;  // density gamma(t)
  std::vector<int> sons;
  std::string name;  // the elementary differential, e.g. "f''(v,f)"
};

namespace sn_detail {

inline std::string derivative_name(std::size_t m) {
  // Appends rather than "literal" + std::string: GCC 12 reports false -Warray-bounds in the latter.
  std::string s = "f";
  if (m <= 3) return s.append(m, '\'');
  s += "^(";
  s += std::to_string(m);
  s += ')';
  return s;
}

/// Appends all fat trees of order n to `trees` (all trees of lower order must be present).
inline void grow(std::vector<SnTree>& trees, std::vector<std::size_t>& first, int n) {
  const int last_key = static_cast<int>(trees.size()) - 1;  // fat trees of order <= n - 1 exist
  auto weight = [&](int key) { return key < 0 ? 1 : trees[static_cast<std::size_t>(key)].order + 1; };
  std::vector<int> cur;
  std::vector<SnTree> made;
  // Multisets of meagre sons with total weight n - 1, keys in non-increasing order.
  auto rec = [&](auto&& self, int remaining, int max_key) -> void {
    if (remaining == 0) {
      SnTree t;
      t.order = n;
      t.sons = cur;
      std::uint64_t g = static_cast<std::uint64_t>(n);
      std::string args;
      for (int k : cur) {
        if (k >= 0) {
          const SnTree& u = trees[static_cast<std::size_t>(k)];
          g *= static_cast<std::uint64_t>(u.order + 1) * u.gamma;
        }
        if (!args.empty()) args += ',';
        args += k < 0 ? std::string("v") : trees[static_cast<std::size_t>(k)].name;
      }
      t.gamma = g;
      t.name = derivative_name(cur.size());
      if (!cur.empty()) {
        t.name += '(';
        t.name += args;
        t.name += ')';
      }
      made.push_back(std::move(t));
      return;
    }
    for (int key = max_key; key >= -1; --key) {
      if (weight(key) > remaining) continue;
      cur.push_back(key);
      self(self, remaining - weight(key), key);
      cur.pop_back();
    }
  };
  rec(rec, n - 1, last_key);
  first.push_back(trees.size());
  for (auto& t : made) trees.push_back(std::move(t));
}

struct Forest {
  std::vector<SnTree> trees;
  std::vector<std::size_t> first;  // first[n - 1] = index of the first tree of order n; one past the end at the back
  int max_order = 0;
};

inline std::shared_ptr<const Forest> forest(int max_order) {
  if (max_order < 0 || max_order > kMaxSnOrder)
    throw std::invalid_argument("SN-tree order must be between 0 and " + std::to_string(kMaxSnOrder) + ", got " +
                                std::to_string(max_order));
  static std::mutex mu;
  static std::shared_ptr<const Forest> cached = std::make_shared<const Forest>();
  std::lock_guard<std::mutex> lock(mu);
  if (cached->max_order >= max_order) return cached;
  auto f = std::make_shared<Forest>(*cached);
  if (!f->first.empty()) f->first.pop_back();
  for (int n = f->max_order + 1; n <= max_order; ++n) grow(f->trees, f->first, n);
  f->first.push_back(f->trees.size());
  f->max_order = max_order;
  cached = f;
  return cached;
}

}  // namespace sn_detail

/// All SN-trees with rho <= max_order, ordered by rho (the index in this list is the tree's index).
inline std::vector<SnTree> sn_trees(int max_order) {
  const auto f = sn_detail::forest(max_order);
  if (max_order == 0) return {};
  return {f->trees.begin(),
          f->trees.begin() + static_cast<std::ptrdiff_t>(f->first[static_cast<std::size_t>(max_order)])};
}

/// Number of SN-trees with rho = n (n >= 1).
inline std::size_t sn_tree_count(int n) {
  if (n < 1) throw std::invalid_argument("SN-tree order must be at least 1, got " + std::to_string(n));
  const auto f = sn_detail::forest(n);
  return f->first[static_cast<std::size_t>(n)] - f->first[static_cast<std::size_t>(n - 1)];
}

// ---- scalar helpers -----------------------------------------------------------------------------

/// 1/den as a coefficient value. Overload for further types (found by argument-dependent lookup
/// through the tag).
template <class C>
struct rkn_tag {};
template <class C>
C rkn_rational_value(rkn_tag<C>, std::uint64_t den) {
  if constexpr (is_complex_v<C>) {
    using T = typename C::value_type;
    return C(T(1) / T(static_cast<long double>(den)), T(0));
  } else if constexpr (std::is_floating_point_v<C>) {
    return C(1) / static_cast<C>(den);
  } else {
    return C(1) / C(static_cast<unsigned long long>(den));
  }
}
inline bigcomplex rkn_rational_value(rkn_tag<bigcomplex>, std::uint64_t den) {
  return bigcomplex(bigfloat(1) / bigfloat(static_cast<unsigned long long>(den)));
}

/// The real type of |x| for a coefficient type.
template <class C>
struct rkn_magnitude {
  using type = real_t<C>;
};
template <>
struct rkn_magnitude<bigcomplex> {
  using type = bigfloat;
};
template <class C>
using rkn_magnitude_t = typename rkn_magnitude<C>::type;

template <class C>
bool rkn_finite(const C& x) {
  if constexpr (std::is_same_v<C, bigcomplex>) {
    return boost::multiprecision::isfinite(x.re) && boost::multiprecision::isfinite(x.im);
  } else {
    return is_finite_scalar(x);
  }
}

template <class C>
rkn_magnitude_t<C> rkn_abs(const C& x) {
  if constexpr (std::is_same_v<C, bigcomplex>) {
    return boost::multiprecision::sqrt(x.re * x.re + x.im * x.im);
  } else {
    using std::abs;
    return abs(x);
  }
}

// ---- conditions ---------------------------------------------------------------------------------

enum class RknWeight : unsigned char { position, velocity };

/// One order condition: tree `tree` (index into sn_trees), weights b (position) or B (velocity),
/// target 1/target_den.
struct RknConditionInfo {
  int tree = 0;
  RknWeight weight = RknWeight::velocity;
  int order = 0;  // the order of the method this condition belongs to
  int rho = 0;
  std::uint64_t target_den = 1;  // the condition reads sum w_i Phi_i(t) = 1/target_den
  std::string name;              // e.g. "B: f'(v)" or "b: f"
};

template <class C>
struct RknResidual {
  RknConditionInfo info;
  C residual;  // sum w_i Phi_i(t) - 1/target_den
};

/// The conditions of order exactly n, position first, then velocity; trees in index order.
inline std::vector<RknConditionInfo> rkn_conditions_of_order(int n) {
  if (n < 1 || n > kMaxSnOrder)
    throw std::invalid_argument("RKN order must be between 1 and " + std::to_string(kMaxSnOrder) + ", got " +
                                std::to_string(n));
  const auto f = sn_detail::forest(n);
  std::vector<RknConditionInfo> out;
  auto add = [&](int rho, RknWeight w) {
    if (rho < 1) return;
    for (std::size_t k = f->first[static_cast<std::size_t>(rho - 1)]; k < f->first[static_cast<std::size_t>(rho)];
         ++k) {
      const SnTree& t = f->trees[k];
      RknConditionInfo c;
      c.tree = static_cast<int>(k);
      c.weight = w;
      c.order = n;
      c.rho = rho;
      c.target_den = w == RknWeight::position ? static_cast<std::uint64_t>(rho + 1) * t.gamma : t.gamma;
      c.name = std::string(w == RknWeight::position ? "b: " : "B: ") + t.name;
      out.push_back(std::move(c));
    }
  };
  add(n - 1, RknWeight::position);
  add(n, RknWeight::velocity);
  return out;
}

/// All conditions of orders 1..order (the order of rkn_residual_vector).
inline std::vector<RknConditionInfo> rkn_conditions(int order) {
  std::vector<RknConditionInfo> out;
  for (int n = 1; n <= order; ++n) {
    auto more = rkn_conditions_of_order(n);
    out.insert(out.end(), more.begin(), more.end());
  }
  return out;
}

/// The tableau with its embedded weights as main weights. Throws if it has none.
template <class C>
RknTableau<C> embedded_tableau(const RknTableau<C>& t) {
  if (t.bhat.empty()) throw std::invalid_argument("RKN tableau has no embedded weights");
  RknTableau<C> e = t;
  e.b = t.bhat;
  e.B = t.Bhat;
  e.bhat.clear();
  e.Bhat.clear();
  return e;
}

/// Evaluates the order conditions of one tableau; keeps the stage weights Phi(t) between calls.
template <class C>
class RknOrderConditions {
 public:
  using magnitude_type = rkn_magnitude_t<C>;

  explicit RknOrderConditions(RknTableau<C> t) : t_(std::move(t)) { t_.validate(); }

  const RknTableau<C>& tableau() const { return t_; }

  /// Residuals of the conditions of order exactly n.
  std::vector<RknResidual<C>> residuals(int n) {
    auto infos = rkn_conditions_of_order(n);
    ensure(n);
    std::vector<RknResidual<C>> out;
    out.reserve(infos.size());
    for (auto& c : infos) {
      C r = weighted(c.weight == RknWeight::position ? t_.b : t_.B, phi_[static_cast<std::size_t>(c.tree)]);
      r = r - rkn_rational_value(rkn_tag<C>{}, c.target_den);
      out.push_back({std::move(c), std::move(r)});
    }
    return out;
  }

  /// All residuals of orders 1..order, in the order of rkn_conditions(order).
  std::vector<C> residual_vector(int order) {
    std::vector<C> out;
    for (int n = 1; n <= order; ++n)
      for (auto& r : residuals(n)) out.push_back(std::move(r.residual));
    return out;
  }

  magnitude_type max_residual_of_order(int n) {
    magnitude_type m(0);
    for (const auto& r : residuals(n)) {
      const magnitude_type a = rkn_abs(r.residual);
      if (!(a <= m)) m = a;  // NaN propagates as "not satisfied"
    }
    return m;
  }

  magnitude_type max_residual(int order) {
    magnitude_type m(0);
    for (int n = 1; n <= order; ++n) {
      const magnitude_type a = max_residual_of_order(n);
      if (!(a <= m)) m = a;
    }
    return m;
  }

  /// Highest p <= max_order whose conditions (and those of all lower orders) hold to tol.
  int order(const magnitude_type& tol, int max_order = 16) {
    if (!(tol >= magnitude_type(0))) throw std::invalid_argument("order-condition tolerance must be non-negative");
    int p = 0;
    while (p < max_order && max_residual_of_order(p + 1) <= tol) ++p;
    return p;
  }

 private:
  static C weighted(const std::vector<C>& w, const std::vector<C>& phi) {
    C s(0);
    for (std::size_t i = 0; i < w.size(); ++i)
      if (!(w[i] == C(0))) s = s + w[i] * phi[i];
    return s;
  }

  // Stage weights of all trees with rho <= n, and A Phi for the trees that can be sons.
  void ensure(int n) {
    if (n <= built_) return;
    forest_ = sn_detail::forest(n);
    const auto& trees = forest_->trees;
    const std::size_t end = forest_->first[static_cast<std::size_t>(n)];
    const std::size_t s = t_.stages();
    for (std::size_t k = phi_.size(); k < end; ++k) {
      std::vector<C> p(s, C(1));
      for (int son : trees[k].sons) {
        const std::vector<C>& f = son < 0 ? t_.c : aphi(static_cast<std::size_t>(son));
        for (std::size_t i = 0; i < s; ++i) p[i] = p[i] * f[i];
      }
      phi_.push_back(std::move(p));
    }
    built_ = n;
  }

  const std::vector<C>& aphi(std::size_t k) {
    while (aphi_.size() <= k) {
      const std::size_t u = aphi_.size();
      const std::size_t s = t_.stages();
      std::vector<C> r(s, C(0));
      for (std::size_t i = 0; i < s; ++i)
        for (std::size_t j = 0; j < i; ++j)
          if (!(t_.a[i][j] == C(0))) r[i] = r[i] + t_.a[i][j] * phi_[u][j];
      aphi_.push_back(std::move(r));
    }
    return aphi_[k];
  }

  RknTableau<C> t_;
  std::shared_ptr<const sn_detail::Forest> forest_;
  std::vector<std::vector<C>> phi_;
  std::vector<std::vector<C>> aphi_;
  int built_ = 0;
};

template <class C>
std::vector<RknResidual<C>> rkn_residuals(const RknTableau<C>& t, int n) {
  return RknOrderConditions<C>(t).residuals(n);
}
template <class C>
std::vector<C> rkn_residual_vector(const RknTableau<C>& t, int order) {
  return RknOrderConditions<C>(t).residual_vector(order);
}
template <class C>
rkn_magnitude_t<C> max_residual_of_order(const RknTableau<C>& t, int n) {
  return RknOrderConditions<C>(t).max_residual_of_order(n);
}
template <class C>
rkn_magnitude_t<C> max_residual(const RknTableau<C>& t, int order) {
  return RknOrderConditions<C>(t).max_residual(order);
}
template <class C>
int rkn_order(const RknTableau<C>& t, const rkn_magnitude_t<C>& tol, int max_order = 16) {
  return RknOrderConditions<C>(t).order(tol, max_order);
}

// ---- splitting schemes as RKN tableaux ----------------------------------------------------------

/// The RKN tableau of a splitting scheme (sub-steps in order of application). Adjacent sub-steps of
/// one flow are merged first. The drifts must add up to 1 (to within drift_tolerance in magnitude:
/// published decimal tables are consistent only to their digits); the tableau takes b_i = B_i (1 - c_i).
template <class C>
RknTableau<C> to_rkn_tableau(const SplittingScheme<C>& scheme, double drift_tolerance = 1e-12) {
  const SplittingScheme<C> s = normalized(scheme);
  std::vector<C> c, B;
  C drift(0);
  for (const auto& st : s.steps) {
    if (!rkn_finite(st.coef)) throw std::invalid_argument("splitting coefficient is not finite");
    if (st.flow == Flow::drift) {
      drift = drift + st.coef;
    } else {
      c.push_back(drift);
      B.push_back(st.coef);
    }
  }
  if (B.empty()) throw std::invalid_argument("splitting scheme has no kick: it has no RKN tableau");
  const double defect = as_double(rkn_abs(C(drift - C(1))));
  if (!(defect <= drift_tolerance))
    throw std::invalid_argument("splitting scheme is not consistent: its drifts add up to 1 + " +
                                std::to_string(defect) + " (in magnitude), not 1");
  RknTableau<C> t;
  const std::size_t n = c.size();
  t.c = c;
  t.B = B;
  t.a.assign(n, std::vector<C>(n, C(0)));
  for (std::size_t i = 0; i < n; ++i) {
    t.b.push_back(B[i] * (C(1) - c[i]));
    for (std::size_t j = 0; j < i; ++j) t.a[i][j] = B[j] * (c[i] - c[j]);
  }
  return t;
}

}  // namespace nystrom
