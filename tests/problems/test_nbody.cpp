// N-body force (generic and SIMD kernels, real and complex, thread-count independence), whole runs bitwise
// reproducible across thread counts, two-body and Plummer initial conditions, particle files, statistics.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "nystrom/diagnostics/stats.hpp"
#include "nystrom/engines/integrator.hpp"
#include "nystrom/engines/splitting.hpp"
#include "nystrom/methods/catalog.hpp"
#include "nystrom/problems/nbody.hpp"
#include "nystrom/problems/plummer.hpp"

using namespace nystrom;
using C = std::complex<double>;

namespace {

std::vector<C> complexify(const std::vector<double>& q, double scale, unsigned seed) {
  std::mt19937_64 g(seed);
  std::vector<C> out(q.size());
  for (std::size_t i = 0; i < q.size(); ++i) out[i] = C(q[i], scale * (detail::uniform01(g) - 0.5));
  return out;
}

template <class V>
double max_rel_diff(const V& a, const V& b) {
  double m = 0, s = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    m = std::max(m, std::abs(a[i] - b[i]));
    s = std::max(s, std::abs(a[i]));
  }
  return m / s;
}

std::string temp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("nystrom_test_nbody_" + name)).string();
}

}  // namespace

TEST(NBodyForce, TwoBodiesFollowNewton) {
  NBodyForce<double> f({2.0, 3.0}, 0.0);
  const std::vector<double> q = {0.0, 1.0, 0.0, 2.0, 0.0, 2.0};  // x0=0, x1=1; y0=0, y1=2; z0=0, z1=2: r = 3
  std::vector<double> a;
  f(q, a);
  // a_0 = m_1 (q_1 - q_0) / r^3 = 3 (1, 2, 2) / 27;  a_1 = -m_0 (1, 2, 2) / 27
  EXPECT_NEAR(a[0], 3.0 / 27, 1e-15);
  EXPECT_NEAR(a[2], 6.0 / 27, 1e-15);
  EXPECT_NEAR(a[4], 6.0 / 27, 1e-15);
  EXPECT_NEAR(a[1], -2.0 / 27, 1e-15);
  EXPECT_NEAR(a[3], -4.0 / 27, 1e-15);
  EXPECT_NEAR(a[5], -4.0 / 27, 1e-15);
  // Softening: r^2 -> r^2 + eps^2.
  NBodyForce<double> g({2.0, 3.0}, 16.0);
  g(q, a);
  EXPECT_NEAR(a[0], 3.0 / 125, 1e-15);
}

TEST(NBodyForce, RejectsBadInput) {
  EXPECT_THROW(NBodyForce<double>({}, 0.0), std::invalid_argument);
  EXPECT_THROW(NBodyForce<double>({1.0, -1.0}, 0.0), std::invalid_argument);
  EXPECT_THROW(NBodyForce<double>({1.0, NAN}, 0.0), std::invalid_argument);
  EXPECT_THROW(NBodyForce<double>({1.0, 1.0}, -1.0), std::invalid_argument);
  EXPECT_THROW(NBodyForce<double>({1.0, 1.0}, INFINITY), std::invalid_argument);
  NBodyForce<double> f({1.0, 1.0}, 0.0);
  std::vector<double> q(5, 0.0), a;
  EXPECT_THROW(f(q, a), std::invalid_argument);
  NBodyForce<double> empty;
  EXPECT_THROW(empty(q, a), std::invalid_argument);
}

TEST(NBodyForce, ComplexInversePowerIsThePrincipalBranch) {
  const double vals[] = {3.0, 0.5, -0.7, -2.0, 1e-3};
  for (double a : vals)
    for (double b : vals) {
      double wr, wi;
      detail::complex_inv_pow32(a, b, wr, wi);
      const C ref = std::pow(C(a, b), -1.5);
      EXPECT_NEAR(wr, ref.real(), 1e-13 * std::abs(ref)) << a << " " << b;
      EXPECT_NEAR(wi, ref.imag(), 1e-13 * std::abs(ref)) << a << " " << b;
    }
  // On the negative real axis the sign of the zero imaginary part picks the side of the cut.
  double wr, wi;
  detail::complex_inv_pow32(-4.0, 0.0, wr, wi);
  EXPECT_NEAR(wi, std::pow(C(-4.0, 0.0), -1.5).imag(), 1e-15);
  detail::complex_inv_pow32(-4.0, -0.0, wr, wi);
  EXPECT_NEAR(wi, std::pow(C(-4.0, -0.0), -1.5).imag(), 1e-15);
}

#if NYSTROM_HAVE_AVX512_KERNEL
// The SIMD r^{-3/2} (hardware square root and division, a branch for lanes with Re z < 0) against the
// scalar reference and std::pow, in all four quadrants, on the cut and far from 1; a lane's result does
// not depend on the other lanes of its vector (a vector with one lane of Re z < 0 takes the other path).
TEST(NBodyForce, SimdComplexInversePowerAgreesWithTheScalarReference) {
  if (!nbody_simd_available()) GTEST_SKIP() << "no AVX-512 on this CPU";
  std::vector<std::pair<double, double>> z = {{3.0, 0.5},   {3.0, -0.5},     {-0.7, 2.0},  {-0.7, -2.0},  {-4.0, 0.0},
                                              {-4.0, -0.0}, {4.0, 0.0},      {1e-3, 1e-3}, {0.0, 2.0},    {0.0, -2.0},
                                              {1e60, 3e59}, {-2e-50, 1e-50}, {5e-3, -7e2}, {-1.0, 1e-30}, {2.5, 1e-12}};
  std::mt19937_64 g(17);
  for (int k = 0; k < 200; ++k) {
    const double r = std::exp(40 * (detail::uniform01(g) - 0.5)), t = 6.283185307179586 * detail::uniform01(g);
    z.emplace_back(r * std::cos(t), r * std::sin(t));
  }
  double worst = 0;
  for (std::size_t k = 0; k + 8 <= z.size(); k += 8) {
    double a[8], b[8], wr[8], wi[8];
    for (int l = 0; l < 8; ++l) std::tie(a[l], b[l]) = z[k + l];
    detail::avx512_complex_inv_pow32_lanes(a, b, wr, wi);
    for (int l = 0; l < 8; ++l) {
      // Reference: the scalar formula in long double (64-bit mantissa), and std::pow for the branch.
      long double lr, li;
      detail::complex_inv_pow32<long double>(a[l], b[l], lr, li);
      const C ref = std::pow(C(a[l], b[l]), -1.5);
      const double mag = std::abs(ref);
      const double err = static_cast<double>(std::hypot(wr[l] - lr, wi[l] - li)) / mag;
      EXPECT_LT(err, 4 * 0x1p-52) << a[l] << " " << b[l];  // a few ulp
      EXPECT_NEAR(wr[l], ref.real(), 1e-14 * mag) << a[l] << " " << b[l];
      EXPECT_NEAR(wi[l], ref.imag(), 1e-14 * mag) << a[l] << " " << b[l];
      worst = std::max(worst, err);
      // The same z alone in an otherwise right-half-plane (or left-half-plane) vector: the same bits.
      for (double fill : {1.0, -1.0}) {
        double a1[8], b1[8], vr[8], vi[8];
        for (int m = 0; m < 8; ++m) a1[m] = fill, b1[m] = 0.25;
        a1[3] = a[l];
        b1[3] = b[l];
        detail::avx512_complex_inv_pow32_lanes(a1, b1, vr, vi);
        EXPECT_EQ(vr[3], wr[l]);
        EXPECT_EQ(vi[3], wi[l]);
      }
    }
  }
  EXPECT_GT(worst, 0.0);  // the comparison is not vacuous
}
#endif

// The complex force is the analytic continuation: Im a(q + i d u) / d is the directional derivative of the
// real force (complex-step differentiation), Re a(q + i d u) = a(q) + O(d^2).
TEST(NBodyForce, ComplexForceIsTheAnalyticContinuation) {
  for (auto kernel : {NBodyKernel::generic, NBodyKernel::simd}) {
    if (kernel == NBodyKernel::simd && !nbody_simd_available()) continue;
    auto p = plummer_sphere<double>(100, 7);
    NBodyForce<double> f(p.m, 1e-4);
    f.kernel = kernel;
    std::vector<double> u(p.s.q.size());
    std::mt19937_64 g(3);
    for (auto& x : u) x = detail::uniform01(g) - 0.5;
    const double d = 1e-20;
    std::vector<C> qc(p.s.q.size()), ac;
    for (std::size_t i = 0; i < u.size(); ++i) qc[i] = C(p.s.q[i], d * u[i]);
    f(qc, ac);
    const double fd = 1e-5;
    std::vector<double> qp = p.s.q, qm = p.s.q, ap, am, a0;
    for (std::size_t i = 0; i < u.size(); ++i) {
      qp[i] += fd * u[i];
      qm[i] -= fd * u[i];
    }
    f(qp, ap);
    f(qm, am);
    f(p.s.q, a0);
    double scale = 0, err_im = 0, err_re = 0;
    for (std::size_t i = 0; i < u.size(); ++i) {
      const double deriv = (ap[i] - am[i]) / (2 * fd);
      scale = std::max(scale, std::abs(deriv));
      err_im = std::max(err_im, std::abs(ac[i].imag() / d - deriv));
      err_re = std::max(err_re, std::abs(ac[i].real() - a0[i]) / std::max(1.0, std::abs(a0[i])));
    }
    EXPECT_LT(err_im / scale, 1e-6);
    EXPECT_LT(err_re, 1e-12);
  }
}

TEST(NBodyForce, SimdKernelAgreesWithGenericKernel) {
  if (!nbody_simd_available()) GTEST_SKIP() << "no AVX-512 on this CPU: only the generic kernel runs";
  for (std::size_t n : {64u, 301u, 1000u}) {
    for (double eps2 : {0.0, 1.0 / (double(n) * double(n))}) {
      auto p = plummer_sphere<double>(n, 11 + n);
      NBodyForce<double> f(p.m, eps2);
      std::vector<double> ag, as;
      f.kernel = NBodyKernel::generic;
      f(p.s.q, ag);
      f.kernel = NBodyKernel::simd;
      EXPECT_TRUE(f.uses_simd<double>());
      f(p.s.q, as);
      EXPECT_LT(max_rel_diff(ag, as), 1e-13) << "n = " << n << " eps2 = " << eps2;
      const auto qc = complexify(p.s.q, 1e-3, 5);
      std::vector<C> bg, bs;
      f.kernel = NBodyKernel::generic;
      f(qc, bg);
      f.kernel = NBodyKernel::simd;
      f(qc, bs);
      EXPECT_LT(max_rel_diff(bg, bs), 1e-13) << "complex, n = " << n << " eps2 = " << eps2;
    }
  }
}

// Imaginary parts large enough that Re r^2 < 0 for some pairs (the other branch of the SIMD r^{-3/2}).
TEST(NBodyForce, SimdComplexKernelAgreesFarFromTheRealAxis) {
  if (!nbody_simd_available()) GTEST_SKIP() << "no AVX-512 on this CPU";
  auto p = plummer_sphere<double>(300, 23);
  const auto qc = complexify(p.s.q, 0.6, 29);
  long left = 0;
  for (std::size_t i = 0; i < 300; ++i)
    for (std::size_t j = 0; j < 300; ++j) {
      C r2 = 0;
      for (std::size_t c = 0; c < 3; ++c)
        r2 += (qc[c * 300 + j] - qc[c * 300 + i]) * (qc[c * 300 + j] - qc[c * 300 + i]);
      left += (r2.real() + 1e-4 < 0) ? 1 : 0;
    }
  EXPECT_GT(left, 1000);  // the test covers the branch
  for (double eps2 : {0.0, 1e-4}) {
    NBodyForce<double> f(p.m, eps2);
    std::vector<C> bg, bs;
    f.kernel = NBodyKernel::generic;
    f(qc, bg);
    f.kernel = NBodyKernel::simd;
    f(qc, bs);
    EXPECT_LT(max_rel_diff(bg, bs), 1e-12) << "eps2 = " << eps2;
  }
}

// The largest blocks (B = 256 from N = 8192 on, the size of the complex kernel's stack buffer), a padded
// last block: sampled particles against direct sums with the scalar reference.
TEST(NBodyForce, SimdKernelsAgreeWithDirectSumsOnLargeBlocks) {
  if (!nbody_simd_available()) GTEST_SKIP() << "no AVX-512 on this CPU";
  const std::size_t n = 8200;
  ASSERT_EQ(detail::nbody_block(n), 256u);
  auto p = plummer_sphere<double>(n, 31, [] {
    PlummerOptions o;
    o.exact_energy = false;
    return o;
  }());
  const auto qc = complexify(p.s.q, 1e-3, 37);
  for (double eps2 : {0.0, 1.0 / (double(n) * double(n))}) {
    NBodyForce<double> f(p.m, eps2);
    f.kernel = NBodyKernel::simd;
    std::vector<double> a;
    std::vector<C> ac;
    f(p.s.q, a);
    f(qc, ac);
    double dr = 0, sr = 0, dc = 0, sc = 0;
    for (std::size_t i = 0; i < n; i += 97) {
      double s[3] = {0, 0, 0};
      C t[3] = {0, 0, 0};
      for (std::size_t j = 0; j < n; ++j) {
        if (j == i) continue;
        double d[3];
        C e[3];
        for (std::size_t c = 0; c < 3; ++c) {
          d[c] = p.s.q[c * n + j] - p.s.q[c * n + i];
          e[c] = qc[c * n + j] - qc[c * n + i];
        }
        const double w = detail::mass_inv_r3(d[0] * d[0] + d[1] * d[1] + d[2] * d[2] + eps2, p.m[j]);
        const C v = detail::mass_inv_r3(e[0] * e[0] + e[1] * e[1] + e[2] * e[2] + eps2, p.m[j]);
        for (std::size_t c = 0; c < 3; ++c) {
          s[c] += w * d[c];
          t[c] += v * e[c];
        }
      }
      for (std::size_t c = 0; c < 3; ++c) {
        dr = std::max(dr, std::abs(s[c] - a[c * n + i]));
        sr = std::max(sr, std::abs(s[c]));
        dc = std::max(dc, std::abs(t[c] - ac[c * n + i]));
        sc = std::max(sc, std::abs(t[c]));
      }
    }
    EXPECT_LT(dr / sr, 1e-13) << "eps2 = " << eps2;
    EXPECT_LT(dc / sc, 1e-13) << "eps2 = " << eps2;
  }
}

// The real SIMD kernel (two passes per pair of rows) against the pairwise sums written out in long double,
// N = 130: three blocks of 64, the last one padded, so the diagonal tiles, the pair tiles and the padding all
// contribute. Per component, |a - a_ref| within 1e-14 of sum_j |m_j d_ij / r_ij^3| (about 45 ulp of that
// scale; the kernel's r^{-3} is good to a few ulp and its sums run over at most N terms).
TEST(NBodyForce, SimdRealKernelAgreesWithLongDoublePairwiseSums) {
  if (!nbody_simd_available()) GTEST_SKIP() << "no AVX-512 on this CPU";
  const std::size_t n = 130;
  auto p = plummer_sphere<double>(n, 41);
  for (double eps2 : {0.0, 1.0 / (double(n) * double(n))}) {
    NBodyForce<double> f(p.m, eps2);
    f.kernel = NBodyKernel::simd;
    std::vector<double> a;
    f(p.s.q, a);
    double worst = 0;
    for (std::size_t i = 0; i < n; ++i) {
      long double s[3] = {0, 0, 0}, scale[3] = {0, 0, 0};
      for (std::size_t j = 0; j < n; ++j) {
        if (j == i) continue;
        long double d[3];
        for (std::size_t c = 0; c < 3; ++c)
          d[c] = static_cast<long double>(p.s.q[c * n + j]) - static_cast<long double>(p.s.q[c * n + i]);
        const long double r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2] + static_cast<long double>(eps2);
        const long double w = static_cast<long double>(p.m[j]) / (r2 * std::sqrt(r2));
        for (std::size_t c = 0; c < 3; ++c) {
          s[c] += w * d[c];
          scale[c] += std::abs(w * d[c]);
        }
      }
      for (std::size_t c = 0; c < 3; ++c)
        worst =
            std::max(worst, static_cast<double>(std::abs(static_cast<long double>(a[c * n + i]) - s[c]) / scale[c]));
    }
    EXPECT_LT(worst, 1e-14) << "eps2 = " << eps2;
    EXPECT_GT(worst, 0.0);  // the kernel runs in double: some rounding shows
  }
}

TEST(NBodyForce, ResultsDoNotDependOnTheThreadCount) {
  auto p = plummer_sphere<double>(1500, 5);
  const auto qc = complexify(p.s.q, 1e-3, 9);
  for (auto kernel : {NBodyKernel::generic, NBodyKernel::simd}) {
    if (kernel == NBodyKernel::simd && !nbody_simd_available()) continue;
    NBodyForce<double> f(p.m, 1e-6);
    f.kernel = kernel;
    std::vector<double> a1, an;
    std::vector<C> c1, cn;
    f.threads = 1;
    f(p.s.q, a1);
    f(qc, c1);
    for (int t : {2, 3, 4, 7}) {
      f.threads = t;
      f(p.s.q, an);
      f(qc, cn);
      EXPECT_TRUE(a1 == an) << "threads = " << t;  // bitwise
      EXPECT_TRUE(c1 == cn) << "threads = " << t;
    }
  }
}

TEST(NBodyForce, ConservesMomentum) {
  auto p = plummer_sphere<double>(500, 1);
  NBodyForce<double> f(p.m, 1e-4);
  std::vector<double> a;
  f(p.s.q, a);
  for (std::size_t c = 0; c < 3; ++c) {
    double s = 0, mag = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      s += p.m[i] * a[c * p.size() + i];
      mag += std::abs(p.m[i] * a[c * p.size() + i]);
    }
    EXPECT_LT(std::abs(s), 1e-13 * mag);
  }
}

TEST(NBodyForce, LongDoubleAgreesWithDouble) {
  auto p = plummer_sphere<double>(50, 2);
  NBodyForce<double> f(p.m, 0.0);
  std::vector<long double> m(p.m.begin(), p.m.end()), q(p.s.q.begin(), p.s.q.end()), al;
  NBodyForce<long double> fl(m, 0.0L);
  std::vector<double> a;
  f(p.s.q, a);
  fl(q, al);
  for (std::size_t i = 0; i < a.size(); ++i)
    EXPECT_NEAR(a[i], static_cast<double>(al[i]), 1e-12 * (1 + std::abs(a[i])));
}

TEST(NBodyForce, IntegratesWithRealAndComplexSplittings) {
  // Leapfrog conserves the energy of a softened Plummer sphere to O(h^2); the complex third-order method
  // of Chambers (imaginary parts dropped after each step) does better at the same step.
  auto p = plummer_sphere<double>(64, 3);
  NBodyForce<double> f(p.m, 1.0 / (64.0 * 64.0));
  const double e0 = nbody_energy(f, p.s);
  SplittingScheme<double> lf{{{Flow::kick, 0.5}, {Flow::drift, 1.0}, {Flow::kick, 0.5}}};
  SplittingStepper<std::vector<double>, NBodyForce<double>> st(lf, f);
  auto s = p.s;
  st.integrate(s, 1e-3, 200);
  const double dlf = std::abs(nbody_energy(f, s) - e0);
  EXPECT_LT(dlf, 1e-5);
  const C a1(0.25, 0.25 / std::sqrt(3.0));
  SplittingScheme<C> ch{{{Flow::drift, a1},
                         {Flow::kick, 2.0 * a1},
                         {Flow::drift, C(0.5)},
                         {Flow::kick, std::conj(2.0 * a1)},
                         {Flow::drift, std::conj(a1)}}};
  SplittingStepper<std::vector<C>, NBodyForce<double>> sc(ch, f);
  auto z = convert_state<std::vector<C>>(p.s);
  sc.integrate(z, 1e-3, 200);
  const auto zr = convert_state<std::vector<double>>(z);
  const double dch = std::abs(nbody_energy(f, zr) - e0);
  EXPECT_LT(dch, dlf);
}

TEST(TwoBody, IsTheKeplerOrbitInTheCentreOfMassFrame) {
  const auto p = two_body(0.2);
  ASSERT_EQ(p.size(), 2u);
  // relative position (1.2, 0, 0), relative velocity (0, sqrt(0.8/1.2), 0); total momentum zero
  EXPECT_DOUBLE_EQ(p.s.q[1] - p.s.q[0], 1.2);
  EXPECT_NEAR(p.s.v[3] - p.s.v[2], std::sqrt(0.8 / 1.2), 1e-15);
  EXPECT_EQ(p.m[0] * p.s.v[2] + p.m[1] * p.s.v[3], 0.0);
  NBodyForce<double> f(p.m, 0.0);
  // E = -G m1 m2 / (2a) = -1/8
  EXPECT_NEAR(nbody_energy(f, p.s), -0.125, 1e-15);
  EXPECT_THROW(two_body(1.0), std::invalid_argument);
  EXPECT_THROW(two_body(-0.1), std::invalid_argument);
}

TEST(Plummer, IsReproducibleAndInStandardUnits) {
  const auto a = plummer_sphere<double>(1000, 42), b = plummer_sphere<double>(1000, 42),
             c = plummer_sphere<double>(1000, 43);
  EXPECT_TRUE(a.s.q == b.s.q && a.s.v == b.s.v);
  EXPECT_FALSE(a.s.q == c.s.q);
  EXPECT_NEAR(particle_energy(a), -0.25, 1e-13);
  const auto pc = nbody_momentum_and_centre(a.m, a.s);
  for (double x : pc) EXPECT_NEAR(x, 0.0, 1e-15);
  // Virial ratio 2T/|W| near 1, half-mass radius near 0.769 (Plummer: 1.305 a with a = 3 pi / 16).
  const double T = nbody_kinetic_energy(a.m, a.s.v), W = nbody_potential_energy(a.m, 0.0, a.s.q);
  EXPECT_NEAR(2 * T / -W, 1.0, 0.15);
  std::vector<double> r(a.size());
  for (std::size_t i = 0; i < a.size(); ++i)
    r[i] = std::sqrt(a.s.q[i] * a.s.q[i] + a.s.q[1000 + i] * a.s.q[1000 + i] + a.s.q[2000 + i] * a.s.q[2000 + i]);
  EXPECT_NEAR(median(r), 0.769, 0.08);
  EXPECT_THROW(plummer_sphere<double>(1, 1), std::invalid_argument);
}

TEST(ParticleFile, RoundTripsBitForBit) {
  const auto p = plummer_sphere<double>(37, 9);
  const std::string path = temp_path("roundtrip.csv");
  save_particles(path, p);
  const auto q = load_particles<double>(path);
  EXPECT_TRUE(p.m == q.m && p.s.q == q.s.q && p.s.v == q.s.v);
  std::filesystem::remove(path);
}

TEST(ParticleFile, RejectsMalformedFiles) {
  const std::string path = temp_path("bad.csv");
  auto check = [&](const std::string& text, const std::string& what) {
    { std::ofstream(path) << text; }
    try {
      load_particles<double>(path);
      ADD_FAILURE() << "accepted: " << what;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("line"), std::string::npos) << e.what();
    }
  };
  const std::string ok = "1,0,0,0,0,0,0\n";
  check(ok + "1,0,0,0,0,0\n", "six numbers");
  check(ok + "1,0,0,0,0,0,0,0\n", "eight numbers");
  check(ok + "1,0,0,x,0,0,0\n", "not a number");
  check(ok + "1,0,0,1e999,0,0,0\n", "overflow");
  check(ok + "-1,0,0,0,0,0,0\n", "negative mass");
  check(ok + "0,0,0,0,0,0,0\n", "zero mass");
  check(ok + "1,0,0,nan,0,0,0\n", "nan");
  check(ok + "1,0,0,0.5.5,0,0,0\n", "two points");
  { std::ofstream(path) << "# only a comment\n\n"; }
  EXPECT_THROW(load_particles<double>(path), std::invalid_argument);
  { std::ofstream(path) << "m,x,y,z,vx,vy,vz\n# c\n0.5 1 0 0 0 0.5 0\n\n0.5,-1,0,0,0,-0.5,0\n"; }
  const auto p = load_particles<double>(path);
  EXPECT_EQ(p.size(), 2u);
  EXPECT_EQ(p.s.v[2], 0.5);  // vy of particle 0
  std::filesystem::remove(path);
  EXPECT_THROW(load_particles<double>(temp_path("does-not-exist.csv")), std::invalid_argument);
  EXPECT_THROW(save_particles("/nonexistent-dir/x.csv", p), std::invalid_argument);
}

TEST(Stats, QuantilesInterpolateLinearly) {
  EXPECT_DOUBLE_EQ(quantile(std::vector<double>{4, 1, 3, 2}, 0.25), 1.75);
  EXPECT_DOUBLE_EQ(quantile(std::vector<double>{4, 1, 3, 2}, 0.75), 3.25);
  EXPECT_DOUBLE_EQ(interquartile_range(std::vector<double>{4, 1, 3, 2}), 1.5);
  EXPECT_DOUBLE_EQ(quantile(std::vector<double>{5}, 0.3), 5.0);
  EXPECT_DOUBLE_EQ(median(std::vector<double>{3, 1, 2}), 2.0);
  EXPECT_DOUBLE_EQ(quantile(std::vector<double>{1, 2, 3}, 1.0), 3.0);
  EXPECT_THROW(quantile(std::vector<double>{}, 0.5), std::invalid_argument);
  EXPECT_THROW(quantile(std::vector<double>{1, NAN}, 0.5), std::invalid_argument);
  EXPECT_THROW(quantile(std::vector<double>{1}, 1.5), std::invalid_argument);
}

TEST(NBodyIntegration, SplittingsConvergeAtTheirOrders) {
  // Accuracy of whole N-body integrations: a softened Plummer sphere of 32 bodies (eps^2 = 1/N^2, as in
  // Gurkan sec. 5) over t = 1/8, with n = 16, 32, 64, 128 steps. The differences d_n = |x_n - x_2n|
  // (max-norm over all positions and velocities) fall like h^p: log2(d_n / d_2n) within 0.35 of p for
  // the two finest pairs, leapfrog p = 2, Forest-Ruth p = 4, and Chambers' complex method with the
  // imaginary parts dropped, which behaves as fourth order (Gurkan Fig. 5.2; formally third order).
  auto p = plummer_sphere<double>(32, 7);
  NBodyForce<double> f(p.m, 1.0 / (32.0 * 32.0));
  NBodyForce<double> fc(p.m, 1.0 / (32.0 * 32.0));
  const double t_end = 0.125;
  const double theta = 1 / (2 - std::cbrt(2.0));
  const SplittingScheme<double> lf{{{Flow::kick, 0.5}, {Flow::drift, 1.0}, {Flow::kick, 0.5}}};
  const SplittingScheme<double> fr{{{Flow::drift, theta / 2},
                                    {Flow::kick, theta},
                                    {Flow::drift, (1 - theta) / 2},
                                    {Flow::kick, 1 - 2 * theta},
                                    {Flow::drift, (1 - theta) / 2},
                                    {Flow::kick, theta},
                                    {Flow::drift, theta / 2}}};
  const C a1(0.25, 0.25 / std::sqrt(3.0));
  const SplittingScheme<C> ch{{{Flow::drift, a1},
                               {Flow::kick, 2.0 * a1},
                               {Flow::drift, C(0.5)},
                               {Flow::kick, std::conj(2.0 * a1)},
                               {Flow::drift, std::conj(a1)}}};
  auto run_real = [&](const SplittingScheme<double>& m, long n) {
    SplittingStepper<std::vector<double>, NBodyForce<double>> st(m, f);
    auto s = p.s;
    st.integrate(s, t_end / static_cast<double>(n), n);
    return s;
  };
  auto run_complex = [&](long n) {
    SplittingStepper<std::vector<C>, NBodyForce<double>> st(ch, fc);
    auto z = convert_state<std::vector<C>>(p.s);
    st.integrate(z, t_end / static_cast<double>(n), n);
    return convert_state<std::vector<double>>(z);
  };
  auto diff = [](const State<std::vector<double>>& a, const State<std::vector<double>>& b) {
    double d = 0;
    for (std::size_t i = 0; i < a.q.size(); ++i)
      d = std::max({d, std::abs(a.q[i] - b.q[i]), std::abs(a.v[i] - b.v[i])});
    return d;
  };
  for (int method = 0; method < 3; ++method) {
    const char* name = method == 0 ? "leapfrog" : method == 1 ? "Forest-Ruth" : "Chambers";
    const double order = method == 0 ? 2 : 4;
    std::vector<State<std::vector<double>>> x;
    for (long n : {16, 32, 64, 128})
      x.push_back(method == 0 ? run_real(lf, n) : method == 1 ? run_real(fr, n) : run_complex(n));
    const double d0 = diff(x[0], x[1]), d1 = diff(x[1], x[2]), d2 = diff(x[2], x[3]);
    std::printf("[ nbody    ] %-12s differences %.3e %.3e %.3e  slopes %.3f %.3f\n", name, d0, d1, d2,
                std::log2(d0 / d1), std::log2(d1 / d2));
    EXPECT_NEAR(std::log2(d0 / d1), order, 0.35) << name << ": " << d0 << ", " << d1 << ", " << d2;
    EXPECT_NEAR(std::log2(d1 / d2), order, 0.35) << name << ": " << d0 << ", " << d1 << ", " << d2;
    EXPECT_GT(d2, 1e-13) << name << ": differences at the round-off level";
  }
}

// Whole N-body runs are bitwise reproducible: the same result for 1, 2 and 3 force threads (and, for the
// multi-product expansion, its products on 1, 2 or 3 threads) and for a repeated run. Real, complex and
// MPE methods; the kernel the machine offers (SIMD where available) and the generic one.
TEST(NBodyDeterminism, RunsAreBitwiseIndependentOfThreadsAndRepeatable) {
  const auto p = plummer_sphere<double>(96, 11);
  for (auto kernel : {NBodyKernel::generic, NBodyKernel::simd}) {
    if (kernel == NBodyKernel::simd && !nbody_simd_available()) continue;
    for (const char* name : {"RKNb6", "AC1", "M6"}) {
      const MethodDef def = resolve_method(name);
      auto run = [&](int threads) {
        NBodyForce<double> f(p.m, 1.0 / (96.0 * 96.0));
        f.kernel = kernel;
        f.threads = threads;
        EngineOptions opt;
        if (def.info.family == "mpe") {
          opt.mpe_schedule = MpeSchedule::concurrent;
          opt.mpe_threads = threads;
        }
        auto s = p.s;
        if (def.info.complex) {
          auto integ = make_integrator<std::vector<C>>(def, f, opt);
          auto z = convert_state<std::vector<C>>(s);
          integ.integrate(z, 0.01, 8);  // the imaginary parts are dropped after every step
          s = convert_state<std::vector<double>>(z);
        } else {
          auto integ = make_integrator<std::vector<double>>(def, f, opt);
          integ.integrate(s, 0.01, 8);
        }
        return s;
      };
      const auto ref = run(1);
      for (int t : {1, 2, 3}) {
        const auto s = run(t);
        EXPECT_TRUE(s.q == ref.q && s.v == ref.v)
            << name << ", " << t << " threads, kernel " << static_cast<int>(kernel);
      }
    }
  }
}
