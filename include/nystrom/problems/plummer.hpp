// Plummer-sphere initial conditions and plain-text particle files.
//
// plummer_sphere<T>(N, seed): the procedure of Aarseth, Hénon & Wielen (1974), A&A 37, 183 (appendix), in
// the form popularised by Hut & Makino's mkplummer:
//   * equal masses 1/N;
//   * radius from the cumulative mass: X uniform in (0, mfrac), r = (X^{-2/3} - 1)^{-1/2} (Plummer radius 1);
//     mfrac = 0.999 cuts the infinite tail (r < 38.7 Plummer radii);
//   * speed v = q sqrt(2) (1 + r^2)^{-1/4} (q times the local escape speed), q drawn from
//     g(q) = q^2 (1 - q^2)^{7/2} by von Neumann rejection (q uniform in (0,1), y uniform in (0, 0.1));
//   * isotropic directions for position and velocity;
//   * standard (Hénon/Heggie-Mathieu) units G = M = 1, E = -1/4: lengths times 3 pi / 16, velocities
//     times sqrt(16 / (3 pi));
//   * centre-of-mass frame (position and velocity of the centre of mass subtracted);
//   * finally lengths are multiplied by lambda and velocities divided by sqrt(lambda) so that the energy of
//     this finite sample (unsoftened) is exactly -1/4; the sample's own virial ratio is kept.
// The random numbers come from std::mt19937_64 (its output is fixed by the C++ standard) mapped to doubles
// by hand, so a seed gives the same particles with every compiler and library.
//
// Particle files (load_particles / save_particles): text, one particle per line, seven numbers
//   m, x, y, z, vx, vy, vz
// separated by commas (or blanks). Blank lines and lines starting with '#' are ignored; a first line
// "m,x,y,z,vx,vy,vz" is accepted as a header. Masses must be positive, all numbers finite.
// save_particles writes 17 significant digits (the file reads back bit for bit), atomically (write_file_atomic,
// core/files.hpp). load_particles reads a regular file of at most 64 MiB (read_input_file).
#pragma once

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "nystrom/core/files.hpp"
#include "nystrom/problems/nbody.hpp"

namespace nystrom {

namespace detail {

/// Uniform double in the open interval (0, 1) from 53 random bits.
inline double uniform01(std::mt19937_64& g) { return (static_cast<double>(g() >> 11) + 0.5) * 0x1.0p-53; }

}  // namespace detail

/// Options of plummer_sphere.
struct PlummerOptions {
  double mass_cutoff = 0.999;  // mfrac: fraction of the model's mass sampled (cuts the radial tail)
  bool exact_energy = true;    // rescale the sample to E = -1/4 exactly
};

/// Total energy (kinetic + unsoftened potential) of a particle set.
template <class T>
T particle_energy(const ParticleSet<T>& p, const T& eps2 = T(0)) {
  return nbody_kinetic_energy(p.m, p.s.v) + nbody_potential_energy(p.m, eps2, p.s.q);
}

/// Moves a particle set to its centre-of-mass frame.
template <class T>
void to_centre_of_mass_frame(ParticleSet<T>& p) {
  const std::size_t n = p.size();
  T M(0);
  for (const auto& m : p.m) M += m;
  for (std::size_t c = 0; c < 3; ++c) {
    T cq(0), cv(0);
    for (std::size_t i = 0; i < n; ++i) {
      cq += p.m[i] * p.s.q[c * n + i];
      cv += p.m[i] * p.s.v[c * n + i];
    }
    cq /= M;
    cv /= M;
    for (std::size_t i = 0; i < n; ++i) {
      p.s.q[c * n + i] -= cq;
      p.s.v[c * n + i] -= cv;
    }
  }
}

/// A Plummer sphere of n equal-mass particles in standard units (see the top of the file).
template <class T>
ParticleSet<T> plummer_sphere(std::size_t n, std::uint64_t seed, const PlummerOptions& opt = {}) {
  using std::cos;
  using std::pow;
  using std::sin;
  using std::sqrt;
  if (n < 2) throw std::invalid_argument("a Plummer sphere needs at least 2 particles");
  if (n > 100000000) throw std::invalid_argument("too many particles for a Plummer sphere (at most 1e8)");
  if (!(opt.mass_cutoff > 0.0 && opt.mass_cutoff < 1.0))
    throw std::invalid_argument("Plummer mass cutoff must lie in (0, 1)");
  std::mt19937_64 g(seed);
  ParticleSet<T> p;
  p.m.assign(n, T(1) / T(static_cast<double>(n)));
  p.s.q.assign(3 * n, T(0));
  p.s.v.assign(3 * n, T(0));
  const double pi = std::acos(-1.0);
  auto direction = [&](double len, double& x, double& y, double& z) {
    const double ct = 2.0 * detail::uniform01(g) - 1.0;
    const double st = std::sqrt(std::max(0.0, 1.0 - ct * ct));
    const double ph = 2.0 * pi * detail::uniform01(g);
    x = len * st * std::cos(ph);
    y = len * st * std::sin(ph);
    z = len * ct;
  };
  const double lscale = 3.0 * pi / 16.0, vscale = std::sqrt(16.0 / (3.0 * pi));
  for (std::size_t i = 0; i < n; ++i) {
    const double X = opt.mass_cutoff * detail::uniform01(g);
    const double r = 1.0 / std::sqrt(std::pow(X, -2.0 / 3.0) - 1.0);
    double x, y, z;
    direction(r * lscale, x, y, z);
    p.s.q[i] = T(x);
    p.s.q[n + i] = T(y);
    p.s.q[2 * n + i] = T(z);
    double q = 0.0, yv = 0.1;
    while (yv > q * q * std::pow(1.0 - q * q, 3.5)) {
      q = detail::uniform01(g);
      yv = 0.1 * detail::uniform01(g);
    }
    const double speed = q * std::sqrt(2.0) * std::pow(1.0 + r * r, -0.25) * vscale;
    direction(speed, x, y, z);
    p.s.v[i] = T(x);
    p.s.v[n + i] = T(y);
    p.s.v[2 * n + i] = T(z);
  }
  to_centre_of_mass_frame(p);
  if (opt.exact_energy) {
    const T E = particle_energy(p);
    if (!(E < T(0)))
      throw std::invalid_argument("the sampled Plummer sphere is unbound (E >= 0): use more particles or another seed");
    const T lambda = T(-4) * E;  // E' = E / lambda = -1/4
    const T vs = T(1) / sqrt(lambda);
    for (auto& x : p.s.q) x *= lambda;
    for (auto& v : p.s.v) v *= vs;
  }
  return p;
}

/// Reads a particle file (see the top of the file). Throws std::invalid_argument with the line number.
template <class T = double>
ParticleSet<T> load_particles(const std::string& path) {
  std::istringstream in(read_input_file<std::invalid_argument>(path, "particle file"));
  std::vector<std::array<double, 7>> rows;
  std::string line;
  long lineno = 0;
  bool first = true;
  while (std::getline(in, line)) {
    ++lineno;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const auto start = line.find_first_not_of(" \t");
    if (start == std::string::npos || line[start] == '#') continue;
    std::string body = line.substr(start);
    if (first) {
      first = false;
      std::string h;
      for (char c : body)
        if (c != ' ' && c != '\t') h += c;
      if (h == "m,x,y,z,vx,vy,vz") continue;
    }
    for (auto& c : body)
      if (c == ',' || c == '\t') c = ' ';
    std::array<double, 7> row{};
    const char* s = body.c_str();
    char* end = nullptr;
    int k = 0;
    const std::string where = "particle file '" + path + "', line " + std::to_string(lineno) + ": ";
    for (;; ++k) {
      while (*s == ' ') ++s;
      if (*s == '\0') break;
      if (k == 7) throw std::invalid_argument(where + "more than 7 numbers (expected m x y z vx vy vz)");
      errno = 0;
      const double v = std::strtod(s, &end);
      if (end == s || (*end != ' ' && *end != '\0'))
        throw std::invalid_argument(where + "malformed number '" + std::string(s, std::strcspn(s, " ")) + "'");
      if (!std::isfinite(v)) throw std::invalid_argument(where + "number is not finite");
      row[static_cast<std::size_t>(k)] = v;
      s = end;
    }
    if (k != 7)
      throw std::invalid_argument(where + "expected 7 numbers (m x y z vx vy vz), found " + std::to_string(k));
    if (!(row[0] > 0.0)) throw std::invalid_argument(where + "mass must be positive");
    rows.push_back(row);
  }
  if (rows.size() < 2)
    throw std::invalid_argument("particle file '" + path + "' must hold at least 2 particles, found " +
                                std::to_string(rows.size()));
  const std::size_t n = rows.size();
  ParticleSet<T> p;
  p.m.resize(n);
  p.s.q.assign(3 * n, T(0));
  p.s.v.assign(3 * n, T(0));
  for (std::size_t i = 0; i < n; ++i) {
    p.m[i] = T(rows[i][0]);
    for (std::size_t c = 0; c < 3; ++c) {
      p.s.q[c * n + i] = T(rows[i][1 + c]);
      p.s.v[c * n + i] = T(rows[i][4 + c]);
    }
  }
  return p;
}

/// Writes text to path atomically (write_file_atomic, core/files.hpp: a unique temporary file in the same
/// folder, fsync, rename; a folder, device, FIFO or symbolic link is refused). Throws std::invalid_argument.
inline void write_text_atomic(const std::string& path, const std::string& text) {
  try {
    write_file_atomic(path, text);
  } catch (const error& e) {
    throw std::invalid_argument(e.what());
  }
}

/// Saves a particle set (17 significant digits, atomic).
template <class T>
void save_particles(const std::string& path, const ParticleSet<T>& p) {
  const std::size_t n = p.size();
  if (p.s.q.size() != 3 * n || p.s.v.size() != 3 * n) throw std::invalid_argument("inconsistent particle set");
  std::string text = "m,x,y,z,vx,vy,vz\n";
  char buf[64];
  for (std::size_t i = 0; i < n; ++i) {
    const double row[7] = {as_double(p.m[i]),           as_double(p.s.q[i]), as_double(p.s.q[n + i]),
                           as_double(p.s.q[2 * n + i]), as_double(p.s.v[i]), as_double(p.s.v[n + i]),
                           as_double(p.s.v[2 * n + i])};
    for (int k = 0; k < 7; ++k) {
      std::snprintf(buf, sizeof buf, "%.17g%s", row[k], k == 6 ? "\n" : ",");
      text += buf;
    }
  }
  write_text_atomic(path, text);
}

}  // namespace nystrom
