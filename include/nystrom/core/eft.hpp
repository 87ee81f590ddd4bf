// Error-free transformations of the built-in floating types (Knuth's two-sum, Dekker's exact product),
// forced inline: a + b = s + e and a b = p + e exactly, s and p the rounded results. The exact product
// uses the hardware fused multiply-add where the target has it (__FMA__) and Dekker's splitting
// otherwise; both give the same e, so results do not depend on the instruction set. (Ogita, Rump and
// Oishi, "Accurate sum and dot product", SIAM J. Sci. Comput. 26 (2005) 1955.)
#pragma once

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

}  // namespace nystrom::eft
