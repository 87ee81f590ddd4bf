// Splittings of Langevin dynamics as data: a string over the three flows
//   A  drift                 q += tau v
//   B  kick                  v += tau a(q)
//   O  Ornstein-Uhlenbeck    v  = e^{-gamma tau} v + sqrt(kT/m (1 - e^{-2 gamma tau})) xi   (exact in law)
// read left to right as the order in which they act during one step h. Each letter's occurrences share the
// step equally: in BAOAB both B and both A take h/2 and O takes h; in OBABO the O's and B's take h/2, A takes
// h. This is the notation of B. Leimkuhler and C. Matthews, "Rational construction of stochastic numerical
// methods for molecular sampling", Appl. Math. Res. Express 2013 (1), 34-56. OpenMM's letters are accepted
// too: R (drift) for A and V (kick) for B (so "VRORV" is BAOAB).
#pragma once

#include <algorithm>
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "nystrom/core/error.hpp"

namespace nystrom::stochastic {

enum class Flow : unsigned char { drift, kick, ou };

struct Stage {
  Flow flow;
  double fraction;  // of the step h
};

struct LangevinSplitting {
  std::string name;  // canonical letters A, B, O
  std::vector<Stage> stages;
  int ou_stages = 0;       // O letters per step: each takes h / ou_stages
  bool symmetric = false;  // the string reads the same backwards: the weak error is even in h
};

/// The weak order of the multi-product combination of `members` runs of the splitting: 2 per member for a symmetric
/// splitting (its weak error is even in h), 1 for any other (which check_extrapolation admits with one member only).
inline int weak_order(const LangevinSplitting& s, std::size_t members) {
  return s.symmetric ? 2 * static_cast<int>(members) : 1;
}

/// Most letters in a splitting string.
inline constexpr std::size_t max_splitting_letters = 64;

/// Parses and validates a splitting string; throws nystrom::invalid_input with one line otherwise.
inline LangevinSplitting parse_langevin_splitting(std::string_view text) {
  const auto quoted = [&] { return "'" + std::string(text.substr(0, 40)) + (text.size() > 40 ? "...'" : "'"); };
  if (text.empty())
    throw invalid_input("empty Langevin splitting: give letters A (drift), B (kick), O (noise), e.g. BAOAB");
  if (text.size() > max_splitting_letters)
    throw invalid_input("Langevin splitting " + quoted() + " has more than " + std::to_string(max_splitting_letters) +
                        " letters");
  LangevinSplitting s;
  for (const char ch : text) {
    switch (ch) {
      case 'A':
      case 'R': s.name += 'A'; break;
      case 'B':
      case 'V': s.name += 'B'; break;
      case 'O': s.name += 'O'; break;
      default:
        throw invalid_input("Langevin splitting " + quoted() + ": '" +
                            std::string(1, (ch >= 32 && ch < 127) ? ch : '?') +
                            "' is not A (drift), B (kick) or O (Ornstein-Uhlenbeck) (also R = A, V = B)");
    }
  }
  const auto count = [&](char c) { return static_cast<int>(std::count(s.name.begin(), s.name.end(), c)); };
  const int na = count('A'), nb = count('B'), no = count('O');
  for (const auto& [n, letter] : {std::pair{na, "A (drift)"}, std::pair{nb, "B (kick)"}, std::pair{no, "O (noise)"}})
    if (n == 0) throw invalid_input("Langevin splitting " + quoted() + " has no " + letter + ": it needs A, B and O");
  for (const char c : s.name) {
    const Flow f = c == 'A' ? Flow::drift : c == 'B' ? Flow::kick : Flow::ou;
    const int n = c == 'A' ? na : c == 'B' ? nb : no;
    s.stages.push_back({f, 1.0 / n});
  }
  s.ou_stages = no;
  s.symmetric = std::equal(s.name.begin(), s.name.end(), s.name.rbegin());
  return s;
}

}  // namespace nystrom::stochastic
