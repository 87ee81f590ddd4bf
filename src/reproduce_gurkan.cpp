// The figures and the table of M. A. Gurkan, "Fifth order Runge-Kutta-Nystrom methods with complex
// coefficients" (preprint, 2012), sec. 5, recomputed by `nystrom reproduce`:
//   gurkan-fig5.1    interquartile range of the local position error against h, two-body problem, e = 0.2;
//   gurkan-fig5.2    the same for the 400-body Plummer sphere;
//   gurkan-table5.1  CPU time per step normalised to the leapfrog, 10 000 bodies;
//   gurkan-fig5.3    error against CPU time (Fig. 5.2's errors, Table 5.1's costs).
// The measurements are the library's (src/experiments/localerr.hpp: run_localerr, run_cputime),
// the same as `nystrom localerr` and `nystrom cputime`; this file chooses the paper's settings and compares.
#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <optional>

#include <fmt/core.h>

#include "cli.hpp"
#include "experiments/localerr.hpp"
#include "output_file.hpp"
#include "plot.hpp"
#include "progress.hpp"
#include "reproduce.hpp"

namespace nystrom::cli::reproduce {

namespace {

const double kInf = std::numeric_limits<double>::infinity();
constexpr double kIqrFloor = 1e-13;  // IQRs below this are near the double-precision floor (~1e-15)

// The methods of Figs. 5.1-5.3 in the paper's order, with its names and symbols (gnuplot point types).
struct Shown {
  std::string method, label;
  int point;
};
const std::vector<Shown> kMethods{{"VV", "Leapfrog", 11}, {"Y4", "Triple jump", 1}, {"Chambers", "Chambers", 9},
                                  {"RKNb6", "RKNb6", 3},  {"RKNa14", "RKNa14", 7},  {"BR1", "RKNbr1", 15},
                                  {"AC1", "RKNac1", 5}};

std::string label_of(const std::string& m) {
  for (const auto& s : kMethods)
    if (s.method == m) return s.label;
  return m;
}

std::vector<double> iqr_of(const LocalErrResult& r, const std::string& m, std::vector<double>* hs = nullptr) {
  std::vector<double> v;
  for (const auto& row : r.rows)
    if (row.method == m) {
      v.push_back(row.iqr);
      if (hs) hs->push_back(row.h);
    }
  return v;
}

double iqr_at(const LocalErrResult& r, const std::string& m, double h) {
  for (const auto& row : r.rows)
    if (row.method == m && std::abs(row.h / h - 1) < 1e-9) return row.iqr;
  return nan;
}

/// Observed order: the least-squares slope of log IQR against log h, minus one (the local error of an order-p
/// method is O(h^{p+1})), over the points with kIqrFloor < IQR < 1e-4 (asymptotic, above rounding).
double observed_order(const LocalErrResult& r, const std::string& m) {
  std::vector<double> hs;
  const auto v = iqr_of(r, m, &hs);
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int k = 0;
  for (std::size_t i = 0; i < v.size(); ++i)
    if (v[i] > kIqrFloor && v[i] < 1e-4) {
      const double x = std::log10(hs[i]), y = std::log10(v[i]);
      sx += x, sy += y, sxx += x * x, sxy += x * y, ++k;
    }
  return k < 2 ? nan : (k * sxy - sx * sy) / (k * sxx - sx * sx) - 1;
}

LocalErrResult localerr(const std::string& label, LocalErrConfig cfg) {
  std::unique_ptr<Progress> p;
  return run_localerr(cfg, [&](long done, long all) {
    if (!p) p = std::make_unique<Progress>(label + " (reference steps)", all);
    if (done % 8 == 0 || done == all) p->tick(done);
  });
}

std::string localerr_csv(const LocalErrResult& r) {
  std::string text = "method,h,h_time,steps,samples,q25,q75,iqr\n";
  for (const auto& x : r.rows)
    text += fmt::format("{},{:.17g},{:.17g},{},{},{:.17g},{:.17g},{:.17g}\n", x.method, x.h, x.h_time, x.steps,
                        x.samples, x.q25, x.q75, x.iqr);
  return text;
}

std::vector<Series> localerr_series(const LocalErrResult& r, const std::vector<std::string>& methods) {
  std::vector<Series> out;
  for (const auto& m : methods) {
    int pt = 0;
    for (const auto& s : kMethods)
      if (s.method == m) pt = s.point;
    Series s{label_of(m), {}, {}, "linespoints", pt};
    for (const auto& row : r.rows)
      if (row.method == m) {
        s.x.push_back(row.h);
        s.y.push_back(row.iqr);
      }
    out.push_back(s);
  }
  return out;
}

std::string orders_table(const LocalErrResult& r, const std::vector<std::string>& methods) {
  std::vector<double> hs;
  for (const auto& row : r.rows)
    if (std::find(hs.begin(), hs.end(), row.h) == hs.end()) hs.push_back(row.h);
  std::string t = "| method | formal order | observed order |";
  for (double h : hs) t += fmt::format(" h = {:.3g} |", h);
  t += "\n|---|---|---|";
  for (std::size_t i = 0; i < hs.size(); ++i) t += "---|";
  t += "\n";
  for (const auto& m : methods) {
    t += fmt::format("| {} | {} | {} |", label_of(m), resolve_method(m).info.order, fmt_g(observed_order(r, m)));
    for (double h : hs) t += fmt::format(" {} |", fmt_g(iqr_at(r, m, h), 3));
    t += "\n";
  }
  return t;
}

std::vector<std::string> names(const std::vector<Shown>& v) {
  std::vector<std::string> out;
  for (const auto& s : v) out.push_back(s.method);
  return out;
}

// The runs shared by several targets, kept for the duration of the process (fig5.3 reuses fig5.2 and table5.1).
struct Cache {
  std::optional<LocalErrResult> fig52;
  std::optional<CpuTimeResult> table51;
  bool quick = false;
};
Cache& cache(const Context& ctx) {
  static Cache c;
  if (c.quick != ctx.quick) c = Cache{std::nullopt, std::nullopt, ctx.quick};
  return c;
}

const LocalErrResult& run_fig52(const Context& ctx) {
  auto& c = cache(ctx);
  if (!c.fig52) {
    LocalErrConfig cfg;
    cfg.setup.problem = "nbody";
    cfg.setup.n = 400;
    cfg.setup.threads = ctx.threads;
    cfg.methods = names(kMethods);
    cfg.methods.push_back("AC1-6");
    cfg.hs = ctx.quick ? std::vector<double>{std::pow(10.0, -1.5), 0.1} : log_grid(-3, -1, 4);
    c.fig52 = localerr("gurkan-fig5.2", cfg);
  }
  return *c.fig52;
}

const CpuTimeResult& run_table51(const Context& ctx) {
  auto& c = cache(ctx);
  if (!c.table51) {
    CpuTimeConfig cfg;
    cfg.setup.problem = "nbody";
    cfg.setup.n = ctx.quick ? 1000 : 10000;
    cfg.setup.threads = ctx.threads;
    cfg.methods = {"Chambers", "Y4", "RKNb6", "RKNa14", "BR1", "AC1"};
    cfg.steps = ctx.quick ? 2 : 3;
    cfg.repeats = ctx.quick ? 2 : 3;
    std::unique_ptr<Progress> p;
    c.table51 = run_cputime(cfg, [&](long done, long all) {
      if (!p) p = std::make_unique<Progress>("gurkan-table5.1 (timings)", all);
      p->tick(done);
    });
  }
  return *c.table51;
}

const std::map<std::string, double> kPublishedCost{{"Chambers", 12}, {"Y4", 3},  {"RKNb6", 6},
                                                   {"RKNa14", 14},   {"BR1", 5}, {"AC1", 28}};

// ------------------------------------------------------------------------------------------------

TargetResult fig51(const Context& ctx) {
  TargetResult res;
  res.name = "gurkan-fig5.1";
  res.title = "Interquartile range of the local position error against step size, two-body problem, e = 0.2";
  res.paper = "Gurkan, Fig. 5.1 and sec. 5";
  res.quick = ctx.quick;
  res.precision = "double (methods), GBS reference at tolerance 1e-14";
  LocalErrConfig cfg;
  cfg.setup.problem = "twobody";
  cfg.setup.ecc = 0.2;
  cfg.methods = names(kMethods);
  cfg.hs = ctx.quick ? std::vector<double>{0.01, std::pow(10.0, -1.5), 0.1} : log_grid(-3, -1, 4);
  const auto r = localerr(res.name, cfg);
  write_file_atomic(ctx.path(res.name + ".csv"), localerr_csv(r));
  res.files.push_back(res.name + ".csv");
  plot_loglog(ctx.path(res.name + ".png"), "Gurkan Fig. 5.1: two-body problem, e = 0.2, 50 periods",
              "time step h (orbital periods)", "interquartile range of the position error",
              localerr_series(r, cfg.methods));
  res.files.push_back(res.name + ".png");
  res.interpretation = {
      "Two equal masses on an e = 0.2 orbit (period 2 pi) for 50 periods. The reference is followed with "
      "Gragg-Bulirsch-Stoer (harmonic sequence, 12 columns, tolerance 1e-14); at every reference step each method "
      "takes one step of size h from the reference state, and the differences of its position components from the "
      "reference's are collected; the interquartile range (q75 - q25) over the run is plotted.",
      "Complex methods (Chambers, RKNac1) run on the complexified state and drop the imaginary parts after each step, "
      "as in the paper. Leapfrog is velocity Verlet; Triple jump is Yoshida's fourth-order composition Y4.",
      "Observed order = (least-squares slope of log IQR against log h) - 1, since the local error of an order-p "
      "method is O(h^(p+1)); fitted over the points with 1e-13 < IQR < 1e-4 (above the rounding floor, "
      "asymptotic).",
      "\"Holds\" for an observed order means within 0.3 of the order the paper reports."};
  res.table = orders_table(r, cfg.methods);

  const double och = observed_order(r, "Chambers"), oac = observed_order(r, "AC1");
  Claim c1 =
      band_claim("chambers_order", "the method of Chambers (formally third order) shows fourth-order behaviour", 4, och,
                 3.7, 4.3, "Chambers' observed order exceeds its formal order 3 by more than half an order", och > 3.5);
  c1.measured_text = "observed order " + fmt_g(och);
  res.claims.push_back(c1);
  Claim c2 = band_claim("ac1_order", "RKNac1 (formally fifth order) shows sixth-order behaviour", 6, oac, 5.7, 6.3,
                        "RKNac1's observed order exceeds its formal order 5 by more than half an order", oac > 5.5);
  c2.measured_text = "observed order " + fmt_g(oac);
  res.claims.push_back(c2);
  {
    double worst = kInf;
    int compared = 0;
    for (const auto& row : r.rows) {
      if (row.method != "BR1" || row.iqr <= kIqrFloor) continue;
      worst = std::min(worst, row.iqr / iqr_at(r, "RKNb6", row.h));
      ++compared;
    }
    Claim c = band_claim(
        "rknb6_beats_br1",
        "the optimized fourth-order RKNb6 outperforms the higher-order RKNbr1 down to machine accuracy", nan, worst, 1,
        kInf, "RKNb6's IQR is below RKNbr1's at every step size above the floor", compared > 0 && worst > 1);
    c.measured_text = fmt::format("smallest IQR(RKNbr1) / IQR(RKNb6) over {} step sizes: {}", compared, fmt_g(worst));
    c.criterion = "ratio > 1 at every h where RKNbr1's IQR > 1e-13";
    res.claims.push_back(c);
  }
  return res;
}

TargetResult fig52(const Context& ctx) {
  TargetResult res;
  res.name = "gurkan-fig5.2";
  res.title = "Interquartile range of the local position error against step size, 400-body Plummer sphere";
  res.paper = "Gurkan, Fig. 5.2 and sec. 5";
  res.quick = ctx.quick;
  res.precision = "double (methods), GBS reference at tolerance 1e-14";
  const auto& r = run_fig52(ctx);
  write_file_atomic(ctx.path(res.name + ".csv"), localerr_csv(r));
  res.files.push_back(res.name + ".csv");
  // Triple jump is omitted from the plot, as in the paper ("it nearly coincides with Chambers").
  std::vector<std::string> shown;
  for (const auto& s : kMethods)
    if (s.method != "Y4") shown.push_back(s.method);
  plot_loglog(ctx.path(res.name + ".png"), "Gurkan Fig. 5.2: 400-body Plummer sphere, " + r.description,
              "time step h (code units)", "interquartile range of the position error", localerr_series(r, shown));
  res.files.push_back(res.name + ".png");
  res.interpretation = {
      "A Plummer sphere of 400 equal masses (Aarseth-Henon-Wielen construction, seed 42, N-body units G = M = 1, "
      "E = -1/4), softening eps^2 = (1/N)^2, followed for one time unit with the GBS reference; errors collected "
      "over the x, y, z components of every particle as in gurkan-fig5.1.",
      "The paper does not give the duration or the seed; one time unit and seed 42 are our choices. Triple jump and "
      "the 7-stage AC1-6 of eq. (6.1) are measured (CSV, table) for the claims below but not plotted.",
      "\"Nearly coincides\" holds when the IQRs of Triple jump and Chambers agree within a factor 2 at every h "
      "above the floor (1e-13)."};
  std::vector<std::string> all = names(kMethods);
  all.push_back("AC1-6");
  res.table = orders_table(r, all);
  {
    double lo = kInf, hi = 0;
    for (const auto& row : r.rows) {
      if (row.method != "Y4" || row.iqr <= kIqrFloor) continue;
      const double q = row.iqr / iqr_at(r, "Chambers", row.h);
      lo = std::min(lo, q);
      hi = std::max(hi, q);
    }
    Claim c =
        band_claim("tj_coincides_chambers", "Triple jump nearly coincides with Chambers for this problem", 1, hi, 0, 2,
                   "Triple jump and Chambers agree within a factor 3 at every h", lo >= 1.0 / 3 && hi <= 3 && hi > 0);
    c.holds = lo >= 0.5 && hi <= 2;
    c.measured_text = fmt::format("IQR(Triple jump) / IQR(Chambers) between {} and {}", fmt_g(lo), fmt_g(hi));
    c.criterion = "every ratio within [0.5, 2]";
    res.claims.push_back(c);
  }
  {
    // sec. 6: AC1-6 has a ~40x smaller (imaginary) sixth-order error, "this optimization does not benefit the
    // solutions of gravitational N-body problem"
    std::vector<double> q;
    for (const auto& row : r.rows)
      if (row.method == "AC1" && row.iqr > kIqrFloor) q.push_back(row.iqr / iqr_at(r, "AC1-6", row.h));
    std::sort(q.begin(), q.end());
    const double med = q.empty() ? nan : q[q.size() / 2];
    Claim c = band_claim("ac16_no_benefit",
                         "AC1-6 (eq. 6.1) minimizes the imaginary sixth-order error terms (2.6e-7 against 1.02e-5 for "
                         "AC1), but this does not benefit the gravitational N-body problem",
                         nan, med, 0, 3, "AC1-6 is not markedly more accurate than AC1 (less than 10x)",
                         std::isfinite(med) && med < 10);
    c.measured_text = "median IQR(AC1) / IQR(AC1-6) = " + fmt_g(med) + " (the error coefficients would predict ~39)";
    c.criterion = "median ratio <= 3";
    res.claims.push_back(c);
  }
  return res;
}

TargetResult table51(const Context& ctx) {
  TargetResult res;
  res.name = "gurkan-table5.1";
  res.title = "CPU time per step normalised to the leapfrog";
  res.paper = "Gurkan, Table 5.1 and sec. 5";
  res.quick = ctx.quick;
  res.precision = "double";
  const auto& r = run_table51(ctx);
  std::string csv = "method,forces_per_step,complex,seconds_per_step,ratio_to_leapfrog,published_ratio\n";
  csv += fmt::format("LF,1,0,{:.6g},1,1\n", r.leapfrog_seconds);
  for (const auto& row : r.rows)
    csv += fmt::format("{},{},{},{:.6g},{:.6g},{}\n", row.method, row.forces_per_step, row.complex ? 1 : 0,
                       row.seconds_per_step, row.ratio, kPublishedCost.at(row.method));
  write_file_atomic(ctx.path(res.name + ".csv"), csv);
  res.files.push_back(res.name + ".csv");
  // a plot of measured against published cost (both normalised to the leapfrog)
  std::vector<Series> series;
  for (const auto& row : r.rows) {
    int pt = 0;
    for (const auto& s : kMethods)
      if (s.method == row.method) pt = s.point;
    series.push_back({label_of(row.method), {kPublishedCost.at(row.method)}, {row.ratio}, "points", pt});
  }
  series.push_back({"measured = published", {1, 40}, {1, 40}, "lines"});
  plot_loglog(ctx.path(res.name + ".png"),
              fmt::format("Gurkan Table 5.1: CPU time per step / leapfrog's, {}", r.description),
              "published (Table 5.1)", "measured (this run)", series);
  res.files.push_back(res.name + ".png");
  const int threads = ctx.threads > 0 ? ctx.threads : nbody_max_threads();
  res.interpretation = {
      fmt::format("{} with softening (1/N)^2; each method takes one untimed step (it pays the first force), then "
                  "{} timed steps; the minimum over {} interleaved repeats is kept; {} force thread(s). The leapfrog "
                  "is velocity Verlet with the force reused across steps (one force per step).",
                  r.description, ctx.quick ? 2 : 3, ctx.quick ? 2 : 3, threads),
      "Complex methods run on complex positions and velocities (complex force kernel) and drop the imaginary parts "
      "after each step; since the last force is then taken at a complex position, they cannot reuse it and pay one "
      "more force than the number of stages when they start with a kick (RKNA schemes such as Chambers and RKNac1 "
      "start with a drift and pay exactly their stages).",
      "Timings depend on the machine and its load; the claims below are reported but not asserted by the tests.",
      "\"Holds\" for a ratio means within a factor 1.5 of the published one; the stage-proportionality claim uses "
      "the real methods (time per step / forces per step within [0.7, 1.3] of the leapfrog's)."};
  std::string t =
      "| method | forces/step | complex | s/step | measured / leapfrog | published |\n|---|---|---|---|---|---|\n";
  t += fmt::format("| Leapfrog | 1 | no | {:.4g} | 1 | 1 |\n", r.leapfrog_seconds);
  for (const auto& row : r.rows)
    t += fmt::format("| {} | {} | {} | {:.4g} | {:.3g} | {} |\n", label_of(row.method), row.forces_per_step,
                     row.complex ? "yes" : "no", row.seconds_per_step, row.ratio, kPublishedCost.at(row.method));
  res.table = t;
  for (const auto& row : r.rows) {
    const double p = kPublishedCost.at(row.method);
    Claim c =
        band_claim("cost_" + row.method, fmt::format("{} costs {} leapfrog steps per step", label_of(row.method), p), p,
                   row.ratio, p / 1.5, p * 1.5, "costs more than the leapfrog", row.ratio > 1);
    c.timing = true;
    res.claims.push_back(c);
  }
  double lo = kInf, hi = 0, real_per_force = 0, cplx_per_force = 0;
  int nreal = 0, ncplx = 0;
  for (const auto& row : r.rows) {
    const double per = row.ratio / std::max(1, row.forces_per_step);
    if (row.complex) {
      cplx_per_force += per;
      ++ncplx;
    } else {
      lo = std::min(lo, per);
      hi = std::max(hi, per);
      real_per_force += per;
      ++nreal;
    }
  }
  {
    Claim c =
        band_claim("proportional_to_stages", "the integration time is proportional to the number of stages", 1, hi, 0.7,
                   1.3, "the real methods cost between half and twice a leapfrog step per force", lo >= 0.5 && hi <= 2);
    c.holds = lo >= 0.7 && hi <= 1.3;
    c.measured_text = fmt::format("time per force / leapfrog's between {} and {} (real methods)", fmt_g(lo), fmt_g(hi));
    c.criterion = "every ratio within [0.7, 1.3]";
    c.timing = true;
    res.claims.push_back(c);
  }
  {
    const double factor = (cplx_per_force / ncplx) / (real_per_force / nreal);
    Claim c = band_claim("complex_factor", "complex arithmetic increases the computation cost by about a factor of 6",
                         6, factor, 3, 12, "a complex force evaluation costs more than a real one", factor > 1.5);
    c.measured_text = fmt::format("factor {} (time per force, complex / real methods)", fmt_g(factor));
    c.timing = true;
    res.claims.push_back(c);
  }
  return res;
}

/// log-log interpolation (or extrapolation from the two nearest points) of cost at a given IQR.
double cost_for(const std::vector<std::pair<double, double>>& pts /* (cost, iqr), iqr > floor */, double iqr) {
  if (pts.size() < 2) return nan;
  std::vector<std::pair<double, double>> v = pts;
  std::sort(v.begin(), v.end(), [](const auto& a, const auto& b) { return a.second < b.second; });
  std::size_t i = 0;
  while (i + 2 < v.size() && v[i + 1].second < iqr) ++i;
  const double x0 = std::log(v[i].second), x1 = std::log(v[i + 1].second);
  const double y0 = std::log(v[i].first), y1 = std::log(v[i + 1].first);
  if (x1 == x0) return nan;
  return std::exp(y0 + (y1 - y0) * (std::log(iqr) - x0) / (x1 - x0));
}

TargetResult fig53(const Context& ctx) {
  TargetResult res;
  res.name = "gurkan-fig5.3";
  res.title = "Error against CPU time, 400-body Plummer sphere";
  res.paper = "Gurkan, Fig. 5.3 and secs. 5-6";
  res.quick = ctx.quick;
  res.precision = "double";
  const auto& r = run_fig52(ctx);
  const auto& t = run_table51(ctx);
  std::map<std::string, double> ratio{{"VV", 1.0}};
  for (const auto& row : t.rows) ratio[row.method] = row.ratio;
  // cost of following one time unit: (time per step / leapfrog's) x (steps) / (leapfrog's steps at h = 0.01)
  std::string csv = "method,h,cost_relative_to_leapfrog_at_h_0.01,iqr\n";
  std::vector<Series> series;
  std::map<std::string, std::vector<std::pair<double, double>>> pts;
  for (const auto& s : kMethods) {
    Series se{s.label, {}, {}, "linespoints", s.point};
    for (const auto& row : r.rows)
      if (row.method == s.method) {
        const double cost = ratio.at(s.method) * 0.01 / row.h;
        csv += fmt::format("{},{:.17g},{:.6g},{:.17g}\n", s.method, row.h, cost, row.iqr);
        se.x.push_back(cost);
        se.y.push_back(row.iqr);
        if (row.iqr > kIqrFloor) pts[s.method].emplace_back(cost, row.iqr);
      }
    series.push_back(se);
  }
  write_file_atomic(ctx.path(res.name + ".csv"), csv);
  res.files.push_back(res.name + ".csv");
  plot_loglog(ctx.path(res.name + ".png"), "Gurkan Fig. 5.3: error against CPU time, 400-body Plummer sphere",
              "CPU time / leapfrog's at h = 0.01", "interquartile range of the position error", series);
  res.files.push_back(res.name + ".png");
  res.interpretation = {
      "CPU time for a fixed interval = (time per step relative to the leapfrog, gurkan-table5.1 of this run) x "
      "(number of steps), normalised to the leapfrog at h = 0.01, as the paper's axis; the errors are those of "
      "gurkan-fig5.2. So Fig. 5.3 combines the two, as the paper does (\"based on these findings\").",
      "The paper draws no numeric conclusion from Fig. 5.3. Its discussion expects the complex methods \"to be "
      "already competitive with lower order methods\"; we compare the CPU time that RKNac1 and the lower-order "
      "methods need to reach the same error (log-log interpolation, extrapolated from the two nearest points "
      "when the error is outside a method's range).",
      "These claims depend on timings (machine, load) and are not asserted by the tests."};
  const double target = 1e-10;
  std::string tb = fmt::format(
      "CPU time (leapfrog steps at h = 0.01) to reach IQR = {:g}:\n\n| method | cost |\n|---|---|\n", target);
  std::map<std::string, double> cost;
  for (const auto& s : kMethods) {
    cost[s.method] = cost_for(pts[s.method], target);
    tb += fmt::format("| {} | {} |\n", s.label, fmt_g(cost[s.method]));
  }
  res.table = tb;
  {
    const double ac = cost["AC1"];
    const double best_lower = std::min({cost["Chambers"], cost["Y4"], cost["VV"]});
    Claim c = band_claim(
        "ac1_competitive", "the complex fifth-order methods are already competitive with lower order methods", nan,
        best_lower / ac, 1, kInf,
        "RKNac1 reaches IQR 1e-10 for less CPU time than Chambers, Triple jump and the leapfrog", ac < best_lower);
    c.measured_text = fmt::format("cost to IQR 1e-10: RKNac1 {}, Chambers {}, Triple jump {}, Leapfrog {}", fmt_g(ac),
                                  fmt_g(cost["Chambers"]), fmt_g(cost["Y4"]), fmt_g(cost["VV"]));
    c.criterion = "cost of the cheapest lower-order method / RKNac1's >= 1";
    c.timing = true;
    res.claims.push_back(c);
  }
  return res;
}

}  // namespace

TargetResult gurkan_fig51(const Context& ctx) { return fig51(ctx); }
TargetResult gurkan_fig52(const Context& ctx) { return fig52(ctx); }
TargetResult gurkan_table51(const Context& ctx) { return table51(ctx); }
TargetResult gurkan_fig53(const Context& ctx) { return fig53(ctx); }

}  // namespace nystrom::cli::reproduce
