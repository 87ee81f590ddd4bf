// The Gragg-Bulirsch-Stoer extrapolation integrator for q'' = f(q), in the manner of Hairer's ODEX2
// (Hairer, Nørsett & Wanner, Solving ODEs I, secs. II.9 and II.14):
//
//   * base method: Störmer's rule with Gragg's starting and end formulas, in the summed form (II.14.32)
//     that limits rounding: with h = H / n (n even) and Δ_k = q_{k+1} - q_k,
//        Δ_0 = h (v_0 + h/2 f(q_0)),  Δ_k = Δ_{k-1} + h^2 f(q_k),  v_n = Δ_{n-1}/h + h/2 f(q_n);
//     its error expands in powers of h^2;
//   * extrapolation: the Aitken-Neville table in h^2, T_{j,k+1} = T_{j,k} + (T_{j,k} - T_{j-1,k}) /
//     ((n_j / n_{j-k})^2 - 1);
//   * step-size sequence n_j (a parameter): harmonic doubled 2, 4, 6, 8, ... (ODEX2's and the Gürkan
//     paper's, the default), Romberg 2, 4, 8, 16, ..., or Bulirsch 2, 4, 6, 8, 12, 16, 24, ...;
//   * error of column j: err_j = RMS_i |T_{j,j} - T_{j,j-1}|_i / (atol + rtol max(|y0_i|, |y1_i|)) over all
//     position and velocity components; step H_j = H * 0.94 (0.65 / err_j)^{1/(2j-1)} (bounded);
//     work per unit step W_j = A_j / H_j with A_j the force evaluations of columns 1..j;
//   * order and step control of HNW II.9: convergence is tested in the order window k-1, k, k+1; a step
//     that cannot converge there is rejected early; after a step, the order moves to the neighbour with
//     the least work per unit step.
//
// integrate_to(s, T) advances exactly the time T (the last step is shortened); the controller's step
// size is kept between calls, so many short calls (one per step of another method) are efficient.
// As a "method", integrate(s, h, n) makes n such calls of length h.
//
// A velocity-dependent force q'' = f(q, v) (the force callable as force(q, v, a)) runs the first-order
// form z = (q, v), z' = (v, f(q, v)) with Gragg's modified midpoint rule as the base method (HNW II.9,
// ODEX; no smoothing step): with h = H / n (n even),
//        z_1 = z_0 + h z'(z_0),  z_{k+1} = z_{k-1} + 2h z'(z_k)  (k = 1 .. n-1),  result z_n,
// whose error also expands in powers of h^2 (Gragg 1965); extrapolation and control are the same. It costs
// n - 1 forces per row besides the shared first one.
//
// A time-dependent force runs as an autonomous one with the time as one more coordinate (velocity 1,
// acceleration 0; solve() does so). set_clock(i, end) names that coordinate: GBS then sets it exactly at
// every substep (t + k H / n, and t + H at the end of a step) instead of summing and extrapolating it, so
// the force sees no rounding drift of the time and never a time beyond `end` (the end of the span).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "nystrom/core/error.hpp"
#include "nystrom/core/state.hpp"
#include "nystrom/engines/options.hpp"

namespace nystrom {

namespace detail {
inline std::string fmt_g(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3g", x);
  return b;
}

/// The columns of the next step after an accepted step of kc columns (HNW I, sec. II.9, as in ODEX), from the work
/// per unit step W[j] of j columns: one fewer when W[kc - 1] < 0.8 W[kc] (from three columns); else one more
/// when W[kc] < 0.9 W[kc - 1] and the step did not follow a rejection; kept within [2, km - 1].
template <class R>
int gbs_next_columns(int kc, const std::vector<R>& W, int km, bool last_rejected) {
  int kn = kc;
  if (kc >= 3 && W[static_cast<std::size_t>(kc) - 1] < R(0.8) * W[static_cast<std::size_t>(kc)]) kn = kc - 1;
  if (kc >= 2 && kn == kc && !last_rejected && kc + 1 <= km - 1 &&
      W[static_cast<std::size_t>(kc)] < R(0.9) * W[static_cast<std::size_t>(kc) - 1])
    kn = kc + 1;
  return std::clamp(kn, 2, km - 1);
}
}  // namespace detail

inline GbsSequence parse_gbs_sequence(const std::string& s) {
  if (s == "harmonic") return GbsSequence::harmonic;
  if (s == "romberg") return GbsSequence::romberg;
  if (s == "bulirsch") return GbsSequence::bulirsch;
  throw std::invalid_argument("unknown GBS step-size sequence '" + s + "' (known: harmonic, romberg, bulirsch)");
}

/// n_1 .. n_kmax of a sequence (all even).
inline std::vector<long> gbs_sequence(GbsSequence seq, int kmax) {
  std::vector<long> n;
  for (int j = 1; j <= kmax; ++j) {
    switch (seq) {
      case GbsSequence::harmonic: n.push_back(2L * j); break;
      case GbsSequence::romberg: n.push_back(2L << (j - 1)); break;
      case GbsSequence::bulirsch:
        n.push_back(j <= 3 ? 2L * j : 2 * n[static_cast<std::size_t>(j) - 3]);  // 2,4,6,8,12,16,24,...
        break;
    }
  }
  return n;
}

template <class V, class F>
class GbsIntegrator {
  struct NoObserver {
    void operator()(const real_t<typename V::value_type>&, const State<V>&) const {}
  };

 public:
  using scalar_type = typename V::value_type;
  using real_type = real_t<scalar_type>;
  static_assert(!is_complex_v<scalar_type>, "GBS works on real states");
  /// Whether the force takes the velocity (force(q, v, a)): the modified midpoint base.
  static constexpr bool velocity_dependent = takes_velocity_v<F, V>;

  GbsIntegrator(F force, GbsOptions opt = {}) : force_(std::move(force)), opt_(opt) {
    if (opt_.max_columns < 3 || opt_.max_columns > 30)
      throw std::invalid_argument("GBS: the number of columns must be between 3 and 30");
    const double eps = as_double(epsilon_of<real_type>());
    if (!(opt_.rtol >= 0) || !(opt_.atol >= 0) || !std::isfinite(opt_.rtol) || !std::isfinite(opt_.atol) ||
        (opt_.rtol == 0 && opt_.atol == 0))
      throw std::invalid_argument("GBS: tolerances must be finite, >= 0 and not both zero");
    const double floor = 20 * eps;
    if ((opt_.rtol > 0 && opt_.rtol < floor) || (opt_.atol > 0 && opt_.atol < floor) ||
        std::max(opt_.rtol, opt_.atol) < floor)
      throw std::invalid_argument(
          "GBS: tolerance " +
          detail::fmt_g(std::min(opt_.rtol > 0 ? opt_.rtol : 1.0, opt_.atol > 0 ? opt_.atol : 1.0)) +
          " is below what " + scalar_traits<real_type>::name() + " can reach (>= " + detail::fmt_g(floor) +
          "; use a wider --precision)");
    if (!(opt_.initial_step >= 0) || !std::isfinite(opt_.initial_step))
      throw std::invalid_argument("GBS: the initial step must be finite and >= 0");
    if (opt_.max_steps <= 0) throw std::invalid_argument("GBS: max_steps must be positive");
    nseq_ = gbs_sequence(opt_.sequence, opt_.max_columns);
    const int km = opt_.max_columns;
    // Initial order from the tolerance (HNW II.9): about 0.6 * -log10(tol) + 1.5 columns.
    const double tol = std::max(opt_.rtol, 1e-40);
    k_ = std::clamp(static_cast<int>(-std::log10(tol) * 0.6 + 1.5), 3, km - 1);
    H_ = static_cast<real_type>(opt_.initial_step);
    A_.resize(static_cast<std::size_t>(km) + 1);
    // Force evaluations of columns 1..j (the midpoint rule needs one less per row than Störmer's).
    const long per_row = velocity_dependent ? -1 : 0;
    A_[1] = nseq_[0] + 1 + per_row;
    for (int j = 2; j <= km; ++j)
      A_[static_cast<std::size_t>(j)] =
          A_[static_cast<std::size_t>(j) - 1] + nseq_[static_cast<std::size_t>(j) - 1] + per_row;
    row_.resize(static_cast<std::size_t>(km));
    prev_.resize(static_cast<std::size_t>(km));
  }

  long force_evals() const { return evals_; }
  long steps() const { return accepted_; }
  long rejected() const { return rejected_; }
  int order() const { return 2 * k_; }
  real_type step_size() const { return H_; }
  F& force() { return force_; }
  const std::vector<long>& sequence() const { return nseq_; }

  /// Coordinate `index` of the state is the time (velocity 1, acceleration 0): it is set exactly at every
  /// substep and never exceeds `end` (see the top of the file).
  void set_clock(std::size_t index, real_type end) {
    clock_ = static_cast<long>(index);
    clock_end_ = end;
  }

  /// Where a run stopped at its observer's request, with the controller's state: integrate_to with the
  /// same span continues from it exactly as if it had not stopped (also on a new integrator after
  /// set_resume_point: a restart from a checkpoint).
  struct ResumePoint {
    real_type t{}, span{}, H{};
    int k = 0;
    bool last_rejected = false;
    bool valid = false;
  };
  const ResumePoint& resume_point() const { return resume_; }
  /// A valid point must be one this integrator can have stopped at: 0 < t < span, a finite step H > 0 and
  /// an order k of 2 to max_columns - 1 columns (invalid_input otherwise: a checkpoint is refused).
  void set_resume_point(const ResumePoint& p) {
    if (p.valid) {
      const int km = opt_.max_columns;
      if (p.k < 2 || p.k > km - 1)
        throw invalid_input("GBS: the order of the resume point (" + std::to_string(p.k) + " columns) is outside 2.." +
                            std::to_string(km - 1) + " of this integrator");
      if (!is_finite_scalar(p.H) || !(p.H > real_type(0)) || !is_finite_scalar(p.span) || !is_finite_scalar(p.t) ||
          !(p.t > real_type(0)) || !(p.t < p.span))
        throw invalid_input("GBS: the resume point needs 0 < t < span and a finite step > 0");
    }
    resume_ = p;
  }
  /// The counters (a restart from a checkpoint continues them).
  void set_counters(long force_evals, long accepted, long rejected) {
    evals_ = force_evals;
    accepted_ = accepted;
    rejected_ = rejected;
  }

  /// Advances s by exactly `span` (> 0) with adaptive steps. obs(t, s) is called after every accepted
  /// step with t the time since the start of the span; if it returns true, the run stops there and keeps
  /// its resume point.
  template <class Obs = NoObserver>
  void integrate_to(State<V>& s, real_type span, Obs&& obs = {}) {
    using std::abs;
    if (!(span > real_type(0)) || !is_finite_scalar(span))
      throw std::invalid_argument("GBS: the time span must be positive");
    if (clock_ >= 0 && static_cast<std::size_t>(clock_) >= s.q.size())
      throw std::invalid_argument("GBS: the clock coordinate lies outside the state");
    real_type t(0);
    if (!(H_ > real_type(0))) H_ = span;
    long tries = 0;
    bool last_rejected = false;
    if (resume_.valid && resume_.span == span) {
      t = resume_.t;
      H_ = resume_.H;
      k_ = resume_.k;
      last_rejected = resume_.last_rejected;
    }
    resume_.valid = false;
    while (t < span) {
      if (++tries > opt_.max_steps)
        throw too_many_steps("GBS: more than " + std::to_string(opt_.max_steps) + " steps for one span (t = " +
                             detail::fmt_g(as_double(t)) + " of " + detail::fmt_g(as_double(span)) + ")");
      const real_type rem = span - t;
      const bool final_step = H_ >= rem * real_type(0.999999);  // avoid a sliver of a last step
      const real_type H = final_step ? rem : H_;
      // A step below the rounding level of t would not advance it (t + H == t): accepted steps of that size
      // (a force that is NaN past a point the state reaches) would repeat until max_steps.
      const real_type h_floor =
          abs(span) * real_type(1e-3) > real_type(16) * t ? abs(span) * real_type(1e-3) : real_type(16) * t;
      if (!(H > h_floor * epsilon_of<real_type>()) && !final_step)
        throw step_size_underflow("GBS: step size underflow at t = " + detail::fmt_g(as_double(t)) +
                                  " (singular force, or a tolerance the precision cannot reach)");
      real_type Hnew;
      if (try_step(s, H, last_rejected, Hnew)) {
        t = final_step ? span : t + H;
        ++accepted_;
        last_rejected = false;
        // keep the controller's step unless this was a shortened final step that is smaller than it
        if (!final_step || Hnew < H_ || H >= H_)
          H_ = Hnew;
        else
          H_ = std::max(H_, Hnew);
        bool stop = false;
        if constexpr (std::is_same_v<std::invoke_result_t<Obs&, const real_type&, const State<V>&>, bool>)
          stop = obs(static_cast<const real_type&>(t), static_cast<const State<V>&>(s));
        else
          obs(static_cast<const real_type&>(t), static_cast<const State<V>&>(s));
        if (stop && t < span) {
          resume_ = {t, span, H_, k_, false, true};
          return;
        }
      } else {
        ++rejected_;
        last_rejected = true;
        H_ = Hnew;
      }
      if (!is_finite_scalar(H_) || !(H_ > real_type(0)))
        throw step_size_underflow("GBS: the step size became invalid (the solution is not finite)");
    }
  }

  /// n consecutive spans of length h (the "method" interface).
  void integrate(State<V>& s, real_type h, long n) {
    for (long i = 0; i < n; ++i) integrate_to(s, h);
  }
  /// The controller's order (columns) and step, for a restart.
  int columns() const { return k_; }
  void step(State<V>& s, real_type h) { integrate_to(s, h); }

 private:
  // The force at (q, v), whichever form it has.
  void eval(const V& q, const V& v, V& a) {
    if constexpr (velocity_dependent) {
      force_(q, v, a);
    } else {
      (void)v;
      force_(q, a);
    }
    ++evals_;
  }

  // Gragg's modified midpoint rule on z = (q, v) with n substeps of H / n from s with f0 = f(q0, v0):
  // z_n in out (velocity-dependent forces).
  void midpoint(const State<V>& s, const V& f0, real_type H, long n, State<V>& out) {
    const std::size_t dim = s.q.size();
    const real_type h = H / real_type(n);
    const real_type h2 = h + h;
    resize_like(out.q, s.q);
    resize_like(out.v, s.q);
    resize_like(zp_.q, s.q);
    resize_like(zp_.v, s.q);
    resize_like(f_, s.q);
    for (std::size_t i = 0; i < dim; ++i) {
      zp_.q[i] = s.q[i];
      zp_.v[i] = s.v[i];
      out.q[i] = s.q[i] + h * s.v[i];
      out.v[i] = s.v[i] + h * f0[i];
    }
    set_clock_at(s, H, 1, n, out);
    for (long k = 1; k < n; ++k) {
      eval(out.q, out.v, f_);
      for (std::size_t i = 0; i < dim; ++i) {
        const scalar_type q = zp_.q[i] + h2 * out.v[i];
        const scalar_type v = zp_.v[i] + h2 * f_[i];
        zp_.q[i] = out.q[i];
        zp_.v[i] = out.v[i];
        out.q[i] = q;
        out.v[i] = v;
      }
      set_clock_at(s, H, k + 1, n, out);
    }
  }

  // Störmer/Gragg with n substeps of H / n from (q0, v0) with f0 = f(q0): result (q, v) in out.
  void stoermer(const State<V>& s, const V& f0, real_type H, long n, State<V>& out) {
    const std::size_t dim = s.q.size();
    const real_type h = H / real_type(n);
    const real_type h2 = h * h;
    resize_like(out.q, s.q);
    resize_like(out.v, s.q);
    resize_like(delta_, s.q);
    resize_like(f_, s.q);
    for (std::size_t i = 0; i < dim; ++i) {
      delta_[i] = h * (s.v[i] + h / real_type(2) * f0[i]);
      out.q[i] = s.q[i] + delta_[i];
    }
    set_clock_at(s, H, 1, n, out);
    for (long k = 1; k < n; ++k) {
      force_(out.q, f_);
      ++evals_;
      for (std::size_t i = 0; i < dim; ++i) {
        delta_[i] += h2 * f_[i];
        out.q[i] += delta_[i];
      }
      set_clock_at(s, H, k + 1, n, out);
    }
    force_(out.q, f_);
    ++evals_;
    for (std::size_t i = 0; i < dim; ++i) out.v[i] = delta_[i] / h + h / real_type(2) * f_[i];
  }

  // The clock coordinate (set_clock) at substep k of n of the step of H from s: exactly t + k H / n (t + H
  // at k = n), at most the end of the span. Every row of the table has the same value, so the extrapolated
  // state has it too.
  void set_clock_at(const State<V>& s, real_type H, long k, long n, State<V>& out) const {
    if (clock_ < 0) return;
    const auto c = static_cast<std::size_t>(clock_);
    const real_type t = k == n ? real_type(s.q[c] + H) : real_type(s.q[c] + real_type(k) * (H / real_type(n)));
    out.q[c] = std::min(t, clock_end_);
  }

  // Scaled RMS of T[j] - T[j-1] (after extrapolation of row j), relative to y0 and the new value.
  real_type error_norm(const State<V>& y0, const State<V>& hi, const State<V>& lo) const {
    using std::abs;
    using std::sqrt;
    const std::size_t dim = y0.q.size();
    const real_type atol(opt_.atol), rtol(opt_.rtol);
    real_type sum(0);
    for (std::size_t i = 0; i < dim; ++i) {
      const real_type sq = atol + rtol * std::max(abs(y0.q[i]), abs(hi.q[i]));
      const real_type sv = atol + rtol * std::max(abs(y0.v[i]), abs(hi.v[i]));
      const real_type eq = (hi.q[i] - lo.q[i]) / sq, ev = (hi.v[i] - lo.v[i]) / sv;
      sum += eq * eq + ev * ev;
    }
    return sqrt(sum / real_type(2 * dim));
  }

  real_type step_for(real_type H, real_type err, int j) const {
    using std::pow;
    const real_type e = real_type(1) / real_type(2 * j - 1);
    real_type fac;
    if (!(err > real_type(0)))
      fac = real_type(4);
    else
      fac = real_type(0.94) * pow(real_type(0.65) / err, e);
    fac = std::clamp(fac, real_type(0.02), real_type(4));
    return H * fac;
  }

  // One attempted step of size H. Returns true if accepted (s advanced); Hnew is the next step size.
  bool try_step(State<V>& s, real_type H, bool last_rejected, real_type& Hnew) {
    const int km = opt_.max_columns;
    resize_like(f0_, s.q);
    eval(s.q, s.v, f0_);
    std::vector<real_type> Hj(static_cast<std::size_t>(km) + 1, H),
        W(static_cast<std::size_t>(km) + 1, std::numeric_limits<real_type>::max());
    const int k = k_;
    const std::size_t dim = s.q.size();
    for (int j = 1; j <= std::min(k + 1, km); ++j) {
      const std::size_t J = static_cast<std::size_t>(j) - 1;
      // Row j of the table: row_[0] = T_{j,1} (Störmer with n_j), row_[l] = T_{j,l+1}; prev_ is row j-1.
      std::swap(row_, prev_);
      if (row_.size() < static_cast<std::size_t>(km)) row_.resize(static_cast<std::size_t>(km));
      if constexpr (velocity_dependent)
        midpoint(s, f0_, H, nseq_[J], row_[0]);
      else
        stoermer(s, f0_, H, nseq_[J], row_[0]);
      for (std::size_t l = 1; l <= J; ++l) {
        const real_type r = real_type(nseq_[J]) / real_type(nseq_[J - l]);
        const real_type c = real_type(1) / (r * r - real_type(1));
        State<V>& out = row_[l];
        const State<V>& a = row_[l - 1];
        const State<V>& b = prev_[l - 1];
        resize_like(out.q, s.q);
        resize_like(out.v, s.q);
        for (std::size_t i = 0; i < dim; ++i) {
          out.q[i] = a.q[i] + (a.q[i] - b.q[i]) * c;
          out.v[i] = a.v[i] + (a.v[i] - b.v[i]) * c;
        }
      }
      if (j == 1) continue;
      const State<V>& best = row_[J];
      const real_type err = error_norm(s, best, row_[J - 1]);
      Hj[static_cast<std::size_t>(j)] = step_for(H, err, j);
      W[static_cast<std::size_t>(j)] = real_type(A_[static_cast<std::size_t>(j)]) / Hj[static_cast<std::size_t>(j)];
      const bool finite = is_finite_state(best);
      const bool ok = err <= real_type(1) && finite;
      if (j < k - 1 && finite) continue;
      if (ok) {
        assign(s.q, best.q);
        assign(s.v, best.v);
        accept(j, H, Hj, W, last_rejected, Hnew);
        return true;
      }
      // Can the step still converge within the window? (HNW II.9: err_{k-1} > (n_{k+1} n_k / n_1^2)^2 or
      // err_k > (n_{k+1} / n_1)^2 means no.)
      const double n1 = static_cast<double>(nseq_[0]);
      const double nk1 = static_cast<double>(nseq_[static_cast<std::size_t>(std::min(k, km - 1))]) / n1;
      const double nk = static_cast<double>(nseq_[static_cast<std::size_t>(k) - 1]) / n1;
      double bound = 0;  // at j = k+1 (or kmax): last chance
      if (j == k - 1)
        bound = (nk1 * nk) * (nk1 * nk);
      else if (j == k)
        bound = nk1 * nk1;
      if (!finite || !(as_double(err) <= bound) || j >= k + 1 || j == km) {
        int kn = 2;
        for (int l = 3; l <= j; ++l)
          if (W[static_cast<std::size_t>(l)] < W[static_cast<std::size_t>(kn)]) kn = l;
        k_ = std::clamp(kn, 2, km - 1);
        Hnew = finite ? std::min(Hj[static_cast<std::size_t>(k_)], H * real_type(0.9)) : H * real_type(0.25);
        return false;
      }
    }
    // not reached: the loop always decides at j = min(k+1, km)
    Hnew = H * real_type(0.5);
    return false;
  }

  void accept(int kc, real_type H, const std::vector<real_type>& Hj, const std::vector<real_type>& W,
              bool last_rejected, real_type& Hnew) {
    const int kn = detail::gbs_next_columns(kc, W, opt_.max_columns, last_rejected);
    if (kn <= kc)
      Hnew = Hj[static_cast<std::size_t>(kn)];
    else
      Hnew = Hj[static_cast<std::size_t>(kc)] * real_type(A_[static_cast<std::size_t>(kc) + 1]) /
             real_type(A_[static_cast<std::size_t>(kc)]);
    if (last_rejected) Hnew = std::min(Hnew, H);
    k_ = kn;
  }

  static bool is_finite_state(const State<V>& x) { return all_finite(x.q) && all_finite(x.v); }

  F force_;
  GbsOptions opt_;
  std::vector<long> nseq_;
  std::vector<long> A_;
  int k_ = 3;
  real_type H_ = 0;
  std::vector<State<V>> row_, prev_;
  V f0_{}, f_{}, delta_{};
  State<V> zp_{};  // the midpoint rule's z_{k-1}
  long evals_ = 0, accepted_ = 0, rejected_ = 0;
  ResumePoint resume_;
  long clock_ = -1;  // the time coordinate (set_clock), -1: none
  real_type clock_end_{};
};

}  // namespace nystrom
