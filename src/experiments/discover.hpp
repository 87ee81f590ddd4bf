// Finding RKN splitting methods by solving order conditions (Gürkan, sec. 4 and 6).
//
// 1. The ten fifth-order conditions (2.4) of canonical RKN methods, in the unknowns B_i, c_i:
//      RKNA, eq (3.6), 5 stages:      x = (B_1..B_5, c_1..c_5)
//      RKNB, eq (3.8), 6 stages with c_1 = 0, c_6 = 1:  x = (B_1..B_6, c_2..c_5)
//    The splitting coefficients follow from (3.5): alpha_i = c_i - c_{i-1} (c_0 = 0), alpha_{s+1} = 1 - c_s,
//    beta_i = B_i. In time order RKNA is drift alpha_1, kick beta_1, ..., kick beta_5, drift alpha_6; RKNB
//    is kick beta_1, drift alpha_2, ..., drift alpha_6, kick beta_6 (alpha_1 = alpha_7 = 0).
// 2. discover(): damped Newton or Levenberg-Marquardt in complex double precision from many random starts
//    (real and imaginary parts uniform in [-box, box], the paper's box is 2), reproducible from a seed
//    (start k uses its own generator seeded from (seed, k), so threads do not change the result).
//    Converged solutions are merged up to the symmetries that map solutions to solutions: the adjoint
//    (sub-steps reversed) and complex conjugation. Each class representative is polished by Newton's
//    method in MPFR (default 256 bits, ~77 digits), then classified with the BCH analysis (degree 6, Hall
//    basis of the RKN algebra): REAL (real coefficients), IMAGINARY (complex, leading error purely
//    imaginary) or OTHER; methods whose coefficients all have positive real parts are flagged.
// 3. optimize_skew(): the six-stage extension of eq (6.1). A skew-symmetric splitting (reversing the list
//    gives its complex conjugate) with an odd number of sub-steps is parametrised by the real and
//    imaginary parts of its first half and its real middle coefficient. For such methods the degree-k
//    terms of Z are real for odd k and imaginary for even k, so "order p" is one real condition per basis
//    element of degrees 1..p and the degree-(p+1) terms are real numbers times i (p odd). The method
//    minimises the sum of squares of the degree-(p+1) terms subject to the order conditions by
//    constrained Gauss-Newton (a KKT system per step), first in double, then polished in MPFR.
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <complex>
#include <cstdint>
#include <functional>
#include <limits>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "nystrom/analysis/bch.hpp"
#include "nystrom/analysis/linsolve.hpp"

namespace nystrom::analysis {

using cd = std::complex<double>;

enum class RknForm { A, B };
inline std::string to_string(RknForm f) { return f == RknForm::A ? "RKNA" : "RKNB"; }
inline RknForm parse_rkn_form(const std::string& s) {
  if (s == "A" || s == "a" || s == "RKNA" || s == "rkna") return RknForm::A;
  if (s == "B" || s == "b" || s == "RKNB" || s == "rknb") return RknForm::B;
  throw std::invalid_argument("unknown scheme '" + s + "' (known: A, B)");
}

inline constexpr std::size_t rkn_unknowns = 10;
template <class S>
using RknVector = std::array<S, rkn_unknowns>;

/// Stage weights B_i and nodes c_i from the unknowns.
template <class S>
void rkn_stages(RknForm form, const RknVector<S>& x, std::vector<S>& B, std::vector<S>& c) {
  if (form == RknForm::A) {
    B.assign(x.begin(), x.begin() + 5);
    c.assign(x.begin() + 5, x.end());
  } else {
    B.assign(x.begin(), x.begin() + 6);
    c = {S{}, x[6], x[7], x[8], x[9], from_rational<S>(mpq_class(1))};
  }
}

/// Residuals t_k - target_k of the fifth-order conditions (2.4).
template <class S>
RknVector<S> rkn5_conditions(RknForm form, const RknVector<S>& x) {
  std::vector<S> B, c;
  rkn_stages(form, x, B, c);
  RknVector<S> t{};
  const std::size_t s = B.size();
  for (std::size_t i = 0; i < s; ++i) {
    const S c2 = c[i] * c[i];
    t[0] += B[i];
    t[1] += B[i] * c[i];
    t[2] += B[i] * c2;
    t[3] += B[i] * c2 * c[i];
    t[4] += B[i] * c2 * c2;
    S inner{};
    for (std::size_t j = 0; j < i; ++j) {
      const S w = B[i] * B[j] * (c[i] - c[j]);
      t[5] += w;
      t[6] += w * c[i];
      t[7] += w * c2;
      t[8] += w * c[i] * c[j];
      inner += B[j] * (c[i] - c[j]);
    }
    t[9] += B[i] * inner * inner;  // sum_{j<i} sum_{l<i} B_i B_j B_l (c_i - c_j)(c_i - c_l)
  }
  static const std::array<mpq_class, 10> target{mpq_class(1),     mpq_class(1, 2), mpq_class(1, 3), mpq_class(1, 4),
                                                mpq_class(1, 5),  mpq_class(1, 6), mpq_class(1, 8), mpq_class(1, 10),
                                                mpq_class(1, 30), mpq_class(1, 20)};
  for (std::size_t k = 0; k < 10; ++k) t[k] = t[k] - from_rational<S>(target[k]);
  return t;
}

/// Sub-step coefficients in time order (see the top of the file).
template <class S>
std::vector<S> rkn_substeps(RknForm form, const RknVector<S>& x) {
  std::vector<S> B, c;
  rkn_stages(form, x, B, c);
  std::vector<S> out;
  if (form == RknForm::A) {
    S prev{};
    for (std::size_t i = 0; i < 5; ++i) {
      out.push_back(c[i] - prev);
      out.push_back(B[i]);
      prev = c[i];
    }
    out.push_back(from_rational<S>(mpq_class(1)) - prev);
  } else {
    for (std::size_t i = 0; i < 6; ++i) {
      out.push_back(B[i]);
      if (i < 5) out.push_back(c[i + 1] - c[i]);
    }
  }
  return out;
}

/// Inverse of rkn_substeps (cumulative sums of the drifts are the nodes).
template <class S>
RknVector<S> rkn_unknowns_from(RknForm form, const std::vector<S>& sub) {
  RknVector<S> x{};
  if (form == RknForm::A) {
    if (sub.size() != 11) throw std::invalid_argument("RKNA needs 11 sub-steps");
    S c{};
    for (std::size_t i = 0; i < 5; ++i) {
      c += sub[2 * i];
      x[i] = sub[2 * i + 1];
      x[5 + i] = c;
    }
  } else {
    if (sub.size() != 11) throw std::invalid_argument("RKNB needs 11 sub-steps");
    S c{};
    for (std::size_t i = 0; i < 6; ++i) x[i] = sub[2 * i];
    for (std::size_t i = 0; i < 4; ++i) {
      c += sub[2 * i + 1];
      x[6 + i] = c;
    }
  }
  return x;
}

inline Flow rkn_first_flow(RknForm form) { return form == RknForm::A ? Flow::drift : Flow::kick; }

/// Splitting scheme (time order, alternating from the first flow) from a list of coefficients.
template <class C>
SplittingScheme<bigcomplex> alternating_scheme(Flow first, const std::vector<C>& sub) {
  SplittingScheme<bigcomplex> s;
  Flow f = first;
  for (const auto& c : sub) {
    if constexpr (std::is_same_v<C, bigcomplex>) {
      s.steps.push_back({f, c});
    } else {
      s.steps.push_back({f, bigcomplex(bigfloat(c.real()), bigfloat(c.imag()))});
    }
    f = f == Flow::drift ? Flow::kick : Flow::drift;
  }
  return s;
}

// ---- helpers on coefficient lists ------------------------------------------------------------------------

inline std::vector<cd> reversed(std::vector<cd> v) {
  std::reverse(v.begin(), v.end());
  return v;
}
inline std::vector<cd> conjugated(std::vector<cd> v) {
  for (auto& x : v) x = std::conj(x);
  return v;
}
inline double max_distance(const std::vector<cd>& a, const std::vector<cd>& b) {
  if (a.size() != b.size()) return std::numeric_limits<double>::infinity();
  double d = 0;
  for (std::size_t i = 0; i < a.size(); ++i) d = std::max(d, std::abs(a[i] - b[i]));
  return d;
}
/// a == b up to the adjoint (reversal) and complex conjugation, within tol.
inline bool same_up_to_symmetry(const std::vector<cd>& a, const std::vector<cd>& b, double tol) {
  return max_distance(a, b) <= tol || max_distance(reversed(a), b) <= tol || max_distance(conjugated(a), b) <= tol ||
         max_distance(conjugated(reversed(a)), b) <= tol;
}
/// Coefficients of a splitting scheme (time order) as complex doubles, after merging adjacent sub-steps.
inline std::vector<cd> scheme_coefficients(const SplittingScheme<bigcomplex>& s) {
  std::vector<cd> v;
  for (const auto& st : normalized(s).steps) v.push_back(to_cd(st.coef));
  return v;
}

/// The canonical representative among {v, reverse v, conj v, conj reverse v}: lexicographically largest by
/// (real part, then imaginary part), ties within 1e-9 ignored.
inline std::vector<cd> canonical_variant(const std::vector<cd>& v) {
  auto greater = [](const std::vector<cd>& a, const std::vector<cd>& b) {
    for (std::size_t i = 0; i < a.size(); ++i)
      if (std::abs(a[i].real() - b[i].real()) > 1e-9) return a[i].real() > b[i].real();
    for (std::size_t i = 0; i < a.size(); ++i)
      if (std::abs(a[i].imag() - b[i].imag()) > 1e-9) return a[i].imag() > b[i].imag();
    return false;
  };
  std::vector<cd> best = v;
  for (const auto& w : {reversed(v), conjugated(v), conjugated(reversed(v))})
    if (greater(w, best)) best = w;
  return best;
}

// ---- the random-start solver -------------------------------------------------------------------------------

enum class Solver { lm, newton };
inline Solver parse_solver(const std::string& s) {
  if (s == "lm" || s == "levenberg-marquardt") return Solver::lm;
  if (s == "newton") return Solver::newton;
  throw std::invalid_argument("unknown solver '" + s + "' (known: lm, newton)");
}

/// splitmix64 (Steele, Lea, Flood 2014): a small generator with a well-defined output on every platform.
struct SplitMix64 {
  std::uint64_t state;
  std::uint64_t next() {
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }  // [0, 1)
};

/// The random start number k of a search with this seed.
inline RknVector<cd> random_start(std::uint64_t seed, std::uint64_t k, double box) {
  SplitMix64 g{seed * 0x9e3779b97f4a7c15ULL + k * 0xd1b54a32d192ed03ULL + 0x632be59bd9b4e019ULL};
  g.next();
  RknVector<cd> x;
  for (auto& z : x) {
    const double re = (2 * g.uniform() - 1) * box;
    const double im = (2 * g.uniform() - 1) * box;
    z = cd(re, im);
  }
  return x;
}

struct LocalSolve {
  bool converged = false;
  RknVector<cd> x{};
  int iterations = 0;
  double residual = 0;
};

namespace detail {
inline double norm2(const RknVector<cd>& f) {
  double s = 0;
  for (const auto& z : f) s += std::norm(z);
  return s;
}
inline void conditions_and_jacobian(RknForm form, const RknVector<cd>& x, RknVector<cd>& f,
                                    std::vector<std::vector<cd>>& j) {
  using D = Dual<cd, rkn_unknowns>;
  RknVector<D> xd;
  for (std::size_t k = 0; k < rkn_unknowns; ++k) xd[k] = D::variable(x[k], k);
  const auto fd = rkn5_conditions(form, xd);
  j.assign(rkn_unknowns, std::vector<cd>(rkn_unknowns));
  for (std::size_t r = 0; r < rkn_unknowns; ++r) {
    f[r] = fd[r].v;
    for (std::size_t k = 0; k < rkn_unknowns; ++k) j[r][k] = fd[r].d[k];
  }
}
// Ratio of the largest to the smallest pivot of the Jacobian (LU with partial pivoting): a cheap condition
// estimate; solutions on positive-dimensional solution sets (e.g. a vanishing kick) have singular Jacobians.
inline double jacobian_pivot_ratio(RknForm form, const RknVector<cd>& x) {
  RknVector<cd> f;
  std::vector<std::vector<cd>> a;
  conditions_and_jacobian(form, x, f, a);
  const std::size_t n = rkn_unknowns;
  double pmax = 0, pmin = std::numeric_limits<double>::infinity();
  for (std::size_t c = 0; c < n; ++c) {
    std::size_t p = c;
    for (std::size_t r = c + 1; r < n; ++r)
      if (std::abs(a[r][c]) > std::abs(a[p][c])) p = r;
    std::swap(a[p], a[c]);
    const double piv = std::abs(a[c][c]);
    pmax = std::max(pmax, piv);
    pmin = std::min(pmin, piv);
    if (piv == 0) return std::numeric_limits<double>::infinity();
    for (std::size_t r = c + 1; r < n; ++r) {
      const cd m = a[r][c] / a[c][c];
      for (std::size_t k = c; k < n; ++k) a[r][k] -= m * a[c][k];
    }
  }
  return pmax / pmin;
}
}  // namespace detail

/// Solves the conditions (2.4) from x0 in complex double precision.
inline LocalSolve solve_rkn_conditions(RknForm form, RknVector<cd> x, Solver solver, int max_iter = 200) {
  LocalSolve out;
  RknVector<cd> f;
  std::vector<std::vector<cd>> j;
  detail::conditions_and_jacobian(form, x, f, j);
  double fn = detail::norm2(f);
  double mu = -1;
  const double target = 1e-26;  // |F|^2
  for (int it = 0; it < max_iter; ++it) {
    out.iterations = it;
    if (fn < target) break;
    std::vector<cd> step(rkn_unknowns);
    bool ok;
    if (solver == Solver::newton) {
      for (std::size_t r = 0; r < rkn_unknowns; ++r) step[r] = -f[r];
      ok = solve_linear(j, step);
    } else {
      // (J^H J + mu I) step = -J^H F
      std::vector<std::vector<cd>> a(rkn_unknowns, std::vector<cd>(rkn_unknowns));
      double dmax = 0;
      for (std::size_t r = 0; r < rkn_unknowns; ++r) {
        for (std::size_t k = 0; k < rkn_unknowns; ++k) {
          cd s = 0;
          for (std::size_t i = 0; i < rkn_unknowns; ++i) s += std::conj(j[i][r]) * j[i][k];
          a[r][k] = s;
        }
        dmax = std::max(dmax, a[r][r].real());
        cd g = 0;
        for (std::size_t i = 0; i < rkn_unknowns; ++i) g -= std::conj(j[i][r]) * f[i];
        step[r] = g;
      }
      if (mu < 0) mu = 1e-3 * dmax;
      for (std::size_t r = 0; r < rkn_unknowns; ++r) a[r][r] += mu;
      ok = solve_linear(a, step);
    }
    if (!ok) {
      if (solver == Solver::newton) return out;
      mu = std::max(mu * 10, 1e-12);
      continue;
    }
    // trial step (Newton: backtracking; LM: accept or raise mu)
    double t = 1;
    bool accepted = false;
    for (int ls = 0; ls < (solver == Solver::newton ? 30 : 1); ++ls, t *= 0.5) {
      RknVector<cd> xt;
      for (std::size_t k = 0; k < rkn_unknowns; ++k) xt[k] = x[k] + t * step[k];
      const auto ft = rkn5_conditions(form, xt);
      const double fnt = detail::norm2(ft);
      if (std::isfinite(fnt) && fnt < fn) {
        x = xt;
        accepted = true;
        break;
      }
    }
    if (accepted) {
      if (solver == Solver::lm) mu = std::max(mu / 3, 1e-15);
      detail::conditions_and_jacobian(form, x, f, j);
      fn = detail::norm2(f);
    } else {
      if (solver == Solver::newton) return out;
      mu *= 4;
      if (mu > 1e20) return out;
    }
    for (const auto& z : x)
      if (!(std::abs(z) < 1e3)) return out;  // diverged
  }
  out.x = x;
  out.residual = std::sqrt(fn);
  out.converged = fn < target;
  return out;
}

/// Newton's method in MPFR at the current BigPrecision from a converged double solution. Returns false
/// if it does not converge (singular Jacobian or no quadratic convergence). `digits` receives the number
/// of correct digits reached (from the size of the last Newton correction).
inline bool polish_rkn_solution(RknForm form, RknVector<bigcomplex>& x, int& digits, bigfloat& residual) {
  using D = Dual<bigcomplex, rkn_unknowns>;
  const int target = static_cast<int>(bigfloat::default_precision()) - 8;
  digits = 0;
  for (int it = 0; it < 40; ++it) {
    RknVector<D> xd;
    for (std::size_t k = 0; k < rkn_unknowns; ++k) xd[k] = D::variable(x[k], k);
    const auto fd = rkn5_conditions(form, xd);
    std::vector<std::vector<bigcomplex>> j(rkn_unknowns, std::vector<bigcomplex>(rkn_unknowns));
    std::vector<bigcomplex> step(rkn_unknowns);
    for (std::size_t r = 0; r < rkn_unknowns; ++r) {
      step[r] = neg(fd[r].v);
      for (std::size_t k = 0; k < rkn_unknowns; ++k) j[r][k] = fd[r].d[k];
    }
    if (!solve_linear(j, step)) return false;
    bigfloat smax = 0;
    for (std::size_t k = 0; k < rkn_unknowns; ++k) {
      x[k] += step[k];
      smax = std::max(smax, abs_big(step[k]));
    }
    if (smax == 0) {
      digits = target;
    } else {
      digits = std::max(0, static_cast<int>(-boost::multiprecision::log10(smax).convert_to<double>()));
    }
    if (digits >= target) break;
    if (it > 8 && digits < 10) return false;
  }
  const auto f = rkn5_conditions(form, x);
  residual = 0;
  for (const auto& z : f) residual = std::max(residual, abs_big(z));
  return digits >= target / 2;
}

// ---- the search ----------------------------------------------------------------------------------------------

struct DiscoverOptions {
  RknForm form = RknForm::A;
  long starts = 1000;
  std::uint64_t seed = 1;
  double box = 2;
  int threads = 1;
  Solver solver = Solver::newton;
  int max_iterations = 500;
  unsigned polish_bits = 256;
};

enum class MethodClass { real, imaginary, other };
inline std::string to_string(MethodClass c) {
  return c == MethodClass::real ? "REAL" : c == MethodClass::imaginary ? "IMAGINARY" : "OTHER";
}

struct DiscoveredMethod {
  RknForm form = RknForm::A;
  std::vector<bigcomplex> coefficients;  // polished sub-step coefficients, time order (representative)
  std::vector<cd> coefficients_d;
  long hits = 0;         // random starts that converged to this class
  long first_start = 0;  // the first start that found it
  int digits = 0;        // correct digits after polishing
  double residual = 0;   // max |t_k - target| after polishing
  MethodClass cls = MethodClass::other;
  bool positive = false;           // every coefficient has a positive real part
  bool skew_symmetric = false;     // reverse == conjugate
  bool symmetric = false;          // reverse == itself
  std::vector<ErrorTerm> leading;  // degree-6 terms of H - Z (Hall basis, RKN algebra)
  double error_norm = 0;
  double max_abs_coefficient = 0;
  SplittingScheme<bigcomplex> scheme() const { return alternating_scheme(rkn_first_flow(form), coefficients); }
};

struct DiscoverReport {
  DiscoverOptions options;
  long converged = 0;     // starts that converged in double precision
  long not_polished = 0;  // classes dropped: singular Jacobian (pivot ratio > 1e11) or no MPFR Newton convergence
  std::vector<DiscoveredMethod> methods;  // sorted: REAL, IMAGINARY, OTHER; then by error norm
  /// Methods of class c.
  long count(MethodClass c) const {
    long n = 0;
    for (const auto& m : methods) n += m.cls == c;
    return n;
  }
  /// Methods of class c whose coefficients all have positive real parts.
  long count_positive(MethodClass c) const {
    long n = 0;
    for (const auto& m : methods) n += m.cls == c && m.positive;
    return n;
  }
};

namespace detail {

inline void classify(DiscoveredMethod& m) {
  const auto& v = m.coefficients_d;
  bool real = true, positive = true;
  for (const auto& c : m.coefficients) {
    if (boost::multiprecision::abs(c.im) > bigfloat("1e-30")) real = false;
    if (!(c.re > 0)) positive = false;
  }
  m.positive = positive;
  m.max_abs_coefficient = 0;
  for (const auto& z : v) m.max_abs_coefficient = std::max(m.max_abs_coefficient, std::abs(z));
  m.skew_symmetric = max_distance(reversed(v), conjugated(v)) < 1e-12;
  m.symmetric = max_distance(reversed(v), v) < 1e-12;
  AnalysisOptions opt;
  opt.degree = 6;
  opt.precision_bits = 128;
  const MethodAnalysis a = analyze_scheme(m.scheme(), opt);
  m.leading = a.degrees[5].terms;
  m.error_norm = a.degrees[5].norm;
  double re_max = 0;
  for (const auto& t : m.leading) re_max = std::max(re_max, std::abs(t.value.real()));
  if (real) {
    m.cls = MethodClass::real;
  } else if (re_max <= 1e-20 + 1e-12 * m.error_norm) {
    m.cls = MethodClass::imaginary;
  } else {
    m.cls = MethodClass::other;
  }
}

template <class Fn>
void parallel_for(long n, int threads, Fn&& fn) {
  threads = std::max(1, std::min<int>(threads, static_cast<int>(std::min<long>(n, 256))));
  std::atomic<long> next{0};
  auto work = [&] {
    for (long k = next++; k < n; k = next++) fn(k);
  };
  if (threads == 1) {
    work();
    return;
  }
  std::vector<std::thread> pool;
  for (int t = 0; t < threads; ++t) pool.emplace_back(work);
  for (auto& th : pool) th.join();
}

}  // namespace detail

/// The random-start search for one scheme (see the top of the file). `progress` (optional) is called with
/// the number of finished starts.
inline DiscoverReport discover(const DiscoverOptions& opt, const std::function<void(long)>& progress = {}) {
  if (opt.starts < 1 || opt.starts > 100000000L)
    throw std::invalid_argument("the number of starts must be between 1 and 1e8");
  if (!(opt.box > 0) || !std::isfinite(opt.box)) throw std::invalid_argument("the start box must be positive");
  if (opt.threads < 1 || opt.threads > 256) throw std::invalid_argument("threads must be between 1 and 256");
  if (opt.polish_bits < 128 || opt.polish_bits > 4096)
    throw std::invalid_argument("polish precision must be 128..4096 bits");
  DiscoverReport rep;
  rep.options = opt;
  // 1. local solves in double
  std::vector<LocalSolve> sol(static_cast<std::size_t>(opt.starts));
  std::atomic<long> done{0};
  std::mutex progress_mu;
  detail::parallel_for(opt.starts, opt.threads, [&](long k) {
    sol[static_cast<std::size_t>(k)] = solve_rkn_conditions(
        opt.form, random_start(opt.seed, static_cast<std::uint64_t>(k), opt.box), opt.solver, opt.max_iterations);
    const long d = ++done;
    if (progress && (d % 64 == 0 || d == opt.starts)) {
      std::lock_guard<std::mutex> lock(progress_mu);
      progress(d);
    }
  });
  // 2. merge in start order (deterministic)
  struct Class {
    std::vector<cd> rep;
    long hits = 0, first = 0;
    bool singular = false;
  };
  std::vector<Class> classes;
  for (long k = 0; k < opt.starts; ++k) {
    const auto& s = sol[static_cast<std::size_t>(k)];
    if (!s.converged) continue;
    ++rep.converged;
    const auto v = canonical_variant(rkn_substeps(opt.form, s.x));
    bool found = false;
    for (auto& c : classes)
      if (max_distance(c.rep, v) < 1e-7) {
        ++c.hits;
        found = true;
        break;
      }
    if (!found) classes.push_back({v, 1, k, detail::jacobian_pivot_ratio(opt.form, s.x) > 1e11});
  }
  // 3. polish and classify each class. In this thread: the MPFR default precision is process-wide (Boost 1.74).
  std::vector<DiscoveredMethod> out(classes.size());
  std::vector<char> ok(classes.size(), 0);
  {
    BigPrecision guard(opt.polish_bits);
    for (std::size_t ci = 0; ci < classes.size(); ++ci) {
      const Class& c = classes[ci];
      if (c.singular) continue;
      std::vector<bigcomplex> sub;
      for (const auto& z : c.rep) sub.push_back(bigcomplex(bigfloat(z.real()), bigfloat(z.imag())));
      RknVector<bigcomplex> x = rkn_unknowns_from(opt.form, sub);
      DiscoveredMethod m;
      bigfloat res;
      if (!polish_rkn_solution(opt.form, x, m.digits, res)) continue;
      m.form = opt.form;
      m.coefficients = rkn_substeps(opt.form, x);
      for (const auto& z : m.coefficients) m.coefficients_d.push_back(to_cd(z));
      m.residual = static_cast<double>(res);
      m.hits = c.hits;
      m.first_start = c.first;
      detail::classify(m);
      out[ci] = std::move(m);
      ok[ci] = 1;
    }
  }
  // 4. merge again after polishing (two double-precision classes may polish to the same solution)
  for (std::size_t i = 0; i < out.size(); ++i) {
    if (!ok[i]) {
      ++rep.not_polished;
      continue;
    }
    bool merged = false;
    for (auto& m : rep.methods)
      if (same_up_to_symmetry(m.coefficients_d, out[i].coefficients_d, 1e-12)) {
        m.hits += out[i].hits;
        merged = true;
        break;
      }
    if (!merged) rep.methods.push_back(std::move(out[i]));
  }
  std::stable_sort(rep.methods.begin(), rep.methods.end(), [](const DiscoveredMethod& a, const DiscoveredMethod& b) {
    if (a.cls != b.cls) return static_cast<int>(a.cls) < static_cast<int>(b.cls);
    return a.error_norm < b.error_norm;
  });
  return rep;
}

// ---- eq (6.1): minimising the leading error of a skew-symmetric method ------------------------------------

struct SkewOptimum {
  std::vector<bigcomplex> coefficients;  // time order
  Flow first = Flow::kick;
  int order = 0;
  double error_norm = 0;        // (sum |X_i|^2)^{1/2} over the degree order+1 terms (Hall basis, RKN algebra)
  double start_error_norm = 0;  // the same for the start
  double constraint_residual = 0;
  int iterations = 0;
  bool converged = false;
  SplittingScheme<bigcomplex> scheme() const { return alternating_scheme(first, coefficients); }
};

namespace detail {

template <class C>
struct complex_ops;
template <>
struct complex_ops<cd> {
  using real = double;
  static double re(const cd& z) { return z.real(); }
  static double im(const cd& z) { return z.imag(); }
  static cd make(double r, double i) { return {r, i}; }
};
template <>
struct complex_ops<bigcomplex> {
  using real = bigfloat;
  static bigfloat re(const bigcomplex& z) { return z.re; }
  static bigfloat im(const bigcomplex& z) { return z.im; }
  static bigcomplex make(const bigfloat& r, const bigfloat& i) { return {r, i}; }
};

// Sub-step coefficients of the skew-symmetric method with parameters x (first half re/im, then middle).
template <class C, class R>
std::vector<C> skew_substeps(const std::vector<R>& x, std::size_t m) {
  using O = complex_ops<C>;
  const std::size_t h = m / 2;
  std::vector<C> s(m);
  for (std::size_t k = 0; k < h; ++k) {
    s[k] = O::make(x[2 * k], x[2 * k + 1]);
    s[m - 1 - k] = O::make(x[2 * k], -x[2 * k + 1]);
  }
  s[h] = O::make(x[2 * h], R(0));
  return s;
}

// Constraints c (order conditions, one real per basis element of degrees 1..p) and objective r (degree p+1),
// with their Jacobians with respect to the real parameters.
template <class C, std::size_t M>
void skew_system(const std::vector<typename complex_ops<C>::real>& x, Flow first, int order,
                 const LieProjector<Dual<C, M>>& proj, std::vector<typename complex_ops<C>::real>& c,
                 std::vector<std::vector<typename complex_ops<C>::real>>& jc,
                 std::vector<typename complex_ops<C>::real>& r,
                 std::vector<std::vector<typename complex_ops<C>::real>>& jr) {
  using O = complex_ops<C>;
  using R = typename O::real;
  using D = Dual<C, M>;
  const auto s = skew_substeps<C>(x, M);
  std::vector<std::pair<int, D>> factors;  // operator order: time order reversed
  for (std::size_t k = M; k-- > 0;) {
    const bool drift = (k % 2 == 0) == (first == Flow::drift);
    factors.emplace_back(drift ? letter_T : letter_V, D::variable(s[k], k));
  }
  const auto z = bch_coordinates(factors, proj);
  const std::size_t n = x.size();
  const std::size_t h = M / 2;
  // d s_k / d x_j
  auto ds = [&](std::size_t k, std::size_t j) -> C {
    if (k == h) return j == 2 * h ? O::make(R(1), R(0)) : O::make(R(0), R(0));
    const std::size_t kk = k < h ? k : M - 1 - k;
    if (j == 2 * kk) return O::make(R(1), R(0));
    if (j == 2 * kk + 1) return O::make(R(0), k < h ? R(1) : R(-1));
    return O::make(R(0), R(0));
  };
  c.clear();
  jc.clear();
  r.clear();
  jr.clear();
  for (int d = 1; d <= order + 1; ++d) {
    const bool take_re = d % 2 == 1;
    for (std::size_t e = 0; e < z[d].size(); ++e) {
      const D& v = z[d][e];
      R val = take_re ? O::re(v.v) : O::im(v.v);
      if (d == 1) val = val - R(1);
      std::vector<R> grad(n, R(0));
      for (std::size_t j = 0; j < n; ++j) {
        C g = O::make(R(0), R(0));
        for (std::size_t k = 0; k < M; ++k) g += v.d[k] * ds(k, j);
        grad[j] = take_re ? O::re(g) : O::im(g);
      }
      if (d <= order) {
        c.push_back(val);
        jc.push_back(std::move(grad));
      } else {
        r.push_back(val);
        jr.push_back(std::move(grad));
      }
    }
  }
}

template <class R>
R sumsq(const std::vector<R>& v) {
  R s(0);
  for (const auto& x : v) s += x * x;
  return s;
}

// Restores c(x) = 0 by minimum-norm Newton steps dx = -Jc^T (Jc Jc^T)^{-1} c. Returns false if it fails.
template <class C, std::size_t M>
bool skew_restore(std::vector<typename complex_ops<C>::real>& x, Flow first, int order,
                  const LieProjector<Dual<C, M>>& proj, double tol, std::vector<typename complex_ops<C>::real>& c,
                  std::vector<std::vector<typename complex_ops<C>::real>>& jc,
                  std::vector<typename complex_ops<C>::real>& r,
                  std::vector<std::vector<typename complex_ops<C>::real>>& jr) {
  using R = typename complex_ops<C>::real;
  skew_system<C, M>(x, first, order, proj, c, jc, r, jr);
  auto cnorm = [](const std::vector<R>& v) {
    double m = 0;
    for (const auto& e : v) m = std::max(m, std::abs(static_cast<double>(e)));
    return std::isfinite(m) ? m : std::numeric_limits<double>::infinity();
  };
  double cmax = cnorm(c);
  for (int it = 0; it < 40; ++it) {
    if (cmax <= tol) return true;
    if (!std::isfinite(cmax)) return false;
    const std::size_t nc = c.size(), n = x.size();
    std::vector<std::vector<R>> a(nc, std::vector<R>(nc, R(0)));
    std::vector<R> y(nc);
    for (std::size_t i = 0; i < nc; ++i) {
      for (std::size_t j = 0; j < nc; ++j) {
        R s(0);
        for (std::size_t k = 0; k < n; ++k) s += jc[i][k] * jc[j][k];
        a[i][j] = s;
      }
      y[i] = -c[i];
    }
    if (!solve_linear(a, y)) return false;
    std::vector<R> dx(n, R(0));
    for (std::size_t k = 0; k < n; ++k)
      for (std::size_t i = 0; i < nc; ++i) dx[k] += jc[i][k] * y[i];
    // damped: halve until |c| decreases
    bool ok = false;
    R t(1);
    for (int ls = 0; ls < 20 && !ok; ++ls, t = t / 2) {
      std::vector<R> xt = x;
      for (std::size_t k = 0; k < n; ++k) xt[k] += t * dx[k];
      std::vector<R> ct, rt;
      std::vector<std::vector<R>> jct, jrt;
      skew_system<C, M>(xt, first, order, proj, ct, jct, rt, jrt);
      const double cm = cnorm(ct);
      if (cm < cmax) {
        x = std::move(xt);
        c = std::move(ct);
        jc = std::move(jct);
        r = std::move(rt);
        jr = std::move(jrt);
        cmax = cm;
        ok = true;
      }
    }
    if (!ok) return false;
  }
  return cmax <= tol;
}

template <class R>
R dot(const std::vector<R>& a, const std::vector<R>& b) {
  R s(0);
  for (std::size_t i = 0; i < a.size(); ++i) s += a[i] * b[i];
  return s;
}

// Orthonormal basis of the tangent space {dx : Jc dx = 0}: the projections P e_j of the coordinate vectors
// j in `free` (P the orthogonal projector onto the null space of Jc), Gram-Schmidt orthonormalised. If `free`
// is empty it is chosen greedily (most independent projections first) and returned.
template <class R>
bool tangent_basis(const std::vector<std::vector<R>>& jc, std::size_t n, std::vector<std::size_t>& free,
                   std::vector<std::vector<R>>& u) {
  const std::size_t nc = jc.size();
  std::vector<std::vector<R>> a(nc, std::vector<R>(nc, R(0)));
  for (std::size_t i = 0; i < nc; ++i)
    for (std::size_t j = 0; j < nc; ++j) a[i][j] = dot(jc[i], jc[j]);
  auto project = [&](std::size_t j) -> std::optional<std::vector<R>> {
    std::vector<R> w(nc);
    for (std::size_t i = 0; i < nc; ++i) w[i] = jc[i][j];
    if (!solve_linear(a, w)) return std::nullopt;
    std::vector<R> v(n, R(0));
    v[j] = R(1);
    for (std::size_t i = 0; i < nc; ++i)
      for (std::size_t k = 0; k < n; ++k) v[k] -= jc[i][k] * w[i];
    return v;
  };
  auto orthonormalise = [&](std::vector<R> v) -> std::pair<std::vector<R>, double> {
    for (const auto& q : u) {
      const R d = dot(v, q);
      for (std::size_t k = 0; k < n; ++k) v[k] -= d * q[k];
    }
    const double nv = std::sqrt(static_cast<double>(dot(v, v)));
    if (nv > 0)
      for (auto& e : v) e = e / R(nv);
    return {v, nv};
  };
  u.clear();
  const std::size_t k = n - nc;
  if (free.empty()) {
    std::vector<std::vector<R>> p;
    for (std::size_t j = 0; j < n; ++j) {
      auto v = project(j);
      if (!v) return false;
      p.push_back(std::move(*v));
    }
    while (u.size() < k) {
      double best = 0;
      std::size_t bj = n;
      for (std::size_t j = 0; j < n; ++j) {
        if (std::find(free.begin(), free.end(), j) != free.end()) continue;
        const double nv = orthonormalise(p[j]).second;
        if (nv > best) {
          best = nv;
          bj = j;
        }
      }
      if (bj == n || best < 1e-8) return false;
      free.push_back(bj);
      u.push_back(orthonormalise(p[bj]).first);
    }
    return true;
  }
  for (std::size_t j : free) {
    auto v = project(j);
    if (!v) return false;
    auto [q, nv] = orthonormalise(std::move(*v));
    if (nv < 1e-8) return false;
    u.push_back(std::move(q));
  }
  return true;
}

// Reduced-space Newton for min |r(x)|^2 subject to c(x) = 0 on the skew-symmetric parameters: at a feasible x
// with tangent basis U, the reduced gradient is 2 U^T Jr^T r (exact, from the dual numbers) and the reduced
// Hessian is taken by central differences of |r|^2 along U (each point restored onto c = 0). Steps are
// accepted when |r|^2 decreases. `hessian`/`free` are outputs of a first run and inputs of a polishing run
// (reuse_hessian: keep them fixed, a quasi-Newton iteration that needs no finite differences).
template <class C, std::size_t M>
int skew_reduced_newton(std::vector<typename complex_ops<C>::real>& x, Flow first, int order, int max_iter, double stop,
                        double ctol, double fd_step, bool reuse_hessian, std::vector<std::vector<double>>& hessian,
                        std::vector<std::size_t>& free, bool& converged) {
  using R = typename complex_ops<C>::real;
  const LieStructure& st = lie_structure(order + 1, BasisKind::hall, AlgebraKind::rkn);
  const LieProjector<Dual<C, M>> proj(st);
  const std::size_t n = x.size();
  std::vector<R> c, r;
  std::vector<std::vector<R>> jc, jr;
  converged = false;
  if (!skew_restore<C, M>(x, first, order, proj, ctol, c, jc, r, jr))
    throw std::invalid_argument("optimize_skew: the start is not close to a method of the requested order");
  if (c.size() >= n)
    throw std::invalid_argument("optimize_skew: no free parameters are left once the order conditions hold");
  const std::size_t k = n - c.size();
  R obj = sumsq(r);
  // |r|^2 at the restoration of x + U y (or +inf)
  auto value_at = [&](const std::vector<std::vector<R>>& u, const std::vector<double>& y) -> double {
    std::vector<R> xt = x;
    for (std::size_t i = 0; i < k; ++i)
      for (std::size_t j = 0; j < n; ++j) xt[j] += R(y[i]) * u[i][j];
    std::vector<R> ct, rt;
    std::vector<std::vector<R>> jct, jrt;
    if (!skew_restore<C, M>(xt, first, order, proj, ctol, ct, jct, rt, jrt))
      return std::numeric_limits<double>::infinity();
    return static_cast<double>(sumsq(rt));
  };
  int it = 0;
  for (; it < max_iter; ++it) {
    std::vector<std::vector<R>> u;
    if (!reuse_hessian && it == 0) free.clear();
    if (!tangent_basis(jc, n, free, u)) break;
    std::vector<double> g(k);
    for (std::size_t i = 0; i < k; ++i) {
      R s(0);
      for (std::size_t q = 0; q < r.size(); ++q) s += r[q] * dot(jr[q], u[i]);
      g[i] = 2 * static_cast<double>(s);
    }
    if (!reuse_hessian) {
      const double h = fd_step, f0 = static_cast<double>(obj);
      hessian.assign(k, std::vector<double>(k, 0));
      for (std::size_t i = 0; i < k; ++i) {
        std::vector<double> y(k, 0);
        y[i] = h;
        const double fp = value_at(u, y);
        y[i] = -h;
        const double fm = value_at(u, y);
        hessian[i][i] = (fp - 2 * f0 + fm) / (h * h);
        for (std::size_t j = 0; j < i; ++j) {
          std::vector<double> z(k, 0);
          double f4[4];
          int idx = 0;
          for (double si : {1.0, -1.0})
            for (double sj : {1.0, -1.0}) {
              z[i] = si * h;
              z[j] = sj * h;
              f4[idx++] = value_at(u, z);
            }
          hessian[i][j] = hessian[j][i] = (f4[0] - f4[1] - f4[2] + f4[3]) / (4 * h * h);
        }
      }
    }
    // (H + lambda I) y = -g, lambda raised until the step is a descent direction of a positive definite model
    double hmax = 0;
    for (std::size_t i = 0; i < k; ++i) hmax = std::max(hmax, std::abs(hessian[i][i]));
    if (!std::isfinite(hmax)) break;
    std::vector<double> y;
    for (double lambda = 0; lambda < 1e12 * (hmax + 1e-300); lambda = lambda == 0 ? 1e-10 * hmax : lambda * 10) {
      std::vector<std::vector<double>> a = hessian;
      for (std::size_t i = 0; i < k; ++i) a[i][i] += lambda;
      std::vector<double> yy(k);
      for (std::size_t i = 0; i < k; ++i) yy[i] = -g[i];
      if (!solve_linear(a, yy)) continue;
      double gy = 0, yhy = 0;
      for (std::size_t i = 0; i < k; ++i) {
        gy += g[i] * yy[i];
        for (std::size_t j = 0; j < k; ++j) yhy += yy[i] * a[i][j] * yy[j];
      }
      if (gy < 0 && yhy > 0) {
        y = std::move(yy);
        break;
      }
    }
    if (y.empty()) break;
    double ymax = 0;
    for (double v : y) ymax = std::max(ymax, std::abs(v));
    if (ymax < stop) {
      converged = true;
      break;
    }
    double t = 1;
    bool accepted = false;
    for (int ls = 0; ls < 30 && !accepted; ++ls, t /= 2) {
      std::vector<R> xt = x;
      for (std::size_t i = 0; i < k; ++i)
        for (std::size_t j = 0; j < n; ++j) xt[j] += R(t * y[i]) * u[i][j];
      std::vector<R> ct, rt;
      std::vector<std::vector<R>> jct, jrt;
      if (!skew_restore<C, M>(xt, first, order, proj, ctol, ct, jct, rt, jrt)) continue;
      const R ot = sumsq(rt);
      if (ot <= obj) {
        x = std::move(xt);
        c = std::move(ct);
        r = std::move(rt);
        jc = std::move(jct);
        jr = std::move(jrt);
        obj = ot;
        accepted = true;
      }
    }
    if (!accepted) {  // no decrease along the Newton step: stationary within rounding
      converged = ymax < std::sqrt(stop);
      break;
    }
    if (ymax * t * 2 < stop) {  // the accepted step was already below the tolerance
      converged = true;
      ++it;
      break;
    }
  }
  return it;
}

// Parameters of the skew-symmetric parametrisation from a coefficient list (first half and middle).
inline std::vector<double> skew_parameters(const std::vector<bigcomplex>& start) {
  const std::size_t h = start.size() / 2;
  std::vector<double> x(2 * h + 1);
  for (std::size_t k = 0; k < h; ++k) {
    x[2 * k] = re_d(start[k]);
    x[2 * k + 1] = im_d(start[k]);
  }
  x[2 * h] = re_d(start[h]);
  return x;
}

// One optimisation in double precision (thread-safe: no MPFR default precision involved).
struct SkewRun {
  std::vector<double> x;
  bool converged = false;
  int iterations = 0;
  std::vector<std::vector<double>> hessian;
  std::vector<std::size_t> free;
};

template <std::size_t M>
SkewRun skew_run_n(std::vector<double> x, Flow first, int order, double perturbation, std::uint64_t seed,
                   int max_iterations) {
  if (perturbation > 0) {  // a random move in the tangent space of the start (restored onto the constraints later)
    const LieStructure& st = lie_structure(order + 1, BasisKind::hall, AlgebraKind::rkn);
    const LieProjector<Dual<cd, M>> proj(st);
    std::vector<double> c, r;
    std::vector<std::vector<double>> jc, jr;
    if (!skew_restore<cd, M>(x, first, order, proj, 1e-14, c, jc, r, jr))
      throw std::invalid_argument("optimize_skew: the start is not close to a method of the requested order");
    std::vector<std::size_t> free;
    std::vector<std::vector<double>> u;
    if (!tangent_basis(jc, x.size(), free, u))
      throw std::invalid_argument("optimize_skew: degenerate constraints at the start");
    SplitMix64 g{seed};
    g.next();
    for (const auto& dir : u) {
      const double y = (2 * g.uniform() - 1) * perturbation;
      for (std::size_t j = 0; j < x.size(); ++j) x[j] += y * dir[j];
    }
  }
  SkewRun run;
  run.iterations = skew_reduced_newton<cd, M>(x, first, order, max_iterations, 1e-10, 1e-14, 1e-4, false, run.hessian,
                                              run.free, run.converged);
  run.x = std::move(x);
  return run;
}

// Continues a converged double run in MPFR at the current BigPrecision (quasi-Newton with the double Hessian).
template <std::size_t M>
std::vector<bigfloat> skew_polish_n(SkewRun& run, Flow first, int order, int max_iterations) {
  std::vector<bigfloat> xb;
  for (double v : run.x) xb.emplace_back(v);
  const double digits = static_cast<double>(bigfloat::default_precision());
  bool conv = false;
  run.iterations +=
      skew_reduced_newton<bigcomplex, M>(xb, first, order, max_iterations, std::pow(10.0, -0.45 * digits),
                                         std::pow(10.0, -0.8 * digits), 0, true, run.hessian, run.free, conv);
  run.converged = conv;
  return xb;
}

#define NYSTROM_SKEW_SIZES(X) X(5) X(7) X(9) X(11) X(13) X(15) X(17)

inline SkewRun skew_run(std::size_t m, const std::vector<double>& x, Flow first, int order, double perturbation,
                        std::uint64_t seed, int max_iterations) {
  switch (m) {
#define NYSTROM_CASE(N) \
  case N: return skew_run_n<N>(x, first, order, perturbation, seed, max_iterations);
    NYSTROM_SKEW_SIZES(NYSTROM_CASE)
#undef NYSTROM_CASE
    default:
      throw std::invalid_argument(
          "optimize_skew: the start must have an odd number of sub-steps between 5 and 17, got " + std::to_string(m));
  }
}
inline std::vector<bigfloat> skew_polish(std::size_t m, SkewRun& run, Flow first, int order, int max_iterations) {
  switch (m) {
#define NYSTROM_CASE(N) \
  case N: return skew_polish_n<N>(run, first, order, max_iterations);
    NYSTROM_SKEW_SIZES(NYSTROM_CASE)
#undef NYSTROM_CASE
    default: throw std::invalid_argument("optimize_skew: unsupported number of sub-steps");
  }
}
#undef NYSTROM_SKEW_SIZES

// The optimum as coefficients with its error norms (calling thread: sets the MPFR precision).
inline SkewOptimum make_optimum(const std::vector<bigfloat>& x, std::size_t m, Flow first, int order, int iterations,
                                bool converged, const std::vector<bigcomplex>& start, unsigned bits) {
  SkewOptimum o;
  o.first = first;
  o.order = order;
  o.iterations = iterations;
  o.converged = converged;
  BigPrecision guard(std::max(128u, bits));
  o.coefficients = skew_substeps<bigcomplex>(x, m);
  AnalysisOptions opt;
  opt.degree = order + 1;
  opt.precision_bits = std::max(128u, bits);
  const auto a = analyze_scheme(o.scheme(), opt);
  o.error_norm = a.degrees[static_cast<std::size_t>(order)].norm;
  double cmax = 0;
  for (int d = 1; d <= order; ++d)
    for (const auto& t : a.degrees[static_cast<std::size_t>(d - 1)].terms) cmax = std::max(cmax, std::abs(t.value));
  o.constraint_residual = cmax;
  const auto a0 = analyze_scheme(alternating_scheme(first, start), opt);
  o.start_error_norm = a0.degrees[static_cast<std::size_t>(order)].norm;
  return o;
}

}  // namespace detail

struct SkewSearchOptions {
  int order = 5;
  int tries = 1;              // try 0 starts at `start` itself, tries 1.. after random moves along the constraints
  double perturbation = 0.1;  // size of the random moves (each tangent coordinate uniform in [-p, p])
  std::uint64_t seed = 1;
  int max_iterations = 60;
  unsigned polish_bits = 0;  // > 0: polish the best minimum in MPFR at this precision
  int threads = 1;
};

struct SkewSearchResult {
  std::vector<SkewOptimum> minima;  // distinct local minima, best first
  int failed = 0;                   // tries that did not converge
};

/// Minimises (sum |X_i|^2)^{1/2} over the degree order+1 terms (Hall basis, RKN algebra) among skew-symmetric
/// splittings with the sub-step pattern of `start` (time order, alternating from `first`, odd length 5..17)
/// that keep the order: reduced Newton from `start` and from seeded random moves along the constraint manifold
/// (Gürkan eq 6.1: start = AC1 with zero kicks added at both ends). Only the first half and the middle of
/// `start` are used. Deterministic for a seed (independent of the number of threads).
inline SkewSearchResult optimize_skew(const std::vector<bigcomplex>& start, Flow first, const SkewSearchOptions& opt) {
  if (opt.order < 1 || opt.order % 2 == 0 || opt.order > 9)
    throw std::invalid_argument(
        "optimize_skew: the order must be odd (the leading error of a skew-symmetric method is "
        "imaginary only for odd orders), between 1 and 9");
  if (opt.tries < 1 || opt.tries > 100000)
    throw std::invalid_argument("optimize_skew: tries must be between 1 and 100000");
  if (!(opt.perturbation >= 0) || opt.perturbation > 10)
    throw std::invalid_argument("optimize_skew: the perturbation must be between 0 and 10");
  if (opt.polish_bits != 0 && (opt.polish_bits < 128 || opt.polish_bits > 2048))
    throw std::invalid_argument("optimize_skew: the polishing precision must be 0 or 128..2048 bits");
  if (opt.max_iterations < 1 || opt.max_iterations > 100000)
    throw std::invalid_argument("optimize_skew: max_iterations must be between 1 and 100000");
  if (opt.threads < 1 || opt.threads > 256)
    throw std::invalid_argument("optimize_skew: threads must be between 1 and 256");
  const std::size_t m = start.size();
  if (m < 5 || m > 17 || m % 2 == 0)
    throw std::invalid_argument("optimize_skew: the start must have an odd number of sub-steps between 5 and 17, got " +
                                std::to_string(m));
  const std::vector<double> x0 = detail::skew_parameters(start);
  std::vector<std::optional<detail::SkewRun>> runs(static_cast<std::size_t>(opt.tries));
  std::string first_error;
  std::mutex mu;
  detail::parallel_for(opt.tries, opt.threads, [&](long t) {
    try {
      runs[static_cast<std::size_t>(t)] =
          detail::skew_run(m, x0, first, opt.order, t == 0 ? 0.0 : opt.perturbation,
                           opt.seed * 0x9e3779b97f4a7c15ULL + static_cast<std::uint64_t>(t), opt.max_iterations);
    } catch (const std::invalid_argument& e) {
      if (t == 0) {
        std::lock_guard<std::mutex> lock(mu);
        first_error = e.what();
      }
    }
  });
  if (!first_error.empty()) throw std::invalid_argument(first_error);
  SkewSearchResult res;
  std::vector<detail::SkewRun*> kept;
  for (auto& r : runs) {
    if (!r || !r->converged) {
      ++res.failed;
      continue;
    }
    std::vector<bigfloat> xb;
    {
      BigPrecision guard(128);
      for (double v : r->x) xb.emplace_back(v);
    }
    auto o = detail::make_optimum(xb, m, first, opt.order, r->iterations, true, start, 128);
    const auto v = scheme_coefficients(o.scheme());
    bool dup = false;
    for (const auto& q : res.minima)
      if (max_distance(scheme_coefficients(q.scheme()), v) < 1e-6) dup = true;
    if (dup) continue;
    res.minima.push_back(std::move(o));
    kept.push_back(&*r);
  }
  std::vector<std::size_t> order(res.minima.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return res.minima[a].error_norm < res.minima[b].error_norm; });
  std::vector<SkewOptimum> sorted;
  for (std::size_t i : order) sorted.push_back(std::move(res.minima[i]));
  res.minima = std::move(sorted);
  if (opt.polish_bits > 0 && !res.minima.empty()) {
    detail::SkewRun& best = *kept[order.front()];
    std::vector<bigfloat> xb;
    {
      BigPrecision guard(opt.polish_bits);
      xb = detail::skew_polish(m, best, first, opt.order, 40);
    }
    res.minima.front() =
        detail::make_optimum(xb, m, first, opt.order, best.iterations, best.converged, start, opt.polish_bits);
  }
  return res;
}

/// Eq (6.1): a 5-stage RKNA method (drift first, 11 sub-steps) embedded in the 6-stage kick-first pattern
/// with zero kicks at both ends (beta'_1 = beta'_7 = 0).
inline std::vector<bigcomplex> embed_rkna_in_kick_first(const SplittingScheme<bigcomplex>& rkna) {
  const auto s = normalized(rkna);
  if (s.steps.empty() || s.steps.front().flow != Flow::drift || s.steps.back().flow != Flow::drift)
    throw std::invalid_argument("the method to embed must start and end with a drift (an RKNA scheme)");
  std::vector<bigcomplex> v{bigcomplex()};
  for (const auto& st : s.steps) v.push_back(st.coef);
  v.push_back(bigcomplex());
  return v;
}

}  // namespace nystrom::analysis
