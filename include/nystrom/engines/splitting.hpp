// The splitting engine: executes any product of exponentials e^{a_1 h A} e^{b_1 h B} ... .
//
// A splitting scheme is data: a sequence of sub-steps, each the flow of A ("drift",
// q += c h v) or of B ("kick", v += c h a(q)), listed IN THE ORDER THEY ARE APPLIED in time.
// (Operator products in the papers are often written right-to-left; the catalog converts.)
//
// The engine
//   * caches the last force together with the position it was evaluated at, so a kick that
//     follows a kick, or the first kick of a step that starts where the last one ended
//     (first-same-as-last), costs no new force evaluation; the count is exact;
//   * in integrate(), merges the last sub-step of a step with the first of the next when
//     they are of the same flow (drift ... drift, kick ... kick);
//   * works for real or complex coefficients: the state scalar is the coefficient type.
//     With complex coefficients the imaginary parts of q and v are dropped after each step
//     (Gürkan, sec. 5) unless keep_complex is set.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "nystrom/core/state.hpp"

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

template <class V, class Force>
class SplittingStepper {
 public:
  using vector_type = V;
  using scalar_type = typename V::value_type;
  using real_type = real_t<scalar_type>;

  SplittingStepper(SplittingScheme<scalar_type> scheme, Force force, EngineOptions opt = {})
      : scheme_(normalized(scheme)), force_(std::move(force)), opt_(opt) {
    if (scheme_.steps.empty()) throw std::invalid_argument("splitting scheme has no sub-steps");
    for (const auto& s : scheme_.steps)
      if (!is_finite_scalar(s.coef)) throw std::invalid_argument("splitting coefficient is not finite");
  }

  const SplittingScheme<scalar_type>& scheme() const { return scheme_; }
  long force_evals() const { return evals_; }
  Force& force() { return force_; }

  /// Forget the cached force (the next kick evaluates).
  void reset_cache() { cache_valid_ = false; }
  /// Provide a force already known at position q (used by the multi-product engine).
  void seed_force(const V& q, const V& a) {
    resize_like(a_, a);
    assign(a_, a);
    resize_like(aq_, q);
    assign(aq_, q);
    cache_valid_ = true;
  }

  void step(State<V>& s, real_type h) { integrate(s, h, 1); }

  /// n steps of size h.
  void integrate(State<V>& s, real_type h, long n) {
    if (n <= 0) return;
    if (use_compensation<scalar_type>(opt_.compensated)) {
      comp_.begin(s);
      run<true>(s, h, n, comp_);
      comp_.end(s);
    } else {
      run<false>(s, h, n, comp_);
    }
  }

  /// n compensated steps of size h with the caller's carry c (c.begin() is the caller's business;
  /// used by the multi-product engine to obtain each product's increment to full precision).
  void integrate_compensated(State<V>& s, real_type h, long n, Compensator<V>& c) {
    if (n > 0) run<true>(s, h, n, c);
  }

 private:
  template <bool Comp>
  void run(State<V>& s, real_type h, long n, Compensator<V>& c) {
    resize_like(a_, s.q);
    check_cache(s.q);
    const auto& st = scheme_.steps;
    const std::size_t m = st.size();
    hc_.resize(m);
    for (std::size_t i = 0; i < m; ++i) hc_[i] = st[i].coef * scalar_type(h);
    const bool project = is_complex_v<scalar_type> && !opt_.keep_complex;
    const bool merge = !project && m > 1 && st.front().flow == st.back().flow;
    if (!merge) {
      for (long k = 0; k < n; ++k) {
        for (std::size_t i = 0; i < m; ++i) apply<Comp>(s, st[i].flow, hc_[i], c);
        if (project) {
          project_real(s.q);
          project_real(s.v);
          if constexpr (Comp) {
            project_real(c.cq);
            project_real(c.cv);
          }
          cache_valid_ = false;
        }
      }
      remember(s.q);
      return;
    }
    const scalar_type joined = hc_[m - 1] + hc_[0];
    for (std::size_t i = 0; i + 1 < m; ++i) apply<Comp>(s, st[i].flow, hc_[i], c);
    for (long k = 1; k < n; ++k) {
      apply<Comp>(s, st[0].flow, joined, c);
      for (std::size_t i = 1; i + 1 < m; ++i) apply<Comp>(s, st[i].flow, hc_[i], c);
    }
    apply<Comp>(s, st[m - 1].flow, hc_[m - 1], c);
    remember(s.q);
  }

  template <bool Comp>
  void apply(State<V>& s, Flow f, const scalar_type& c, Compensator<V>& comp) {
    if (f == Flow::drift) {
      if constexpr (Comp)
        comp.axpy_q(s.q, c, s.v);
      else
        axpy(s.q, c, s.v);
      cache_valid_ = false;
    } else {
      if (!cache_valid_) {
        force_(s.q, a_);
        ++evals_;
        cache_valid_ = true;
      }
      if constexpr (Comp)
        comp.axpy_v(s.v, c, a_);
      else
        axpy(s.v, c, a_);
    }
  }
  // The cache survives between calls only if the caller did not move q.
  void check_cache(const V& q) {
    if (!cache_valid_) return;
    if (aq_.size() != q.size()) {
      cache_valid_ = false;
      return;
    }
    for (std::size_t i = 0; i < q.size(); ++i)
      if (!(aq_[i] == q[i])) {
        cache_valid_ = false;
        return;
      }
  }
  void remember(const V& q) {
    if (cache_valid_) {
      resize_like(aq_, q);
      assign(aq_, q);
    }
  }

  SplittingScheme<scalar_type> scheme_;
  Force force_;
  EngineOptions opt_;
  Compensator<V> comp_;
  V a_{};
  V aq_{};
  bool cache_valid_ = false;
  long evals_ = 0;
  std::vector<scalar_type> hc_;
};

}  // namespace nystrom
