// `nystrom bch --method NAME [--degree 7] [--basis hall|lyndon] [--algebra rkn|free] [--bits B] [--json]`:
// the BCH series of a splitting method in a Lie basis: the coefficients of every basis element of H - Z per
// degree, the algebraic order (all lower-degree terms vanish) and the leading error terms with their norm
// (Gürkan, sec. 4 and Table 4.3). `nystrom bch --gurkan-table` prints Table 4.3 computed from the catalog.
#include <cmath>
#include <complex>
#include <iostream>
#include <memory>
#include <string>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "nystrom/analysis/bch.hpp"
#include "nystrom/analysis/bch_report.hpp"
#include "nystrom/analysis/method_file.hpp"
#include "nystrom/methods/catalog.hpp"

namespace {

namespace an = nystrom::analysis;

struct Options {
  std::string method;
  int degree = 7;
  std::string basis = "hall";
  std::string algebra = "rkn";
  unsigned bits = 192;
  double tolerance = 0;
  bool json = false;
  bool table = false;
  bool all = false;
};

std::string show(std::complex<double> z) {
  if (z.imag() == 0) return fmt::format("{:+.6e}", z.real());
  if (z.real() == 0) return fmt::format("{:+.6e}i", z.imag());
  return fmt::format("{:+.6e} {:+.6e}i", z.real(), z.imag());
}
// Values within the tolerance are printed as 0 (they are rounding of coefficients that vanish).
std::string show_term(const an::ErrorTerm& t, double tol) {
  if (!t.exact.empty()) return t.exact;
  std::complex<double> z = t.value;
  if (std::abs(z.real()) <= tol) z.real(0);
  if (std::abs(z.imag()) <= tol) z.imag(0);
  if (z == std::complex<double>(0, 0)) return fmt::format("0 (|.| = {:.1e})", std::abs(t.value));
  return show(z);
}

int print_table() {
  const auto rows = an::gurkan_table_4_3([](const std::string& n) { return nystrom::resolve_method(n); });
  fmt::print("Gurkan Table 4.3 from the catalog: coefficients of H - Z in degree 6 (Hall basis of the RKN algebra)\n");
  fmt::print("{:<5}", "");
  for (const auto& [name, v] : rows.front().terms) fmt::print(" {:>13}", name);
  fmt::print(" {:>10}\n", "norm");
  for (const auto& r : rows) {
    fmt::print("{:<5}", r.method);
    for (const auto& [name, v] : r.terms) {
      const bool im = std::abs(v.real()) < 1e-3 * std::abs(v);
      fmt::print(" {:>13}", im ? fmt::format("{:+.2e}i", v.imag()) : fmt::format("{:+.2e}", v.real()));
    }
    fmt::print(" {:>10.3e}\n", r.norm);
  }
  fmt::print(
      "(the paper prints the AC2 row with the opposite signs: it matches the adjoint of AC2, which for this\n"
      " skew-symmetric method is its complex conjugate; AC1 and AC2 agree to 2-3 digits in every coefficient)\n");
  return 0;
}

int run(const Options& o) {
  if (o.table) return print_table();
  if (o.method.empty()) throw nystrom::cli::UsageError("bch needs --method NAME (or --gurkan-table)");
  an::check_degree(o.degree);
  if (o.bits < 64 || o.bits > 4096) throw nystrom::cli::UsageError("--bits must be between 64 and 4096");
  if (!(o.tolerance >= 0) || !std::isfinite(o.tolerance) || o.tolerance >= 1)
    throw nystrom::cli::UsageError("--tolerance must be >= 0 and below 1");
  an::AnalysisOptions opt;
  opt.degree = o.degree;
  opt.basis = an::parse_basis(o.basis);
  opt.algebra = an::parse_algebra(o.algebra);
  opt.precision_bits = o.bits;
  opt.tolerance = o.tolerance;
  const auto def = nystrom::resolve_method(o.method);
  {
    nystrom::BigPrecision guard(64);
    const auto data = def.build();
    if (const auto* sp = std::get_if<nystrom::SplittingScheme<nystrom::bigcomplex>>(&data))
      an::check_bch_work(sp->steps.size(), o.degree, "bch --method " + o.method);
  }
  const an::MethodAnalysis a = an::analyze_method(def, opt);
  const std::string order_text = a.order_is_lower_bound ? ">= " + std::to_string(a.order) : std::to_string(a.order);
  if (o.json) {
    const auto j = an::bch_report_json<nlohmann::json>(a);
    std::cout << j.dump(2) << "\n";
    return 0;
  }
  fmt::print("{}: {} ({}); {} basis of the {} Lie algebra{}, degrees 1..{}\n", a.method, def.info.description,
             def.info.source, a.basis == an::BasisKind::hall ? "Hall (Gurkan X_i)" : "Lyndon",
             a.algebra == an::AlgebraKind::rkn ? "RKN" : "free",
             a.algebra == an::AlgebraKind::rkn ? " ([V,[V,[T,V]]] = 0)" : "", a.degree);
  fmt::print(
      "arithmetic: {}; coefficients of H - Z, Z = log of the operator product (first sub-step rightmost)\n",
      a.exact ? "exact rationals"
              : fmt::format("MPFR complex, {} bits; terms below {:.1e} count as zero", a.precision_bits, a.tolerance));
  for (const auto& d : a.degrees) {
    fmt::print("degree {} ({} term{}): {}\n", d.degree, d.terms.size(), d.terms.size() == 1 ? "" : "s",
               d.vanishes ? "vanishes" : fmt::format("norm {:.6e}", d.norm));
    if (d.vanishes && !o.all) continue;
    for (const auto& t : d.terms) {
      const std::string def_text = t.definition == t.bracket ? t.bracket : t.definition + " = " + t.bracket;
      fmt::print("  {:<7} {:<28} {}\n", t.name, show_term(t, a.tolerance), def_text);
    }
  }
  fmt::print("order: {} (declared {}: {})\n", order_text, a.declared_order,
             a.declared_order_confirmed() ? "confirmed" : "NOT confirmed");
  if (const auto* l = a.leading()) {
    fmt::print("leading error, degree {}:", l->degree);
    for (const auto& t : l->terms) fmt::print(" {} = {};", t.name, show_term(t, a.tolerance));
    fmt::print(" (sum |X_i|^2)^(1/2) = {:.6e}\n", l->norm);
  } else {
    fmt::print("leading error: beyond degree {} (raise --degree)\n", a.degree);
  }
  return 0;
}

nystrom::cli::Registrar reg(
    "bch", "BCH error terms of a splitting method in a Lie basis (Gurkan Table 4.3)", [](CLI::App& app) {
      auto o = std::make_shared<Options>();
      app.add_option("--method", o->method, "Splitting method (catalog name, adjoint:NAME, file:PATH)");
      app.add_option("--degree", o->degree, "Highest degree of the series (1..12)")->capture_default_str();
      app.add_option("--basis", o->basis, "Lie basis: hall (Gurkan's X1..X23, extended) or lyndon")
          ->capture_default_str();
      app.add_option("--algebra", o->algebra, "rkn ([V,[V,[T,V]]] = 0, for q'' = a(q)) or free")->capture_default_str();
      app.add_option("--bits", o->bits, "MPFR precision for irrational coefficients")->capture_default_str();
      app.add_option("--tolerance", o->tolerance, "Terms below this count as zero (0: from the published digits)");
      app.add_flag("--all", o->all, "Also list the terms of the vanishing degrees");
      app.add_flag("--json", o->json, "JSON output");
      app.add_flag("--gurkan-table", o->table, "Print Table 4.3 of the Gurkan paper computed from the catalog");
      return [o] { return run(*o); };
    });

}  // namespace
