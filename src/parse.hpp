// The tool's one parser of numbers and option values: every number a command reads from its command line or
// from an input file is checked as a whole string here (finite, no empty string, no trailing characters,
// integers without exponent or fraction), and a bad one is a UsageError of one line that names it.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "usage_error.hpp"

namespace nystrom::cli {

/// Which numbers a text may spell: decimal ones, or integers (no fraction, no exponent).
enum class NumberSyntax : unsigned char { decimal, integer };

/// Strict syntax of a decimal number: [+-]digits[.digits][(e|E)[+-]digits] (or .digits); no spaces, no
/// hex, inf or nan. Returns an empty string when `text` is valid, otherwise what is wrong.
std::string number_syntax_error(std::string_view text, NumberSyntax syntax);

/// What a numeric option accepts: its syntax, and whether a minus sign is refused.
struct NumberRule {
  NumberSyntax syntax = NumberSyntax::decimal;
  bool non_negative = false;
};

/// The check of a numeric option's text: an empty string when `v` is a valid number of its kind (finite, in
/// range of its type), otherwise the end of a message ("must be a finite number, got 'x'").
std::string option_number_error(const std::string& v, NumberRule rule);

/// `v` as quoted in a message: at most 40 characters.
std::string quoted_value(const std::string& v);

/// What a parsed number must be: finite, or finite and positive.
enum class Bound : unsigned char { finite, positive };

/// Parses a number that must satisfy `bound`; `what` names it in errors.
double parse_double(const std::string& text, const std::string& what, Bound bound = Bound::finite);

/// Parses a whole-string integer (no exponent or fraction) within [lo, hi]; `what` names it in errors.
long long parse_integer(const std::string& text, const std::string& what, long long lo, long long hi);

/// Splits "a,b,c"; empty items are errors.
std::vector<std::string> split_list(const std::string& text, const std::string& what);

/// "1,0,-0.5" -> its finite numbers (split_list, then parse_double on each).
std::vector<double> parse_double_list(const std::string& text, const std::string& what);

/// The order of the ends of a range FROM:TO:COUNT: TO at least FROM, or either way (e.g. tolerances 1e-6:1e-14:9).
enum class RangeOrder : unsigned char { increasing, either };

/// "1e3:1e6:20" -> 20 values spaced evenly in log between 1e3 and 1e6 (inclusive).
std::vector<double> parse_log_range(const std::string& text, const std::string& what,
                                    RangeOrder order = RangeOrder::increasing);

/// The most bytes an input file of values for `points` grid points may have: 128 per point (two numbers of 17
/// digits and a comment fit) and 1 MiB more.
std::size_t grid_file_bound(std::size_t points);

/// The values of an input file given by option `flag` (e.g. "--potential-file"): numbers separated by white
/// space, `#` to the end of a line a comment, exactly `points` of them (one per grid point, row-major, last
/// axis fastest). A regular file of at most grid_file_bound(points) bytes (nystrom::read_input_file: a
/// folder, a FIFO or a device is refused, since reading one could block or never end).
std::vector<double> read_grid_values(const std::string& path, const std::string& flag, std::size_t points);

}  // namespace nystrom::cli
