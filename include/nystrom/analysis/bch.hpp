// BCH analysis of splitting methods: log(prod_i e^{a_i h T} e^{b_i h V}) in a Lie basis, the algebraic
// order of a method and its leading error coefficients (Gürkan, sec. 4 and Table 4.3).
//
// Conventions (checked by the tests against Gürkan's Table 4.3 and by symmetry):
//   * T is the drift (q += a h v), V the kick (v += b h a(q)); [A,B] = AB - BA.
//   * A splitting scheme lists its sub-steps in time order. The operator product is written as in the
//     paper, eq (3.6): the sub-step applied FIRST is the RIGHTMOST factor, e^{tZ} = ... e^{b1 tV} e^{a1 tT}.
//     operator_factors() performs this reversal.
//   * Z (per unit step) = log of that product; H = T + V. The reported error terms are the coefficients
//     of H - Z in the chosen basis, degree by degree (Table 4.3 lists H - Z in degree 6).
//   * A method has order p when the degree 1..p terms of H - Z vanish (degree 1: consistency, sum of
//     drift and of kick coefficients equal to 1). Its leading error terms are those of degree p + 1, and
//     their size is (sum_i |X_i|^2)^{1/2} over the basis elements of that degree (the paper's norm; it
//     depends on the basis: the Hall basis reproduces the paper).
//   * Arithmetic: exact rationals when every coefficient is an exact rational (recognised from its
//     high-precision value, denominators up to 10^6; not for decimal tables with a published number of digits),
//     MPFR complex numbers otherwise (precision chosen by the caller).
#pragma once

#include <algorithm>
#include <cmath>
#include <complex>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include <gmpxx.h>

#include "nystrom/analysis/coef.hpp"
#include "nystrom/analysis/lie_algebra.hpp"
#include "nystrom/methods/method.hpp"

namespace nystrom::analysis {

/// The factors of the operator product, left to right as the paper writes it (time order reversed).
template <class C>
std::vector<std::pair<int, C>> operator_factors(const SplittingScheme<C>& s) {
  std::vector<std::pair<int, C>> f;
  for (auto it = s.steps.rbegin(); it != s.steps.rend(); ++it)
    f.emplace_back(it->flow == Flow::drift ? letter_T : letter_V, it->coef);
  return f;
}

/// Coordinates of Z = log(product) per degree (coords[d], d = 1..N) in the structure's basis.
template <class K>
std::vector<std::vector<K>> bch_coordinates(const std::vector<std::pair<int, K>>& factors,
                                            const LieProjector<K>& proj) {
  return proj(log_of_product(factors, proj.structure().degree()));
}
template <class K>
std::vector<std::vector<K>> bch_coordinates(const std::vector<std::pair<int, K>>& factors, const LieStructure& s) {
  return bch_coordinates(factors, LieProjector<K>(s));
}

/// H - Z from the coordinates of Z: degree 1 gets T + V subtracted from the other side.
template <class K>
std::vector<std::vector<K>> error_terms(std::vector<std::vector<K>> z, const LieStructure& s) {
  const K one = from_rational<K>(mpq_class(1));
  for (auto& deg : z)
    for (auto& x : deg) x = K{} - x;
  // degree 1: the kept elements are the generators T (element 0) and V (element 1) in both bases
  for (std::size_t k = 0; k < z[1].size(); ++k) z[1][k] = z[1][k] + one;
  (void)s;
  return z;
}

// ---- rational recognition ----------------------------------------------------------------------------

/// The rational p/q (q <= max_den) equal to x up to rounding at the current precision, if there is one.
inline bool recognise_rational(const bigfloat& x, mpq_class& out, long max_den = 1000000000L) {
  using boost::multiprecision::abs;
  using boost::multiprecision::floor;
  const int digits = static_cast<int>(bigfloat::default_precision());
  const bigfloat tol =
      boost::multiprecision::pow(bigfloat(10), -(digits - 6)) * std::max<bigfloat>(bigfloat(1), abs(x));
  mpz_class p0 = 0, q0 = 1, p1 = 1, q1 = 0;  // continued-fraction convergents
  bigfloat r = x;
  for (int it = 0; it < 80; ++it) {
    const bigfloat a = floor(r);
    mpz_class ai;
    mpfr_get_z(ai.get_mpz_t(), a.backend().data(), MPFR_RNDN);
    const mpz_class p2 = ai * p1 + p0, q2 = ai * q1 + q0;
    if (q2 > max_den) return false;
    p0 = p1;
    q0 = q1;
    p1 = p2;
    q1 = q2;
    bigfloat num, den;
    mpfr_set_z(num.backend().data(), p1.get_mpz_t(), MPFR_RNDN);
    mpfr_set_z(den.backend().data(), q1.get_mpz_t(), MPFR_RNDN);
    if (abs(num / den - x) <= tol) {
      out = mpq_class(p1, q1);
      out.canonicalize();
      return true;
    }
    const bigfloat frac = r - a;
    if (frac == 0) return false;
    r = 1 / frac;
  }
  return false;
}

// ---- method analysis ---------------------------------------------------------------------------------

struct AnalysisOptions {
  int degree = 7;
  BasisKind basis = BasisKind::hall;
  AlgebraKind algebra = AlgebraKind::rkn;
  unsigned precision_bits = 192;  // MPFR precision when the coefficients are not all rational
  double tolerance = 0;           // 0: automatic (exact: 0; else from the published digits / precision)
};

struct ErrorTerm {
  std::string name;        // basis element, e.g. "X16"
  std::string definition;  // e.g. "[X3,X6]"
  std::string bracket;     // in T and V
  std::complex<double> value;
  std::string exact;  // the rational, when computed exactly
};

struct DegreeTerms {
  int degree = 0;
  std::vector<ErrorTerm> terms;  // coefficients of H - Z
  double norm = 0;               // (sum |X_i|^2)^{1/2}
  bool vanishes = false;         // all terms within the tolerance
};

struct MethodAnalysis {
  std::string method;
  int degree = 0;
  BasisKind basis = BasisKind::hall;
  AlgebraKind algebra = AlgebraKind::rkn;
  bool exact = false;
  unsigned precision_bits = 0;
  double tolerance = 0;
  int declared_order = 0;
  int order = 0;  // largest p with degrees 1..p vanishing (p = degree means "at least")
  bool order_is_lower_bound = false;
  std::vector<DegreeTerms> degrees;  // index d - 1 for degree d
  const DegreeTerms* leading() const { return order < degree ? &degrees[static_cast<std::size_t>(order)] : nullptr; }
  bool declared_order_confirmed() const {
    return declared_order <= 0 || (order == declared_order || (order_is_lower_bound && order >= declared_order));
  }
};

namespace detail {

/// The magnitude up to which an error coefficient of a method with decimal coefficients counts as zero:
/// 10^-(d - 4), d the decimal digits the coefficients are accurate to (the working precision or the published
/// digits, whichever is less).
inline double default_tolerance(unsigned bits, int published_digits) {
  const int prec_digits = static_cast<int>(bits * 30103u / 100000u);
  const int digits = published_digits > 0 ? std::min(published_digits, prec_digits) : prec_digits;
  return std::pow(10.0, -(digits - 4));
}

template <class K>
MethodAnalysis fill_analysis(const std::vector<std::vector<K>>& err, const LieStructure& s, double tol) {
  MethodAnalysis a;
  a.degree = s.degree();
  a.basis = s.basis();
  a.algebra = s.algebra();
  a.tolerance = tol;
  a.order = -1;
  for (int d = 1; d <= s.degree(); ++d) {
    DegreeTerms dt;
    dt.degree = d;
    double sum = 0;
    bool van = true;
    for (std::size_t k = 0; k < err[d].size(); ++k) {
      const LieElement& e = s.elements()[static_cast<std::size_t>(s.at(d).kept[k])];
      ErrorTerm t{e.name, e.definition, e.bracket, to_cd(err[d][k]), ""};
      if constexpr (std::is_same_v<K, mpq_class>) {
        t.exact = err[d][k].get_str();
        van = van && err[d][k] == 0;
      } else {
        van = van && magnitude_of(err[d][k]) <= tol;
      }
      sum += std::norm(t.value);
      dt.terms.push_back(std::move(t));
    }
    dt.norm = std::sqrt(sum);
    dt.vanishes = van;
    if (!van && a.order < 0) a.order = d - 1;
    a.degrees.push_back(std::move(dt));
  }
  if (a.order < 0) {
    a.order = s.degree();
    a.order_is_lower_bound = true;
  }
  return a;
}

}  // namespace detail

/// BCH analysis of a splitting scheme given in time order.
inline MethodAnalysis analyze_scheme(const SplittingScheme<bigcomplex>& scheme, const AnalysisOptions& opt,
                                     int published_digits = 0) {
  check_degree(opt.degree);
  if (scheme.steps.empty()) throw std::invalid_argument("splitting scheme has no sub-steps");
  const LieStructure& s = lie_structure(opt.degree, opt.basis, opt.algebra);
  const unsigned bits = std::max(64u, opt.precision_bits);
  BigPrecision guard(bits);
  // Exact rationals: only for coefficients given exactly (not a decimal table, no tolerance asked for), recognised
  // from their high-precision values with denominators up to 10^6.
  std::vector<std::pair<int, mpq_class>> qf;
  bool rational = published_digits == 0 && opt.tolerance == 0;
  for (const auto& [letter, c] : operator_factors(scheme)) {
    if (!rational) break;
    mpq_class q;
    if (!(c.im == 0) || !recognise_rational(c.re, q, 1000000L)) {
      rational = false;
      break;
    }
    qf.emplace_back(letter, q);
  }
  MethodAnalysis a;
  if (rational) {
    a = detail::fill_analysis(error_terms(bch_coordinates(qf, s), s), s, 0);
    a.exact = true;
  } else {
    std::vector<std::pair<int, bigcomplex>> f;
    for (const auto& [letter, c] : operator_factors(scheme))
      f.emplace_back(letter, bigcomplex(bigfloat(c.re), bigfloat(c.im)));
    const double tol = opt.tolerance > 0 ? opt.tolerance : detail::default_tolerance(bits, published_digits);
    a = detail::fill_analysis(error_terms(bch_coordinates(f, s), s), s, tol);
  }
  a.precision_bits = a.exact ? 0 : bits;
  return a;
}

/// BCH analysis of a catalog method (splitting methods only).
inline MethodAnalysis analyze_method(const MethodDef& def, const AnalysisOptions& opt) {
  const unsigned bits = std::max(64u, opt.precision_bits);
  SplittingScheme<bigcomplex> scheme;
  {
    BigPrecision guard(bits + 64);
    const MethodData data = def.build();
    const auto* sp = std::get_if<SplittingScheme<bigcomplex>>(&data);
    if (!sp)
      throw std::invalid_argument("the BCH analysis applies to splitting methods; '" + def.info.name + "' is a " +
                                  def.info.family + " method");
    scheme = normalized(*sp);
  }
  MethodAnalysis a = analyze_scheme(scheme, opt, def.info.published_digits);
  a.method = def.info.name;
  a.declared_order = def.info.order;
  return a;
}

// ---- Gürkan, Table 4.3 ---------------------------------------------------------------------------------

struct Table43Row {
  std::string method;
  std::vector<std::pair<std::string, std::complex<double>>> terms;  // X11, X16, X17, X19, X20 of H - Z
  double norm = 0;
  int order = 0;
};

/// Table 4.3 of the Gürkan paper computed from the catalog: the degree-6 coefficients of H - Z in the Hall
/// basis of the RKN algebra for AR1, AR2, BR1, BR2, BR3, AC1, AC2, BC1, BC2, with their norm.
/// `resolve` finds a method by name (the catalog's resolve_method).
inline std::vector<Table43Row> gurkan_table_4_3(const std::function<MethodDef(const std::string&)>& resolve) {
  std::vector<Table43Row> rows;
  for (const char* name : {"AR1", "AR2", "BR1", "BR2", "BR3", "AC1", "AC2", "BC1", "BC2"}) {
    AnalysisOptions opt;
    opt.degree = 6;
    const MethodAnalysis a = analyze_method(resolve(name), opt);
    Table43Row r;
    r.method = name;
    r.order = a.order;
    const DegreeTerms& d6 = a.degrees[5];
    for (const auto& t : d6.terms) r.terms.emplace_back(t.name, t.value);
    r.norm = d6.norm;
    rows.push_back(std::move(r));
  }
  return rows;
}

}  // namespace nystrom::analysis
