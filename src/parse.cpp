#include "parse.hpp"

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include "nystrom/core/files.hpp"

namespace nystrom::cli {

std::string number_syntax_error(std::string_view t, NumberSyntax syntax) {
  const bool integer = syntax == NumberSyntax::integer;
  if (t.empty()) return "an empty string is not a number";
  std::size_t i = 0;
  if (t[i] == '+' || t[i] == '-') ++i;
  std::size_t digits = 0;
  while (i < t.size() && t[i] >= '0' && t[i] <= '9') ++i, ++digits;
  if (!integer && i < t.size() && t[i] == '.') {
    ++i;
    while (i < t.size() && t[i] >= '0' && t[i] <= '9') ++i, ++digits;
  }
  if (digits == 0) return "not a number";
  if (!integer && i < t.size() && (t[i] == 'e' || t[i] == 'E')) {
    ++i;
    if (i < t.size() && (t[i] == '+' || t[i] == '-')) ++i;
    std::size_t exp_digits = 0;
    while (i < t.size() && t[i] >= '0' && t[i] <= '9') ++i, ++exp_digits;
    if (exp_digits == 0) return "not a number (exponent without digits)";
  }
  if (i != t.size()) return integer ? "not a whole number" : "not a number";
  return "";
}

std::string quoted_value(const std::string& v) { return "'" + (v.size() > 40 ? v.substr(0, 40) + "..." : v) + "'"; }

std::string option_number_error(const std::string& v, NumberRule rule) {
  const bool integer = rule.syntax == NumberSyntax::integer;
  if (const auto err = number_syntax_error(v, rule.syntax); !err.empty())
    return "must be " + std::string(integer ? "a whole number" : "a finite number") + ", got " + quoted_value(v);
  if (rule.non_negative && v[0] == '-') return "must not be negative, got " + quoted_value(v);
  if (integer) {
    long long x = 0;
    const char* b = v.c_str() + (v[0] == '+' ? 1 : 0);
    const auto [p, ec] = std::from_chars(b, v.c_str() + v.size(), x);
    if (ec != std::errc() || p != v.c_str() + v.size()) return "is out of range, got " + quoted_value(v);
  } else {
    errno = 0;
    const double x = std::strtod(v.c_str(), nullptr);
    if (!std::isfinite(x) || (errno == ERANGE && std::abs(x) > 1)) return "must be finite, got " + quoted_value(v);
  }
  return "";
}

double parse_double(const std::string& text, const std::string& what, Bound bound) {
  if (const auto err = number_syntax_error(text, NumberSyntax::decimal); !err.empty())
    throw UsageError(what + " must be a number, got '" + text + "'");
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size()) throw UsageError(what + " must be a number, got '" + text + "'");
  if (!std::isfinite(v) || (errno == ERANGE && std::abs(v) > 1))
    throw UsageError(what + " must be finite, got '" + text + "'");
  if (errno == ERANGE) throw UsageError(what + " is too small to represent, got '" + text + "'");
  if (bound == Bound::positive && !(v > 0)) throw UsageError(what + " must be positive, got '" + text + "'");
  return v;
}

long long parse_integer(const std::string& text, const std::string& what, long long lo, long long hi) {
  if (!number_syntax_error(text, NumberSyntax::integer).empty())
    throw UsageError(what + " must be a whole number, got '" + text + "'");
  long long v = 0;
  const char* b = text.c_str() + (text[0] == '+' ? 1 : 0);
  const auto [ptr, ec] = std::from_chars(b, text.c_str() + text.size(), v);
  if (ec != std::errc() || ptr != text.c_str() + text.size() || v < lo || v > hi)
    throw UsageError(what + " must be between " + std::to_string(lo) + " and " + std::to_string(hi) + ", got '" + text +
                     "'");
  return v;
}

std::vector<std::string> split_list(const std::string& text, const std::string& what) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (item.empty()) throw UsageError(what + " has an empty item: '" + text + "'");
    out.push_back(item);
  }
  if (out.empty() || text.back() == ',') throw UsageError(what + " is empty or malformed: '" + text + "'");
  return out;
}

std::vector<double> parse_double_list(const std::string& text, const std::string& what) {
  std::vector<double> v;
  for (const auto& item : split_list(text, what)) v.push_back(parse_double(item, what));
  return v;
}

std::vector<double> parse_log_range(const std::string& text, const std::string& what, RangeOrder order) {
  std::vector<std::string> parts;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ':')) parts.push_back(item);
  if (parts.size() != 3 || text.empty() || text.back() == ':')
    throw UsageError(what + " must be FROM:TO:COUNT (e.g. 1e3:1e6:20), got '" + text + "'");
  const double lo = parse_double(parts[0], what + " start", Bound::positive);
  const double hi = parse_double(parts[1], what + " end", Bound::positive);
  const int n = static_cast<int>(parse_integer(parts[2], what + " count", 1, 10000));
  if (hi < lo && order == RangeOrder::increasing) throw UsageError(what + ": end must not be below start");
  std::vector<double> v;
  for (int i = 0; i < n; ++i)
    v.push_back(n == 1 ? lo : std::exp(std::log(lo) + (std::log(hi) - std::log(lo)) * i / (n - 1)));
  return v;
}

std::size_t grid_file_bound(std::size_t points) { return 128 * points + (std::size_t{1} << 20); }

std::vector<double> read_grid_values(const std::string& path, const std::string& flag, std::size_t points) {
  std::istringstream in(nystrom::read_input_file<UsageError>(path, flag, grid_file_bound(points)));
  std::vector<double> v;
  std::string line;
  for (long number = 1; std::getline(in, line); ++number) {
    std::istringstream words(line.substr(0, line.find('#')));
    for (std::string w; words >> w;) {
      if (v.size() == points)
        throw UsageError(flag + " '" + path + "' has more values than the " + std::to_string(points) + " grid points");
      v.push_back(parse_double(w, flag + " value on line " + std::to_string(number)));
    }
  }
  if (v.size() != points)
    throw UsageError(flag + " '" + path + "' has " + std::to_string(v.size()) + " values for " +
                     std::to_string(points) + " grid points");
  return v;
}

}  // namespace nystrom::cli
