// Langevin dynamics
//   dq = v dt,   dv = a(q) dt - gamma v dt + sqrt(2 gamma kT / m) dW
// by a splitting over the drift A, the kick B and the exact Ornstein-Uhlenbeck flow O (splitting.hpp), with
// expectations and time averages over many independent paths, and their extrapolation by the multi-product
// expansion.
//
// Observables. For each path and each observable phi(q, v):
//   * final:         phi(q_T, v_T) at the end T = N h;
//   * time average:  the trapezoidal average of phi over the second half [n0 h, N h], n0 = floor(N / 2).
// The result gives their means over the paths with standard errors (the sample standard deviation over the
// paths divided by sqrt(paths)).
//
// Extrapolation. With a sequence k_1..k_n, every path runs n times, at the steps h / k_i, and the estimator of
// the path is sum_i c_i A_i, with the coefficients c_i = prod_{j != i} k_i^2 / (k_i^2 - k_j^2) of the
// multi-product expansion (S. A. Chin, "Multi-product splitting and Runge-Kutta-Nystrom integrators", Celest.
// Mech. Dyn. Astron. 106 (2010) 391, eq 14; methods/mpe_coefficients.hpp). For a symmetric splitting the
// one-step generator is exp(h L + h^3 L_3 + h^5 L_5 + ...) (symmetric BCH), so the expectations at a fixed time
// and the stationary averages have errors in even powers of h: the n-term combination removes h^2 .. h^{2n-2},
// and a weak-order-2 scheme (BAOAB) becomes order 2n. Non-symmetric splittings are refused with n > 1.
// The n runs of a path share one Brownian path: the step h is cut into L * m slots (L = lcm(k_i), m the O
// letters per step) and one standard normal per slot and component is drawn (philox_normals.hpp); an O stage of
// run i spans L / k_i slots and uses their sum divided by sqrt(L / k_i), the normalised Brownian increment over
// its interval. Each run alone has exactly the law of the scheme at its step; the coupling keeps the runs close,
// so that the combination, whose coefficients have alternating signs, has about the variance of one run.
//
// Reproducibility. The noise is a pure function of (seed, path, slot, component); paths are processed in chunks
// of `chunk_paths` and the per-chunk statistics are merged in chunk order: results are bitwise the same for any
// thread count, and for any partition of the paths at chunk boundaries (run_langevin_paths + merge).
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <numeric>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "nystrom/core/error.hpp"
#include "nystrom/methods/mpe_coefficients.hpp"
#include "nystrom/stochastic/philox_normals.hpp"
#include "nystrom/stochastic/splitting.hpp"

namespace nystrom::stochastic {

/// The error of a run stopped through LangevinOptions::stop.
inline error error_interrupted() { return error("interrupted"); }

/// Most members of an extrapolation sequence.
inline constexpr std::size_t max_members = 8;

/// Most paths of one run (the statistics of every chunk of 64 paths are kept until the end: about 1 kB each for
/// five observables and three members).
inline constexpr long max_paths = 100000000;

/// Paths per chunk: the unit of work and of the deterministic reduction.
inline constexpr long chunk_paths = 64;

/// A Langevin problem. `acceleration(q, a)` writes a(q) = -grad U(q) / m; `observe(q, v, out)` writes the
/// observables phi_j(q, v), j = 0 .. observable_names.size() - 1. Both must be safe to call from several
/// threads at once (pure functions of their arguments).
template <class Acceleration, class Observe>
struct LangevinProblem {
  Acceleration acceleration;
  Observe observe;
  std::vector<std::string> observable_names;
  std::vector<double> q0, v0;
  double gamma = 1;  // friction
  double kT = 1;     // temperature (Boltzmann's constant times T)
  double mass = 1;
  double t_end = 10;  // T: a whole number of steps h
};

struct LangevinOptions {
  std::string method = "BAOAB";
  double h = 0.05;
  long paths = 1000;
  std::uint64_t seed = 1;
  std::vector<long> extrapolate = {1};  // k_1..k_n; {1}: the scheme alone
  int threads = 1;
  /// Called with the number of paths done (from the worker threads, one call at a time); may be empty.
  std::function<void(long done, long total)> progress{};
  /// Set to true from elsewhere to stop early: the run then throws nystrom::error("interrupted").
  const std::atomic<bool>* stop = nullptr;
};

/// A mean over paths with its standard error.
struct Estimate {
  double value = 0, stderr_ = 0;
};

/// Running statistics of one quantity over paths (Welford; merged by Chan et al.'s pairwise formula).
struct RunningStats {
  double n = 0, mean = 0, m2 = 0;
  void add(double x) {
    n += 1;
    const double d = x - mean;
    mean += d / n;
    m2 += d * (x - mean);
  }
  void merge(const RunningStats& o) {
    if (o.n == 0) return;
    if (n == 0) {
      *this = o;
      return;
    }
    const double tot = n + o.n, d = o.mean - mean;
    mean += d * (o.n / tot);
    m2 += o.m2 + d * d * (n * o.n / tot);
    n = tot;
  }
  Estimate estimate() const { return {mean, n > 1 ? std::sqrt(m2 / (n - 1) / n) : 0.0}; }
};

/// Statistics of a range of paths, chunk by chunk: for each observable j and each member i of the sequence
/// (and the combination, index n), the stats of the final value and of the time average. The chunks are merged
/// only at the end, in path order (floating-point merging is not associative): so any split of the paths at
/// chunk boundaries gives bitwise the same result.
struct LangevinPartial {
  struct Chunk {
    std::vector<RunningStats> final_stats, average_stats;  // [j * members + i]
  };
  long first_path = 0, paths = 0;
  long long force_evaluations = 0;
  std::size_t observables = 0, members = 0;  // members: n + 1 (the n runs, then the combination)
  std::vector<Chunk> chunks;
  /// Appends the paths that follow this range (throws unless next.first_path == first_path + paths).
  void merge(const LangevinPartial& next);
};

inline void LangevinPartial::merge(const LangevinPartial& next) {
  if (next.paths == 0) return;
  if (paths == 0) {
    *this = next;
    return;
  }
  if (next.first_path != first_path + paths || next.observables != observables || next.members != members)
    throw invalid_input("Langevin partial results merge in path order: paths " + std::to_string(first_path) + ".." +
                        std::to_string(first_path + paths) + " cannot take paths from " +
                        std::to_string(next.first_path));
  chunks.insert(chunks.end(), next.chunks.begin(), next.chunks.end());
  paths += next.paths;
  force_evaluations += next.force_evaluations;
}

/// One observable's results.
struct ObservableResult {
  std::string name;
  Estimate average, final;                             // the (extrapolated) estimates
  std::vector<Estimate> member_average, member_final;  // each run h / k_i alone
};

struct LangevinResult {
  std::string method;
  double h = 0, t_end = 0, window_start = 0;  // the time average runs over [window_start, t_end]
  long steps = 0;                             // N = t_end / h
  long paths = 0;
  std::vector<long> extrapolate;
  std::vector<double> coefficients;  // c_i
  int order = 2;                     // weak order of the combination (2n; that of the scheme when n = 1)
  long long force_evaluations = 0;
  std::vector<ObservableResult> observables;
};

/// Checks an extrapolation sequence for a splitting: distinct positive members, at most max_members, and more
/// than one only for a symmetric splitting (throws nystrom::invalid_input with one line).
inline void check_extrapolation(const LangevinSplitting& splitting, const std::vector<long>& k) {
  try {
    validate_mpe_sequence(k);
  } catch (const std::invalid_argument& e) {
    throw invalid_input(e.what());
  }
  if (k.size() > max_members)
    throw invalid_input("an extrapolation sequence has at most " + std::to_string(max_members) + " members here");
  if (k.size() > 1 && !splitting.symmetric)
    throw invalid_input("extrapolation needs a symmetric splitting (one that reads the same backwards, e.g. BAOAB): '" +
                        splitting.name + "' has an error in odd powers of h too");
}

namespace detail {

struct Plan {
  LangevinSplitting splitting;
  std::vector<long> k;
  std::vector<double> c;
  double h = 0;
  long lcm = 1;
  long slots = 1;  // normals per component per base step: lcm * ou_stages
  long steps = 0;
  long window = 0;  // n0
};

template <class P>
Plan make_plan(const P& problem, const LangevinOptions& o) {
  Plan p;
  p.splitting = parse_langevin_splitting(o.method);
  if (!(o.h > 0) || !std::isfinite(o.h)) throw invalid_input("the step h must be positive and finite");
  if (!(problem.t_end > 0) || !std::isfinite(problem.t_end))
    throw invalid_input("the end time must be positive and finite");
  const double n = problem.t_end / o.h;
  if (!(n < 1e12)) throw invalid_input("t_end / h is too large (at most 1e12 steps)");
  p.steps = std::lround(n);
  if (p.steps < 1 || std::abs(static_cast<double>(p.steps) * o.h - problem.t_end) > 1e-9 * problem.t_end)
    throw invalid_input("the end time " + std::to_string(problem.t_end) +
                        " is not a whole number of steps h = " + std::to_string(o.h));
  p.window = p.steps / 2;
  p.h = o.h;
  if (!(problem.gamma >= 0) || !std::isfinite(problem.gamma))
    throw invalid_input("the friction gamma must be finite and not negative");
  if (!(problem.kT >= 0) || !std::isfinite(problem.kT))
    throw invalid_input("the temperature kT must be finite and not negative");
  if (!(problem.mass > 0) || !std::isfinite(problem.mass)) throw invalid_input("the mass must be positive and finite");
  if (problem.q0.empty() || problem.q0.size() != problem.v0.size())
    throw invalid_input("q0 and v0 must have the same non-zero size");
  for (std::size_t i = 0; i < problem.q0.size(); ++i)
    if (!std::isfinite(problem.q0[i]) || !std::isfinite(problem.v0[i]))
      throw invalid_input("the initial state must be finite");
  if (problem.observable_names.empty()) throw invalid_input("a Langevin run needs at least one observable");
  if (o.paths < 1 || o.paths > max_paths)
    throw invalid_input("the number of paths must be between 1 and " + std::to_string(max_paths) + ", got " +
                        std::to_string(o.paths));
  if (o.threads < 1 || o.threads > 1024) throw invalid_input("threads must be between 1 and 1024");
  check_extrapolation(p.splitting, o.extrapolate);
  p.k = o.extrapolate;
  for (long k : p.k) {
    p.lcm = std::lcm(p.lcm, k);
    if (p.lcm > 100000) throw invalid_input("the least common multiple of the extrapolation sequence exceeds 100000");
  }
  p.slots = p.lcm * p.splitting.ou_stages;
  const MpeCoefficients m = mpe_coefficients(p.k);
  for (const auto& ci : m.c) p.c.push_back(ci.get_d());
  return p;
}

// One path of run k: state and cached acceleration.
struct Walker {
  std::vector<double> q, v, a, xi;
  bool force_valid = false;
};

// Runs one path (all members of the sequence) and writes, for observable j and member i, the final value
// finals[j * nk + i] and the time average averages[j * nk + i]. Returns the force evaluations spent.
template <class P>
long long run_path(const P& problem, const Plan& plan, std::uint64_t seed, long path, std::span<double> finals,
                   std::span<double> averages, std::vector<double>& noise, std::vector<Walker>& w,
                   std::vector<double>& obs) {
  const std::size_t d = problem.q0.size(), nobs = problem.observable_names.size(), nk = plan.k.size();
  const PathNormals normals(seed, static_cast<std::uint64_t>(path));
  const long no = plan.splitting.ou_stages;
  long long forces = 0;
  for (std::size_t i = 0; i < nk; ++i) {
    w[i].q = problem.q0;
    w[i].v = problem.v0;
    w[i].a.assign(d, 0.0);
    w[i].xi.assign(d, 0.0);
    w[i].force_valid = false;
  }
  std::fill(averages.begin(), averages.end(), 0.0);
  const auto sample = [&](std::size_t i, double weight) {
    problem.observe(std::span<const double>(w[i].q), std::span<const double>(w[i].v), std::span<double>(obs));
    for (std::size_t j = 0; j < nobs; ++j) averages[j * nk + i] += weight * obs[j];
  };
  // the O flow of run i over its stage h / (k_i m): damping and the scale of the summed normals
  std::array<double, max_members> damp{}, scale{};
  for (std::size_t i = 0; i < nk; ++i) {
    const double h = plan.h / static_cast<double>(plan.k[i]);
    damp[i] = std::exp(-problem.gamma * h / static_cast<double>(no));
    scale[i] = std::sqrt(problem.kT / problem.mass * (1 - damp[i] * damp[i])) /
               std::sqrt(static_cast<double>(plan.lcm / plan.k[i]));
  }
  for (long n = 0; n < plan.steps; ++n) {
    // the normals of this base step: slot s, component c at noise[s * d + c]
    normals.fill(static_cast<std::uint64_t>(n), std::span<double>(noise));
    for (std::size_t i = 0; i < nk; ++i) {
      Walker& wk = w[i];
      const long k = plan.k[i];
      const double h = plan.h / static_cast<double>(k);
      const long span_slots = plan.lcm / k;  // slots per O stage of this run
      const double e = damp[i], sigma = scale[i];
      for (long sub = 0; sub < k; ++sub) {
        const long t_index = n * k + sub;  // this sub-step runs from t_index to t_index + 1 (units h / k)
        if (t_index == plan.window * k) sample(i, 0.5);
        long o_index = 0;
        for (const Stage& st : plan.splitting.stages) {
          const double tau = st.fraction * h;
          if (st.flow == Flow::drift) {
            for (std::size_t c = 0; c < d; ++c) wk.q[c] += tau * wk.v[c];
            wk.force_valid = false;
          } else if (st.flow == Flow::kick) {
            if (!wk.force_valid) {
              problem.acceleration(std::span<const double>(wk.q), std::span<double>(wk.a));
              ++forces;
              wk.force_valid = true;
            }
            for (std::size_t c = 0; c < d; ++c) wk.v[c] += tau * wk.a[c];
          } else {
            const long first = (sub * no + o_index) * span_slots;
            std::fill(wk.xi.begin(), wk.xi.end(), 0.0);
            for (long s = first; s < first + span_slots; ++s)
              for (std::size_t c = 0; c < d; ++c) wk.xi[c] += noise[static_cast<std::size_t>(s) * d + c];
            for (std::size_t c = 0; c < d; ++c) wk.v[c] = e * wk.v[c] + sigma * wk.xi[c];
            ++o_index;
          }
        }
        const long t_next = t_index + 1;
        if (t_next > plan.window * k) sample(i, t_next == plan.steps * k ? 0.5 : 1.0);
      }
    }
  }
  const long window_steps = plan.steps - plan.window;
  for (std::size_t i = 0; i < nk; ++i) {
    const double scale = 1.0 / static_cast<double>(window_steps * plan.k[i]);
    for (std::size_t j = 0; j < nobs; ++j) averages[j * nk + i] *= scale;
    problem.observe(std::span<const double>(w[i].q), std::span<const double>(w[i].v), std::span<double>(obs));
    for (std::size_t j = 0; j < nobs; ++j) finals[j * nk + i] = obs[j];
  }
  for (std::size_t i = 0; i < nk * nobs; ++i)
    if (!std::isfinite(finals[i]) || !std::isfinite(averages[i]))
      throw invalid_input("path " + std::to_string(path) + " became infinite or NaN at the step h / " +
                          std::to_string(plan.k[i % nk]) +
                          ": the step is beyond the scheme's stability (or the force is singular)");
  return forces;
}

// The statistics of the paths of one chunk.
template <class P>
LangevinPartial run_chunk(const P& problem, const Plan& plan, std::uint64_t seed, long first, long count) {
  const std::size_t d = problem.q0.size(), nobs = problem.observable_names.size(), nk = plan.k.size();
  LangevinPartial r;
  r.first_path = first;
  r.paths = count;
  r.observables = nobs;
  r.members = nk + 1;
  r.chunks.resize(1);
  auto& fs = r.chunks[0].final_stats;
  auto& as = r.chunks[0].average_stats;
  fs.assign(nobs * r.members, {});
  as.assign(nobs * r.members, {});
  std::vector<double> finals(nobs * nk), averages(nobs * nk), obs(nobs);
  std::vector<double> noise(static_cast<std::size_t>(plan.slots) * d);
  std::vector<Walker> walkers(nk);
  for (long p = first; p < first + count; ++p) {
    r.force_evaluations += run_path(problem, plan, seed, p, finals, averages, noise, walkers, obs);
    for (std::size_t j = 0; j < nobs; ++j) {
      double cf = 0, ca = 0;
      for (std::size_t i = 0; i < nk; ++i) {
        fs[j * r.members + i].add(finals[j * nk + i]);
        as[j * r.members + i].add(averages[j * nk + i]);
        cf += plan.c[i] * finals[j * nk + i];
        ca += plan.c[i] * averages[j * nk + i];
      }
      fs[j * r.members + nk].add(cf);
      as[j * r.members + nk].add(ca);
    }
  }
  return r;
}

}  // namespace detail

/// Checks a problem and options as a run does (throws nystrom::invalid_input with one line).
template <class P>
void check_langevin(const P& problem, const LangevinOptions& options) {
  detail::make_plan(problem, options);
}

/// Runs the paths first_path .. first_path + count - 1 on options.threads threads and returns their
/// statistics. first_path must be a multiple of chunk_paths: partial results of consecutive ranges then merge
/// (LangevinPartial::merge, in path order) into bitwise the statistics of one run over all of them.
template <class P>
LangevinPartial run_langevin_paths(const P& problem, const LangevinOptions& options, long first_path, long count) {
  const detail::Plan plan = detail::make_plan(problem, options);
  if (first_path < 0 || first_path % chunk_paths != 0)
    throw invalid_input("a range of Langevin paths starts at a multiple of " + std::to_string(chunk_paths) + ", got " +
                        std::to_string(first_path));
  if (count < 1 || count > max_paths)
    throw invalid_input("a range of Langevin paths holds 1 to " + std::to_string(max_paths) + " paths");
  const long chunks = (count + chunk_paths - 1) / chunk_paths;
  std::vector<LangevinPartial> parts(static_cast<std::size_t>(chunks));
  std::atomic<long> next{0};
  std::atomic<bool> failed{false};
  std::exception_ptr failure;
  std::mutex mutex;
  long done = 0;
  const auto work = [&] {
    for (;;) {
      const long c = next.fetch_add(1);
      if (c >= chunks || failed.load()) return;
      try {
        if (options.stop && options.stop->load()) throw error_interrupted();
        const long first = first_path + c * chunk_paths;
        const long n = std::min(chunk_paths, first_path + count - first);
        parts[static_cast<std::size_t>(c)] = detail::run_chunk(problem, plan, options.seed, first, n);
        if (options.progress) {
          const std::lock_guard lock(mutex);
          done += n;
          options.progress(done, count);
        }
      } catch (...) {
        const std::lock_guard lock(mutex);
        if (!failure) failure = std::current_exception();
        failed = true;
        return;
      }
    }
  };
  const int threads = static_cast<int>(std::min<long>(options.threads, chunks));
  if (threads <= 1) {
    work();
  } else {
    std::vector<std::thread> pool;
    for (int t = 0; t < threads; ++t) pool.emplace_back(work);
    for (auto& t : pool) t.join();
  }
  if (failure) std::rethrow_exception(failure);
  LangevinPartial all;
  for (const auto& p : parts) all.merge(p);
  return all;
}

/// The estimates of merged statistics (all the paths).
template <class P>
LangevinResult finish_langevin(const P& problem, const LangevinOptions& options, const LangevinPartial& stats) {
  const detail::Plan plan = detail::make_plan(problem, options);
  LangevinResult r;
  r.method = plan.splitting.name;
  r.h = options.h;
  r.t_end = problem.t_end;
  r.steps = plan.steps;
  r.window_start = static_cast<double>(plan.window) * options.h;
  r.paths = stats.paths;
  r.extrapolate = plan.k;
  r.coefficients = plan.c;
  r.order = weak_order(plan.splitting, plan.k.size());
  r.force_evaluations = stats.force_evaluations;
  const std::size_t nk = plan.k.size();
  if (stats.observables != problem.observable_names.size() || stats.members != nk + 1)
    throw invalid_input("Langevin statistics do not match the problem and options");
  std::vector<RunningStats> fs(stats.observables * stats.members), as(fs.size());
  for (const auto& c : stats.chunks)
    for (std::size_t m = 0; m < fs.size(); ++m) {
      fs[m].merge(c.final_stats[m]);
      as[m].merge(c.average_stats[m]);
    }
  for (std::size_t j = 0; j < stats.observables; ++j) {
    ObservableResult o;
    o.name = problem.observable_names[j];
    o.final = fs[j * stats.members + nk].estimate();
    o.average = as[j * stats.members + nk].estimate();
    for (std::size_t i = 0; i < nk; ++i) {
      o.member_final.push_back(fs[j * stats.members + i].estimate());
      o.member_average.push_back(as[j * stats.members + i].estimate());
    }
    r.observables.push_back(std::move(o));
  }
  return r;
}

/// Runs options.paths paths and returns the estimates.
template <class P>
LangevinResult langevin(const P& problem, const LangevinOptions& options) {
  return finish_langevin(problem, options, run_langevin_paths(problem, options, 0, options.paths));
}

}  // namespace nystrom::stochastic
