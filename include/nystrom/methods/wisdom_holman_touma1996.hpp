// The symplectic correctors of the Wisdom-Holman map: J. Wisdom, M. Holman and J. Touma, "Symplectic
// correctors", in Integration Algorithms and Classical Mechanics, Fields Inst. Commun. 10 (1996) 217; the
// orders 3, 5, 7, 11 and 17 as used in WHFast (H. Rein and D. Tamayo, "WHFast: a fast and unbiased
// implementation of a symplectic Wisdom-Holman integrator for long-term gravitational simulations",
// MNRAS 452 (2015) 376).
//
// For H = A + eps B and the map W(h) = e^{hA/2} e^{hB} e^{hA/2}, a corrector C with C W C^{-1} = the exact flow
// of a Hamiltonian whose error is O(eps h^{n+1} + eps^2 h^2) is built from the kernels
//   X(alpha, beta) = e^{alpha h A} e^{beta h B} e^{-alpha h A},   Z(alpha, beta) = X(alpha, -beta) X(-alpha, beta),
// C = Z(alpha_1, beta_1) ... Z(alpha_m, beta_m) applied once before the first step, C^{-1} to every output
// (the run itself continues from the uncorrected state). alpha_k = k sqrt(7/40) and beta_k = r_k sqrt(10/7)
// with rational r_k. To first order in eps, Z(-alpha, -beta) Z(alpha, beta) = 1 - 2 beta (B(alpha) - B(-alpha)),
// B(a) = e^{a h A} B e^{-a h A}, an odd series in alpha; an order-n corrector (m = (n - 1) / 2 pairs,
// m = 8 for n = 17) fixes the odd moments sum_k r_k k^{2j+1} for j < m. The rationals below reproduce the
// published 50-digit values to 1e-52; the moments they share agree between the orders
// (tests/planetary/test_planetary.cpp).
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include <gmpxx.h>

#include "nystrom/methods/method.hpp"

namespace nystrom::methods {

/// The orders of the published correctors.
inline const std::vector<int>& wh_corrector_orders() {
  static const std::vector<int> orders{3, 5, 7, 11, 17};
  return orders;
}

/// The rationals r_k (k = 1..m, beta_k = r_k sqrt(10/7) pairs with alpha_k = k sqrt(7/40)) of the corrector of
/// order n, in the form C = prod over k = m..1 of Z(-alpha_k, -beta_k), then prod over k = 1..m of
/// Z(alpha_k, beta_k). Throws std::invalid_argument for an order without a published corrector.
inline std::vector<mpq_class> wh_corrector_rationals(int order) {
  auto q = [](const char* s) { return mpq_class(s); };
  switch (order) {
    case 3: return {q("1/48")};
    case 5: return {q("5/144"), q("-1/144")};
    case 7: return {q("53521/1185408"), q("-22651/1481760"), q("12361/5927040")};
    case 11:
      return {q("3394141/55883520"), q("-14556229/456382080"), q("895249/86929920"), q("-329447/167650560"),
              q("2798927/16429754880")};
    case 17:
      return {q("45815578591785473/588463175082182400"), q("-104807478104929387/1921512408431616000"),
              q("422297952838709/15567808864608000"),    q("-27170077124018711/2690117371804262400"),
              q("102433989269/36952161700608"),          q("-33737961615779/63403439739494400"),
              q("26880679644439/420330839344416000"),    q("-682938344463443/188308216026298368000")};
    default:
      throw std::invalid_argument("no symplectic corrector of order " + std::to_string(order) +
                                  " (published: 3, 5, 7, 11, 17)");
  }
}

/// The corrector C of order n as drifts (A) and kicks (B) in units of the step h, in time order, at the current
/// reference precision (BigPrecision). Its exact inverse is the reversed scheme with negated coefficients.
inline SplittingScheme<bigcomplex> wh_corrector_scheme(int order) {
  using boost::multiprecision::sqrt;
  const std::vector<mpq_class> r = wh_corrector_rationals(order);
  const bigfloat alpha1 = sqrt(bigfloat(7) / 40), sbeta = sqrt(bigfloat(10) / 7);
  const long m = static_cast<long>(r.size());
  SplittingScheme<bigcomplex> s;
  auto z = [&](const bigfloat& alpha, const bigfloat& beta) {  // Z(alpha, beta) = X(alpha, -beta) X(-alpha, beta)
    s.steps.push_back(drift(alpha));
    s.steps.push_back(kick(bigfloat(-beta)));
    s.steps.push_back(drift(bigfloat(-2 * alpha)));
    s.steps.push_back(kick(beta));
    s.steps.push_back(drift(alpha));
  };
  auto beta = [&](long k) -> bigfloat { return big(r[static_cast<std::size_t>(k - 1)].get_str()) * sbeta; };
  for (long k = m; k >= 1; --k) z(bigfloat(-alpha1 * k), bigfloat(-beta(k)));
  for (long k = 1; k <= m; ++k) z(bigfloat(alpha1 * k), beta(k));
  return normalized(s);
}

}  // namespace nystrom::methods
