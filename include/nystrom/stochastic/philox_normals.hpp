// Counter-based standard normal numbers: each number is a pure function of (seed, path, slot, component),
// computed by the Philox4x64-10 generator (Salmon, Moraes, Dror, Shaw, "Parallel random numbers: as easy as
// 1, 2, 3", SC'11; the Random123 library) and the Box-Muller transform. No generator state travels between
// paths or threads, so a path's noise is the same whatever the thread count, the partition of the paths over
// processes or the order in which they run.
#pragma once

#include <cstdint>
#include <span>

#include <Random123/philox.h>
#include <Random123/boxmuller.hpp>

namespace nystrom::stochastic {

/// The normal numbers of one path: fill(step, out) fills out[m] (m = 0 .. size-1) with the standard normal
/// numbers of (seed, path, step, m). Philox's key is (seed, path), its counter (step, m / 4); the four 64-bit
/// outputs of one counter give four normals by two Box-Muller transforms.
class PathNormals {
 public:
  PathNormals(std::uint64_t seed, std::uint64_t path) : key_{{seed, path}} {}

  void fill(std::uint64_t step, std::span<double> out) const {
    const std::size_t n = out.size();
    for (std::size_t block = 0; 4 * block < n; ++block) {
      const r123::Philox4x64::ctr_type ctr{{step, static_cast<std::uint64_t>(block), 0, 0}};
      const auto r = generator_(ctr, key_);
      const r123::double2 a = r123::boxmuller(r.v[0], r.v[1]);
      const r123::double2 b = r123::boxmuller(r.v[2], r.v[3]);
      const double z[4] = {a.x, a.y, b.x, b.y};
      for (std::size_t j = 0; j < 4 && 4 * block + j < n; ++j) out[4 * block + j] = z[j];
    }
  }

 private:
  r123::Philox4x64 generator_{};
  r123::Philox4x64::key_type key_;
};

}  // namespace nystrom::stochastic
