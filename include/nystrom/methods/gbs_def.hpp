// The Gragg-Bulirsch-Stoer extrapolation method as data: its step-number sequence and the columns of its
// extrapolation table (the method of the catalog specification "GBS", "GBS:SEQUENCE" or
// "GBS:SEQUENCE:COLUMNS"; the engine is engines/gbs.hpp). Plain data, no coefficients.
#pragma once

namespace nystrom {

/// The step numbers n_j of the j-th column: harmonic 2, 4, 6, 8, ... (Deuflhard's, ODEX's); romberg 2, 4, 8,
/// 16, ...; bulirsch 2, 4, 6, 8, 12, 16, 24, ...
enum class GbsSequence { harmonic, romberg, bulirsch };

struct GbsDef {
  GbsSequence sequence = GbsSequence::harmonic;
  int max_columns = 12;  // kmax: columns of the extrapolation table (order up to 2 kmax)
};

}  // namespace nystrom
