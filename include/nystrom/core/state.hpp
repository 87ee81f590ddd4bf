// Phase-space state of q'' = a(q) and the few vector operations the engines use.
//
// A state is a pair of containers (positions q, velocities v). Any container with size(),
// operator[] and value_type works: std::array<S, N> for small fixed systems (the compiler
// unrolls everything), std::vector<S> for N-body. The algebra is deliberately tiny, in the
// spirit of Boost.Odeint's separation of stepper and algebra.
#pragma once

#include <array>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "nystrom/core/scalar.hpp"

// Forces inlining of the engines' inner steps (the hot loops keep fixed-size states in registers).
#ifndef NYSTROM_ALWAYS_INLINE
#if defined(__GNUC__) || defined(__clang__)
#define NYSTROM_ALWAYS_INLINE __attribute__((always_inline))
#else
#define NYSTROM_ALWAYS_INLINE
#endif
#endif

namespace nystrom {

/// Compensated (Kahan/Knuth two-sum) summation of the position and velocity updates.
/// automatic: on for float and double (as in Hairer's GNI codes), off for wider types.
enum class Compensation : unsigned char { automatic, on, off };

/// How the multi-product engine schedules its independent products (EngineOptions::mpe_schedule).
enum class MpeSchedule : unsigned char { automatic, sequential, lockstep, concurrent };

/// Options shared by all engines.
struct EngineOptions {
  /// Complex-coefficient methods: keep the complexified state instead of dropping the
  /// imaginary parts after every step (the default drops them, as in the Gürkan paper).
  bool keep_complex = false;
  /// Compensated summation of the updates q += dq, v += dv (carries the rounding error of each
  /// addition to the next one; see Compensator below).
  Compensation compensated = Compensation::automatic;
  /// MPE only, for measurements: combine the products naively as sum c_i T_i instead of
  /// T_ref + sum c_i (T_i - T_ref).
  bool mpe_naive_combination = false;
  /// MPE only: how the independent products of a step are scheduled. Every schedule gives bitwise the
  /// same result. lockstep: sub-step j of every product before sub-step j + 1 of any, so that the
  /// processor overlaps their independent chains of force evaluations (small systems); concurrent: the
  /// products on mpe_threads OpenMP threads, each with its own copy of the force functor (expensive
  /// forces such as N-body; the force's own threading is then nested and runs serially); sequential:
  /// one product after the other; automatic: lockstep for fixed-size states (std::array), else
  /// sequential.
  MpeSchedule mpe_schedule = MpeSchedule::automatic;
  /// Threads of the concurrent schedule (0: OpenMP's default). Without OpenMP it runs sequentially.
  int mpe_threads = 0;
};

/// Whether compensated summation is used for scalar type S under option c.
template <class S>
constexpr bool use_compensation(Compensation c) {
  using T = real_t<S>;
  if (c == Compensation::on) return true;
  if (c == Compensation::off) return false;
  return std::is_same_v<T, float> || std::is_same_v<T, double>;
}

template <class V>
struct State {
  using vector_type = V;
  using value_type = typename V::value_type;
  V q;
  V v;
};

/// Whether an engine's force takes the velocity, force(q, v, a) (and not force(q, a)): the velocity-dependent
/// forces that GBS, the general RKN pairs and the first-step estimate call with the stage velocity.
template <class F, class V>
inline constexpr bool takes_velocity_v =
    std::is_invocable_v<F&, const V&, const V&, V&> && !std::is_invocable_v<F&, const V&, V&>;

/// Whether a force is also compensated, force(q, cq, a, alo) besides force(q, a): it takes the position q + cq (cq
/// the carry of compensated summation) and returns the acceleration a + alo to about twice the working precision.
/// The compensated runs of the adaptive RKN pairs (engines/rkn.hpp) and of the fixed-step splitting and multi-product
/// engines (engines/splitting.hpp, engines/mpe.hpp) and of the adaptive multi-product expansion of one order
/// (engines/adaptive_mpe_kernels.hpp) use it in double and float; the other engines call force(q, a),
/// and solve() runs such a force on the inline path (solve.hpp).
template <class F, class V>
inline constexpr bool takes_carry_v =
    std::conjunction_v<std::is_invocable<F&, const V&, const V&, V&, V&>, std::is_invocable<F&, const V&, V&>>;

/// The scalar types whose rounding the engines carry in double-word arithmetic (core/eft.hpp): double and float. The
/// wider types (long double, dd, qd, float128, MPFR) run without it.
template <class T>
inline constexpr bool word_scalar = std::is_same_v<T, double> || std::is_same_v<T, float>;

/// Whether two states hold the same values, element by element (a NaN is never the same): the engines' test that
/// a cached force or carry still belongs to the state they are given.
template <class V>
bool same_values(const V& x, const V& y) {
  if (x.size() != y.size()) return false;
  for (std::size_t i = 0; i < x.size(); ++i)
    if (!(x[i] == y[i])) return false;
  return true;
}

template <class V>
struct is_std_array : std::false_type {};
template <class S, std::size_t N>
struct is_std_array<std::array<S, N>> : std::true_type {};

/// Make `a` the same size as `b` (no-op for fixed-size containers).
template <class V>
void resize_like(V& a, const V& b) {
  if constexpr (!is_std_array<V>::value) {
    if (a.size() != b.size()) a.resize(b.size());
  }
}

/// y += c * x, elementwise. Forced inline: GCC otherwise calls it out of line for double-double
/// states (a fifth of an M8 step in dd went to the calls).
template <class V, class C>
NYSTROM_ALWAYS_INLINE inline void axpy(V& y, const C& c, const V& x) {
  const std::size_t n = y.size();
  for (std::size_t i = 0; i < n; ++i) y[i] += c * x[i];
}

/// y = x, elementwise (keeps y's storage).
template <class V>
inline void assign(V& y, const V& x) {
  if constexpr (is_std_array<V>::value) {
    y = x;
  } else {
    y.assign(x.begin(), x.end());
  }
}

/// Replace every element by its real part (complex-coefficient methods).
template <class V>
inline void project_real(V& x) {
  for (auto& e : x) e = real_part(e);
}

template <class V>
bool all_finite(const V& x) {
  for (const auto& e : x)
    if (!is_finite_scalar(e)) return false;
  return true;
}

/// Throws std::invalid_argument unless the state is non-empty, consistent and finite.
template <class V>
void validate_state(const State<V>& s) {
  if (s.q.size() == 0) throw std::invalid_argument("empty system: the state has no coordinates");
  if (s.q.size() != s.v.size())
    throw std::invalid_argument("inconsistent state: " + std::to_string(s.q.size()) + " positions but " +
                                std::to_string(s.v.size()) + " velocities");
  if (!all_finite(s.q) || !all_finite(s.v)) throw std::invalid_argument("state contains NaN or infinite values");
}

/// x + c += d with x + c carried exactly up to the rounding of c: Knuth's two-sum of x and (c + d),
/// valid whatever the relative sizes of x and the increment (positions cross zero).
template <class S>
inline void compensated_add(S& x, S& c, const S& d) {
  const S a = c + d;
  const S t = x + a;
  const S bp = t - x;
  c = (x - (t - bp)) + (a - bp);
  x = t;
}

/// The rounding errors of q and v carried between compensated updates. The carry survives from one
/// integrate() call to the next only if the caller did not move the state in between.
template <class V>
struct Compensator {
  V cq{}, cv{};
  V lastq{}, lastv{};
  bool valid = false;

  /// Start (or continue, if s is the state last left) a compensated run.
  void begin(const State<V>& s) {
    if (valid && same_values(lastq, s.q) && same_values(lastv, s.v)) return;
    resize_like(cq, s.q);
    resize_like(cv, s.v);
    for (auto& e : cq) e = typename V::value_type(0);
    for (auto& e : cv) e = typename V::value_type(0);
  }
  void end(const State<V>& s) {
    resize_like(lastq, s.q);
    resize_like(lastv, s.v);
    assign(lastq, s.q);
    assign(lastv, s.v);
    valid = true;
  }
  void invalidate() { valid = false; }
  /// Carries restored from a checkpoint taken at state s: the next begin(s) continues with them.
  void restore(const V& q_carry, const V& v_carry, const State<V>& s) {
    resize_like(cq, q_carry);
    resize_like(cv, v_carry);
    assign(cq, q_carry);
    assign(cv, v_carry);
    end(s);
  }
  /// q += d (compensated).
  void add_q(V& q, const V& d) {
    for (std::size_t i = 0; i < q.size(); ++i) compensated_add(q[i], cq[i], d[i]);
  }
  void add_v(V& v, const V& d) {
    for (std::size_t i = 0; i < v.size(); ++i) compensated_add(v[i], cv[i], d[i]);
  }
  /// q += c x (compensated).
  template <class C>
  void axpy_q(V& q, const C& c, const V& x) {
    for (std::size_t i = 0; i < q.size(); ++i) compensated_add(q[i], cq[i], typename V::value_type(c * x[i]));
  }
  template <class C>
  void axpy_v(V& v, const C& c, const V& x) {
    for (std::size_t i = 0; i < v.size(); ++i) compensated_add(v[i], cv[i], typename V::value_type(c * x[i]));
  }
};

/// Converts a real state to its complex counterpart (or copies if the types agree).
template <class VOut, class VIn>
State<VOut> convert_state(const State<VIn>& s) {
  State<VOut> out;
  if constexpr (!is_std_array<VOut>::value) {
    out.q.resize(s.q.size());
    out.v.resize(s.v.size());
  }
  using SOut = typename VOut::value_type;
  for (std::size_t i = 0; i < s.q.size(); ++i) {
    if constexpr (is_complex_v<SOut> && !is_complex_v<typename VIn::value_type>) {
      out.q[i] = SOut(s.q[i], 0);
      out.v[i] = SOut(s.v[i], 0);
    } else if constexpr (!is_complex_v<SOut> && is_complex_v<typename VIn::value_type>) {
      out.q[i] = s.q[i].real();
      out.v[i] = s.v[i].real();
    } else {
      out.q[i] = static_cast<SOut>(s.q[i]);
      out.v[i] = static_cast<SOut>(s.v[i]);
    }
  }
  return out;
}

/// Rebinds a container type to another element type: array<S,N> -> array<U,N>, vector<S> -> vector<U>.
template <class V, class U>
struct rebind_vector;
template <class S, std::size_t N, class U>
struct rebind_vector<std::array<S, N>, U> {
  using type = std::array<U, N>;
};
template <class S, class A, class U>
struct rebind_vector<std::vector<S, A>, U> {
  using type = std::vector<U>;
};
template <class V, class U>
using rebind_vector_t = typename rebind_vector<V, U>::type;

}  // namespace nystrom
