// The outer-solar-system problem of bench_brouwer_planetary and of the IAS15 driver in bench/rebound: the same
// initial states, masses and output times in both programs.
#pragma once

#include <cmath>

#include "nystrom/planetary/system.hpp"

namespace nystrom::bench {

inline constexpr double kJupiterPeriod = 4332.59;  // days
inline constexpr double kBrouwerMapStep = 150;     // days: the map's step
inline constexpr long kStepsPerOutput = 29;        // output m at m * 29 map steps (4350 days, 1.004 periods)

/// The time of output m (1, 2, 5, 10, ...), in days; exact in double.
inline double brouwer_time(long m) { return kBrouwerMapStep * static_cast<double>(m * kStepsPerOutput); }

/// Realization r of the initial state: Hairer's outer solar system in its centre-of-mass frame (computed in long
/// double), rounded to double, the planets' positions then scaled by 1 + r 2^-50 (r = 0: unperturbed), so that
/// every realization rounds differently from the first step on (Brouwer's law is a statement about the spread of
/// such runs; a single run's error wanders).
inline planetary::PlanetarySystem<double> brouwer_start(int r) {
  planetary::PlanetarySystem<double> s =
      planetary::convert_system<double>(planetary::barycentric(planetary::outer_solar_system<long double>()));
  for (std::size_t i = 1; i < s.size(); ++i)
    for (int k = 0; k < 3; ++k) s.x[i][k] *= 1 + r * std::ldexp(1.0, -50);
  return s;
}

}  // namespace nystrom::bench
