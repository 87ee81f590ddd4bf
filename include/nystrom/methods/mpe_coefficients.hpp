// The coefficients of a multi-product expansion as data: the exact rationals c_i (Chin eq 14) and
// e_{2n+1} (eq 15) of a sequence {k_i}, its validation and parsing, and the sequence of least error for
// a given number of force evaluations. The engine that runs it: engines/mpe.hpp.
#pragma once

#include <cstddef>
#include <numeric>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <gmpxx.h>

namespace nystrom {

struct MpeCoefficients {
  std::vector<long> k;
  std::vector<mpq_class> c;
  mpq_class error;  // e_{2n+1}
  int order() const { return 2 * static_cast<int>(k.size()); }
};

/// Most products of an MPE sequence (order 400): the exact coefficients cost O(n^2) products of rationals
/// whose size grows with n (5000 products take hours).
inline constexpr std::size_t max_mpe_products = 200;

/// Throws std::invalid_argument unless k is a non-empty set of at most max_mpe_products distinct positive
/// integers.
inline void validate_mpe_sequence(const std::vector<long>& k) {
  if (k.empty()) throw std::invalid_argument("MPE sequence is empty");
  if (k.size() > max_mpe_products)
    throw std::invalid_argument("MPE sequence has " + std::to_string(k.size()) + " members, more than " +
                                std::to_string(max_mpe_products) + " (order 400)");
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
    // digits only (std::stol would take spaces, a sign and overflow with an exception of its own)
    if (item.empty() || item.size() > 9 || item.find_first_not_of("0123456789") != std::string::npos)
      throw std::invalid_argument("malformed MPE sequence: '" + item.substr(0, 40) +
                                  "' is not a positive integer up to 1000000");
    k.push_back(std::stol(item));
    if (k.size() > max_mpe_products) validate_mpe_sequence(k);  // stop reading at once
  }
  if (!text.empty() && text.back() == ',') throw std::invalid_argument("malformed MPE sequence '" + text + "'");
  validate_mpe_sequence(k);
  return k;
}

/// The n distinct positive integers with sum K of least error |e_{2n+1}| (largest product),
/// i.e. the integers closest to K/n (Chin, discussion of eq 16). Throws if K < n(n+1)/2.
inline std::vector<long> optimal_mpe_sequence(int n, long K) {
  if (n <= 0) throw std::invalid_argument("MPE order must be positive");
  if (static_cast<std::size_t>(n) > max_mpe_products)
    throw std::invalid_argument("an MPE sequence has at most " + std::to_string(max_mpe_products) + " members");
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

}  // namespace nystrom
