// The operator layer: splitting and multi-product methods for any evolution e^{h(A+B)}.
//
// A problem supplies its two flows, not a force. An object F models OperatorFlows when
//   f.apply_a(s, z)   s <- e^{z A} s      (z complex: the sub-step's coefficient times h)
//   f.apply_b(s, z)   s <- e^{z B} s
//   f.assign(d, s)    d <- s               (d may be empty; it takes s's shape)
//   f.scale(s, r)     s <- r s             (r real)
//   f.axpy(d, r, s)   d <- d + r s         (the linear combination of the multi-product expansion)
// with F::state_type, F::real_type. Optional members the engines use when present:
//   f.end_step(s)                 after every step (e.g. renormalisation in imaginary time);
//   f.apply_b_gradient(s, z, w)   s <- e^{z B + w [B,[A,B]]} s: the modified potential of the forward
//                                 (all-positive) fourth-order methods with a gradient term (a splitting with
//                                 gradient coefficients needs it; for Schrodinger, [B,[A,B]] is a potential);
//   f.merge_across_steps()        false forbids merging the last sub-step of a step with the first of the
//                                 next (a flow that is not a group in its coefficient: e^{aB} e^{bB} !=
//                                 e^{(a+b)B}, such as a nonlinear potential flow). Default: merge. When
//                                 steps merge, end_step() runs after the merged sub-step, so it must commute
//                                 with the flows (a scalar renormalisation of a linear problem does).
//
// Classical drift/kick is one instance (A = v d/dq, B = a(q) d/dv); the Schrödinger equation (A = -iT,
// B = -iV, quantum/) and a pair of matrices (tests) are others. The scheme's "drift" sub-steps are A,
// its "kicks" B, in the order they are applied.
#pragma once

#include <algorithm>
#include <cmath>
#include <complex>
#include <concepts>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "nystrom/engines/splitting.hpp"
#include "nystrom/methods/splitting_scheme.hpp"

namespace nystrom::operators {

template <class F>
concept OperatorFlows = requires(F& f, typename F::state_type& s, const typename F::state_type& cs,
                                 std::complex<typename F::real_type> z, typename F::real_type r) {
  f.apply_a(s, z);
  f.apply_b(s, z);
  f.assign(s, cs);
  f.scale(s, r);
  f.axpy(s, r, cs);
};

namespace detail {

template <class F>
void end_step(F& f, typename F::state_type& s) {
  if constexpr (requires { f.end_step(s); }) f.end_step(s);
}

template <class F>
bool merge_across_steps(const F& f) {
  if constexpr (requires { f.merge_across_steps(); })
    return f.merge_across_steps();
  else
    return true;
}

/// One sub-step; w, the coefficient of [B,[A,B]] (gradient coefficient times h^3), is 0 for plain splittings.
template <class F, class R>
void apply(F& f, typename F::state_type& s, Flow which, std::complex<R> z, std::complex<R> w = {}) {
  if (which == Flow::drift) {
    f.apply_a(s, z);
  } else if (w == std::complex<R>()) {
    f.apply_b(s, z);
  } else if constexpr (requires { f.apply_b_gradient(s, z, w); }) {
    f.apply_b_gradient(s, z, w);
  } else {
    throw std::invalid_argument("these flows have no gradient term [B,[A,B]] for a gradient method");
  }
}

}  // namespace detail

/// Runs a splitting scheme (real or complex coefficients) over flows F. Adjacent sub-steps of the same
/// flow merge; in integrate() the last sub-step of a step merges with the first of the next unless the
/// flows forbid it (merge_across_steps()). Optional gradient coefficients c_j, one per sub-step of the
/// (normalised) scheme, make kick j the modified potential e^{h b_j B + h^3 c_j [B,[A,B]]} (Chin's forward
/// methods; flows with apply_b_gradient()).
template <OperatorFlows F>
class SplittingFlowStepper {
 public:
  using flows_type = F;
  using state_type = typename F::state_type;
  using real_type = typename F::real_type;
  using complex_type = std::complex<real_type>;

  explicit SplittingFlowStepper(const SplittingScheme<complex_type>& scheme, std::vector<complex_type> gradient = {})
      : scheme_(normalized(scheme)), grad_(std::move(gradient)) {
    if (scheme_.steps.empty()) throw std::invalid_argument("splitting scheme has no sub-steps");
    for (const auto& s : scheme_.steps)
      if (!std::isfinite(s.coef.real()) || !std::isfinite(s.coef.imag()))
        throw std::invalid_argument("splitting coefficient is not finite");
    if (grad_.empty())
      grad_.assign(scheme_.steps.size(), complex_type());
    else if (grad_.size() != scheme_.steps.size() || scheme.steps.size() != scheme_.steps.size())
      throw std::invalid_argument("one gradient coefficient per sub-step of a scheme without adjacent equal flows");
  }

  const SplittingScheme<complex_type>& scheme() const { return scheme_; }

  /// The sub-steps of one step, without end_step().
  void apply_once(F& f, state_type& s, real_type h) const { run(f, s, h, 1, false, false); }

  void step(F& f, state_type& s, real_type h) const {
    apply_once(f, s, h);
    detail::end_step(f, s);
  }

  void integrate(F& f, state_type& s, real_type h, long n) const {
    if (n > 0) run(f, s, h, n, merges(f), true);
  }

  /// Whether integrate() merges the last sub-step of a step with the first of the next.
  bool merges(const F& f) const {
    const auto& st = scheme_.steps;
    return st.size() > 1 && st.front().flow == st.back().flow && grad_.front() == complex_type() &&
           grad_.back() == complex_type() && detail::merge_across_steps(f);
  }

  /// Applications of flow A and of flow B in n steps of integrate().
  std::pair<long, long> applications(const F& f, long n) const {
    long a = 0, b = 0;
    for (const auto& s : scheme_.steps) (s.flow == Flow::drift ? a : b) += 1;
    a *= n;
    b *= n;
    if (n > 1 && merges(f)) (scheme_.steps.front().flow == Flow::drift ? a : b) -= n - 1;
    return {a, b};
  }

 private:
  /// n steps through the classical engine's loop (run_merged_splitting, run_sequential_splitting of
  /// engines/splitting.hpp): merged across steps when `merge`, with end_step() after each step when `end`.
  void run(F& f, state_type& s, real_type h, long n, bool merge, bool end) const {
    const auto& st = scheme_.steps;
    const std::size_t m = st.size();
    std::vector<complex_type> hc(m);
    std::vector<Flow> flows(m);
    for (std::size_t j = 0; j < m; ++j) {
      hc[j] = st[j].coef * h;
      flows[j] = st[j].flow;
    }
    const real_type g = h * h * h;
    auto drift = [&](const complex_type& z, std::size_t) { f.apply_a(s, z); };
    auto kick = [&](const complex_type& z, std::size_t j) { detail::apply(f, s, Flow::kick, z, grad_[j] * g); };
    auto step_end = [&] {
      if (end) detail::end_step(f, s);
    };
    if (merge)
      run_merged_splitting(st.front().flow == Flow::kick, hc.data(), m, n,
                           complex_type((st.back().coef + st.front().coef) * h), drift, kick, step_end);
    else
      run_sequential_splitting(flows.data(), hc.data(), m, n, drift, kick, step_end);
  }

  SplittingScheme<complex_type> scheme_;
  std::vector<complex_type> grad_;
};

/// Whether the multi-product expansion over flows F can carry a compensated sum per state component: states
/// that are contiguous arrays of float or double, real or complex (std::vector<double>, a complex field).
template <class F>
constexpr bool flow_state_compensable() {
  using S = typename F::state_type;
  if constexpr (requires(S & s) {
                  s.size();
                  s.data();
                  typename S::value_type;
                })
    return use_compensation<typename S::value_type>(Compensation::automatic);
  else
    return false;
}

/// Runs a multi-product expansion sum_i c_i B^{k_i}(h / k_i) over flows F, for any symmetric base
/// splitting B (second order: Chin's eq 14 coefficients; higher even order p: the extrapolation in powers
/// k^-p, k^-(p+2), ... of operators/flow_methods.hpp). Each product is one splitting scheme (k_i copies
/// of the base at h/k_i, adjacent sub-steps merged). The combination is not a group element (neither
/// unitary nor symplectic), so nothing merges across steps.
///
/// With compensated summation (on by default for states of float or double, flow_state_compensable()) the
/// combined increment is added to the state with a carry per component, kept from step to step and from
/// one integrate() call to the next while the state is the one the last call returned (as the classical
/// engine's Compensator does). The products themselves run on the flows' own arithmetic.
template <OperatorFlows F>
class MpeFlowStepper {
 public:
  using flows_type = F;
  using state_type = typename F::state_type;
  using real_type = typename F::real_type;
  using complex_type = std::complex<real_type>;

  MpeFlowStepper(const std::vector<long>& k, std::vector<real_type> c, const SplittingScheme<complex_type>& base,
                 Compensation compensated = Compensation::automatic)
      : k_(k), c_(std::move(c)) {
    if (k_.empty() || k_.size() != c_.size())
      throw std::invalid_argument("MPE: sequence and coefficients differ in size");
    if constexpr (flow_state_compensable<F>())
      compensated_ = compensated != Compensation::off;
    else if (compensated == Compensation::on)
      throw std::invalid_argument("MPE: compensated summation needs a state of float or double components");
    std::size_t ref = 0;  // the product of largest k first
    for (std::size_t i = 0; i < k_.size(); ++i)
      if (k_[i] > k_[ref]) ref = i;
    order_.push_back(ref);
    for (std::size_t i = 0; i < k_.size(); ++i)
      if (i != ref) order_.push_back(i);
    for (long ki : k_) {
      SplittingScheme<complex_type> p;
      for (long r = 0; r < ki; ++r)
        for (const auto& st : base.steps) p.steps.push_back({st.flow, st.coef / static_cast<real_type>(ki)});
      products_.emplace_back(p);
    }
  }

  const std::vector<long>& sequence() const { return k_; }
  const std::vector<real_type>& coefficients() const { return c_; }
  bool compensated() const { return compensated_; }

  void step(F& f, state_type& s, real_type h) {
    if (compensated_) {
      if constexpr (flow_state_compensable<F>()) {
        begin_carry(s);
        compensated_step(f, s, h);
        end_carry(s);
        return;
      }
    }
    plain_step(f, s, h);
  }

  void integrate(F& f, state_type& s, real_type h, long n) {
    if (n <= 0) return;
    if (compensated_) {
      if constexpr (flow_state_compensable<F>()) {
        begin_carry(s);
        for (long i = 0; i < n; ++i) compensated_step(f, s, h);
        end_carry(s);
        return;
      }
    }
    for (long i = 0; i < n; ++i) plain_step(f, s, h);
  }

  /// Applications of flow A and of flow B per step.
  std::pair<long, long> applications(const F& f) const {
    long a = 0, b = 0;
    for (const auto& p : products_) {
      const auto [pa, pb] = p.applications(f, 1);
      a += pa;
      b += pb;
    }
    return {a, b};
  }

 private:
  // sum_ <- s + sum_i c_i (T_i - s) (from_state) or the increment sum_i c_i (T_i - s) alone. Not sum_i c_i T_i:
  // the rounded c_i sum to 1 only to rounding, and the plain sum scales the state by that sum every step, a
  // secular error (measured on the outer solar system with WH-M8: relative energy error growing with the number
  // of steps, 1e-10 over 1e5 years); in the increments the coefficients' rounding multiplies T_i - s only.
  void combine(F& f, const state_type& s, real_type h, bool from_state) {
    f.assign(sum_, s);
    if (!from_state) f.scale(sum_, real_type(0));
    for (std::size_t i : order_) {
      f.assign(work_, s);
      products_[i].apply_once(f, work_, h);
      f.axpy(work_, real_type(-1), s);
      f.axpy(sum_, c_[i], work_);
    }
  }

  void plain_step(F& f, state_type& s, real_type h) {
    combine(f, s, h, true);
    using std::swap;
    swap(s, sum_);
    detail::end_step(f, s);
  }

  // s + carry += the increment, component by component (Knuth's two-sum, core/state.hpp).
  void compensated_step(F& f, state_type& s, real_type h) {
    combine(f, s, h, false);
    auto* x = s.data();
    auto* c = carry_.data();
    const auto* d = sum_.data();
    for (std::size_t j = 0; j < s.size(); ++j) compensated_add(x[j], c[j], d[j]);
    detail::end_step(f, s);
  }

  // The carry continues if s is the state the last compensated run returned, else it starts at zero.
  void begin_carry(const state_type& s) {
    if (carry_valid_ && last_.size() == s.size() && std::equal(last_.begin(), last_.end(), s.begin())) return;
    carry_ = s;
    for (auto& e : carry_) e = typename state_type::value_type(0);
  }
  void end_carry(const state_type& s) {
    last_ = s;
    carry_valid_ = true;
  }

  std::vector<long> k_;
  std::vector<real_type> c_;
  std::vector<std::size_t> order_;
  std::vector<SplittingFlowStepper<F>> products_;
  state_type work_{}, sum_{};    // allocated on the first step, reused after
  state_type carry_{}, last_{};  // compensated summation: the carry and the state it belongs to
  bool compensated_ = false, carry_valid_ = false;
};

}  // namespace nystrom::operators
