// Table 4.3 of M. A. Gurkan, "Fifth order Runge-Kutta-Nystrom methods with complex coefficients"
// (preprint, 2012), recomputed by `nystrom reproduce gurkan-table4.3`: the degree-6 coefficients X11, X16, X17,
// X19, X20 of H - Z in Gurkan's Philip Hall basis of the RKN Lie algebra, and their norm (sum |X_i|^2)^(1/2), for the
// nine methods of Tables 4.1 and 4.2, computed from the catalog's coefficients with the library's BCH analysis
// (include/nystrom/analysis/bch.hpp, the same as `nystrom bch --gurkan-table`) and compared digit by digit with the
// published table. Also the norm of the 7-stage AC1-6 of eq. (6.1) (sec. 6: 2.6e-7).
#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <limits>
#include <map>
#include <stdexcept>

#include <fmt/core.h>

#include "cli.hpp"
#include "nystrom/analysis/bch.hpp"
#include "nystrom/methods/catalog.hpp"
#include "output_file.hpp"
#include "plot.hpp"
#include "reproduce.hpp"

namespace nystrom::cli::reproduce {

namespace {

namespace an = nystrom::analysis;
using cd = std::complex<double>;

// Gurkan, Table 4.3 ("Coefficients of the terms in the expansion H - Z, for the methods given in Tables 4.1 and
// 4.2"), as printed: two significant digits for X11, X16, X17, X19, X20 (real for the real methods, purely
// imaginary for the complex ones), three for the norm.
struct PublishedRow {
  const char* method;
  std::array<cd, 5> x;  // X11, X16, X17, X19, X20
  double norm;
};
constexpr cd I(double v) { return {0, v}; }
constexpr cd R(double v) { return {v, 0}; }
const std::array<PublishedRow, 9> kTable43{{
    {"AR1", {R(-3.1e-3), R(4.5e-4), R(5.6e-3), R(1.8e-5), R(-6.3e-5)}, 6.44e-3},
    {"AR2", {R(5.0e-3), R(-3.1e-4), R(-5.7e-3), R(1.5e-5), R(2.5e-4)}, 7.58e-3},
    {"BR1", {R(1.5e-4), R(6.2e-5), R(-4.1e-4), R(5.7e-5), R(1.6e-4)}, 4.71e-4},
    {"BR2", {R(-7.0e-5), R(9.7e-4), R(2.7e-4), R(5.2e-4), R(5.2e-4)}, 1.25e-3},
    {"BR3", {R(3.5e-2), R(1.9e-4), R(-3.5e-2), R(-3.0e-5), R(-1.0e-4)}, 4.90e-2},
    {"AC1", {I(-2.5e-6), I(7.3e-6), I(-5.0e-6), I(8.3e-7), I(4.2e-6)}, 1.02e-5},
    {"AC2", {I(3.0e-6), I(-7.9e-6), I(6.0e-6), I(-9.4e-7), I(-4.7e-6)}, 1.15e-5},
    {"BC1", {I(1.2e-5), I(-1.3e-5), I(8.4e-6), I(2.2e-7), I(-4.2e-6)}, 1.96e-5},
    {"BC2", {I(-4.1e-5), I(4.9e-5), I(-1.2e-4), I(7.7e-6), I(5.0e-5)}, 1.49e-4},
}};
const std::array<const char*, 5> kTerms{"X11", "X16", "X17", "X19", "X20"};
const double kInfD = std::numeric_limits<double>::infinity();
constexpr double kPublishedAc16Norm = 2.6e-7;  // sec. 6, after eq. (6.1)

/// The printed value's last-digit unit: 10^(floor(log10 |p|) - digits + 1).
double unit_of(double p, int digits) { return std::pow(10.0, std::floor(std::log10(std::abs(p))) - digits + 1); }

/// How many units of the last printed digit the computed value is away from the printed one, after rounding the
/// computed value to the printed digits (0: the digits agree).
long digit_offset(double published, double computed, int digits) {
  const double u = unit_of(published, digits);
  return std::lround(computed / u) - std::lround(published / u);
}

/// The component that the paper prints (real for the real methods, imaginary for the complex ones).
double printed_part(cd published, cd v) { return published.imag() != 0 ? v.imag() : v.real(); }
double other_part(cd published, cd v) { return published.imag() != 0 ? v.real() : v.imag(); }

std::string show(cd p) { return p.imag() != 0 ? fmt::format("{:.1e}i", p.imag()) : fmt::format("{:.1e}", p.real()); }
std::string show_full(cd v, bool imag) {
  return imag ? fmt::format("{:.4e}i", v.imag()) : fmt::format("{:.4e}", v.real());
}

}  // namespace

TargetResult gurkan_table43(const Context& ctx) {
  TargetResult res;
  res.name = "gurkan-table4.3";
  res.title = "Leading (degree-6) BCH error coefficients X11, X16, X17, X19, X20 and their norm";
  res.paper = "Gurkan, Table 4.3 and secs. 4 and 6";
  res.quick = ctx.quick;
  res.precision = "MPFR, 192 bits";
  const auto rows = an::gurkan_table_4_3([](const std::string& n) { return resolve_method(n); });
  double ac16_norm = nan;
  {
    an::AnalysisOptions opt;
    opt.degree = 6;
    const auto a = an::analyze_method(resolve_method("AC1-6"), opt);
    ac16_norm = a.degrees[5].norm;
  }

  std::string csv = "method,term,published_re,published_im,computed_re,computed_im,printed_digits,last_digit_offset\n";
  std::string tb =
      "Each cell: published / computed (rounded to the printed digits); a mark after the computed value "
      "gives its offset in units of the last printed digit, or says that only the sign differs.\n\n| method |";
  for (const char* t : kTerms) tb += fmt::format(" {} |", t);
  tb += " norm | digits agreeing |\n|---|---|---|---|---|---|---|---|\n";
  Series pub_vs{"X_i (published sign)", {}, {}, "points", 7}, neg_vs{"X_i (opposite sign)", {}, {}, "points", 6},
      norms{"norm", {}, {}, "points", 5};
  int all_entries = 0, all_agree = 0, all_within1 = 0, all_abs_agree = 0;
  double worst_imag_real = 0, worst_real_imag = 0;
  double min_real_norm = kInfD, max_cplx_norm = 0, min_norm = kInfD;
  std::vector<Claim> row_claims;
  for (const auto& p : kTable43) {
    const an::Table43Row* row = nullptr;
    for (const auto& r : rows)
      if (r.method == p.method) row = &r;
    if (!row) throw std::runtime_error(std::string("Table 4.3: no computed row for ") + p.method);
    const bool cplx = p.x[0].imag() != 0;
    std::map<std::string, cd> val(row->terms.begin(), row->terms.end());
    tb += fmt::format("| {} |", p.method);
    int agree = 0, within1 = 0, abs_agree = 0, opposite = 0;
    for (std::size_t k = 0; k < kTerms.size(); ++k) {
      if (!val.count(kTerms[k])) throw std::runtime_error(std::string("Table 4.3: no term ") + kTerms[k]);
      const cd v = val.at(kTerms[k]);
      const double pub = printed_part(p.x[k], p.x[k]), got = printed_part(p.x[k], v);
      const long off = digit_offset(pub, got, 2);
      agree += off == 0;
      within1 += std::abs(off) <= 1;
      abs_agree += digit_offset(std::abs(pub), std::abs(got), 2) == 0;
      opposite += pub * got < 0;
      const double rel_other = std::abs(other_part(p.x[k], v)) / std::max(1e-300, std::abs(v));
      if (cplx)
        worst_imag_real = std::max(worst_imag_real, rel_other);
      else
        worst_real_imag = std::max(worst_real_imag, rel_other);
      const double u = unit_of(pub, 2);
      tb += fmt::format(
          " {} / {}{} |", show(p.x[k]), show(cplx ? cd(0, std::lround(got / u) * u) : cd(std::lround(got / u) * u, 0)),
          off == 0                                                              ? ""
          : pub * got < 0 && digit_offset(std::abs(pub), std::abs(got), 2) == 0 ? " (opposite sign)"
                                                                                : fmt::format(" ({:+d})", off));
      csv += fmt::format("{},{},{:.2g},{:.2g},{:.17g},{:.17g},2,{}\n", p.method, kTerms[k], p.x[k].real(),
                         p.x[k].imag(), v.real(), v.imag(), off);
      (pub * got > 0 ? pub_vs : neg_vs).x.push_back(std::abs(pub));
      (pub * got > 0 ? pub_vs : neg_vs).y.push_back(std::abs(got));
    }
    const long noff = digit_offset(p.norm, row->norm, 3);
    tb += fmt::format(" {:.3g} / {:.3g}{} |", p.norm, std::lround(row->norm / unit_of(p.norm, 3)) * unit_of(p.norm, 3),
                      noff == 0 ? "" : fmt::format(" ({:+d})", noff));
    csv += fmt::format("{},norm,{:.3g},0,{:.17g},0,3,{}\n", p.method, p.norm, row->norm, noff);
    norms.x.push_back(p.norm);
    norms.y.push_back(row->norm);
    agree += noff == 0;
    within1 += std::abs(noff) <= 1;
    abs_agree += noff == 0;
    tb += fmt::format(" {} / 6 |\n", agree);
    all_entries += 6;
    all_agree += agree;
    all_within1 += within1;
    all_abs_agree += abs_agree;
    (cplx ? max_cplx_norm : min_real_norm) =
        cplx ? std::max(max_cplx_norm, row->norm) : std::min(min_real_norm, row->norm);
    min_norm = std::min(min_norm, row->norm);

    Claim c;
    c.id = std::string("row_") + p.method;
    c.paper = fmt::format("Table 4.3, {}: X11 {}, X16 {}, X17 {}, X19 {}, X20 {}, norm {:.3g}", p.method, show(p.x[0]),
                          show(p.x[1]), show(p.x[2]), show(p.x[3]), show(p.x[4]), p.norm);
    c.published = p.norm;
    c.measured = row->norm;
    c.measured_text = fmt::format(
        "norm {:.4g}; X11 {}, X16 {}, X17 {}, X19 {}, X20 {}; {} of 6 printed values agree "
        "digit by digit{}",
        row->norm, show_full(val.at("X11"), cplx), show_full(val.at("X16"), cplx), show_full(val.at("X17"), cplx),
        show_full(val.at("X19"), cplx), show_full(val.at("X20"), cplx), agree,
        opposite ? fmt::format(" ({} of 5 with the opposite sign)", opposite) : "");
    c.criterion = "all six printed values reproduced when the computed ones are rounded to the printed digits";
    c.holds = agree == 6;
    c.qualitative = std::string(
                        "the norm agrees to the printed digits (+-1 in the last) and every |X_i| to +-1 in the "
                        "last printed digit; the terms are ") +
                    (cplx ? "purely imaginary" : "real");
    int abs_within1 = 0;
    for (std::size_t k = 0; k < kTerms.size(); ++k)
      abs_within1 += std::abs(digit_offset(std::abs(printed_part(p.x[k], p.x[k])),
                                           std::abs(printed_part(p.x[k], val.at(kTerms[k]))), 2)) <= 1;
    bool character = true;
    for (const auto& [name, v] : row->terms)
      character = character && std::abs(other_part(p.x[0], v)) <= 1e-9 * std::max(1e-300, std::abs(v));
    c.qualitative_holds = std::abs(noff) <= 1 && abs_within1 == 5 && character;
    if (std::string(p.method) == "AC2" && opposite == 5)
      c.measured_text +=
          "; the printed AC2 row is that of the adjoint method (for this skew-symmetric method, its "
          "complex conjugate), whose X_i change sign: the magnitudes agree";
    row_claims.push_back(c);
  }
  write_file_atomic(ctx.path(res.name + ".csv"), csv);
  res.files.push_back(res.name + ".csv");
  Series diag{"computed = published", {1e-7, 0.1}, {1e-7, 0.1}, "lines"};
  plot_loglog(ctx.path(res.name + ".png"), "Gurkan Table 4.3: |X_i| and norms, computed against published",
              "published (Table 4.3)", "computed (this run, 192-bit MPFR)", {pub_vs, neg_vs, norms, diag});
  res.files.push_back(res.name + ".png");

  res.interpretation = {
      "Coefficients of H - Z in degree 6, Z = log of the method's operator product, in Gurkan's Philip Hall basis "
      "with his multiplication table (sec. 4) and the RKN simplification [V,[V,[T,V]]] = 0; the degree-6 "
      "coefficients other than X11, X16, X17, X19, X20 vanish in that algebra, so the norm is over these five. "
      "Computed by include/nystrom/analysis/bch.hpp from the catalog's coefficients (Tables 4.1 and 4.2 as "
      "published, 17 digits, refined to the order conditions at 192 bits where the catalog does so), in 192-bit MPFR.",
      "Digit by digit: the computed value is rounded to the number of digits the table prints (two for X_i, three "
      "for the norm) and compared with the printed value; the table shows the offset in units of the last digit "
      "where they differ. \"In words\" allows +-1 in the last digit and ignores the sign of X_i (see AC2).",
      "The published numbers are typed into src/reproduce_bch.cpp (kTable43) from Gurkan, Table 4.3."};
  res.table = tb + fmt::format("\nNorm of AC1-6 (eq. 6.1), degree 6: published {:.2g}, computed {:.4g}.\n",
                               kPublishedAc16Norm, ac16_norm);

  res.claims = row_claims;
  {
    Claim c = band_claim("all_digits", "Table 4.3 as a whole (54 printed values)", 54, all_agree, 54, 54,
                         "at least 90% of the printed values agree to +-1 in the last digit",
                         all_within1 >= 0.9 * all_entries);
    c.measured_text = fmt::format("{} of {} agree digit by digit, {} ignoring the sign, {} to +-1 in the last digit",
                                  all_agree, all_entries, all_abs_agree, all_within1);
    c.criterion = "every printed value reproduced";
    res.claims.push_back(c);
  }
  {
    Claim c = band_claim(
        "imaginary_leading", "the complex methods of Table 4.2 have purely imaginary leading order errors (sec. 4)", 0,
        worst_imag_real, 0, 1e-9, "the real parts of X_i of AC1, AC2, BC1, BC2 vanish", worst_imag_real <= 1e-9);
    c.measured_text = fmt::format("largest |Re X_i| / |X_i| = {:.2g} (real methods: largest |Im| / |.| = {:.2g})",
                                  worst_imag_real, worst_real_imag);
    c.criterion = "largest |Re X_i| / |X_i| <= 1e-9";
    res.claims.push_back(c);
  }
  {
    Claim c = band_claim("complex_smaller",
                         "the complex methods have much smaller leading order errors than the real ones (sec. 6; Table "
                         "4.3: largest complex norm 1.49e-4, smallest real 4.71e-4)",
                         4.71e-4 / 1.49e-4, min_real_norm / max_cplx_norm, 4.71 / 1.49 / 1.1, 4.71 / 1.49 * 1.1,
                         "every complex method's norm is below every real method's", max_cplx_norm < min_real_norm);
    c.measured_text = fmt::format("smallest real norm / largest complex norm = {:.3g}", min_real_norm / max_cplx_norm);
    c.criterion = "ratio within 10% of the published 3.16";
    res.claims.push_back(c);
  }
  {
    Claim c =
        band_claim("ac16_norm",
                   "AC1-6 (eq. 6.1) has an error (sum |X_i|^2)^(1/2) = 2.6e-7, about two orders of magnitude "
                   "smaller than the other methods",
                   kPublishedAc16Norm, ac16_norm, 2.55e-7, 2.65e-7,
                   "AC1-6's norm is more than 30x below that of every method of Table 4.3", ac16_norm * 30 < min_norm);
    c.measured_text = fmt::format("{:.4g} (smallest of Table 4.3: {:.3g}, {:.0f}x larger)", ac16_norm, min_norm,
                                  min_norm / ac16_norm);
    c.criterion = "rounds to the printed 2.6e-7";
    res.claims.push_back(c);
  }
  return res;
}

}  // namespace nystrom::cli::reproduce
