// The Schrödinger (and Gross-Pitaevskii) equation as a pair of operator flows (operators/flows.hpp):
//   real time       i psi_t = (T + V + g|psi|^2) psi:  A = -iT, B = -i(V + g|psi|^2)
//   imaginary time  psi_tau = -(T + V + g|psi|^2) psi: A = -T,  B = -(V + g|psi|^2), renormalised each step
// T = -nabla^2/2 is diagonal in Fourier space (FFTW, one forward and one backward transform per
// application of A), V in position space. A sub-step with coefficient z (times h) multiplies by
// exp(s z k^2/2) in Fourier space and by exp(s z V) in position space, s = -i (real) or -1 (imaginary);
// complex z is allowed (Re z > 0 keeps imaginary-time sub-steps bounded; negative real parts amplify
// the highest wave numbers by exp(|Re z| h k_max^2 / 2)).
//
// The nonlinear term (g != 0), at each B sub-step with coefficient z:
//   real time, real z: exp(-i z (V + g rho0)) with rho0 = |psi|^2 at the start of the sub-step: the
//     exact flow, since the phase leaves |psi|^2 unchanged;
//   imaginary time, real z: the exact flow of psi_tau = -(V + g|psi|^2) psi, a Bernoulli equation for rho:
//     psi *= (e^{2 V z} + 2 g z rho0 phi1(2 V z))^{-1/2}, phi1(x) = (e^x - 1)/x;
//   complex z (either time): exp(s z (V + g rho0)), the density frozen at the start of the sub-step. This
//     is not an exact flow (|psi|^2 is not analytic in z), so complex-coefficient methods lose their
//     order on the nonlinear part; real-coefficient methods keep theirs.
// Nothing merges across steps for g != 0 in imaginary time (the renormalisation sits between steps).
// Imaginary time with g != 0 also needs the chemical potential: the nonlinear term must see the normalised
// density throughout a step, but e^{-tau H} lets the norm decay as e^{-mu tau} within it, which moves the
// fixed point by O(tau) (measured: mu 1.8% too high at g = 1000, tau = 0.002, falling only linearly with
// tau). The B flows therefore use V + g|psi|^2 - mu_s, with mu_s updated after every step from the norm
// decay of that step (set_step_size() gives the step): at the fixed point the norm is conserved and mu_s
// is the method's chemical potential.
#pragma once

#include <chrono>
#include <cmath>
#include <complex>
#include <cstddef>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "nystrom/quantum/fftw.hpp"
#include "nystrom/quantum/grid.hpp"

namespace nystrom::quantum {

enum class TimeKind { real, imaginary };

template <class R>
class SchrodingerFlows {
 public:
  using state_type = Field<R>;
  using real_type = R;
  using complex_type = std::complex<R>;

  /// `potential`: the values on the whole grid (sample_potential()).
  SchrodingerFlows(const Grid<R>& grid, std::vector<R> potential, TimeKind kind, R g = 0, FftOptions fft = {})
      : SchrodingerFlows(grid, std::move(potential), kind, g, std::make_unique<FftPair<R>>(grid.shape(), fft)) {}

  /// Over given transforms, e.g. a grid distributed over MPI ranks (quantum/fftw_mpi.hpp): `potential` holds
  /// the values on the points of this process (sample_potential(grid, v, range)).
  SchrodingerFlows(const Grid<R>& grid, std::vector<R> potential, TimeKind kind, R g,
                   std::unique_ptr<FftTransforms<R>> transforms)
      : grid_(grid), v_(std::move(potential)), kind_(kind), g_(g), fft_(std::move(transforms)) {
    if (!fft_) throw std::invalid_argument("no transforms");
    if (v_.size() != fft_->local_size()) throw std::invalid_argument("potential and grid differ in size");
    if (!std::isfinite(static_cast<double>(g))) throw std::invalid_argument("g must be finite");
    k2half_.resize(v_.size());
    for_each_point(grid_, range(), [&](std::size_t i, const int* idx) {
      R k2 = 0;
      for (int a = 0; a < grid_.dims; ++a) k2 += grid_.wavenumber(idx[a]) * grid_.wavenumber(idx[a]);
      k2half_[i] = k2 / 2;
    });
  }

  const Grid<R>& grid() const { return grid_; }
  const std::vector<R>& potential() const { return v_; }
  const std::vector<R>& half_k2() const { return k2half_; }
  TimeKind kind() const { return kind_; }
  R coupling() const { return g_; }
  const FftTransforms<R>& fft() const { return *fft_; }
  /// The points of the grid this process holds (all of them unless the grid is distributed).
  PointRange range() const { return {fft_->first(), fft_->local_size()}; }
  /// integral |psi|^2 over the whole grid.
  R norm2(const state_type& psi) const {
    R sum = 0;
    for (const auto& x : psi) sum += std::norm(x);
    fft_->sum(&sum, 1);
    return sum * grid_.cell();
  }
  long fft_count() const { return ffts_; }
  void reset_fft_count() { ffts_ = 0; }
  /// Bound on the number of cached exponential tables (each one field); beyond it they are computed per use.
  void set_cache_limit(std::size_t n) { cache_limit_ = n; }

  // ---- the flows ----
  void apply_a(state_type& psi, complex_type z) {
    fft_->forward(psi);
    multiply(psi, factor(cache_a_, k2half_, z, R(1) / static_cast<R>(grid_.size())));
    fft_->backward(psi);
    ffts_ += 2;
  }

  void apply_b(state_type& psi, complex_type z) {
    if (g_ == 0) {
      multiply(psi, factor(cache_b_, v_, z, R(1)));
      return;
    }
    const complex_type s = sign();
    if (kind_ == TimeKind::imaginary && z.imag() == 0) {
      const R t = z.real();
      for (std::size_t i = 0; i < psi.size(); ++i) {
        const R rho = std::norm(psi[i]);
        const R x = 2 * (v_[i] - shift_) * t;
        const R phi1 = std::abs(x) < R(1e-8) ? 1 + x / 2 : std::expm1(x) / x;
        psi[i] *= 1 / std::sqrt(std::exp(x) + 2 * g_ * t * rho * phi1);
      }
      return;
    }
    const R shift = kind_ == TimeKind::imaginary ? shift_ : R(0);
    for (std::size_t i = 0; i < psi.size(); ++i) psi[i] *= std::exp(s * z * (v_[i] - shift + g_ * std::norm(psi[i])));
  }

  /// e^{z B + w [B,[A,B]]}: [V,[T,V]] = |grad V|^2 (m = 1), so [B,[A,B]] = s^3 |grad V|^2 with s = -i (real
  /// time) or -1 (imaginary time): the potential sub-step of a forward method with a gradient term
  /// (operators/flows.hpp). Needs set_gradient_term() and g = 0.
  void apply_b_gradient(state_type& psi, complex_type z, complex_type w) {
    if (g_ != 0) throw std::invalid_argument("gradient methods need g = 0 (no Gross-Pitaevskii term)");
    if (grad2_.size() != v_.size()) throw std::invalid_argument("the gradient term |grad V|^2 is not set");
    const Field<R>* table = nullptr;
    for (const auto& t : cache_g_)
      if (t.z == z && t.w == w) table = &t.values;
    if (!table) {
      Field<R>* out = &scratch_;
      if (cache_g_.size() < cache_limit_) {
        cache_g_.push_back({z, w, {}});
        out = &cache_g_.back().values;
      }
      const complex_type s = sign(), sz = s * z, s3w = s * s * s * w;
      out->resize(v_.size());
      for (std::size_t i = 0; i < v_.size(); ++i) (*out)[i] = std::exp(sz * v_[i] + s3w * grad2_[i]);
      table = out;
    }
    multiply(psi, *table);
  }
  /// |grad V|^2 on the points of this process (sample_gradient_squared()), for apply_b_gradient().
  void set_gradient_term(std::vector<R> grad2) {
    if (grad2.size() != v_.size()) throw std::invalid_argument("gradient term and grid differ in size");
    grad2_ = std::move(grad2);
    cache_g_.clear();
  }

  // ---- the vector space ----
  void assign(state_type& d, const state_type& s) const { d = s; }
  void scale(state_type& s, R r) const {
    for (auto& x : s) x *= r;
  }
  void axpy(state_type& d, R r, const state_type& s) const {
    R* dp = reinterpret_cast<R*>(d.data());
    const R* sp = reinterpret_cast<const R*>(s.data());
    const std::size_t n = 2 * d.size();
    for (std::size_t i = 0; i < n; ++i) dp[i] += r * sp[i];
  }

  /// Imaginary time: psi / ||psi|| after every step (for g = 0 it commutes with both flows, so steps
  /// still merge; for g != 0 they do not). Real time: nothing.
  void end_step(state_type& psi) {
    if (kind_ != TimeKind::imaginary) return;
    if (g_ != 0 && step_ > 0) {
      const R n2 = norm2(psi);
      if (n2 > 0 && std::isfinite(static_cast<double>(n2))) shift_ += -std::log(n2) / (2 * step_);
    }
    renormalize(psi);
  }
  /// The imaginary-time step (for the chemical-potential shift of the Gross-Pitaevskii flows).
  void set_step_size(R h) { step_ = h; }
  /// The chemical potential shift mu_s of the Gross-Pitaevskii flows in imaginary time.
  R chemical_potential_shift() const { return shift_; }
  bool merge_across_steps() const { return g_ == 0 || kind_ == TimeKind::real; }
  void renormalize(state_type& psi) const {
    const R n = std::sqrt(norm2(psi));
    if (!(n > 0) || !std::isfinite(static_cast<double>(n)))
      throw std::runtime_error("the wave function vanished or overflowed (norm " + std::to_string(double(n)) + ")");
    scale(psi, 1 / n);
  }

 private:
  struct Table {
    complex_type z;
    Field<R> values;
  };
  struct GradientTable {
    complex_type z, w;
    Field<R> values;
  };

  complex_type sign() const { return kind_ == TimeKind::real ? complex_type(0, -1) : complex_type(-1, 0); }

  /// exp(s z w_i) * extra, cached per z.
  const Field<R>& factor(std::vector<Table>& cache, const std::vector<R>& w, complex_type z, R extra) {
    for (const auto& t : cache)
      if (t.z == z) return t.values;
    Field<R>* out = &scratch_;
    if (cache.size() < cache_limit_) {
      cache.push_back({z, {}});
      out = &cache.back().values;
    }
    out->resize(w.size());
    const complex_type sz = sign() * z;
    for (std::size_t i = 0; i < w.size(); ++i) (*out)[i] = extra * std::exp(sz * w[i]);
    return *out;
  }

  /// psi_i *= f_i, written out: std::complex's operator* checks for NaN/inf results (a library call per
  /// point at -O2), which made the generic flows 1.6x slower than a hand-written loop.
  static void multiply(state_type& psi, const Field<R>& f) {
    R* p = reinterpret_cast<R*>(psi.data());
    const R* q = reinterpret_cast<const R*>(f.data());
    const std::size_t n = psi.size();
    for (std::size_t i = 0; i < n; ++i) {
      const R a = p[2 * i], b = p[2 * i + 1], c = q[2 * i], d = q[2 * i + 1];
      p[2 * i] = a * c - b * d;
      p[2 * i + 1] = a * d + b * c;
    }
  }

  Grid<R> grid_;
  std::vector<R> v_, k2half_;
  TimeKind kind_;
  R g_;
  std::unique_ptr<FftTransforms<R>> fft_;
  std::vector<Table> cache_a_, cache_b_;
  std::vector<GradientTable> cache_g_;
  std::vector<R> grad2_;
  Field<R> scratch_;
  std::size_t cache_limit_ = 64;
  long ffts_ = 0;
  R shift_ = 0, step_ = 0;
};

}  // namespace nystrom::quantum
