// Coefficients exact to the working precision for methods published only as decimals.
//
// A table printed with d digits is good for a working type of about d * log2(10) bits. For wider
// types the coefficients are refined: Newton's method in MPFR on the method's own order conditions,
// starting from the published digits, at the reference precision of the working type
// (reference_bits()). Refined sets are cached per (method, precision).
//
// What is solved. Every splitting scheme for q'' = a(q) is an RKN method (to_rkn_tableau, Gürkan eqs
// 2.2-2.3); its order conditions (analysis/rkn_order_conditions.hpp: special Nyström trees) up to the
// declared order, together with consistency (the drifts and the kicks each add up to 1), are the
// equations F(p) = 0. The unknowns p are the free coefficients, found from the published table:
//   * a composition of a symmetric leapfrog (the outer flow's coefficients are the half-sums of
//     adjacent weights, as compose() makes them) is parametrised by its weights and stays one;
//   * pairs of coefficients placed symmetrically that are equal (symmetric methods) stay equal, and
//     pairs that are complex conjugates (Gürkan's skew-symmetric methods) stay conjugate;
//   * real coefficients stay real; complex ones contribute their real and imaginary parts.
// The Jacobian is exact (forward-mode dual numbers through the same order-condition code). The
// conditions are redundant (for compositions highly so) and some methods have free parameters (a
// family of solutions, e.g. Kahan-Li, Sofroniou-Spaletta, Blanes-Moan, Gürkan's optimised ones): a
// maximal set of independent equations is chosen once at the published point (greedy pivoting, with
// a threshold of sqrt(|F|) relative to the largest row: directions that the published digits cannot
// resolve are not equations). The result is the solution in the affine space through the published
// point spanned by those equations' gradients there, i.e. the solution nearest to the published table
// to first order, the same whatever the working precision. It is reached by chord steps (minimum-norm
// corrections with the Jacobian of the published point; each gains about as many digits as the table
// has) and, when many digits are still missing, Newton steps within that affine space (quadratic).
// It differs from the table by about the table's rounding and satisfies every condition (including
// those not selected) to the reference precision, which is checked before it is used.
//
// Methods that are neither exact nor refinable (e.g. an RKN tableau printed in decimals), asked for in
// a precision their digits cannot reach, are refused with std::invalid_argument.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "nystrom/core/bignum.hpp"
#include "nystrom/methods/method.hpp"
#include "nystrom/methods/rkn_order_conditions.hpp"

namespace nystrom {

// ---- when is a published table good enough ----------------------------------------------------

/// True when a table of `digits` significant digits (0: exact) is accurate to a working type of
/// `bits` bits: its rounding (half a unit of the last digit) is within 16 ulps of the type.
inline bool published_digits_suffice(int digits, long bits) {
  if (digits <= 0) return true;
  return static_cast<double>(digits) * std::log2(10.0) >= static_cast<double>(bits) - 4.0;
}

namespace refine_detail {

// ---- forward-mode dual numbers over bigfloat or bigcomplex -------------------------------------

inline bigfloat zero_of(const bigfloat*) { return bigfloat(0); }
inline bigcomplex zero_of(const bigcomplex*) { return bigcomplex(bigfloat(0)); }
inline bool is_zero(const bigfloat& x) { return x == 0; }
inline bool is_zero(const bigcomplex& x) { return x.re == 0 && x.im == 0; }

/// A value and its derivatives with respect to the real parameters (an empty list: all zero).
template <class V>
struct Dual {
  V v;
  std::vector<V> d;

  Dual() : v(zero_of(static_cast<const V*>(nullptr))) {}
  Dual(int x) : v(V(bigfloat(x))) {}  // NOLINT: constants in the order-condition code (C(0), C(1))
  explicit Dual(V x) : v(std::move(x)) {}
  Dual(V x, std::vector<V> dx) : v(std::move(x)), d(std::move(dx)) {}

  friend Dual operator+(const Dual& a, const Dual& b) { return combine(a, b, a.v + b.v, 1); }
  friend Dual operator-(const Dual& a, const Dual& b) { return combine(a, b, a.v - b.v, -1); }
  friend Dual operator*(const Dual& a, const Dual& b) {
    Dual r(a.v * b.v);
    const std::size_t n = std::max(a.d.size(), b.d.size());
    if (n == 0) return r;
    r.d.assign(n, zero_of(static_cast<const V*>(nullptr)));
    for (std::size_t k = 0; k < a.d.size(); ++k) r.d[k] = r.d[k] + b.v * a.d[k];
    for (std::size_t k = 0; k < b.d.size(); ++k) r.d[k] = r.d[k] + a.v * b.d[k];
    return r;
  }
  /// Equal values and equal derivatives: a coefficient that is zero but moves is not zero.
  friend bool operator==(const Dual& a, const Dual& b) {
    if (!(a.v == b.v)) return false;
    const std::size_t n = std::max(a.d.size(), b.d.size());
    for (std::size_t k = 0; k < n; ++k) {
      const bool za = k >= a.d.size() || is_zero(a.d[k]);
      const bool zb = k >= b.d.size() || is_zero(b.d[k]);
      if (za != zb) return false;
      if (!za && !(a.d[k] == b.d[k])) return false;
    }
    return true;
  }

 private:
  static Dual combine(const Dual& a, const Dual& b, V value, int sign) {
    Dual r(std::move(value));
    const std::size_t n = std::max(a.d.size(), b.d.size());
    if (n == 0) return r;
    r.d.assign(n, zero_of(static_cast<const V*>(nullptr)));
    for (std::size_t k = 0; k < a.d.size(); ++k) r.d[k] = a.d[k];
    for (std::size_t k = 0; k < b.d.size(); ++k) r.d[k] = sign > 0 ? r.d[k] + b.d[k] : r.d[k] - b.d[k];
    return r;
  }
};

/// 1/den for the order-condition targets (found by argument-dependent lookup).
template <class V>
Dual<V> rkn_rational_value(rkn_tag<Dual<V>>, std::uint64_t den) {
  return Dual<V>(V(bigfloat(1) / bigfloat(static_cast<unsigned long long>(den))));
}

// ---- the parametrisation ----------------------------------------------------------------------

/// One coefficient as a linear function of the real parameters: sum over terms of factor * p[index]
/// (factor 1, i, -i, or halves of them for the outer flow of a composition).
struct LinearCoef {
  std::vector<std::pair<std::size_t, bigcomplex>> terms;
};

struct Parametrization {
  std::vector<Flow> flows;         // normalized scheme, time order
  std::vector<LinearCoef> coefs;   // one per sub-step
  std::vector<bigfloat> start;     // the published parameters
  bool complex = false;            // some coefficient is complex
  bool composition = false;        // parametrised by composition weights
  std::vector<std::string> names;  // "w3", "re b2", ... for messages
};

inline bool close(const bigcomplex& a, const bigcomplex& b, const bigfloat& tol) {
  using boost::multiprecision::abs;
  return abs(a.re - b.re) <= tol && abs(a.im - b.im) <= tol;
}

/// Finds the free parameters of a splitting scheme (see the top of the file).
inline Parametrization parametrize(const SplittingScheme<bigcomplex>& published) {
  using boost::multiprecision::abs;
  const SplittingScheme<bigcomplex> s = normalized(published);
  const std::size_t m = s.steps.size();
  if (m == 0) throw std::invalid_argument("splitting scheme has no sub-steps");
  bigfloat scale(1);
  for (const auto& st : s.steps) scale = std::max(scale, bigfloat(abs(st.coef.re) + abs(st.coef.im)));
  const long prec = static_cast<long>(boost::multiprecision::detail::digits10_2_2(bigfloat::default_precision()));
  const bigfloat tol = ldexp(scale, static_cast<int>(16 - prec));  // rounding of the half-sums, and more

  Parametrization p;
  for (const auto& st : s.steps) p.flows.push_back(st.flow);
  p.coefs.resize(m);
  p.complex = std::any_of(s.steps.begin(), s.steps.end(), [](const auto& x) { return !x.coef.is_real(); });

  // Composition of a symmetric leapfrog: odd length, outer flow at both ends, outer = half-sums.
  std::vector<std::size_t> slot_steps;  // the sub-steps that carry the free values
  if (m >= 3 && m % 2 == 1 && s.steps.front().flow == s.steps.back().flow) {
    bool comp = true;
    const bigcomplex half(big("1/2"));
    for (std::size_t k = 0; k < m && comp; k += 2) {
      bigcomplex expect(bigfloat(0));
      if (k >= 1) expect = expect + s.steps[k - 1].coef;
      if (k + 1 < m) expect = expect + s.steps[k + 1].coef;
      comp = close(s.steps[k].coef, expect * half, tol);
    }
    p.composition = comp;
  }
  for (std::size_t k = 0; k < m; ++k)
    if (!p.composition || k % 2 == 1) slot_steps.push_back(k);

  // Ties between symmetric slots; real slots get one parameter, complex ones two.
  const std::size_t n = slot_steps.size();
  std::vector<LinearCoef> slot(n);
  const bigcomplex one(bigfloat(1)), i_unit(bigfloat(0), bigfloat(1));
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t mirror = n - 1 - k;
    const bigcomplex& z = s.steps[slot_steps[k]].coef;
    if (mirror < k) {
      const bigcomplex& zm = s.steps[slot_steps[mirror]].coef;
      if (close(z, zm, tol)) {
        slot[k] = slot[mirror];
        continue;
      }
      if (close(z, zm.conj(), tol)) {
        slot[k] = slot[mirror];
        for (auto& [idx, f] : slot[k].terms) f = f.conj();
        continue;
      }
    }
    const std::string label =
        (p.composition ? "w" : (s.steps[slot_steps[k]].flow == Flow::drift ? "a" : "b")) + std::to_string(k + 1);
    slot[k].terms.push_back({p.start.size(), one});
    p.start.push_back(z.re);
    p.names.push_back(z.is_real() ? label : "re " + label);
    if (!z.is_real()) {
      slot[k].terms.push_back({p.start.size(), i_unit});
      p.start.push_back(z.im);
      p.names.push_back("im " + label);
    }
  }
  for (std::size_t k = 0; k < n; ++k) p.coefs[slot_steps[k]] = slot[k];
  if (p.composition) {
    const bigcomplex half(big("1/2"));
    for (std::size_t k = 0; k < m; k += 2) {
      LinearCoef c;
      auto add_half_of = [&](std::size_t nb) {
        for (const auto& [idx, f] : p.coefs[nb].terms) c.terms.push_back({idx, f * half});
      };
      if (k >= 1) add_half_of(k - 1);
      if (k + 1 < m) add_half_of(k + 1);
      p.coefs[k] = c;
    }
  }
  return p;
}

/// The scheme at parameters x (plain values).
inline SplittingScheme<bigcomplex> scheme_at(const Parametrization& p, const std::vector<bigfloat>& x) {
  SplittingScheme<bigcomplex> s;
  for (std::size_t k = 0; k < p.flows.size(); ++k) {
    bigcomplex c(bigfloat(0));
    for (const auto& [idx, f] : p.coefs[k].terms) c = c + f * bigcomplex(x[idx]);
    if (!p.complex) c.im = 0;
    s.steps.push_back({p.flows[k], c});
  }
  return s;
}

template <class V>
V to_value(const bigcomplex& z) {
  if constexpr (std::is_same_v<V, bigfloat>) {
    return z.re;
  } else {
    return z;
  }
}

/// The residuals F(x) (consistency, then the RKN order conditions up to `order`) with their
/// derivatives, as real rows: value and gradient.
/// (With jac == nullptr only the values: the dual numbers then carry no derivatives.)
template <class V>
void residual_rows(const Parametrization& p, const std::vector<bigfloat>& x, int order, std::vector<bigfloat>& f,
                   std::vector<std::vector<bigfloat>>* jac) {
  using D = Dual<V>;
  const std::size_t n = x.size();
  std::vector<D> coef;
  for (std::size_t k = 0; k < p.flows.size(); ++k) {
    D c;
    if (jac) c.d.assign(n, zero_of(static_cast<const V*>(nullptr)));
    for (const auto& [idx, fac] : p.coefs[k].terms) {
      const V fv = to_value<V>(fac);
      c.v = c.v + fv * V(x[idx]);
      if (jac) c.d[idx] = c.d[idx] + fv;
    }
    coef.push_back(std::move(c));
  }
  // Splitting -> RKN tableau (Gürkan eqs 2.2-2.3): c_i = drift before kick i, B_i = kick i,
  // b_i = B_i (1 - c_i), a_ij = B_j (c_i - c_j).
  D drift_sum, kick_sum;
  std::vector<D> c, B;
  for (std::size_t k = 0; k < coef.size(); ++k) {
    if (p.flows[k] == Flow::drift) {
      drift_sum = drift_sum + coef[k];
    } else {
      c.push_back(drift_sum);
      B.push_back(coef[k]);
      kick_sum = kick_sum + coef[k];
    }
  }
  if (B.empty()) throw std::invalid_argument("splitting scheme has no kick");
  RknTableau<D> t;
  const std::size_t s = c.size();
  t.c = c;
  t.B = B;
  t.a.assign(s, std::vector<D>(s, D(0)));
  for (std::size_t i = 0; i < s; ++i) {
    t.b.push_back(B[i] * (D(1) - c[i]));
    for (std::size_t j = 0; j < i; ++j) t.a[i][j] = B[j] * (c[i] - c[j]);
  }
  std::vector<D> res{drift_sum - D(1), kick_sum - D(1)};
  for (auto& r : RknOrderConditions<D>(t).residual_vector(order)) res.push_back(std::move(r));

  f.clear();
  if (jac) jac->clear();
  auto push = [&](const D& r, auto part) {
    f.push_back(part(r.v));
    if (!jac) return;
    std::vector<bigfloat> g(n, bigfloat(0));
    for (std::size_t k = 0; k < r.d.size(); ++k) g[k] = part(r.d[k]);
    jac->push_back(std::move(g));
  };
  for (const auto& r : res) {
    if constexpr (std::is_same_v<V, bigfloat>) {
      push(r, [](const bigfloat& z) { return z; });
    } else {
      push(r, [](const bigcomplex& z) { return z.re; });
      push(r, [](const bigcomplex& z) { return z.im; });
    }
  }
}

inline bigfloat dot(const std::vector<bigfloat>& a, const std::vector<bigfloat>& b) {
  bigfloat s(0);
  for (std::size_t k = 0; k < a.size(); ++k) s += a[k] * b[k];
  return s;
}
inline bigfloat norm(const std::vector<bigfloat>& a) { return boost::multiprecision::sqrt(dot(a, a)); }
inline bigfloat max_abs(const std::vector<bigfloat>& a) {
  bigfloat m(0);
  for (const auto& x : a) m = std::max(m, bigfloat(boost::multiprecision::abs(x)));
  return m;
}

/// Greedy choice of independent rows of J (largest remaining component first, Gram-Schmidt with
/// re-orthogonalisation) until the remaining components fall below rel_tol times the largest row.
inline std::vector<std::size_t> independent_rows(const std::vector<std::vector<bigfloat>>& jac,
                                                 const bigfloat& rel_tol) {
  std::vector<std::vector<bigfloat>> rest = jac;
  std::vector<std::vector<bigfloat>> basis;
  std::vector<std::size_t> chosen;
  bigfloat largest(0);
  for (const auto& r : jac) largest = std::max(largest, norm(r));
  if (largest == 0) return chosen;
  const std::size_t n = jac.empty() ? 0 : jac.front().size();
  while (chosen.size() < n) {
    std::size_t best = 0;
    bigfloat best_norm(-1);
    for (std::size_t i = 0; i < rest.size(); ++i) {
      const bigfloat r = norm(rest[i]);
      if (r > best_norm) {
        best_norm = r;
        best = i;
      }
    }
    if (!(best_norm > rel_tol * largest)) break;
    std::vector<bigfloat> q = rest[best];
    for (int pass = 0; pass < 2; ++pass)
      for (const auto& b : basis) {
        const bigfloat c = dot(q, b);
        for (std::size_t k = 0; k < n; ++k) q[k] -= c * b[k];
      }
    const bigfloat qn = norm(q);
    for (auto& x : q) x /= qn;
    for (auto& r : rest) {
      const bigfloat c = dot(r, q);
      for (std::size_t k = 0; k < n; ++k) r[k] -= c * q[k];
    }
    basis.push_back(std::move(q));
    chosen.push_back(best);
  }
  std::sort(chosen.begin(), chosen.end());
  return chosen;
}

/// Minimum-norm solutions of A x = b for A with independent rows (r x n, r <= n): A^T = Q R
/// (Gram-Schmidt with re-orthogonalisation), then R^T z = b and x = Q z.
class MinNormSolver {
 public:
  explicit MinNormSolver(const std::vector<std::vector<bigfloat>>& a) {
    const std::size_t r = a.size();
    n_ = r ? a.front().size() : 0;
    R_.assign(r, std::vector<bigfloat>(r, bigfloat(0)));
    for (std::size_t j = 0; j < r; ++j) {
      std::vector<bigfloat> v = a[j];
      for (int pass = 0; pass < 2; ++pass)
        for (std::size_t i = 0; i < j; ++i) {
          const bigfloat c = dot(v, q_[i]);
          R_[i][j] += c;
          for (std::size_t k = 0; k < n_; ++k) v[k] -= c * q_[i][k];
        }
      R_[j][j] = norm(v);
      if (R_[j][j] == 0) throw std::runtime_error("dependent order conditions");
      for (auto& x : v) x /= R_[j][j];
      q_.push_back(std::move(v));
    }
  }
  std::vector<bigfloat> solve(const std::vector<bigfloat>& b) const {
    const std::size_t r = q_.size();
    std::vector<bigfloat> z(r, bigfloat(0));
    for (std::size_t j = 0; j < r; ++j) {  // R^T z = b: forward substitution
      bigfloat s = b[j];
      for (std::size_t i = 0; i < j; ++i) s -= R_[i][j] * z[i];
      z[j] = s / R_[j][j];
    }
    std::vector<bigfloat> x(n_, bigfloat(0));
    for (std::size_t j = 0; j < r; ++j)
      for (std::size_t k = 0; k < n_; ++k) x[k] += z[j] * q_[j][k];
    return x;
  }

  /// The orthonormal basis of the row space of A (r vectors of length n).
  const std::vector<std::vector<bigfloat>>& basis() const { return q_; }

 private:
  std::size_t n_ = 0;
  std::vector<std::vector<bigfloat>> q_;
  std::vector<std::vector<bigfloat>> R_;
};

/// Solves the square system M x = b by Gaussian elimination with partial pivoting.
inline std::vector<bigfloat> solve_square(std::vector<std::vector<bigfloat>> m, std::vector<bigfloat> b) {
  const std::size_t r = b.size();
  for (std::size_t c = 0; c < r; ++c) {
    std::size_t piv = c;
    for (std::size_t i = c + 1; i < r; ++i)
      if (abs(m[i][c]) > abs(m[piv][c])) piv = i;
    if (m[piv][c] == 0) throw std::runtime_error("singular Newton matrix");
    std::swap(m[piv], m[c]);
    std::swap(b[piv], b[c]);
    for (std::size_t i = c + 1; i < r; ++i) {
      const bigfloat f = m[i][c] / m[c][c];
      if (f == 0) continue;
      for (std::size_t k = c; k < r; ++k) m[i][k] -= f * m[c][k];
      b[i] -= f * b[c];
    }
  }
  std::vector<bigfloat> x(r, bigfloat(0));
  for (std::size_t c = r; c-- > 0;) {
    bigfloat s = b[c];
    for (std::size_t k = c + 1; k < r; ++k) s -= m[c][k] * x[k];
    x[c] = s / m[c][c];
  }
  return x;
}

}  // namespace refine_detail

/// The outcome of a refinement (for tests and reports).
struct Refinement {
  SplittingScheme<bigcomplex> scheme;   // the refined scheme (normalized), at the current precision
  std::vector<std::string> parameters;  // names of the free parameters
  std::vector<bigfloat> published;      // their published values
  std::vector<bigfloat> refined;        // and the refined ones
  std::size_t equations = 0;            // real equations (consistency + order conditions)
  std::size_t independent = 0;          // of which independent at the published point
  int iterations = 0;
  bigfloat residual;            // max |F| over all equations at the refined point
  bigfloat published_residual;  // and at the published point
  bool composition = false;     // parametrised by composition weights
};

inline std::string short_str(const bigfloat& x) { return x.str(3, std::ios_base::scientific); }

/// How refine_splitting reaches its solution (the same point in every case): chord steps, Newton
/// steps, or chord first and Newton when that is cheaper (the default).
enum class RefineStrategy { automatic, chord, newton };

/// Refines a splitting scheme of order `order` at the current MPFR default precision (hold a
/// BigPrecision). Throws std::invalid_argument if the published table is not close to a solution or
/// Newton's method does not reach the precision.
inline Refinement refine_splitting(const SplittingScheme<bigcomplex>& published, int order, const std::string& name,
                                   RefineStrategy strategy = RefineStrategy::automatic) {
  using namespace refine_detail;
  const long prec = static_cast<long>(boost::multiprecision::detail::digits10_2_2(bigfloat::default_precision()));
  const std::string what = "cannot refine the coefficients of " + name + " to " + std::to_string(prec) + " bits: ";
  if (order < 1 || order > kMaxSnOrder)
    throw std::invalid_argument(what + "order " + std::to_string(order) + " is outside the order conditions available");
  const Parametrization p = parametrize(published);
  Refinement out;
  out.parameters = p.names;
  out.published = p.start;
  out.composition = p.composition;
  std::vector<bigfloat> x = p.start, f;
  std::vector<std::vector<bigfloat>> jac;
  enum class Jacobian : bool { skip, compute };
  auto evaluate = [&](const std::vector<bigfloat>& at, Jacobian jacobian) {
    std::vector<std::vector<bigfloat>>* const j = jacobian == Jacobian::compute ? &jac : nullptr;
    if (p.complex)
      residual_rows<bigcomplex>(p, at, order, f, j);
    else
      residual_rows<bigfloat>(p, at, order, f, j);
  };
  evaluate(x, Jacobian::compute);
  out.equations = f.size();
  out.published_residual = max_abs(f);
  if (!(out.published_residual < bigfloat("1e-8")))
    throw std::invalid_argument(what + "the published table misses its order-" + std::to_string(order) +
                                " conditions by " + short_str(out.published_residual));
  const bigfloat eps = ldexp(bigfloat(1), static_cast<int>(-prec));
  // Directions the published digits cannot resolve are not equations: threshold sqrt(|F|).
  const bigfloat rel_tol = boost::multiprecision::sqrt(std::max(out.published_residual, eps));
  const std::vector<std::size_t> rows = independent_rows(jac, rel_tol);
  out.independent = rows.size();
  const bigfloat target = ldexp(bigfloat(1), static_cast<int>(32 - prec));
  // The solution sought: x = x0 + Q^T z on the solution manifold, Q an orthonormal basis of the rows
  // of the selected equations' Jacobian J0 at the published point x0 (the nearest solution to first
  // order; a definition independent of the working precision). Two ways to the same point:
  //   * chord steps  dx = -J0^+ F(x)  (one Jacobian for all; each step gains about as many digits as
  //     the table has, as J(x) - J0 = O(|x - x0|) = O(10^-digits));
  //   * Newton steps in z: (J(x) Q^T) dz = -F(x), quadratic, each with a fresh Jacobian,
  // chord while few steps remain, Newton when many digits are still missing (very high precision).
  std::optional<MinNormSolver> chord;
  try {
    std::vector<std::vector<bigfloat>> a;
    for (const std::size_t r : rows) a.push_back(jac[r]);
    if (!rows.empty()) chord.emplace(a);
  } catch (const std::runtime_error&) {
    throw std::invalid_argument(what + "the selected order conditions are dependent");
  }
  auto selected_max = [&] {
    bigfloat m(0);
    for (const std::size_t r : rows) m = std::max(m, bigfloat(boost::multiprecision::abs(f[r])));
    return m;
  };
  bool newton = strategy == RefineStrategy::newton;
  bigfloat last = selected_max();
  const int max_iterations = 50 + static_cast<int>(prec / 8);  // chord steps gain >= 8 bits, or Newton takes over
  for (int it = 1; it <= max_iterations && chord; ++it) {
    std::vector<bigfloat> b;
    for (const std::size_t r : rows) b.push_back(-f[r]);
    std::vector<bigfloat> dx;
    if (!newton) {
      dx = chord->solve(b);
    } else {
      const auto& q = chord->basis();
      std::vector<std::vector<bigfloat>> m(rows.size(), std::vector<bigfloat>(q.size(), bigfloat(0)));
      for (std::size_t i = 0; i < rows.size(); ++i)
        for (std::size_t j = 0; j < q.size(); ++j) m[i][j] = dot(jac[rows[i]], q[j]);
      std::vector<bigfloat> dz;
      try {
        dz = solve_square(std::move(m), std::move(b));
      } catch (const std::runtime_error&) {
        throw std::invalid_argument(what + "the Newton matrix became singular");
      }
      dx.assign(x.size(), bigfloat(0));
      for (std::size_t j = 0; j < q.size(); ++j)
        for (std::size_t k = 0; k < x.size(); ++k) dx[k] += dz[j] * q[j][k];
    }
    for (std::size_t k = 0; k < x.size(); ++k) x[k] += dx[k];
    out.iterations = it;
    bigfloat size(1);
    for (const auto& v : x) size = std::max(size, bigfloat(boost::multiprecision::abs(v)));
    const bool tiny_step = max_abs(dx) <= ldexp(size, static_cast<int>(8 - prec));
    evaluate(x, newton ? Jacobian::compute : Jacobian::skip);
    const bigfloat now = selected_max();
    if (tiny_step || now == 0) break;                  // converged to rounding
    if (max_abs(f) <= target && !(now < last)) break;  // no further progress
    if (!newton && strategy == RefineStrategy::automatic) {
      // Cost model, in residual evaluations: the chord needs missing / per_step more of them; Newton
      // doubles the correct bits per step, each step a Jacobian (measured: worth about 2 (parameters
      // + 1) evaluations).
      const double per_step = static_cast<double>(log2(last / now));
      const double have = std::max(1.0, -static_cast<double>(log2(now)));
      const double want = static_cast<double>(-log2(target));
      const double chord_cost = (want - have) / std::max(per_step, 1e-3);
      const double newton_cost =
          2.0 * static_cast<double>(x.size() + 1) * std::ceil(std::log2(std::max(2.0, want / have)));
      if (!(per_step > 1) || newton_cost < chord_cost) {
        newton = true;
        evaluate(x, Jacobian::compute);
      }
    }
    last = now;
  }
  out.residual = max_abs(f);
  if (!(out.residual <= target))
    throw std::invalid_argument(what + "Newton's method stopped at residual " + short_str(out.residual) +
                                " (published table: " + short_str(out.published_residual) + ")");
  out.refined = x;
  out.scheme = scheme_at(p, x);
  return out;
}

}  // namespace nystrom

// method_data_for (declared there; defined in lib/method_data.cpp) uses the refinement above.
#include "nystrom/methods/method_data.hpp"
