// The coefficients of the adaptive multi-product expansion (engines/adaptive_mpe.hpp): the pair of one
// sequence and the tables of order control.
//
// The MPE T_2n(h) = sum_i c_i T_2^{k_i}(h / k_i) (Chin eq 14; engines/mpe.hpp) is Richardson
// extrapolation in h^2 of a symmetric second-order base. Dropping the product of largest k leaves
// n - 1 products whose own exact coefficients chat_i (the same formula on the shorter sequence) make
// a method of order 2n - 2 from the same force evaluations: the embedded pair is free. The error
// estimate is
//
//   err = T_2n - T_{2n-2} = sum_i (c_i - chat_i) T_i = sum_{i != ref} d_i (T_i - T_ref),  d = c - chat,
//
// (sum d_i = 0; ref the product of largest k), of order h^{2n-1}; the higher-order solution is
// propagated (local extrapolation), as in the adaptive RKN engine.
#pragma once

#include <algorithm>
#include <cstddef>
#include <stdexcept>
#include <vector>

#include <gmpxx.h>

#include "nystrom/engines/integrator.hpp"  // mpe_coefficients_as
#include "nystrom/methods/mpe_coefficients.hpp"

namespace nystrom {

/// The exact coefficients of an adaptive MPE: `high` (all products, order 2n), `low` (all but the
/// product of largest k, order 2n - 2) and diff_i = c_i - chat_i (chat = 0 for the dropped product).
struct AdaptiveMpeCoefficients {
  MpeCoefficients high, low;
  std::vector<mpq_class> diff;
  std::size_t dropped = 0;
  /// The error combination d = diff as MpeCoefficients (the sequence and order of `high`).
  MpeCoefficients error() const {
    MpeCoefficients d = high;
    d.c = diff;
    return d;
  }
};

inline AdaptiveMpeCoefficients adaptive_mpe_coefficients(const std::vector<long>& k) {
  validate_mpe_sequence(k);
  if (k.size() < 2)
    throw std::invalid_argument("an adaptive MPE needs at least two products (the error estimate drops one)");
  AdaptiveMpeCoefficients r;
  r.high = mpe_coefficients(k);
  r.dropped = static_cast<std::size_t>(std::max_element(k.begin(), k.end()) - k.begin());
  std::vector<long> kl;
  for (std::size_t i = 0; i < k.size(); ++i)
    if (i != r.dropped) kl.push_back(k[i]);
  r.low = mpe_coefficients(kl);
  r.diff.resize(k.size());
  for (std::size_t i = 0, j = 0; i < k.size(); ++i) {
    r.diff[i] = r.high.c[i];
    if (i != r.dropped) r.diff[i] -= r.low.c[j++];
    r.diff[i].canonicalize();
  }
  return r;
}

/// The coefficients of order control (AdaptiveMpeIntegrator): for each number of products n = 2..N of the
/// natural sequence k = 1..N, c[n] those of T_2n over k = 1..n and d[n] those of T_2n - T_{2n-2}; entries 0
/// and 1 empty.
template <class S>
struct MpeOrderTables {
  std::vector<std::vector<S>> c, d;
};

/// The tables of order control over the natural sequence k (1, 2, ..., N) in the working type S.
template <class S>
MpeOrderTables<S> mpe_order_tables(const std::vector<long>& k) {
  for (std::size_t n = 0; n < k.size(); ++n)
    if (k[n] != static_cast<long>(n) + 1)
      throw std::invalid_argument("adaptive MPE order control runs the natural sequence 1, 2, ..., N only");
  MpeOrderTables<S> orders;
  orders.c.resize(k.size() + 1);
  orders.d.resize(k.size() + 1);
  for (std::size_t n = 2; n <= k.size(); ++n) {
    const AdaptiveMpeCoefficients an =
        adaptive_mpe_coefficients(std::vector<long>(k.begin(), k.begin() + static_cast<long>(n)));
    orders.c[n] = mpe_coefficients_as<S>(an.high);
    orders.d[n] = mpe_coefficients_as<S>(an.error());
  }
  return orders;
}

}  // namespace nystrom
