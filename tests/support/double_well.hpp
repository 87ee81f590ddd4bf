// Closed forms the Langevin tests share, written out independently of the library: Chin's multi-product
// coefficients and the Boltzmann moments of the double well U = (q^2 - 1)^2 by Simpson's rule.
#pragma once

#include <cmath>
#include <utility>
#include <vector>

namespace test_support {

/// Chin eq 14: c_i = prod_{j != i} k_i^2 / (k_i^2 - k_j^2) (S. A. Chin, Celest. Mech. Dyn. Astron. 106 (2010) 391).
inline std::vector<double> chin_coefficients(const std::vector<double>& k) {
  std::vector<double> c;
  for (std::size_t i = 0; i < k.size(); ++i) {
    double ci = 1;
    for (std::size_t j = 0; j < k.size(); ++j)
      if (j != i) ci *= k[i] * k[i] / (k[i] * k[i] - k[j] * k[j]);
    c.push_back(ci);
  }
  return c;
}

/// <q^2> and <q^4> of exp(-(q^2 - 1)^2 / kT) by Simpson's rule with n (even) intervals on [-4, 4].
inline std::pair<double, double> double_well_moments(double kT, int n = 8000) {
  double z = 0, m2 = 0, m4 = 0;
  for (int i = 0; i <= n; ++i) {
    const double q = -4 + 8.0 * i / n, u = (q * q - 1) * (q * q - 1);
    const double w = (i == 0 || i == n) ? 1 : (i % 2 ? 4 : 2), rho = w * std::exp(-u / kT);
    z += rho;
    m2 += rho * q * q;
    m4 += rho * q * q * q * q;
  }
  return {m2 / z, m4 / z};
}

}  // namespace test_support
