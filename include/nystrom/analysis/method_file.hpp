// Splitting methods stored in text files: written by `nystrom discover --write`, read back by
// `nystrom run --method file:PATH` (resolve_method) and by read_method_file().
//
// Format (one item per line; '#' starts a comment; blank lines are ignored; keywords are lower case):
//
//   # nystrom splitting method
//   name RKNA-IMAGINARY-01          required, one token (letters, digits, - _ . : + allowed)
//   order 5                          required, 1..12: verified on load (see below)
//   source nystrom discover ...      optional, free text (default: "file PATH")
//   description ...                  optional, free text
//   drift 0.0878084100456632 0.0285238442513418
//   kick  0.1752673433834805 0.0576420400762506
//   ...                              sub-steps IN THE ORDER THEY ARE APPLIED (time order); each line is
//                                    `drift RE [IM]` (q += c h v) or `kick RE [IM]` (v += c h a(q)); numbers
//                                    are decimals (1.5, -2e-3) or exact rationals p/q, at most 400
//                                    characters each; at most 10000 sub-steps
//
// Validation on load (each failure is a std::invalid_argument naming the file and the line):
//   * unknown keywords, repeated header lines, missing name/order/sub-steps, malformed or non-finite numbers;
//   * consistency: the drift coefficients and the kick coefficients must each sum to 1 (within 10^(2 - digits),
//     digits the fewest significant digits of a decimal coefficient; exact rationals: exactly);
//   * the declared order: the BCH analysis in the Hall basis of the RKN Lie algebra (nystrom/analysis/bch.hpp)
//     must find every error term of degree 1..order below a tolerance derived from the number of significant
//     digits given (10^(4 - digits)), so a file cannot claim an order its coefficients do not have.
#pragma once

#include <algorithm>
#include <cctype>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "nystrom/analysis/bch.hpp"
#include "nystrom/core/files.hpp"
#include "nystrom/methods/catalog.hpp"
#include "nystrom/methods/method.hpp"

namespace nystrom::analysis {

struct MethodFileStep {
  Flow flow = Flow::drift;
  std::string re, im;  // as written (im empty for real)
};

struct MethodFile {
  std::string name;
  int order = 0;
  std::string source;
  std::string description;
  std::vector<MethodFileStep> steps;
  int min_digits = 0;  // fewest significant digits among the decimal coefficients (0: all exact rationals)
};

/// Work of a BCH expansion of a splitting with `substeps` sub-steps to `degree`: sub-steps times the square of the
/// dimension of the free Lie algebra on two letters up to that degree (each sub-step is one truncated BCH product).
inline double bch_work(std::size_t substeps, int degree) {
  static constexpr double cumulative_dim[] = {0, 2, 3, 5, 8, 14, 23, 41, 71, 127, 226, 412, 747};
  const double d = cumulative_dim[std::clamp(degree, 0, 12)];
  return static_cast<double>(substeps) * d * d;
}

/// Refuses a BCH expansion beyond bch_work_limit (about a minute: KL8, 35 sub-steps, to degree 12 is 2e7 units and
/// took 2.8 s in Release on one core), naming the estimate.
inline constexpr double bch_work_limit = 4e8;
inline void check_bch_work(std::size_t substeps, int degree, const std::string& what) {
  const double w = bch_work(substeps, degree);
  if (w > bch_work_limit)
    throw std::invalid_argument(what + ": a BCH expansion of " + std::to_string(substeps) + " sub-steps to degree " +
                                std::to_string(degree) + " is too much work (" + std::to_string(static_cast<long>(w)) +
                                " units, limit " + std::to_string(static_cast<long>(bch_work_limit)) +
                                "): use fewer sub-steps or a lower degree");
}

namespace detail {

inline std::string trim(const std::string& s) {
  std::size_t a = 0, b = s.size();
  while (a < b && std::isspace(static_cast<unsigned char>(s[a]))) ++a;
  while (b > a && std::isspace(static_cast<unsigned char>(s[b - 1]))) --b;
  return s.substr(a, b - a);
}

// Strict number syntax: [+-]digits[.digits][e[+-]digits] or [+-]digits/digits. Returns significant digits
// (0 for a rational) or -1 if malformed.
inline int number_digits(const std::string& t) {
  std::size_t i = 0;
  if (i < t.size() && (t[i] == '+' || t[i] == '-')) ++i;
  const std::size_t slash = t.find('/');
  if (slash != std::string::npos) {
    if (slash == i || slash + 1 >= t.size()) return -1;
    for (std::size_t k = i; k < t.size(); ++k)
      if (k != slash && !std::isdigit(static_cast<unsigned char>(t[k]))) return -1;
    return 0;
  }
  std::string mant;
  bool dot = false, any = false;
  for (; i < t.size() && t[i] != 'e' && t[i] != 'E'; ++i) {
    if (t[i] == '.') {
      if (dot) return -1;
      dot = true;
    } else if (std::isdigit(static_cast<unsigned char>(t[i]))) {
      mant += t[i];
      any = true;
    } else {
      return -1;
    }
  }
  if (!any) return -1;
  if (i < t.size()) {  // exponent
    ++i;
    if (i < t.size() && (t[i] == '+' || t[i] == '-')) ++i;
    if (i >= t.size()) return -1;
    for (; i < t.size(); ++i)
      if (!std::isdigit(static_cast<unsigned char>(t[i]))) return -1;
  }
  const std::size_t nz = mant.find_first_not_of('0');
  if (nz == std::string::npos) return 1000;  // zero is exact
  if (!dot) return 1000;                     // an integer is exact
  return static_cast<int>(mant.size() - nz);
}

inline bool valid_name(const std::string& n) {
  if (n.empty() || n.size() > 64) return false;
  for (char c : n)
    if (!std::isalnum(static_cast<unsigned char>(c)) && std::string("-_.:+").find(c) == std::string::npos) return false;
  return true;
}

}  // namespace detail

/// Parses the text of a method file (`where` names it in error messages). Checks syntax only.
inline MethodFile parse_method_file(const std::string& text, const std::string& where) {
  MethodFile f;
  bool have_name = false, have_order = false, have_source = false, have_desc = false;
  f.min_digits = 1000;
  std::istringstream in(text);
  std::string line;
  int lineno = 0;
  auto fail = [&](const std::string& msg) {
    throw std::invalid_argument("method file " + where + ", line " + std::to_string(lineno) + ": " + msg);
  };
  while (std::getline(in, line)) {
    ++lineno;
    if (const auto h = line.find('#'); h != std::string::npos) line.erase(h);
    line = detail::trim(line);
    if (line.empty()) continue;
    std::istringstream ls(line);
    std::string key;
    ls >> key;
    std::string rest;
    std::getline(ls, rest);
    rest = detail::trim(rest);
    if (key == "name") {
      if (have_name) fail("'name' given twice");
      if (!detail::valid_name(rest))
        fail("the name must be one token of letters, digits and - _ . : + (at most 64), got '" + rest + "'");
      f.name = rest;
      have_name = true;
    } else if (key == "order") {
      if (have_order) fail("'order' given twice");
      if (rest.empty() || rest.size() > 3 || !std::all_of(rest.begin(), rest.end(), ::isdigit))
        fail("the order must be an integer, got '" + rest + "'");
      f.order = std::stoi(rest);
      if (f.order < 1 || f.order > max_lie_degree)
        fail("the order must be between 1 and " + std::to_string(max_lie_degree) + ", got " + rest);
      have_order = true;
    } else if (key == "source") {
      if (have_source) fail("'source' given twice");
      f.source = rest;
      have_source = true;
    } else if (key == "description") {
      if (have_desc) fail("'description' given twice");
      f.description = rest;
      have_desc = true;
    } else if (key == "drift" || key == "kick") {
      std::istringstream ns(rest);
      std::vector<std::string> nums;
      for (std::string t; ns >> t;) nums.push_back(t);
      if (nums.empty() || nums.size() > 2) fail("'" + key + "' needs one or two numbers (real part, imaginary part)");
      for (const auto& t : nums) {
        // a longer number only slows the multiprecision check down (its precision follows the digits given)
        if (t.size() > 400) fail("a number longer than 400 characters");
        const int dg = detail::number_digits(t);
        if (dg < 0) fail("malformed number '" + t + "'");
        if (t.find('/') != std::string::npos && t.substr(t.find('/') + 1).find_first_not_of('0') == std::string::npos)
          fail("zero denominator in '" + t + "'");
        if (dg > 0) f.min_digits = std::min(f.min_digits, dg);
      }
      if (f.steps.size() >= 10000) fail("too many sub-steps (at most 10000)");
      f.steps.push_back(
          {key == "drift" ? Flow::drift : Flow::kick, nums[0], nums.size() > 1 ? nums[1] : std::string()});
    } else {
      fail("unknown keyword '" + key + "' (known: name, order, source, description, drift, kick)");
    }
  }
  lineno = 0;
  if (!have_name) throw std::invalid_argument("method file " + where + ": missing 'name' line");
  if (!have_order) throw std::invalid_argument("method file " + where + ": missing 'order' line");
  if (f.steps.empty()) throw std::invalid_argument("method file " + where + ": no 'drift'/'kick' sub-steps");
  if (f.min_digits == 1000) f.min_digits = 0;
  if (!have_source) f.source = "file " + where;
  return f;
}

/// The splitting scheme of a parsed file at the current BigPrecision.
inline SplittingScheme<bigcomplex> method_file_scheme(const MethodFile& f) {
  SplittingScheme<bigcomplex> s;
  for (const auto& st : f.steps) s.steps.push_back({st.flow, bigc(st.re, st.im.empty() ? "0" : st.im)});
  return s;
}

/// Checks consistency and the declared order (see the top of the file). Throws std::invalid_argument.
inline void validate_method_file(const MethodFile& f, const std::string& where) {
  const unsigned bits = static_cast<unsigned>(std::max(128, f.min_digits * 4 + 64));
  BigPrecision guard(bits);
  const SplittingScheme<bigcomplex> s = method_file_scheme(f);
  bigcomplex sd, sk;
  bool has_drift = false, has_kick = false;
  for (const auto& st : s.steps) {
    if (!boost::multiprecision::isfinite(st.coef.re) || !boost::multiprecision::isfinite(st.coef.im))
      throw std::invalid_argument("method file " + where + ": a coefficient is not finite");
    if (st.flow == Flow::drift) {
      sd += st.coef;
      has_drift = true;
    } else {
      sk += st.coef;
      has_kick = true;
    }
  }
  if (!has_drift || !has_kick)
    throw std::invalid_argument("method file " + where + ": a splitting needs at least one drift and one kick");
  const double ed = std::abs(to_cd(sd) - std::complex<double>(1, 0)),
               ek = std::abs(to_cd(sk) - std::complex<double>(1, 0));
  // a file with d significant digits can sum to 1 only within about 10^-d
  const double sum_tol = f.min_digits > 0 ? std::max(1e-13, std::pow(10.0, 2 - f.min_digits)) : 1e-30;
  if (!(ed <= sum_tol) || !(ek <= sum_tol)) {
    std::ostringstream msg;
    msg.precision(17);
    msg << "method file " << where << ": the drift coefficients sum to " << to_cd(sd)
        << " and the kick coefficients to " << to_cd(sk) << "; both must be 1";
    throw std::invalid_argument(msg.str());
  }
  check_bch_work(s.steps.size(), f.order, "method file " + where);
  AnalysisOptions opt;
  opt.degree = f.order;
  opt.precision_bits = bits;
  opt.tolerance = f.min_digits > 0 ? std::pow(10.0, 4 - f.min_digits) : 0;  // 0: exact rationals (or precision)
  const MethodAnalysis a = analyze_scheme(s, opt, f.min_digits);
  if (a.order < f.order) {
    const auto& bad = a.degrees[static_cast<std::size_t>(a.order)];
    double worst = 0;
    for (const auto& t : bad.terms) worst = std::max(worst, std::abs(t.value));
    std::ostringstream msg;
    msg << "method file " << where << ": declares order " << f.order << " but the degree-" << bad.degree
        << " error terms are as large as " << worst << " (";
    if (a.exact) {
      msg << "computed exactly";
    } else {
      msg << "tolerance " << a.tolerance;
    }
    msg << "), so its order is " << a.order;
    throw std::invalid_argument(msg.str());
  }
}

/// Reads, parses and validates a method file.
/// The file must be a regular file of at most 10 MB (read_input_file, core/files.hpp: a device, FIFO or
/// folder is refused before anything is read).
inline MethodFile read_method_file(const std::string& path) {
  const std::string text = read_input_file<std::invalid_argument>(path, "method file", 10'000'000);
  MethodFile f = parse_method_file(text, path);
  validate_method_file(f, path);
  return f;
}

/// A catalog entry for a method file (the coefficients are kept as text and built at the precision asked for).
inline MethodDef method_def_from_file(const std::string& path) {
  auto f = std::make_shared<const MethodFile>(read_method_file(path));
  MethodInfo info;
  info.name = f->name;
  info.family = "splitting";
  info.order = f->order;
  info.published_digits = f->min_digits;
  info.source = f->source;
  info.description = f->description.empty() ? "splitting method read from " + path : f->description;
  {
    BigPrecision guard(256);
    const auto s = method_file_scheme(*f);
    bool sym = true, real = true;
    for (std::size_t i = 0; i < s.steps.size(); ++i) {
      const auto& a = s.steps[i];
      const auto& b = s.steps[s.steps.size() - 1 - i];
      if (a.flow != b.flow || std::abs(to_cd(a.coef) - to_cd(b.coef)) > 1e-14) sym = false;
      if (!(a.coef.im == 0)) real = false;
    }
    info.symmetric = sym;
    info.symplectic = real;
  }
  return {info, [f] { return MethodData{method_file_scheme(*f)}; }};
}

/// Text of a method file for a scheme (coefficients with `digits` significant digits).
inline std::string format_method_file(const std::string& name, int order, const std::string& source,
                                      const std::string& description, const SplittingScheme<bigcomplex>& s,
                                      int digits) {
  if (!detail::valid_name(name)) throw std::invalid_argument("invalid method name '" + name + "'");
  std::ostringstream o;
  o << "# nystrom splitting method: sub-steps in time order, `drift|kick RE [IM]` (see analysis/method_file.hpp)\n";
  o << "name " << name << "\norder " << order << "\n";
  if (!source.empty()) o << "source " << source << "\n";
  if (!description.empty()) o << "description " << description << "\n";
  // parts below 10^-digits of the coefficient's size are rounding noise (e.g. the imaginary part of the real
  // middle coefficient of a polished skew-symmetric method) and are written as zero
  const bigfloat noise = boost::multiprecision::pow(bigfloat(10), -digits);
  for (const auto& st : s.steps) {
    const bigfloat size = std::max<bigfloat>(bigfloat(1), abs_big(st.coef));
    const bigfloat re = boost::multiprecision::abs(st.coef.re) < noise * size ? bigfloat(0) : st.coef.re;
    const bigfloat im = boost::multiprecision::abs(st.coef.im) < noise * size ? bigfloat(0) : st.coef.im;
    o << (st.flow == Flow::drift ? "drift " : "kick  ") << big_str(re, digits);
    if (!(im == 0)) o << " " << big_str(im, digits);
    o << "\n";
  }
  return o.str();
}

/// Installs method_def_from_file as the reader of "file:PATH" specifications (methods/catalog.hpp): a
/// program that accepts method files calls it once at start (the tool and the Python module do).
inline void register_method_file_reader() { set_method_file_reader(&method_def_from_file); }

}  // namespace nystrom::analysis
