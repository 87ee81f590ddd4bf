// A splitting scheme as data: a sequence of sub-steps, each the flow of A ("drift", q += c h v) or of B
// ("kick", v += c h a(q)), listed in the order they are applied in time; conversions between coefficient
// types, normalisation and the adjoint. The engines that run it: engines/splitting.hpp (forces) and
// operators/flows.hpp (user-supplied flows).
#pragma once

#include <cstddef>
#include <vector>

namespace nystrom {

enum class Flow : unsigned char { drift, kick };

template <class C>
struct SubStep {
  Flow flow;
  C coef;
};

/// A splitting scheme: sub-steps in order of application.
template <class C>
struct SplittingScheme {
  std::vector<SubStep<C>> steps;

  /// Number of kicks with distinct force evaluations per step in a long run (FSAL counted).
  int forces_per_step() const {
    int kicks = 0;
    for (std::size_t i = 0; i < steps.size(); ++i)
      if (steps[i].flow == Flow::kick && (i == 0 || steps[i - 1].flow != Flow::kick)) ++kicks;
    if (steps.size() > 1 && steps.front().flow == Flow::kick && steps.back().flow == Flow::kick) --kicks;
    return kicks;
  }
  bool fsal() const { return !steps.empty() && steps.front().flow == Flow::kick && steps.back().flow == Flow::kick; }
};

/// Converts coefficients between types (e.g. from the high-precision catalog value).
template <class COut, class CIn, class Conv>
SplittingScheme<COut> convert_scheme(const SplittingScheme<CIn>& in, Conv conv) {
  SplittingScheme<COut> out;
  out.steps.reserve(in.steps.size());
  for (const auto& s : in.steps) out.steps.push_back({s.flow, conv(s.coef)});
  return out;
}

/// Merges adjacent sub-steps of the same flow and removes zero ones.
template <class C>
SplittingScheme<C> normalized(const SplittingScheme<C>& in) {
  SplittingScheme<C> out;
  for (const auto& s : in.steps) {
    if (s.coef == C(0)) continue;
    if (!out.steps.empty() && out.steps.back().flow == s.flow) {
      out.steps.back().coef += s.coef;
      if (out.steps.back().coef == C(0)) out.steps.pop_back();
    } else {
      out.steps.push_back(s);
    }
  }
  return out;
}

/// The adjoint method: sub-steps in reverse order (Φ*_h = Φ_{-h}^{-1}).
template <class C>
SplittingScheme<C> adjoint(const SplittingScheme<C>& in) {
  SplittingScheme<C> out;
  out.steps.assign(in.steps.rbegin(), in.steps.rend());
  return out;
}

}  // namespace nystrom
