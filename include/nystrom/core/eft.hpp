// Error-free transformations of the built-in floating types (Knuth's two-sum, Dekker's exact product),
// forced inline: a + b = s + e and a b = p + e exactly, s and p the rounded results. The exact product
// uses the hardware fused multiply-add where the target has it (__FMA__) and Dekker's splitting
// otherwise; both give the same e, so results do not depend on the instruction set. (Ogita, Rump and
// Oishi, "Accurate sum and dot product", SIAM J. Sci. Comput. 26 (2005) 1955.)
#pragma once

#include <cmath>
#include <limits>
#include <type_traits>

namespace nystrom::eft {

/// s = fl(a + b), e = a + b - s exactly, whatever the magnitudes of a and b.
template <class S>
[[gnu::always_inline]] inline S two_sum(S a, S b, S& e) {
  static_assert(std::is_floating_point_v<S>);
  const S s = a + b;
  const S bp = s - a;
  e = (a - (s - bp)) + (b - bp);
  return s;
}

/// s = fl(a + b), e = a + b - s exactly, for |a| >= |b| (or a = 0).
template <class S>
[[gnu::always_inline]] inline S fast_two_sum(S a, S b, S& e) {
  static_assert(std::is_floating_point_v<S>);
  const S s = a + b;
  e = b - (s - a);
  return s;
}

/// p = fl(a b), e = a b - p exactly (barring overflow and underflow).
template <class S>
[[gnu::always_inline]] inline S two_prod(S a, S b, S& e) {
  static_assert(std::is_floating_point_v<S>);
  const S p = a * b;
#if defined(__FMA__)
  if constexpr (std::is_same_v<S, double> || std::is_same_v<S, float>) {
    e = __builtin_fma(a, b, -p);
    return p;
  }
#endif
  constexpr S split = S((1ULL << ((std::numeric_limits<S>::digits + 1) / 2)) + 1);
  const S ta = split * a, ah = ta - (ta - a), al = a - ah;
  const S tb = split * b, bh = tb - (tb - b), bl = b - bh;
  e = ((ah * bh - p) + ah * bl + al * bh) + al * bl;
  return p;
}

/// (x, cx) += (p, pl): the double-word x + cx plus the double-word p + pl (|pl| small against |p|), renormalised so
/// that |cx| is at most half an ulp of x.
template <class S>
[[gnu::always_inline]] inline void add_double_word(S& x, S& cx, S p, S pl) {
  S e;
  const S s = two_sum(x, p, e);
  x = fast_two_sum(s, e + (cx + pl), cx);
}

/// 1 / (r2 + r2l)^(3/2) as the double-word m0 + ml, for r2 > 0 and |r2l| at most an ulp of r2: one square root and
/// one division in the working precision, each refined by one Newton correction in double-word (a few units of the
/// working precision squared).
template <class S>
[[gnu::always_inline]] inline S dw_inv_r3(S r2, S r2l, S& ml) {
  static_assert(std::is_floating_point_v<S>);
  using std::sqrt;
  // m0 = 1 / (r2 r0), r0 the rounded square root: the one division, a few ulps from 1 / r^3
  const S r0 = sqrt(r2);
  const S m0 = S(1) / (r2 * r0);
  // r = sqrt(r^2) = r1 + r1l: one Newton correction of r0, the division by 2 r0 as a product with r2 m0 ~ 1 / r0
  S er;
  const S sq = two_prod(r0, r0, er);
  S r1l;
  const S r1 = fast_two_sum(r0, (((r2 - sq) - er) + r2l) * (S(0.5) * r2 * m0), r1l);
  // r^3 = r^2 r = r3 + r3l
  S ep;
  const S p = two_prod(r2, r1, ep);
  S r3l;
  const S r3 = fast_two_sum(p, ep + (r2 * r1l + r2l * r1), r3l);
  // m = 1 / r^3 = m0 + ml: one Newton correction of m0
  S em;
  const S pm = two_prod(m0, r3, em);
  ml = m0 * (((S(1) - pm) - em) - m0 * r3l);
  return m0;
}

}  // namespace nystrom::eft
