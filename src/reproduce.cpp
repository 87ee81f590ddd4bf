// Helpers shared by the targets of `nystrom reproduce` (see reproduce.hpp).
#include "reproduce.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/core.h>

#include "cli.hpp"
#include "nystrom/methods/catalog.hpp"
#include "progress.hpp"

namespace nystrom::cli::reproduce {

namespace {

nlohmann::json num(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); }
double unnum(const nlohmann::json& j) { return j.is_number() ? j.get<double>() : nan; }

}  // namespace

nlohmann::json Claim::to_json() const {
  return {{"id", id},
          {"paper", paper},
          {"criterion", criterion},
          {"published", num(published)},
          {"measured", num(measured)},
          {"measured_text", measured_text},
          {"holds", holds},
          {"qualitative", qualitative},
          {"qualitative_holds", qualitative_holds},
          {"timing", timing}};
}

Claim Claim::from_json(const nlohmann::json& j) {
  Claim c;
  c.id = j.at("id");
  c.paper = j.at("paper");
  c.criterion = j.at("criterion");
  c.published = unnum(j.at("published"));
  c.measured = unnum(j.at("measured"));
  c.measured_text = j.at("measured_text");
  c.holds = j.at("holds");
  c.qualitative = j.at("qualitative");
  c.qualitative_holds = j.at("qualitative_holds");
  c.timing = j.value("timing", false);
  return c;
}

nlohmann::json TargetResult::to_json() const {
  nlohmann::json cl = nlohmann::json::array();
  for (const auto& c : claims) cl.push_back(c.to_json());
  return {{"name", name},       {"title", title},
          {"paper", paper},     {"quick", quick},
          {"seconds", seconds}, {"precision", precision},
          {"files", files},     {"interpretation", interpretation},
          {"table", table},     {"claims", cl}};
}

TargetResult TargetResult::from_json(const nlohmann::json& j) {
  TargetResult r;
  r.name = j.at("name");
  r.title = j.at("title");
  r.paper = j.at("paper");
  r.quick = j.at("quick");
  r.seconds = j.at("seconds");
  r.precision = j.at("precision");
  r.files = j.at("files").get<std::vector<std::string>>();
  r.interpretation = j.at("interpretation").get<std::vector<std::string>>();
  r.table = j.at("table");
  for (const auto& c : j.at("claims")) r.claims.push_back(Claim::from_json(c));
  return r;
}

std::vector<GridRow> kepler_grid(const std::string& label, const std::vector<std::string>& methods,
                                 const std::vector<double>& ns, double ecc, const std::string& precision) {
  std::vector<MethodDef> defs;
  for (const auto& m : methods) defs.push_back(resolve_method(m));
  double total = 0;
  for (std::size_t i = 0; i < defs.size(); ++i)
    for (double n : ns) total += n;
  const double unit = 1000;  // the bar counts thousands of force evaluations
  Progress progress(label + " (kforces)", std::max(1L, std::lround(total / unit)));
  std::vector<GridRow> out;
  double done = 0;
  for (const auto& def : defs) {
    const int f = std::max(1, def.info.forces_per_step);
    for (double n : ns) {
      RunRequest r;
      r.problem = "kepler";
      r.ecc = ecc;
      r.periods = 1;
      r.precision = precision;
      r.steps_per_period = std::max(1L, std::lround(n / f));
      GridRow g;
      g.nominal_n = n;
      g.row.report = run_case(r, def);
      g.row.force_evals_per_period = static_cast<double>(g.row.report.force_evals);
      out.push_back(g);
      done += n;
      progress.tick(std::lround(done / unit));
    }
  }
  return out;
}

double error_at(const std::vector<GridRow>& rows, const std::string& method, double nominal_n) {
  for (const auto& g : rows)
    if (g.row.report.method == method && std::abs(g.nominal_n / nominal_n - 1) < 1e-9)
      return std::abs(g.row.report.precession_per_period);
  return nan;
}

std::vector<double> log_grid(double lo_exp, double hi_exp, int per_decade) {
  std::vector<double> v;
  const long count = std::lround((hi_exp - lo_exp) * per_decade);
  for (long i = 0; i <= count; ++i) {
    const double e = lo_exp + static_cast<double>(i) / per_decade;
    // exact powers of ten where the exponent is whole, so "at N = 1e5" finds its row
    v.push_back(std::abs(e - std::round(e)) < 1e-12 ? std::pow(10.0, std::round(e)) : std::pow(10.0, e));
  }
  return v;
}

Claim band_claim(std::string id, std::string paper, double published, double measured, double lo, double hi,
                 std::string qualitative, bool qualitative_holds) {
  Claim c;
  c.id = std::move(id);
  c.paper = std::move(paper);
  c.published = published;
  c.measured = measured;
  c.measured_text = fmt_g(measured);
  if (std::isinf(hi) && !std::isinf(lo))
    c.criterion = "measured >= " + fmt_g(lo);
  else if (std::isinf(lo) && !std::isinf(hi))
    c.criterion = "measured <= " + fmt_g(hi);
  else
    c.criterion = fmt_g(lo) + " <= measured <= " + fmt_g(hi);
  c.holds = std::isfinite(measured) && measured >= lo && measured <= hi;
  c.qualitative = std::move(qualitative);
  c.qualitative_holds = qualitative_holds;
  return c;
}

std::string fmt_g(double x, int digits) {
  if (!std::isfinite(x)) return "n/a";
  return fmt::format("{:.{}g}", x, digits);
}

}  // namespace nystrom::cli::reproduce
