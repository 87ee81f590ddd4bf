// The gravitational N-body problem with Plummer softening, and the two-body problem of the Gürkan paper.
//
//   a_i = G sum_{j != i} m_j (q_j - q_i) / (|q_j - q_i|^2 + eps^2)^{3/2},   G = 1.
//
// State layout (structure of arrays inside the flat state vector): for N particles,
//   q = [x_0 .. x_{N-1}, y_0 .. y_{N-1}, z_0 .. z_{N-1}], the same for v and a.
//
// The force works for any real scalar T and for std::complex<T> (the analytic continuation used by the
// complex-coefficient methods: (r^2)^{-3/2} on the principal branch, a branch cut on the negative real
// axis of r^2; physically r^2 stays near the positive real axis).
//
// Kernels (NBodyForce::kernel):
//   * generic: every type; each particle's sum over j in increasing order, OpenMP across particles.
//   * simd (double and std::complex<double> on x86-64 with AVX-512F, chosen at run time): pair symmetry
//     (each pair computed once, Newton's third law), AVX-512 across 8 partners. Real: r^{-3/2} from the
//     hardware estimate vrsqrt14pd refined by one polynomial correction to full double accuracy (a few
//     ulp; the division and square-root units are several times slower than this short loop), in two
//     passes over a block of partners like the complex kernel (avx512_pair_real). Complex:
//     z^{-3/2} (z = r^2 + eps^2) with two hardware square roots and one division, whose latency is hidden
//     by computing z^{-3/2} for a whole block of partners of two rows first and accumulating after
//     (a few ulp; 2.6-3x the real kernel's time per pair at N = 10 000, 4.5x when accumulating per partner). Particles
//     are grouped in blocks of B (B depends on N only); the block pairs are visited in the rounds of a
//     round-robin tournament, so that within a round no two tiles touch the same block; each tile is an
//     OpenMP task that depends on its two blocks, so tiles run in parallel while every particle receives its
//     contributions in the round-robin order whatever the number of threads. Results are bitwise
//     independent of the thread count.
//   Both kernels give bitwise identical results for any number of threads; they differ from each other
//   by rounding (relative 1e-13 or less on a Plummer sphere).
//
// Pairs with r^2 + eps^2 exactly zero (with eps = 0: a particle and itself, coincident particles) contribute
// nothing.
#pragma once

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__)) && !defined(NYSTROM_NO_SIMD)
#include <immintrin.h>
#define NYSTROM_HAVE_AVX512_KERNEL 1
#define NYSTROM_TARGET_AVX512 __attribute__((target("avx512f,fma")))
#else
#define NYSTROM_HAVE_AVX512_KERNEL 0
#endif

#include "nystrom/core/eft.hpp"
#include "nystrom/core/state.hpp"

#ifdef _OPENMP
#define NYSTROM_OMP(x) _Pragma(#x)
#else
#define NYSTROM_OMP(x)
#endif

namespace nystrom {

/// Which force kernel to use (see the top of this file).
enum class NBodyKernel { automatic, generic, simd };

/// True when this build and this CPU can run the SIMD kernel.
inline bool nbody_simd_available() {
#if NYSTROM_HAVE_AVX512_KERNEL
  static const bool ok = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("fma");
  return ok;
#else
  return false;
#endif
}

/// Number of threads OpenMP would use (1 without OpenMP).
inline int nbody_max_threads() {
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}

namespace detail {

/// (a + i b)^{-3/2} on the principal branch (the branch cut on the negative real axis, the sign of a zero b
/// picking its side), with real square roots only; the same formula as the SIMD kernel:
///   rho = |z| = sqrt(a^2 + b^2),  p = rho + |a|,  k = 1 / sqrt(2 p rho^2),  f = k / rho^2 (= 2 p k^3);
///   z^{-1/2} = k (p - i b) for a >= 0,  k (|b| - i s p) for a < 0 (s = sign of b, -1 for b = -0);
///   z^{-3/2} = z^{-1/2} conj(z) / rho^2, i.e.
///     a >= 0:  ((p a - b^2) - i b (a + p)) f,      a < 0:  (|b| (a - p) - i s (b^2 + p a)) f.
/// No cancellation in p, a + p (a >= 0) or a - p (a < 0).
template <class T>
void complex_inv_pow32(const T& a, const T& b, T& wr, T& wi) {
  using std::abs;
  using std::copysign;
  using std::sqrt;
  const T bb = b * b;
  const T rho2 = a * a + bb;
  const T rho = sqrt(rho2);
  const T p = rho + abs(a);
  const T k = T(1) / (sqrt(T(2) * p) * rho);
  const T f = k / rho2;
  if (a >= T(0)) {
    wr = (p * a - bb) * f;
    wi = -(b * (a + p)) * f;
  } else {
    wr = abs(b) * (a - p) * f;
    wi = -copysign(T(1), b) * (bb + p * a) * f;
  }
}

/// m * (r2)^{-3/2} for a real or complex r2 (real mass m); zero when r2 == 0.
template <class S>
S mass_inv_r3(const S& r2, const real_t<S>& m) {
  using T = real_t<S>;
  if (r2 == S(0)) return S(0);
  if constexpr (is_complex_v<S>) {
    T wr, wi;
    complex_inv_pow32(r2.real(), r2.imag(), wr, wi);
    return S(m * wr, m * wi);
  } else {
    using std::sqrt;
    return m / (r2 * sqrt(r2));
  }
}

/// Block size of the SIMD kernel: a multiple of 8 that depends on N only.
inline std::size_t nbody_block(std::size_t n) {
  std::size_t b = (n / 32 + 7) / 8 * 8;
  return std::clamp<std::size_t>(b, 64, 256);  // 256: complex_max_block
}

/// Round r (0 <= r < P-1) of the circle-method round-robin over P (even) players: pair k of the round.
inline void round_robin_pair(std::size_t P, std::size_t r, std::size_t k, std::size_t& p1, std::size_t& p2) {
  const std::size_t M = P - 1;
  if (k == 0) {
    p1 = r;
    p2 = M;
  } else {
    p1 = (r + k) % M;
    p2 = (r + M - k) % M;
  }
  if (p1 > p2) std::swap(p1, p2);
}

#if NYSTROM_HAVE_AVX512_KERNEL

/// Sum of the 8 lanes in a fixed order (GCC 12's _mm512_reduce_add_pd trips -Wmaybe-uninitialized).
NYSTROM_TARGET_AVX512 inline double avx512_sum(__m512d v) {
  alignas(64) double t[8];
  _mm512_store_pd(t, v);
  return ((t[0] + t[1]) + (t[2] + t[3])) + ((t[4] + t[5]) + (t[6] + t[7]));
}

/// r2^{-3/2} from vrsqrt14pd (relative error < 2^-14) and one correction:
/// (1-h)^{-3/2} = 1 + 3h/2 + 15h^2/8 + 35h^3/16 + 315h^4/128 + O(h^5), h = 1 - r2 y0^2.
NYSTROM_TARGET_AVX512 inline __m512d avx512_inv_r3(__m512d r2) {
  const __m512d one = _mm512_set1_pd(1.0);
  const __m512d y = _mm512_maskz_rsqrt14_pd(0xFF, r2);
  const __m512d y2 = _mm512_mul_pd(y, y);
  const __m512d h = _mm512_fnmadd_pd(r2, y2, one);
  __m512d p = _mm512_fmadd_pd(h, _mm512_set1_pd(315.0 / 128.0), _mm512_set1_pd(35.0 / 16.0));
  p = _mm512_fmadd_pd(h, p, _mm512_set1_pd(15.0 / 8.0));
  p = _mm512_fmadd_pd(h, p, _mm512_set1_pd(1.5));
  const __m512d y3 = _mm512_mul_pd(y2, y);
  return _mm512_fmadd_pd(_mm512_mul_pd(y3, h), p, y3);
}

/// x^{-1/2}: (1-h)^{-1/2} = 1 + h/2 + 3h^2/8 + 5h^3/16 + O(h^4).
NYSTROM_TARGET_AVX512 inline __m512d avx512_rsqrt(__m512d x) {
  const __m512d y = _mm512_maskz_rsqrt14_pd(0xFF, x);
  const __m512d h = _mm512_fnmadd_pd(_mm512_mul_pd(x, y), y, _mm512_set1_pd(1.0));
  __m512d p = _mm512_fmadd_pd(h, _mm512_set1_pd(5.0 / 16.0), _mm512_set1_pd(3.0 / 8.0));
  p = _mm512_fmadd_pd(h, p, _mm512_set1_pd(0.5));
  return _mm512_fmadd_pd(_mm512_mul_pd(y, h), p, y);
}

// Bitwise operations on doubles with AVX-512F only (the _pd forms need AVX512DQ).
NYSTROM_TARGET_AVX512 inline __m512d avx512_andnot(__m512d a, __m512d b) {
  return _mm512_castsi512_pd(_mm512_maskz_andnot_epi64(0xFF, _mm512_castpd_si512(a), _mm512_castpd_si512(b)));
}
NYSTROM_TARGET_AVX512 inline __m512d avx512_xor(__m512d a, __m512d b) {
  return _mm512_castsi512_pd(_mm512_maskz_xor_epi64(0xFF, _mm512_castpd_si512(a), _mm512_castpd_si512(b)));
}

/// The a >= 0 formula: wr = (p a - b^2) f, wi = -(a + p) b f, f = 1 / (rho^2 sqrt(2 p rho^2)) (p = rho + |a|).
NYSTROM_TARGET_AVX512 inline void avx512_cinv_right(__m512d a, __m512d b, __m512d bb, __m512d rho2, __m512d p,
                                                    __m512d& wr, __m512d& wi, __m512d& f) {
  const __m512d p2 = _mm512_add_pd(p, p);
  const __m512d y = _mm512_maskz_sqrt_pd(0xFF, _mm512_mul_pd(p2, rho2));
  f = _mm512_div_pd(_mm512_set1_pd(1.0), _mm512_mul_pd(rho2, y));
  wr = _mm512_mul_pd(_mm512_fmsub_pd(p, a, bb), f);
  wi = _mm512_mul_pd(_mm512_mul_pd(b, f), _mm512_fnmsub_pd(a, _mm512_set1_pd(1.0), p));  // -(a + p)
}

/// (a + i b)^{-3/2}, the formula of complex_inv_pow32, with the hardware square root and division
/// (correctly rounded). Their unit works beside the FMA units and is far from saturated here: two square
/// roots and one division per 8 pairs replace about 20 FMA-unit operations of two refined vrsqrt14pd
/// estimates. Lanes with a < 0 (never seen with near-real positions: Re r^2 = eps^2 + |Re d|^2 - |Im d|^2)
/// take a branch that blends in the other half-plane's formula; lanes with a >= 0 give the same bits on
/// both paths. 2 p rho^2 (2 to 4 |z|^3) and rho^2 sqrt(2 p rho^2) (1.4 to 2 |z|^{7/2}) must stay finite and
/// normal: |z| = |r^2 + eps^2| within about [1e-87, 1e87] (the generic kernel has no such limit).
NYSTROM_TARGET_AVX512 inline void avx512_complex_inv_pow32(__m512d a, __m512d b, __m512d& wr, __m512d& wi) {
  const __m512d bb = _mm512_mul_pd(b, b);
  const __m512d rho2 = _mm512_fmadd_pd(a, a, bb);
  const __m512d rho = _mm512_maskz_sqrt_pd(0xFF, rho2);  // maskz: GCC 12 warns on _mm512_sqrt_pd
  const __mmask8 neg = _mm512_cmp_pd_mask(a, _mm512_setzero_pd(), _CMP_LT_OQ);
  __m512d f;
  if (neg == 0) {
    avx512_cinv_right(a, b, bb, rho2, _mm512_add_pd(rho, a), wr, wi, f);
    return;
  }
  const __m512d sign = _mm512_set1_pd(-0.0);
  const __m512d p = _mm512_add_pd(rho, avx512_andnot(sign, a));  // rho + |a|
  avx512_cinv_right(a, b, bb, rho2, p, wr, wi, f);
  // a < 0: wr = |b| (a - p) f, wi = -s (b^2 + p a) f (s = sign of b).
  const __m512d nr = _mm512_mul_pd(_mm512_mul_pd(avx512_andnot(sign, b), f), _mm512_sub_pd(a, p));
  const __m512d ni = avx512_xor(_mm512_mul_pd(_mm512_fmadd_pd(p, a, bb), f), avx512_andnot(b, sign));
  wr = _mm512_mask_blend_pd(neg, wr, nr);
  wi = _mm512_mask_blend_pd(neg, wi, ni);
}

/// avx512_complex_inv_pow32 on 8 lanes in memory (for tests: the caller checks nbody_simd_available()).
NYSTROM_TARGET_AVX512 inline void avx512_complex_inv_pow32_lanes(const double* a, const double* b, double* wr,
                                                                 double* wi) {
  __m512d r, i;
  avx512_complex_inv_pow32(_mm512_loadu_pd(a), _mm512_loadu_pd(b), r, i);
  _mm512_storeu_pd(wr, r);
  _mm512_storeu_pd(wi, i);
}

/// Padded SoA buffers of the SIMD kernel (pointers to the arrays of positions, masses, accelerations).
struct RealTileData {
  const double *x, *y, *z, *m;
  double *ax, *ay, *az;
};

/// Contributions within one block (each i sums over all j of the block; i's own term is zero).
template <bool Masked>
NYSTROM_TARGET_AVX512 inline void avx512_diag_real(const RealTileData& d, std::size_t i0, std::size_t B, double eps2) {
  const __m512d e2 = _mm512_set1_pd(eps2);
  for (std::size_t i = i0; i < i0 + B; ++i) {
    const __m512d xi = _mm512_set1_pd(d.x[i]), yi = _mm512_set1_pd(d.y[i]), zi = _mm512_set1_pd(d.z[i]);
    __m512d sx = _mm512_setzero_pd(), sy = sx, sz = sx;
    for (std::size_t j = i0; j < i0 + B; j += 8) {
      const __m512d dx = _mm512_sub_pd(_mm512_loadu_pd(d.x + j), xi);
      const __m512d dy = _mm512_sub_pd(_mm512_loadu_pd(d.y + j), yi);
      const __m512d dz = _mm512_sub_pd(_mm512_loadu_pd(d.z + j), zi);
      const __m512d r2 = _mm512_fmadd_pd(dx, dx, _mm512_fmadd_pd(dy, dy, _mm512_fmadd_pd(dz, dz, e2)));
      __m512d w = _mm512_mul_pd(avx512_inv_r3(r2), _mm512_loadu_pd(d.m + j));
      if constexpr (Masked) w = _mm512_maskz_mov_pd(_mm512_cmp_pd_mask(r2, _mm512_setzero_pd(), _CMP_NEQ_OQ), w);
      sx = _mm512_fmadd_pd(w, dx, sx);
      sy = _mm512_fmadd_pd(w, dy, sy);
      sz = _mm512_fmadd_pd(w, dz, sz);
    }
    d.ax[i] += avx512_sum(sx);
    d.ay[i] += avx512_sum(sy);
    d.az[i] += avx512_sum(sz);
  }
}

/// r2^{-3/2} of rows i and i+1 with the B partners of block J (at j0), into w (row i) and w + B (row i+1);
/// lanes with r2 == 0 give 0 when Masked. Iterations independent of each other: only loads, the short
/// arithmetic of avx512_inv_r3 and stores, which the processor overlaps across iterations.
template <bool Masked>
NYSTROM_TARGET_AVX512 inline void avx512_real_w_rows(const RealTileData& d, std::size_t i, std::size_t j0,
                                                     std::size_t B, __m512d e2, double* __restrict w) {
  const __m512d xi = _mm512_set1_pd(d.x[i]), yi = _mm512_set1_pd(d.y[i]), zi = _mm512_set1_pd(d.z[i]);
  const __m512d xk = _mm512_set1_pd(d.x[i + 1]), yk = _mm512_set1_pd(d.y[i + 1]), zk = _mm512_set1_pd(d.z[i + 1]);
  for (std::size_t j = 0; j < B; j += 8) {
    const __m512d X = _mm512_loadu_pd(d.x + j0 + j), Y = _mm512_loadu_pd(d.y + j0 + j);
    const __m512d Z = _mm512_loadu_pd(d.z + j0 + j);
    const __m512d dx = _mm512_sub_pd(X, xi), dy = _mm512_sub_pd(Y, yi), dz = _mm512_sub_pd(Z, zi);
    const __m512d ex = _mm512_sub_pd(X, xk), ey = _mm512_sub_pd(Y, yk), ez = _mm512_sub_pd(Z, zk);
    const __m512d r2 = _mm512_fmadd_pd(dx, dx, _mm512_fmadd_pd(dy, dy, _mm512_fmadd_pd(dz, dz, e2)));
    const __m512d s2 = _mm512_fmadd_pd(ex, ex, _mm512_fmadd_pd(ey, ey, _mm512_fmadd_pd(ez, ez, e2)));
    __m512d u = avx512_inv_r3(r2), v = avx512_inv_r3(s2);
    if constexpr (Masked) {
      u = _mm512_maskz_mov_pd(_mm512_cmp_pd_mask(r2, _mm512_setzero_pd(), _CMP_NEQ_OQ), u);
      v = _mm512_maskz_mov_pd(_mm512_cmp_pd_mask(s2, _mm512_setzero_pd(), _CMP_NEQ_OQ), v);
    }
    _mm512_store_pd(w + j, u);
    _mm512_store_pd(w + B + j, v);
  }
}

inline constexpr std::size_t real_max_block = 256;  // nbody_block's largest block

/// Both directions of the interactions between block I (at i0) and block J (at j0), each pair once, in two
/// passes per two rows i, i+1 (B is a multiple of 8), as avx512_pair_complex: first r2^{-3/2} of both rows
/// with the whole block J (avx512_real_w_rows), then, with the separations recomputed, a_i += m_j w_ij d_ij
/// and a_j -= m_i w_ij d_ij (then row i+1). The arithmetic and its order are those of one pass per 8
/// partners (bitwise the same forces); the first pass's iterations are short and independent. Measured at
/// N = 10 000 on one core of a shared AMD EPYC (AVX-512): 0.52-0.57 ns per pair, one pass 0.54-0.57, within
/// the noise of that machine. Neither the two passes nor moving the accumulations to the adder (pair forces
/// m_i m_j w d, then a_i = F_i / m_i: fewer multiply-adds) changed the time measurably there.
template <bool Masked>
NYSTROM_TARGET_AVX512 inline void avx512_pair_real(const RealTileData& d, std::size_t i0, std::size_t j0, std::size_t B,
                                                   double eps2) {
  const __m512d e2 = _mm512_set1_pd(eps2);
  const double* __restrict x = d.x;
  const double* __restrict y = d.y;
  const double* __restrict z = d.z;
  const double* __restrict m = d.m;
  double* __restrict ax = d.ax;
  double* __restrict ay = d.ay;
  double* __restrict az = d.az;
  alignas(64) double wbuf[2 * real_max_block];
  for (std::size_t i = i0; i < i0 + B; i += 2) {
    avx512_real_w_rows<Masked>(d, i, j0, B, e2, wbuf);
    const __m512d xi = _mm512_set1_pd(x[i]), yi = _mm512_set1_pd(y[i]), zi = _mm512_set1_pd(z[i]);
    const __m512d xk = _mm512_set1_pd(x[i + 1]), yk = _mm512_set1_pd(y[i + 1]), zk = _mm512_set1_pd(z[i + 1]);
    const __m512d mi = _mm512_set1_pd(m[i]), mk = _mm512_set1_pd(m[i + 1]);
    __m512d sx = _mm512_setzero_pd(), sy = sx, sz = sx, tx = sx, ty = sx, tz = sx;
    for (std::size_t j = j0, jw = 0; j < j0 + B; j += 8, jw += 8) {
      const __m512d X = _mm512_loadu_pd(x + j), Y = _mm512_loadu_pd(y + j), Z = _mm512_loadu_pd(z + j);
      const __m512d M = _mm512_loadu_pd(m + j);
      const __m512d dx = _mm512_sub_pd(X, xi), dy = _mm512_sub_pd(Y, yi), dz = _mm512_sub_pd(Z, zi);
      const __m512d ex = _mm512_sub_pd(X, xk), ey = _mm512_sub_pd(Y, yk), ez = _mm512_sub_pd(Z, zk);
      const __m512d w = _mm512_load_pd(wbuf + jw), v = _mm512_load_pd(wbuf + B + jw);
      const __m512d wj = _mm512_mul_pd(w, M), vj = _mm512_mul_pd(v, M);
      const __m512d wi = _mm512_mul_pd(w, mi), vk = _mm512_mul_pd(v, mk);
      sx = _mm512_fmadd_pd(wj, dx, sx);
      sy = _mm512_fmadd_pd(wj, dy, sy);
      sz = _mm512_fmadd_pd(wj, dz, sz);
      tx = _mm512_fmadd_pd(vj, ex, tx);
      ty = _mm512_fmadd_pd(vj, ey, ty);
      tz = _mm512_fmadd_pd(vj, ez, tz);
      // a_j -= m_i w_ij d_ij, then row i+1: the same order as one row at a time.
      _mm512_storeu_pd(ax + j, _mm512_fnmadd_pd(vk, ex, _mm512_fnmadd_pd(wi, dx, _mm512_loadu_pd(ax + j))));
      _mm512_storeu_pd(ay + j, _mm512_fnmadd_pd(vk, ey, _mm512_fnmadd_pd(wi, dy, _mm512_loadu_pd(ay + j))));
      _mm512_storeu_pd(az + j, _mm512_fnmadd_pd(vk, ez, _mm512_fnmadd_pd(wi, dz, _mm512_loadu_pd(az + j))));
    }
    ax[i] += avx512_sum(sx);
    ay[i] += avx512_sum(sy);
    az[i] += avx512_sum(sz);
    ax[i + 1] += avx512_sum(tx);
    ay[i + 1] += avx512_sum(ty);
    az[i + 1] += avx512_sum(tz);
  }
}

struct ComplexTileData {
  const double *xr, *xi, *yr, *yi, *zr, *zi, *m;
  double *axr, *axi, *ayr, *ayi, *azr, *azi;
};

/// Complex separation d = q_j - q_i of row q (6 broadcast coordinates) and the 8 partners at j.
NYSTROM_TARGET_AVX512 inline void avx512_complex_d(const ComplexTileData& d, std::size_t j, const __m512d* q,
                                                   __m512d* dd) {
  dd[0] = _mm512_sub_pd(_mm512_loadu_pd(d.xr + j), q[0]);
  dd[1] = _mm512_sub_pd(_mm512_loadu_pd(d.xi + j), q[1]);
  dd[2] = _mm512_sub_pd(_mm512_loadu_pd(d.yr + j), q[2]);
  dd[3] = _mm512_sub_pd(_mm512_loadu_pd(d.yi + j), q[3]);
  dd[4] = _mm512_sub_pd(_mm512_loadu_pd(d.zr + j), q[4]);
  dd[5] = _mm512_sub_pd(_mm512_loadu_pd(d.zi + j), q[5]);
}

/// w = r2^{-3/2} for the 8 partners at j of row q, r2 = d.d + eps2 (complex); lanes with r2 == 0 give
/// w = 0 when Masked.
template <bool Masked>
NYSTROM_TARGET_AVX512 inline void avx512_complex_w(const ComplexTileData& d, std::size_t j, const __m512d* q,
                                                   __m512d e2, __m512d& wr, __m512d& wi) {
  __m512d dd[6];
  avx512_complex_d(d, j, q, dd);
  // Re r2 in two chains (x and z; y), to shorten the dependency chain.
  __m512d a = _mm512_fnmadd_pd(dd[1], dd[1], _mm512_fmadd_pd(dd[0], dd[0], e2));
  a = _mm512_fnmadd_pd(dd[5], dd[5], _mm512_fmadd_pd(dd[4], dd[4], a));
  a = _mm512_add_pd(a, _mm512_fnmadd_pd(dd[3], dd[3], _mm512_mul_pd(dd[2], dd[2])));
  __m512d b = _mm512_mul_pd(dd[0], dd[1]);
  b = _mm512_fmadd_pd(dd[2], dd[3], b);
  b = _mm512_fmadd_pd(dd[4], dd[5], b);
  b = _mm512_add_pd(b, b);
  avx512_complex_inv_pow32(a, b, wr, wi);
  if constexpr (Masked) {
    const __mmask8 nz = _mm512_cmp_pd_mask(a, _mm512_setzero_pd(), _CMP_NEQ_OQ) |
                        _mm512_cmp_pd_mask(b, _mm512_setzero_pd(), _CMP_NEQ_OQ);
    wr = _mm512_maskz_mov_pd(nz, wr);
    wi = _mm512_maskz_mov_pd(nz, wi);
  }
}

/// The largest block of the complex kernels (nbody_block's bound): their buffer of w is on the stack.
inline constexpr std::size_t complex_max_block = 256;

/// First pass over a block of partners (j0 .. j0 + B - 1) for rows i and i + 1: w of every pair, stored as
/// [wr_i, wi_i, wr_k, wi_k] per 8 partners. The pass has no dependency from one group of 8 partners to the
/// next, so the processor overlaps the long latency of the square roots and divisions of several groups;
/// interleaved with the accumulation (one pass) it ran 1.6x slower.
template <bool Masked>
NYSTROM_TARGET_AVX512 inline void avx512_complex_w_rows(const ComplexTileData& d, const __m512d* qi, const __m512d* qk,
                                                        std::size_t j0, std::size_t B, __m512d e2, double* wbuf) {
  for (std::size_t j = j0; j < j0 + B; j += 8, wbuf += 32) {
    __m512d wr, wi, vr, vi;
    avx512_complex_w<Masked>(d, j, qi, e2, wr, wi);
    avx512_complex_w<Masked>(d, j, qk, e2, vr, vi);
    _mm512_store_pd(wbuf, wr);
    _mm512_store_pd(wbuf + 8, wi);
    _mm512_store_pd(wbuf + 16, vr);
    _mm512_store_pd(wbuf + 24, vi);
  }
}

/// P = w d for the three complex components (P[2c] + i P[2c+1] = (wr + i wi)(d[2c] + i d[2c+1])).
NYSTROM_TARGET_AVX512 inline void avx512_complex_wd(const double* w, const __m512d* dd, __m512d* P) {
  const __m512d wr = _mm512_load_pd(w), wi = _mm512_load_pd(w + 8);
  for (int c = 0; c < 3; ++c) {
    P[2 * c] = _mm512_fnmadd_pd(wi, dd[2 * c + 1], _mm512_mul_pd(wr, dd[2 * c]));
    P[2 * c + 1] = _mm512_fmadd_pd(wi, dd[2 * c], _mm512_mul_pd(wr, dd[2 * c + 1]));
  }
}

NYSTROM_TARGET_AVX512 inline void avx512_complex_row(const ComplexTileData& d, std::size_t i, __m512d* q) {
  q[0] = _mm512_set1_pd(d.xr[i]);
  q[1] = _mm512_set1_pd(d.xi[i]);
  q[2] = _mm512_set1_pd(d.yr[i]);
  q[3] = _mm512_set1_pd(d.yi[i]);
  q[4] = _mm512_set1_pd(d.zr[i]);
  q[5] = _mm512_set1_pd(d.zi[i]);
}

/// Contributions within one block: rows i, i+1 at a time, each summing over all j of the block in order
/// (i's own term is zero: d = 0, or masked).
template <bool Masked>
NYSTROM_TARGET_AVX512 inline void avx512_diag_complex(const ComplexTileData& d, std::size_t i0, std::size_t B,
                                                      double eps2) {
  const __m512d e2 = _mm512_set1_pd(eps2);
  double* const out[6] = {d.axr, d.axi, d.ayr, d.ayi, d.azr, d.azi};
  alignas(64) double wbuf[4 * complex_max_block];
  for (std::size_t i = i0; i < i0 + B; i += 2) {
    __m512d qi[6], qk[6], s[6], t[6];
    avx512_complex_row(d, i, qi);
    avx512_complex_row(d, i + 1, qk);
    avx512_complex_w_rows<Masked>(d, qi, qk, i0, B, e2, wbuf);
    for (int c = 0; c < 6; ++c) s[c] = t[c] = _mm512_setzero_pd();
    const double* w = wbuf;
    for (std::size_t j = i0; j < i0 + B; j += 8, w += 32) {
      __m512d dd[6], ee[6], P[6], Q[6];
      avx512_complex_d(d, j, qi, dd);
      avx512_complex_d(d, j, qk, ee);
      avx512_complex_wd(w, dd, P);
      avx512_complex_wd(w + 16, ee, Q);
      const __m512d mj = _mm512_loadu_pd(d.m + j);
      for (int c = 0; c < 6; ++c) {
        s[c] = _mm512_fmadd_pd(mj, P[c], s[c]);
        t[c] = _mm512_fmadd_pd(mj, Q[c], t[c]);
      }
    }
    for (int c = 0; c < 6; ++c) {
      out[c][i] += avx512_sum(s[c]);
      out[c][i + 1] += avx512_sum(t[c]);
    }
  }
}

/// Both directions of the complex interactions between block I (at i0) and block J (at j0), each pair
/// once. Two rows i, i+1 at a time, as in avx512_pair_real: w of both rows and the whole block J first
/// (avx512_complex_w_rows), then, with P = w_ij d_ij, a_i += m_j P and a_j -= m_i P (then row i+1): the
/// loads of block J and the read-modify-write of its accelerations serve two rows.
template <bool Masked>
NYSTROM_TARGET_AVX512 inline void avx512_pair_complex(const ComplexTileData& d, std::size_t i0, std::size_t j0,
                                                      std::size_t B, double eps2) {
  const __m512d e2 = _mm512_set1_pd(eps2);
  const ComplexTileData dl = d;  // local copy: the stores below cannot alias its pointers
  double* const out[6] = {dl.axr, dl.axi, dl.ayr, dl.ayi, dl.azr, dl.azi};
  alignas(64) double wbuf[4 * complex_max_block];
  for (std::size_t i = i0; i < i0 + B; i += 2) {
    const std::size_t k = i + 1;
    __m512d qi[6], qk[6], s[6], t[6];
    avx512_complex_row(dl, i, qi);
    avx512_complex_row(dl, k, qk);
    avx512_complex_w_rows<Masked>(dl, qi, qk, j0, B, e2, wbuf);
    const __m512d mi = _mm512_set1_pd(dl.m[i]), mk = _mm512_set1_pd(dl.m[k]);
    for (int c = 0; c < 6; ++c) s[c] = t[c] = _mm512_setzero_pd();
    const double* w = wbuf;
    for (std::size_t j = j0; j < j0 + B; j += 8, w += 32) {
      __m512d dd[6], ee[6], P[6], Q[6];
      avx512_complex_d(dl, j, qi, dd);
      avx512_complex_d(dl, j, qk, ee);
      avx512_complex_wd(w, dd, P);
      avx512_complex_wd(w + 16, ee, Q);
      const __m512d mj = _mm512_loadu_pd(dl.m + j);
      for (int c = 0; c < 6; ++c) {
        s[c] = _mm512_fmadd_pd(mj, P[c], s[c]);
        t[c] = _mm512_fmadd_pd(mj, Q[c], t[c]);
        // a_j -= m_i P_ij, then row i+1: the same order as one row at a time.
        double* pa = out[c] + j;
        _mm512_storeu_pd(pa, _mm512_fnmadd_pd(mk, Q[c], _mm512_fnmadd_pd(mi, P[c], _mm512_loadu_pd(pa))));
      }
    }
    for (int c = 0; c < 6; ++c) {
      out[c][i] += avx512_sum(s[c]);
      out[c][k] += avx512_sum(t[c]);
    }
  }
}

#endif  // NYSTROM_HAVE_AVX512_KERNEL

/// Runs tile(I, J) for all block pairs I <= J in round-robin order (see the top of the file);
/// diag(I) first. Every tile is a task that depends on its two blocks: a block receives its contributions in
/// the round-robin order whatever the number of threads (bitwise the same result), and tiles of different
/// rounds that touch different blocks run side by side.
template <class Diag, class Pair>
void nbody_tiles(std::size_t nb, int threads, Diag diag, Pair pair) {
  const std::size_t P = nb + (nb % 2);  // players, with a phantom block if nb is odd
  // One thread, or a small system (a parallel region costs more than its force, and much more when the
  // machine is oversubscribed): the same order without tasks.
  if (threads <= 1 || nb < 8) {
    for (std::size_t I = 0; I < nb; ++I) diag(I);
    for (std::size_t r = 0; r + 1 < P; ++r)
      for (std::size_t k = 0; k < P / 2; ++k) {
        std::size_t I, J;
        round_robin_pair(P, r, k, I, J);
        if (J < nb) pair(I, J);
      }
    return;
  }
  // Measured at N = 10 000 on 2 cores shared with other work (load average 10): 54-84 ms per force on 2 threads
  // against 189-352 ms with one parallel loop per round, whose barrier (about 40 per force) waits for any
  // thread the operating system has descheduled.
  std::vector<char> block(nb);  // the task dependences' addresses, one per block
  char* dep = block.data();
  (void)dep;
  NYSTROM_OMP(omp parallel num_threads(threads))
  NYSTROM_OMP(omp single) {
    for (std::size_t I = 0; I < nb; ++I) {
      NYSTROM_OMP(omp task default(shared) firstprivate(I) depend(inout : dep[I]))
      diag(I);
    }
    for (std::size_t r = 0; r + 1 < P; ++r)
      for (std::size_t k = 0; k < P / 2; ++k) {
        std::size_t I, J;
        round_robin_pair(P, r, k, I, J);
        if (J >= nb) continue;
        NYSTROM_OMP(omp task default(shared) firstprivate(I, J) depend(inout : dep[I], dep[J]))
        pair(I, J);
      }
  }
}

}  // namespace detail

/// Masses and softening of an N-body system, shared (read-only) by all copies of a force functor.
template <class T>
struct NBodyParams {
  std::vector<T> m;
  T eps2 = T(0);
};

/// The force functor a(q) of the N-body problem for state vectors in SoA layout (see the top of the file).
/// Copies are cheap (the masses are shared); each copy has its own scratch space, so one copy must not be
/// called from two threads at once.
template <class T>
class NBodyForce {
 public:
  NBodyForce() = default;
  /// Masses (positive, finite) and the squared softening length (finite, >= 0).
  NBodyForce(std::vector<T> masses, T eps2) {
    if (masses.empty()) throw std::invalid_argument("N-body system has no particles");
    for (const auto& x : masses) {
      using std::isfinite;
      if (!isfinite(x) || !(x > T(0))) throw std::invalid_argument("particle masses must be positive and finite");
    }
    {
      using std::isfinite;
      if (!isfinite(eps2) || eps2 < T(0)) throw std::invalid_argument("softening eps^2 must be finite and >= 0");
    }
    auto p = std::make_shared<NBodyParams<T>>();
    p->m = std::move(masses);
    p->eps2 = eps2;
    params_ = std::move(p);
  }

  NBodyForce(const NBodyForce& o) : kernel(o.kernel), threads(o.threads), params_(o.params_) {}
  NBodyForce& operator=(const NBodyForce& o) {
    params_ = o.params_;
    kernel = o.kernel;
    threads = o.threads;
#if NYSTROM_HAVE_AVX512_KERNEL
    scratch_.reset();
#endif
    return *this;
  }
  NBodyForce(NBodyForce&&) noexcept = default;
  NBodyForce& operator=(NBodyForce&&) noexcept = default;
  ~NBodyForce() = default;

  std::size_t size() const { return params_ ? params_->m.size() : 0; }
  const std::vector<T>& masses() const { return params_->m; }
  T eps2() const { return params_->eps2; }

  /// Kernel choice (automatic: SIMD where available and N >= 64) and thread count (0: OpenMP's default).
  NBodyKernel kernel = NBodyKernel::automatic;
  int threads = 0;

  /// True when a call with scalar S would run the SIMD kernel.
  template <class S>
  bool uses_simd() const {
    if constexpr (std::is_same_v<real_t<S>, double>) {
      if (kernel == NBodyKernel::generic || !nbody_simd_available()) return false;
      return kernel == NBodyKernel::simd || size() >= 64;
    } else {
      return false;
    }
  }

  template <class V>
  void operator()(const V& q, V& a) const {
    check_state(q);
    resize_like(a, q);
    const int nt = threads > 0 ? threads : nbody_max_threads();
#if NYSTROM_HAVE_AVX512_KERNEL
    using S = typename V::value_type;
    if constexpr (std::is_same_v<S, double> || std::is_same_v<S, std::complex<double>>) {
      if (uses_simd<S>()) {
        simd_force(q, a, nt);
        return;
      }
    }
#endif
    generic_force(q, a, nt);
  }

  /// Throws std::invalid_argument unless q holds 3 coordinates for each of the particles (at least one).
  template <class V>
  void check_state(const V& q) const {
    const std::size_t n = size();
    if (n == 0) throw std::invalid_argument("N-body force used without a particle set");
    if (q.size() != 3 * n)
      throw std::invalid_argument("N-body state has " + std::to_string(q.size()) + " coordinates, expected 3 x " +
                                  std::to_string(n));
  }

  /// The generic kernel: a_i summed over j = 0..N-1 in order, OpenMP across i.
  template <class V>
  void generic_force(const V& q, V& a, int nt) const {
    using S = typename V::value_type;
    const long n = static_cast<long>(size());
    const T* m = params_->m.data();
    const S eps2 = S(params_->eps2);
    const auto* x = q.data();
    const auto* y = x + n;
    const auto* z = y + n;
    auto* ax = a.data();
    auto* ay = ax + n;
    auto* az = ay + n;
    (void)nt;
    NYSTROM_OMP(omp parallel for schedule(static) num_threads(nt) if (nt > 1 && n >= 256))
    for (long i = 0; i < n; ++i) {
      S sx(0), sy(0), sz(0);
      const S xi = x[i], yi = y[i], zi = z[i];
      for (long j = 0; j < n; ++j) {
        if (j == i) continue;
        const S dx = x[j] - xi, dy = y[j] - yi, dz = z[j] - zi;
        const S r2 = dx * dx + dy * dy + dz * dz + eps2;
        const S w = detail::mass_inv_r3(r2, m[j]);
        sx += w * dx;
        sy += w * dy;
        sz += w * dz;
      }
      ax[i] = sx;
      ay[i] = sy;
      az[i] = sz;
    }
  }

 private:
#if NYSTROM_HAVE_AVX512_KERNEL
  struct Scratch {
    std::size_t n = 0, ncomp = 0, B = 0, nb = 0, P = 0;  // P: padded length (nb * B)
    // Distance between consecutive arrays: P plus 72 doubles, so that the arrays do not start at the
    // same address modulo 4096 (4K aliasing between the stores to a_j and the loads of x_j costs 2x).
    std::size_t L = 0;
    std::vector<double> buf;
  };

  template <class V>
  void simd_force(const V& q, V& a, int nt) const {
    using S = typename V::value_type;
    constexpr bool cplx = is_complex_v<S>;
    const std::size_t n = size();
    if (!scratch_) scratch_ = std::make_unique<Scratch>();
    Scratch& s = *scratch_;
    constexpr std::size_t ncomp = cplx ? 6 : 3;  // position (and acceleration) arrays
    if (s.n != n || s.ncomp != ncomp) {
      s.n = n;
      s.ncomp = ncomp;
      s.B = detail::nbody_block(n);
      s.nb = (n + s.B - 1) / s.B;
      s.P = s.nb * s.B;
      s.L = s.P + 72;
      // layout: ncomp position arrays, the masses, ncomp acceleration arrays, each L long
      s.buf.assign((2 * ncomp + 1) * s.L, 0.0);
      double* m = s.buf.data() + ncomp * s.L;
      for (std::size_t i = 0; i < n; ++i) m[i] = static_cast<double>(params_->m[i]);  // padding: mass 0
    }
    const std::size_t L = s.L, B = s.B;
    double* pos = s.buf.data();
    double* mass = pos + ncomp * L;
    double* acc = mass + L;
    for (std::size_t c = 0; c < 3; ++c)
      for (std::size_t i = 0; i < n; ++i) {
        if constexpr (cplx) {
          pos[(2 * c) * L + i] = q[c * n + i].real();
          pos[(2 * c + 1) * L + i] = q[c * n + i].imag();
        } else {
          pos[c * L + i] = q[c * n + i];
        }
      }
    std::fill(acc, acc + ncomp * L, 0.0);
    const double e2 = static_cast<double>(params_->eps2);
    // With eps2 >= 1e-200, r2 >= eps2 > 0 and r2^{-3/2} is finite: the zero-separation mask is not needed.
    const bool masked = !(e2 >= 1e-200);
    if constexpr (cplx) {
      const detail::ComplexTileData d{pos, pos + L, pos + 2 * L, pos + 3 * L, pos + 4 * L, pos + 5 * L, mass,
                                      acc, acc + L, acc + 2 * L, acc + 3 * L, acc + 4 * L, acc + 5 * L};
      if (masked)
        detail::nbody_tiles(
            s.nb, nt, [&](std::size_t I) { detail::avx512_diag_complex<true>(d, I * B, B, e2); },
            [&](std::size_t I, std::size_t J) { detail::avx512_pair_complex<true>(d, I * B, J * B, B, e2); });
      else
        detail::nbody_tiles(
            s.nb, nt, [&](std::size_t I) { detail::avx512_diag_complex<false>(d, I * B, B, e2); },
            [&](std::size_t I, std::size_t J) { detail::avx512_pair_complex<false>(d, I * B, J * B, B, e2); });
      for (std::size_t c = 0; c < 3; ++c)
        for (std::size_t i = 0; i < n; ++i) a[c * n + i] = S(acc[(2 * c) * L + i], acc[(2 * c + 1) * L + i]);
    } else {
      const detail::RealTileData d{pos, pos + L, pos + 2 * L, mass, acc, acc + L, acc + 2 * L};
      if (masked)
        detail::nbody_tiles(
            s.nb, nt, [&](std::size_t I) { detail::avx512_diag_real<true>(d, I * B, B, e2); },
            [&](std::size_t I, std::size_t J) { detail::avx512_pair_real<true>(d, I * B, J * B, B, e2); });
      else
        detail::nbody_tiles(
            s.nb, nt, [&](std::size_t I) { detail::avx512_diag_real<false>(d, I * B, B, e2); },
            [&](std::size_t I, std::size_t J) { detail::avx512_pair_real<false>(d, I * B, J * B, B, e2); });
      for (std::size_t c = 0; c < 3; ++c)
        for (std::size_t i = 0; i < n; ++i) a[c * n + i] = acc[c * L + i];
    }
  }
  mutable std::unique_ptr<Scratch> scratch_;
#endif
  std::shared_ptr<const NBodyParams<T>> params_;
};

/// The N-body force with its own rounding error, for states of double or float: besides NBodyForce's force(q, a),
/// the compensated force(q, cq, a, alo) takes the positions q + cq (cq their carries) and returns the accelerations
/// as a + alo, every pair in double-word arithmetic from error-free transformations (core/eft.hpp): the separation
/// (q_j + cq_j) - (q_i + cq_i) from an exact two-sum, r^2 + eps^2 with exact squares, m_j / r^3 with one square root
/// and one division refined by Newton corrections (eft::dw_inv_r3), and each particle's sum over j in increasing
/// order as a double-word. Relative error a few units of the working precision squared where force(q, a) rounds at
/// units of it; about 6-10x the plain generic kernel's cost per pair (each pair computed for both particles, OpenMP
/// across particles, bitwise independent of the thread count). The splitting, multi-product and adaptive RKN
/// engines use it on a compensated run (takes_carry_v).
template <class T>
class CompensatedNBodyForce : public NBodyForce<T> {
 public:
  using NBodyForce<T>::NBodyForce;
  using NBodyForce<T>::operator();

  template <class V, class S = typename V::value_type>
  requires std::is_floating_point_v<S>
  void operator()(const V& q, const V& cq, V& a, V& alo) const {
    using eft::fast_two_sum;
    using eft::two_prod;
    using eft::two_sum;
    this->check_state(q);
    this->check_state(cq);
    resize_like(a, q);
    resize_like(alo, q);
    const long n = static_cast<long>(this->size());
    const auto& masses = this->masses();
    const S eps2 = S(this->eps2());
    const int nt = this->threads > 0 ? this->threads : nbody_max_threads();
    (void)nt;
    NYSTROM_OMP(omp parallel for schedule(static) num_threads(nt) if (nt > 1 && n >= 256))
    for (long i = 0; i < n; ++i) {
      S sum[3] = {0, 0, 0}, low[3] = {0, 0, 0};
      for (long j = 0; j < n; ++j) {
        if (j == i) continue;
        S d[3], dl[3];
        for (long c = 0; c < 3; ++c) {
          S e;
          d[c] = two_sum(q[c * n + j], S(-q[c * n + i]), e);
          dl[c] = e + (cq[c * n + j] - cq[c * n + i]);
        }
        // r^2 + eps^2 = r2 + r2l
        S e0, e1, e2, e3, e4;
        const S x2 = two_prod(d[0], d[0], e0), y2 = two_prod(d[1], d[1], e1), z2 = two_prod(d[2], d[2], e2);
        const S s1 = two_sum(x2, y2, e3);
        const S s2 = two_sum(s1, z2, e4);
        S e5;
        const S s3 = two_sum(s2, eps2, e5);
        if (s3 == S(0)) continue;  // coincident particles without softening contribute nothing, as in force(q, a)
        S r2l;
        const S r2 = fast_two_sum(
            s3,
            ((e0 + e1) + (e2 + e3)) + (e4 + e5) +
                (S(2) * (d[0] * dl[0] + d[1] * dl[1] + d[2] * dl[2]) + (dl[0] * dl[0] + dl[1] * dl[1] + dl[2] * dl[2])),
            r2l);
        // w = m_j / r^3 = w + wl
        S ml;
        const S m0 = eft::dw_inv_r3(r2, r2l, ml);
        const S mj = S(masses[static_cast<std::size_t>(j)]);
        S ew;
        const S w = two_prod(mj, m0, ew);
        const S wl = ew + mj * ml;
        for (long c = 0; c < 3; ++c) {
          S ep, es;
          const S p = two_prod(w, d[c], ep);
          sum[c] = two_sum(sum[c], p, es);
          low[c] += es + (ep + (w * dl[c] + wl * d[c]));
        }
      }
      for (long c = 0; c < 3; ++c) {
        S lo;
        a[c * n + i] = fast_two_sum(sum[c], low[c], lo);
        alo[c * n + i] = lo;
      }
    }
  }
};

/// Kinetic energy sum m_i |v_i|^2 / 2 (real part for complex states).
template <class T, class V>
T nbody_kinetic_energy(const std::vector<T>& m, const V& v) {
  const std::size_t n = m.size();
  T k(0);
  for (std::size_t c = 0; c < 3; ++c)
    for (std::size_t i = 0; i < n; ++i) {
      const T vi = static_cast<T>(std::real(v[c * n + i]));
      k += m[i] * vi * vi / T(2);
    }
  return k;
}

/// Softened potential energy -sum_{i<j} m_i m_j / sqrt(r_ij^2 + eps^2) of real positions; deterministic
/// (per-particle partial sums, added in order) and parallel.
template <class T, class V>
T nbody_potential_energy(const std::vector<T>& m, const T& eps2, const V& q, int threads = 0) {
  const long n = static_cast<long>(m.size());
  if (q.size() != 3 * m.size()) throw std::invalid_argument("N-body state has the wrong size for its particle set");
  std::vector<T> part(static_cast<std::size_t>(n), T(0));
  const int nt = threads > 0 ? threads : nbody_max_threads();
  (void)nt;
  NYSTROM_OMP(omp parallel for schedule(dynamic, 16) num_threads(nt) if (nt > 1 && n >= 256))
  for (long i = 0; i < n; ++i) {
    using std::sqrt;
    T s(0);
    const T xi = static_cast<T>(std::real(q[i])), yi = static_cast<T>(std::real(q[n + i])),
            zi = static_cast<T>(std::real(q[2 * n + i]));
    for (long j = i + 1; j < n; ++j) {
      const T dx = static_cast<T>(std::real(q[j])) - xi, dy = static_cast<T>(std::real(q[n + j])) - yi,
              dz = static_cast<T>(std::real(q[2 * n + j])) - zi;
      const T r2 = dx * dx + dy * dy + dz * dz + eps2;
      if (r2 > T(0)) s += m[j] / sqrt(r2);
    }
    part[static_cast<std::size_t>(i)] = -m[static_cast<std::size_t>(i)] * s;
  }
  T w(0);
  for (const auto& p : part) w += p;
  return w;
}

/// Total energy of a real N-body state with the given force's masses and softening.
template <class T, class V>
T nbody_energy(const NBodyForce<T>& f, const State<V>& s) {
  return nbody_kinetic_energy(f.masses(), s.v) + nbody_potential_energy(f.masses(), f.eps2(), s.q, f.threads);
}

/// Total momentum (3 components) and centre of mass (3 components) of a real state.
template <class T, class V>
std::array<T, 6> nbody_momentum_and_centre(const std::vector<T>& m, const State<V>& s) {
  const std::size_t n = m.size();
  std::array<T, 6> r{};
  T M(0);
  for (std::size_t i = 0; i < n; ++i) M += m[i];
  for (std::size_t c = 0; c < 3; ++c)
    for (std::size_t i = 0; i < n; ++i) {
      r[c] += m[i] * static_cast<T>(std::real(s.v[c * n + i]));
      r[3 + c] += m[i] * static_cast<T>(std::real(s.q[c * n + i])) / M;
    }
  return r;
}

/// A particle set: masses and phase-space state in SoA layout, real type T.
template <class T>
struct ParticleSet {
  std::vector<T> m;
  State<std::vector<T>> s;
  std::size_t size() const { return m.size(); }
};

/// The two-body problem of the Gürkan paper: two equal masses 1/2 (G = M = 1), relative orbit of
/// semi-major axis 1 and eccentricity e (period 2 pi), started at apocentre in the x-y plane, centre of
/// mass at rest at the origin. Relative coordinates follow KeplerProblem (problems/kepler.hpp):
/// r(0) = (1+e, 0), v(0) = (0, sqrt((1-e)/(1+e))); body 1 at -r/2, body 2 at +r/2. No softening.
template <class T>
ParticleSet<T> two_body(const T& e) {
  using std::isfinite;
  using std::sqrt;
  if (!isfinite(e) || !(e >= T(0)) || !(e < T(1))) throw std::invalid_argument("eccentricity must satisfy 0 <= e < 1");
  ParticleSet<T> p;
  p.m = {T(1) / T(2), T(1) / T(2)};
  p.s.q.assign(6, T(0));
  p.s.v.assign(6, T(0));
  const T rx = T(1) + e, vy = sqrt((T(1) - e) / (T(1) + e));
  p.s.q[0] = -rx / T(2);  // x_0
  p.s.q[1] = rx / T(2);   // x_1
  p.s.v[2] = -vy / T(2);  // vy_0
  p.s.v[3] = vy / T(2);   // vy_1
  return p;
}

}  // namespace nystrom
