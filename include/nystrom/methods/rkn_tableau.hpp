// An explicit Runge-Kutta-Nystrom tableau as data (form (2.1) of the Gurkan paper), with an optional
// embedded pair, and the conversion between coefficient types. The engine that runs it: engines/rkn.hpp.
// A general (RKNG) tableau for y'' = f(t, y, y') also carries the velocity coefficients av of its stages
// (v_i = v_n + h sum_j av_ij f_j; Hairer, Norsett & Wanner I, sec. II.14) and the orders it was
// published with: the order conditions of y'' = f(y) (methods/rkn_order_conditions.hpp) do not decide
// them.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <vector>

namespace nystrom {

template <class C>
struct RknTableau {
  std::vector<C> c;
  std::vector<std::vector<C>> a;   // s x s, strictly lower triangular
  std::vector<C> b;                // position weights
  std::vector<C> B;                // velocity weights
  std::vector<C> bhat, Bhat;       // optional embedded pair (empty if none)
  std::vector<std::vector<C>> av;  // general (RKNG) tableaux: s x s, strictly lower triangular; else empty
  int general_order = 0;           // RKNG: the order of b, B and of bhat, Bhat for y'' = f(t, y, y')
  int general_embedded_order = 0;
  // Optional second embedded solution of lower order (DOP853's third-order weights): the step's error is then
  // Hairer's stretched estimate err^2 / sqrt(err^2 + 0.01 err_low^2), which behaves like the main solution's
  // own error (order general_order - 1 in the controller's exponent; HNW I, sec. II.10).
  std::vector<C> blow, Blow;
  // Optional rounding residuals of c, b and B (the exact values minus the stored ones), for a tableau rounded
  // from a wider one: the precise update with a compensated force uses them (engines/rkn.hpp). Empty: unknown.
  std::vector<C> c_lo, b_lo, B_lo;

  /// Whether the tableau integrates velocity-dependent forces (it has velocity coefficients).
  bool general() const { return !av.empty(); }

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
    if (!blow.empty() && (bhat.empty() || blow.size() != s || Blow.size() != s))
      throw std::invalid_argument("RKN tableau: the second embedded weights have the wrong size");
    for (const auto* r : {&c_lo, &b_lo, &B_lo})
      if (!r->empty() && r->size() != s) throw std::invalid_argument("RKN tableau: a residual has the wrong size");
    if (general()) {
      if (av.size() != s) throw std::invalid_argument("RKNG tableau: av has the wrong size");
      for (std::size_t i = 0; i < s; ++i) {
        if (av[i].size() != s) throw std::invalid_argument("RKNG tableau: av is not square");
        for (std::size_t j = i; j < s; ++j)
          if (!(av[i][j] == C(0))) throw std::invalid_argument("RKNG tableau is not explicit (av_ij != 0 for j >= i)");
      }
      if (general_order < 1) throw std::invalid_argument("RKNG tableau without its order");
    }
  }

  /// Stage 1 evaluates at q_n and the last stage at q_{n+1}: the last force is the next first.
  bool fsal() const {
    const std::size_t s = c.size();
    if (s < 2 || !(c[0] == C(0)) || !(c[s - 1] == C(1))) return false;
    for (std::size_t j = 0; j < s; ++j)
      if (!(a[s - 1][j] == b[j]) || (general() && !(av[s - 1][j] == B[j]))) return false;
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
  for (const auto& row : in.av) out.av.push_back(cv(row));
  out.blow = cv(in.blow);
  out.Blow = cv(in.Blow);
  out.general_order = in.general_order;
  out.general_embedded_order = in.general_embedded_order;
  return out;
}

}  // namespace nystrom
