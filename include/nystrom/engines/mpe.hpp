// The multi-product expansion engine (Chin, sec. II):
//
//   T_2n(h) = sum_i c_i T_2^{k_i}(h / k_i),   c_i = prod_{j != i} k_i^2 / (k_i^2 - k_j^2)   (eq 14)
//   error coefficient e_{2n+1} = (-1)^{n-1} prod_i 1 / k_i^2                                (eq 15)
//
// for any set of distinct positive integers {k_i} and any symmetric second-order splitting T_2
// (velocity Verlet, eq 25; position Verlet, eq 26; or another). The c_i are computed exactly as
// GMP rationals and converted to the working scalar type only at the end.
//
// The combination is formed as T_ref + sum_{i != ref} c_i (T_i - T_ref) with T_ref the product of
// largest k (sum c_i = 1 makes this exact algebra): the differences are O(h^3), so the large c_i
// multiply small numbers and less precision is lost than in sum c_i T_i.
// With compensated summation (EngineOptions::compensated, on by default in double) each product is
// run on a compensated carry and returns its increment T_i - s to full precision; the combined
// increment is added to the state with the carry of the whole run.
#pragma once

#include <algorithm>
#include <cstddef>
#include <numeric>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <gmpxx.h>

#include "nystrom/core/state.hpp"
#include "nystrom/engines/splitting.hpp"

namespace nystrom {

struct MpeCoefficients {
  std::vector<long> k;
  std::vector<mpq_class> c;
  mpq_class error;  // e_{2n+1}
  int order() const { return 2 * static_cast<int>(k.size()); }
};

/// Throws std::invalid_argument unless k is a non-empty set of distinct positive integers.
inline void validate_mpe_sequence(const std::vector<long>& k) {
  if (k.empty()) throw std::invalid_argument("MPE sequence is empty");
  std::set<long> seen;
  for (long x : k) {
    if (x <= 0) throw std::invalid_argument("MPE sequence members must be positive integers, got " + std::to_string(x));
    if (!seen.insert(x).second) throw std::invalid_argument("MPE sequence has duplicate member " + std::to_string(x));
    if (x > 1000000) throw std::invalid_argument("MPE sequence member too large: " + std::to_string(x));
  }
}

/// Exact coefficients c_i (eq 14) and e_{2n+1} (eq 15).
inline MpeCoefficients mpe_coefficients(const std::vector<long>& k) {
  validate_mpe_sequence(k);
  MpeCoefficients r;
  r.k = k;
  const std::size_t n = k.size();
  r.c.resize(n);
  r.error = (n % 2 == 1) ? mpq_class(1) : mpq_class(-1);
  for (std::size_t i = 0; i < n; ++i) {
    mpq_class ci(1);
    const mpz_class ki2 = mpz_class(k[i]) * k[i];
    for (std::size_t j = 0; j < n; ++j) {
      if (j == i) continue;
      const mpz_class kj2 = mpz_class(k[j]) * k[j];
      mpq_class f(ki2, ki2 - kj2);
      f.canonicalize();  // GMP needs a positive denominator before arithmetic
      ci *= f;
    }
    ci.canonicalize();
    r.c[i] = ci;
    r.error /= mpq_class(ki2);
  }
  r.error.canonicalize();
  return r;
}

/// Parses "1,2,4" into {1,2,4}; throws on malformed input.
inline std::vector<long> parse_sequence(const std::string& text) {
  std::vector<long> k;
  std::string item;
  std::stringstream ss(text);
  if (text.empty()) throw std::invalid_argument("MPE sequence is empty");
  while (std::getline(ss, item, ',')) {
    std::size_t pos = 0;
    long v = 0;
    try {
      v = std::stol(item, &pos);
    } catch (const std::exception&) {
      throw std::invalid_argument("malformed MPE sequence '" + text + "': '" + item + "' is not an integer");
    }
    if (pos != item.size()) throw std::invalid_argument("malformed MPE sequence '" + text + "': '" + item + "' is not an integer");
    k.push_back(v);
  }
  if (!text.empty() && text.back() == ',') throw std::invalid_argument("malformed MPE sequence '" + text + "'");
  validate_mpe_sequence(k);
  return k;
}

/// The n distinct positive integers with sum K of least error |e_{2n+1}| (largest product),
/// i.e. the integers closest to K/n (Chin, discussion of eq 16). Throws if K < n(n+1)/2.
inline std::vector<long> optimal_mpe_sequence(int n, long K) {
  if (n <= 0) throw std::invalid_argument("MPE order must be positive");
  const long minimal = static_cast<long>(n) * (n + 1) / 2;
  if (K < minimal)
    throw std::invalid_argument("no " + std::to_string(n) + " distinct positive integers sum to " + std::to_string(K) +
                                " (need at least " + std::to_string(minimal) + ")");
  // Consecutive integers m, m+1, ..., m+n-1 with the largest m that fits, then spread the remainder
  // one unit at a time over the largest members (keeps them distinct and as equal as possible).
  long m = (K - static_cast<long>(n) * (n - 1) / 2) / n;
  std::vector<long> k(n);
  for (int i = 0; i < n; ++i) k[i] = m + i;
  long rest = K - std::accumulate(k.begin(), k.end(), 0L);
  for (int i = n - 1; rest > 0; --i, --rest) k[i] += 1;
  return k;
}

/// Sum of |c_i|: the amplification of rounding errors by the combination.
inline double mpe_amplification(const MpeCoefficients& m) {
  mpq_class s(0);
  for (const auto& c : m.c) s += abs(c);
  return s.get_d();
}

/// Executes an MPE integrator over any symmetric second-order base splitting.
template <class V, class Force>
class MpeStepper {
 public:
  using vector_type = V;
  using scalar_type = typename V::value_type;
  using real_type = real_t<scalar_type>;

  /// k: the sequence; c: its coefficients in the working type; base: T_2 as a splitting scheme.
  MpeStepper(std::vector<long> k, std::vector<scalar_type> c, SplittingScheme<scalar_type> base, Force force,
             EngineOptions opt = {})
      : k_(std::move(k)), c_(std::move(c)), base_(std::move(base), std::move(force), EngineOptions{true, Compensation::off}), opt_(opt) {
    validate_mpe_sequence(k_);
    if (c_.size() != k_.size()) throw std::invalid_argument("MPE: one coefficient per sequence member is needed");
    ref_ = static_cast<std::size_t>(std::max_element(k_.begin(), k_.end()) - k_.begin());
    starts_with_kick_ = base_.scheme().steps.front().flow == Flow::kick;
  }

  long force_evals() const { return base_.force_evals() + extra_evals_; }
  Force& force() { return base_.force(); }
  const std::vector<long>& sequence() const { return k_; }

  void step(State<V>& s, real_type h) { integrate(s, h, 1); }

  void integrate(State<V>& s, real_type h, long n) {
    if (n <= 0) return;
    if (opt_.mpe_naive_combination) {
      for (long i = 0; i < n; ++i) naive_step(s, h);
      comp_.invalidate();
    } else if (use_compensation<scalar_type>(opt_.compensated)) {
      comp_.begin(s);
      for (long i = 0; i < n; ++i) one_step<true>(s, h);
      comp_.end(s);
    } else {
      for (long i = 0; i < n; ++i) one_step<false>(s, h);
    }
  }

 private:
  void first_force(const State<V>& s) {
    resize_like(a0_, s.q);
    if (starts_with_kick_) {
      // All products start with a kick at q_0: evaluate that force once (n(n+1)/2 + 1 for VV).
      base_.force()(s.q, a0_);
      ++extra_evals_;
    }
  }

  // Measurements only: sum c_i T_i, uncompensated.
  void naive_step(State<V>& s, real_type h) {
    first_force(s);
    resize_like(acc_.q, s.q);
    resize_like(acc_.v, s.q);
    for (auto& e : acc_.q) e = scalar_type(0);
    for (auto& e : acc_.v) e = scalar_type(0);
    for (std::size_t i = 0; i < k_.size(); ++i) {
      run_product<false>(s, i, h, ti_);
      axpy(acc_.q, c_[i], ti_.q);
      axpy(acc_.v, c_[i], ti_.v);
    }
    assign(s.q, acc_.q);
    assign(s.v, acc_.v);
    if (is_complex_v<scalar_type> && !opt_.keep_complex) {
      project_real(s.q);
      project_real(s.v);
    }
  }

  // Uncompensated: T_i are end states. Compensated: T_i are the increments T_i - s, each product run
  // with its own compensated carry so that the increment is known to full precision; the combined
  // increment is then added to s with the carry of the whole run.
  template <bool Comp>
  void one_step(State<V>& s, real_type h) {
    first_force(s);
    run_product<Comp>(s, ref_, h, tref_);
    resize_like(acc_.q, s.q);
    resize_like(acc_.v, s.q);
    for (auto& e : acc_.q) e = scalar_type(0);
    for (auto& e : acc_.v) e = scalar_type(0);
    for (std::size_t i = 0; i < k_.size(); ++i) {
      if (i == ref_) continue;
      run_product<Comp>(s, i, h, ti_);
      for (std::size_t j = 0; j < s.q.size(); ++j) {
        acc_.q[j] += c_[i] * (ti_.q[j] - tref_.q[j]);
        acc_.v[j] += c_[i] * (ti_.v[j] - tref_.v[j]);
      }
    }
    if constexpr (Comp) {
      for (std::size_t j = 0; j < s.q.size(); ++j) {
        acc_.q[j] += tref_.q[j];
        acc_.v[j] += tref_.v[j];
      }
      comp_.add_q(s.q, acc_.q);
      comp_.add_v(s.v, acc_.v);
    } else {
      for (std::size_t j = 0; j < s.q.size(); ++j) {
        s.q[j] = tref_.q[j] + acc_.q[j];
        s.v[j] = tref_.v[j] + acc_.v[j];
      }
    }
    if (is_complex_v<scalar_type> && !opt_.keep_complex) {
      project_real(s.q);
      project_real(s.v);
      if constexpr (Comp) {
        project_real(comp_.cq);
        project_real(comp_.cv);
      }
    }
  }

  template <bool Comp>
  void run_product(const State<V>& s, std::size_t i, real_type h, State<V>& out) {
    resize_like(out.q, s.q);
    resize_like(out.v, s.v);
    assign(out.q, s.q);
    assign(out.v, s.v);
    if (starts_with_kick_)
      base_.seed_force(s.q, a0_);
    else
      base_.reset_cache();
    if constexpr (Comp) {
      resize_like(pc_.cq, s.q);
      resize_like(pc_.cv, s.q);
      for (auto& e : pc_.cq) e = scalar_type(0);
      for (auto& e : pc_.cv) e = scalar_type(0);
      base_.integrate_compensated(out, h / static_cast<real_type>(k_[i]), k_[i], pc_);
      for (std::size_t j = 0; j < s.q.size(); ++j) {
        out.q[j] = (out.q[j] - s.q[j]) + pc_.cq[j];
        out.v[j] = (out.v[j] - s.v[j]) + pc_.cv[j];
      }
    } else {
      base_.integrate(out, h / static_cast<real_type>(k_[i]), k_[i]);
    }
  }

  std::vector<long> k_;
  std::vector<scalar_type> c_;
  SplittingStepper<V, Force> base_;
  EngineOptions opt_;
  std::size_t ref_ = 0;
  bool starts_with_kick_ = false;
  long extra_evals_ = 0;
  V a0_{};
  State<V> tref_{}, ti_{}, acc_{};
  Compensator<V> comp_, pc_;
};

}  // namespace nystrom
