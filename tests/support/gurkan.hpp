// Published numbers of M. A. Gürkan, "Fifth order Runge-Kutta-Nyström methods with complex coefficients"
// (preprint, Leiden/Sabanci, 2012), as printed, for the tests that reproduce them: Table 4.3, the coefficients of
// H - Z in degree 6 of the fifth-order methods of Tables 4.1 and 4.2, and their norm.
#pragma once

#include <string>
#include <vector>

namespace nystrom::test {

/// One row of Table 4.3 as printed: X11, X16, X17, X19, X20 with two significant digits (the imaginary part for
/// the complex methods, whose terms are purely imaginary) and the norm with three.
struct GurkanTable43Row {
  std::string name;
  std::vector<double> x;  // real value, or imaginary part for complex methods
  double norm;
  bool imaginary;
};

/// Table 4.3 as printed, in the order of the paper.
inline const std::vector<GurkanTable43Row>& printed_gurkan_table_4_3() {
  static const std::vector<GurkanTable43Row> table{{"AR1", {-3.1e-3, 4.5e-4, 5.6e-3, 1.8e-5, -6.3e-5}, 6.44e-3, false},
                                                   {"AR2", {5.0e-3, -3.1e-4, -5.7e-3, 1.5e-5, 2.5e-4}, 7.58e-3, false},
                                                   {"BR1", {1.5e-4, 6.2e-5, -4.1e-4, 5.7e-5, 1.6e-4}, 4.71e-4, false},
                                                   {"BR2", {-7.0e-5, 9.7e-4, 2.7e-4, 5.2e-4, 5.2e-4}, 1.25e-3, false},
                                                   {"BR3", {3.5e-2, 1.9e-4, -3.5e-2, -3.0e-5, -1.0e-4}, 4.90e-2, false},
                                                   {"AC1", {-2.5e-6, 7.3e-6, -5.0e-6, 8.3e-7, 4.2e-6}, 1.02e-5, true},
                                                   {"AC2", {3.0e-6, -7.9e-6, 6.0e-6, -9.4e-7, -4.7e-6}, 1.15e-5, true},
                                                   {"BC1", {1.2e-5, -1.3e-5, 8.4e-6, 2.2e-7, -4.2e-6}, 1.96e-5, true},
                                                   {"BC2", {-4.1e-5, 4.9e-5, -1.2e-4, 7.7e-6, 5.0e-5}, 1.49e-4, true}};
  return table;
}

}  // namespace nystrom::test
