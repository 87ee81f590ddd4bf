// Helpers for writing splitting tables as the papers print them: two coefficient lists (drifts and
// kicks) that alternate in time, and the (skew-)symmetric completion of a half table.
#pragma once

#include <optional>
#include <stdexcept>
#include <vector>

#include "nystrom/methods/method.hpp"

namespace nystrom::methods {

/// Sub-steps in time order first[0], second[0], first[1], second[1], ...; `first` holds the
/// coefficients of `first_flow` and has as many entries as `second` or one more.
inline SplittingScheme<bigcomplex> alternating(Flow first_flow, const std::vector<bigcomplex>& first,
                                               const std::vector<bigcomplex>& second) {
  if (first.size() != second.size() && first.size() != second.size() + 1)
    throw std::invalid_argument("alternating splitting table: the two coefficient lists do not interleave");
  const Flow other = first_flow == Flow::drift ? Flow::kick : Flow::drift;
  SplittingScheme<bigcomplex> s;
  for (std::size_t i = 0; i < first.size(); ++i) {
    s.steps.push_back({first_flow, first[i]});
    if (i < second.size()) s.steps.push_back({other, second[i]});
  }
  return s;
}

/// The skew-symmetric completion of a half table: half, [middle], then the complex conjugates of
/// half in reverse order (reversing the full list gives its conjugate; Gürkan, Table 4.2).
inline std::vector<bigcomplex> skew_palindrome(const std::vector<bigcomplex>& half,
                                               const std::optional<bigcomplex>& middle = std::nullopt) {
  std::vector<bigcomplex> w = half;
  if (middle) w.push_back(*middle);
  for (std::size_t i = half.size(); i-- > 0;) w.push_back(half[i].conj());
  return w;
}

/// The real middle coefficient that makes a skew-symmetric list sum to `total`:
/// total - 2 Re(sum of the half).
inline bigcomplex skew_middle(const std::vector<bigcomplex>& half, const bigfloat& total) {
  bigfloat s = 0;
  for (const auto& x : half) s += x.re;
  return bigcomplex(total - 2 * s);
}

/// A list of decimal strings as reference numbers.
inline std::vector<bigcomplex> bigs(const std::vector<std::string>& xs) {
  std::vector<bigcomplex> out;
  out.reserve(xs.size());
  for (const auto& x : xs) out.push_back(big(x));
  return out;
}

}  // namespace nystrom::methods
