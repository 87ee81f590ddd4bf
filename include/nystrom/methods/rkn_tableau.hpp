// An explicit Runge-Kutta-Nystrom tableau as data (form (2.1) of the Gurkan paper), with an optional
// embedded pair, and the conversion between coefficient types. The engine that runs it: engines/rkn.hpp.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <vector>

namespace nystrom {

template <class C>
struct RknTableau {
  std::vector<C> c;
  std::vector<std::vector<C>> a;  // s x s, strictly lower triangular
  std::vector<C> b;               // position weights
  std::vector<C> B;               // velocity weights
  std::vector<C> bhat, Bhat;      // optional embedded pair (empty if none)

  std::size_t stages() const { return c.size(); }

  void validate() const {
    const std::size_t s = c.size();
    if (s == 0) throw std::invalid_argument("RKN tableau has no stages");
    if (a.size() != s || b.size() != s || B.size() != s) throw std::invalid_argument("RKN tableau: inconsistent sizes");
    for (std::size_t i = 0; i < s; ++i) {
      if (a[i].size() != s) throw std::invalid_argument("RKN tableau: a is not square");
      for (std::size_t j = i; j < s; ++j)
        if (!(a[i][j] == C(0))) throw std::invalid_argument("RKN tableau is not explicit (a_ij != 0 for j >= i)");
    }
    if (!bhat.empty() && (bhat.size() != s || Bhat.size() != s))
      throw std::invalid_argument("RKN tableau: embedded weights have the wrong size");
  }

  /// Stage 1 evaluates at q_n and the last stage at q_{n+1}: the last force is the next first.
  bool fsal() const {
    const std::size_t s = c.size();
    if (s < 2 || !(c[0] == C(0)) || !(c[s - 1] == C(1))) return false;
    for (std::size_t j = 0; j < s; ++j)
      if (!(a[s - 1][j] == b[j])) return false;
    return true;
  }
  int forces_per_step() const { return static_cast<int>(stages()) - (fsal() ? 1 : 0); }
};

template <class COut, class CIn, class Conv>
RknTableau<COut> convert_tableau(const RknTableau<CIn>& in, Conv conv) {
  auto cv = [&](const std::vector<CIn>& x) {
    std::vector<COut> y;
    y.reserve(x.size());
    for (const auto& e : x) y.push_back(conv(e));
    return y;
  };
  RknTableau<COut> out;
  out.c = cv(in.c);
  for (const auto& row : in.a) out.a.push_back(cv(row));
  out.b = cv(in.b);
  out.B = cv(in.B);
  out.bhat = cv(in.bhat);
  out.Bhat = cv(in.Bhat);
  return out;
}

}  // namespace nystrom
