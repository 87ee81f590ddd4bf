// The whole state of an integration between two steps, written exactly (hexadecimal floating point)
// so that a run restarted from it is bitwise the run that was never interrupted: the engine's state
// (with the time coordinate of a time-dependent force), the compensated-summation carries, the step
// controller's state (adaptive RKN and MPE: next step, step bound, last rejection, predictive
// history; GBS: step and order) and the counters. A format version, the real type, and the method and
// problem descriptions are part of it, so that a checkpoint is refused for another method or problem.
//
// The text (format version 2) is one "key value" line per field in a fixed order, and a last line
//   checksum fnv1a64 <16 hex digits>
// the 64-bit FNV-1a hash of every byte before it. Reading refuses, with one line, any file that is not
// exactly such a text: a changed byte (the checksum), a missing, repeated or reordered line, a NUL byte,
// a number with trailing characters, a number that is not finite, a length that does not match the values
// on its line, and values no run can have written (the fields an engine does not use must be zero; the
// next step of an adaptive engine positive and within its bound; a GBS order within 2..29; the counters
// not negative). What depends on the problem and the engine's options (the state's length, the step index
// within the run, a GBS order within the integrator's columns) is checked where the run restores it.
// Version 1 (no checksum) is refused.
#pragma once

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "nystrom/core/error.hpp"
#include "nystrom/core/files.hpp"

namespace nystrom {

/// T: the real type of the state.
template <class T>
struct Checkpoint {
  static constexpr int format_version = 2;
  std::string method;             // the method specification it was taken with
  std::string problem;            // the caller's description of the problem (refused when it differs)
  std::string engine;             // "fixed", "adaptive-rkn", "adaptive-mpe", "adaptive-mpe-midpoint", "gbs"
  T t{};                          // the time of the step boundary
  long step_index = 0;            // fixed step: steps done
  std::vector<T> state;           // the engine's q then v (complex: real and imaginary parts), flattened
  std::vector<T> carry;           // the compensation carries, cq then cv, flattened (empty: none)
  T h_want{}, hmax{};             // adaptive: next step and step bound; GBS: next step (h_want)
  T span{};                       // GBS: the time since the start of its span
  double q_prev = 0, h_prev = 0;  // adaptive: the predictive controller's history
  int columns = 0;                // GBS: the order (columns of the extrapolation table)
  bool last_rejected = false;
  long force_evals = 0, output_force_evals = 0, accepted = 0, rejected = 0;
};

namespace checkpoint_detail {

template <class T>
constexpr bool exact_text = std::is_same_v<T, float> || std::is_same_v<T, double> || std::is_same_v<T, long double>;

template <class T>
constexpr const char* real_name() {
  if constexpr (std::is_same_v<T, float>)
    return "float";
  else if constexpr (std::is_same_v<T, double>)
    return "double";
  else
    return "long-double";
}

/// The 64-bit FNV-1a hash of the bytes of s.
inline std::uint64_t fnv1a64(std::string_view s) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (const char c : s) {
    h ^= static_cast<unsigned char>(c);
    h *= 0x100000001b3ULL;
  }
  return h;
}

inline std::string checksum_line(std::string_view body) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "checksum fnv1a64 %016llx\n", static_cast<unsigned long long>(fnv1a64(body)));
  return buf;
}

template <class T>
std::string hex(const T& x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%La", static_cast<long double>(x));
  return buf;
}

inline invalid_input malformed(const std::string& why) { return invalid_input("malformed checkpoint: " + why); }

/// A number as hex() writes it: [-]0x<hex digits>[.<hex digits>]p<sign><decimal digits>, finite in T.
template <class T>
T parse_hex(const std::string& key, std::string_view s) {
  std::size_t i = 0;
  auto hexdigit = [&](std::size_t k) { return k < s.size() && std::isxdigit(static_cast<unsigned char>(s[k])); };
  auto digit = [&](std::size_t k) { return k < s.size() && s[k] >= '0' && s[k] <= '9'; };
  if (i < s.size() && s[i] == '-') ++i;
  bool ok = s.substr(i, 2) == "0x";
  i += 2;
  ok = ok && hexdigit(i);
  while (hexdigit(i)) ++i;
  if (ok && i < s.size() && s[i] == '.') {
    ++i;
    while (hexdigit(i)) ++i;
  }
  ok = ok && i < s.size() && s[i] == 'p';
  ++i;
  ok = ok && i < s.size() && (s[i] == '+' || s[i] == '-');
  ++i;
  ok = ok && digit(i);
  while (digit(i)) ++i;
  ok = ok && i == s.size() && s.size() < 64;
  if (!ok) throw malformed("'" + std::string(s.substr(0, 40)) + "' in " + key + " is not a number in hexadecimal");
  const std::string z(s);
  char* end = nullptr;
  const long double x = std::strtold(z.c_str(), &end);
  const T y = static_cast<T>(x);
  if (end != z.c_str() + z.size() || !std::isfinite(x) || !std::isfinite(y))
    throw malformed("the value '" + z + "' of " + key + " is not a finite number");
  return y;
}

/// A decimal integer in [lo, hi]: [-]digits, nothing else.
inline long parse_integer(const std::string& key, std::string_view s, long lo, long hi) {
  long v = 0;
  const char* b = s.data();
  const char* e = s.data() + s.size();
  const bool plain = !s.empty() && (s[0] == '-' || (s[0] >= '0' && s[0] <= '9'));
  const auto r = std::from_chars(b, e, v);
  if (!plain || r.ec != std::errc() || r.ptr != e || v < lo || v > hi)
    throw malformed("the value '" + std::string(s.substr(0, 40)) + "' of " + key + " is not an integer in [" +
                    std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return v;
}

/// Splits s at single spaces (an empty word, i.e. two spaces or a space at an end, is malformed).
inline std::vector<std::string_view> words(const std::string& key, std::string_view s) {
  std::vector<std::string_view> w;
  std::size_t a = 0;
  for (;;) {
    const std::size_t b = s.find(' ', a);
    const std::string_view word = s.substr(a, b == std::string_view::npos ? std::string_view::npos : b - a);
    if (word.empty()) throw malformed("stray space in " + key);
    w.push_back(word);
    if (b == std::string_view::npos) break;
    a = b + 1;
  }
  return w;
}

inline std::string escape(const std::string& s) {
  std::string o;
  for (char c : s) o += (c == '\n' || c == '\r' || c == '\0') ? ' ' : c;
  return o;
}

constexpr long max_count = 1L << 62;

}  // namespace checkpoint_detail

/// Whether c holds values a run can have written (see the top of the file); throws invalid_input with
/// one line if not. checkpoint_from_text calls it; a program that builds a Checkpoint itself can too.
template <class T>
void validate_checkpoint(const Checkpoint<T>& c) {
  using checkpoint_detail::malformed;
  auto finite = [](const T& x) { return std::isfinite(static_cast<long double>(x)); };
  const bool fixed = c.engine == "fixed", gbs = c.engine == "gbs";
  const bool adaptive = c.engine == "adaptive-rkn" || c.engine == "adaptive-mpe" || c.engine == "adaptive-mpe-midpoint";
  if (!fixed && !gbs && !adaptive) throw malformed("unknown engine '" + c.engine.substr(0, 40) + "'");
  if (c.method.empty()) throw malformed("no method");
  if (c.state.empty() || c.state.size() % 2 != 0) throw malformed("the state must hold q and v (an even length)");
  if (!c.carry.empty() && c.carry.size() != c.state.size())
    throw malformed("the carries must be as many as the state's values, or none");
  for (const auto& v : {&c.state, &c.carry})
    for (const auto& x : *v)
      if (!finite(x)) throw malformed("a value of the state or the carries is not finite");
  if (!finite(c.t) || !finite(c.h_want) || !finite(c.hmax) || !finite(c.span) || !std::isfinite(c.q_prev) ||
      !std::isfinite(c.h_prev))
    throw malformed("a time or step is not finite");
  if (c.force_evals < 0 || c.output_force_evals < 0 || c.accepted < 0 || c.rejected < 0 || c.step_index < 0)
    throw malformed("a counter is negative");
  const T zero{};
  if (fixed) {
    if (c.step_index < 1 || c.accepted != c.step_index || c.rejected != 0)
      throw malformed("a fixed-step checkpoint needs step_index >= 1, equal to its accepted steps, and no rejection");
    if (c.h_want != zero || c.hmax != zero || c.span != zero || c.q_prev != 0 || c.h_prev != 0 || c.columns != 0 ||
        c.last_rejected)
      throw malformed("a fixed-step checkpoint has no step controller");
  } else if (adaptive) {
    if (c.step_index != 0 || c.span != zero || c.columns != 0)
      throw malformed("an adaptive checkpoint has no step index, span or columns");
    if (!(c.h_want > zero) || !(c.hmax > zero) || c.h_want > c.hmax)
      throw malformed("the next step of an adaptive checkpoint must be positive and within its bound hmax");
    if (!(c.q_prev >= 0) || !(c.h_prev >= 0)) throw malformed("the step controller's history is negative");
  } else {
    if (c.step_index != 0 || c.hmax != zero || c.q_prev != 0 || c.h_prev != 0)
      throw malformed("a GBS checkpoint has no step index, step bound or step history");
    if (!(c.h_want > zero) || !(c.span > zero))
      throw malformed("the step and span of a GBS checkpoint must be positive");
    if (c.columns < 2 || c.columns > 29) throw malformed("the order of a GBS checkpoint must be 2 to 29 columns");
  }
}

/// The checkpoint as text (see the top of the file); floating-point values in hexadecimal.
template <class T>
std::string to_text(const Checkpoint<T>& c) {
  using namespace checkpoint_detail;
  static_assert(exact_text<T>, "checkpoints are written for float, double and long double states");
  std::ostringstream o;
  o << "nystrom-checkpoint " << Checkpoint<T>::format_version << "\n";
  o << "real " << real_name<T>() << "\n";
  o << "method " << escape(c.method) << "\n";
  o << "problem " << escape(c.problem) << "\n";
  o << "engine " << escape(c.engine) << "\n";
  o << "t " << hex(c.t) << "\n";
  o << "step_index " << c.step_index << "\n";
  auto vec = [&](const char* name, const std::vector<T>& v) {
    o << name << " " << v.size();
    for (const auto& x : v) o << " " << hex(x);
    o << "\n";
  };
  vec("state", c.state);
  vec("carry", c.carry);
  o << "h_want " << hex(c.h_want) << "\nhmax " << hex(c.hmax) << "\nspan " << hex(c.span) << "\n";
  o << "q_prev " << hex(c.q_prev) << "\nh_prev " << hex(c.h_prev) << "\n";
  o << "columns " << c.columns << "\nlast_rejected " << (c.last_rejected ? 1 : 0) << "\n";
  o << "counters " << c.force_evals << " " << c.output_force_evals << " " << c.accepted << " " << c.rejected << "\n";
  const std::string body = o.str();
  return body + checksum_line(body);
}

/// Reads the text of to_text (see the top of the file). Throws invalid_input with one line.
template <class T>
Checkpoint<T> checkpoint_from_text(const std::string& text) {
  using namespace checkpoint_detail;
  static_assert(exact_text<T>, "checkpoints are read for float, double and long double states");
  if (text.empty()) throw malformed("empty");
  if (text.find('\0') != std::string::npos) throw malformed("it contains a NUL byte");
  const std::string_view all(text);
  const std::string_view first = all.substr(0, all.find('\n'));
  {
    constexpr std::string_view magic = "nystrom-checkpoint ";
    if (first.substr(0, magic.size()) != magic) throw malformed("not a nystrom checkpoint");
    const std::string_view v = first.substr(magic.size());
    const int current = Checkpoint<T>::format_version;
    if (v != std::to_string(current)) {
      if (v == "1")
        throw invalid_input("checkpoint format version 1 (without a checksum) is no longer read: this is version " +
                            std::to_string(current) + "; take the checkpoint again");
      throw invalid_input("checkpoint format version '" + std::string(v.substr(0, 20)) +
                          "' is not supported (this is " + std::to_string(current) + ")");
    }
  }
  // The last line is the checksum of everything before it.
  if (all.back() != '\n') throw malformed("truncated (it does not end with a line break)");
  const std::size_t last = all.rfind('\n', all.size() - 2);
  const std::size_t body_end = last == std::string_view::npos ? 0 : last + 1;
  const std::string_view body = all.substr(0, body_end);
  if (all.substr(body_end, 17) != "checksum fnv1a64 ") throw malformed("truncated (no checksum line)");
  if (all.substr(body_end) != checksum_line(body))
    throw malformed("the checksum does not match the content (the file was changed or damaged)");

  Checkpoint<T> c;
  std::size_t pos = first.size() + 1;
  auto line = [&](const std::string& key) -> std::string_view {
    if (pos >= body.size()) throw malformed("the line '" + key + "' is missing");
    const std::size_t nl = body.find('\n', pos);
    const std::string_view l = body.substr(pos, nl - pos);
    pos = nl + 1;
    if (l.substr(0, key.size() + 1) != key + " ") throw malformed("expected the line '" + key + "' here");
    return l.substr(key.size() + 1);
  };
  auto num = [&](const std::string& key) { return parse_hex<T>(key, line(key)); };
  auto vec = [&](const std::string& key, std::vector<T>& v) {
    const auto w = words(key, line(key));
    const long n = parse_integer(key + " length", w[0], 0, max_count);
    if (static_cast<std::size_t>(n) != w.size() - 1)
      throw malformed(key + " declares " + std::to_string(n) + " values but holds " + std::to_string(w.size() - 1));
    v.reserve(w.size() - 1);
    for (std::size_t i = 1; i < w.size(); ++i) v.push_back(parse_hex<T>(key, w[i]));
  };
  if (const std::string_view real = line("real"); real != real_name<T>())
    throw invalid_input("the checkpoint holds " + std::string(real.substr(0, 40)) + " numbers, not " + real_name<T>());
  c.method = std::string(line("method"));
  c.problem = std::string(line("problem"));
  c.engine = std::string(line("engine"));
  c.t = num("t");
  c.step_index = parse_integer("step_index", line("step_index"), 0, max_count);
  vec("state", c.state);
  vec("carry", c.carry);
  c.h_want = num("h_want");
  c.hmax = num("hmax");
  c.span = num("span");
  c.q_prev = static_cast<double>(parse_hex<long double>("q_prev", line("q_prev")));
  c.h_prev = static_cast<double>(parse_hex<long double>("h_prev", line("h_prev")));
  c.columns = static_cast<int>(parse_integer("columns", line("columns"), 0, 1000));
  c.last_rejected = parse_integer("last_rejected", line("last_rejected"), 0, 1) != 0;
  {
    const auto w = words("counters", line("counters"));
    if (w.size() != 4) throw malformed("counters needs 4 values");
    c.force_evals = parse_integer("counters", w[0], 0, max_count);
    c.output_force_evals = parse_integer("counters", w[1], 0, max_count);
    c.accepted = parse_integer("counters", w[2], 0, max_count);
    c.rejected = parse_integer("counters", w[3], 0, max_count);
  }
  if (pos != body.size()) throw malformed("unexpected lines before the checksum");
  validate_checkpoint(c);
  return c;
}

/// Writes checkpoint text to `path` with write_file_atomic (core/files.hpp): a unique temporary file in
/// the same folder, fsync, rename. A reader never sees a half-written checkpoint; several threads or
/// processes may write the same file; a target that is a folder, device, FIFO or symbolic link is refused.
inline void write_checkpoint_text(const std::string& path, const std::string& text) {
  write_file_atomic(path, text, {.what = "the checkpoint file"});
}
template <class T>
void write_checkpoint(const std::string& path, const Checkpoint<T>& c) {
  write_checkpoint_text(path, to_text(c));
}

/// Reads a checkpoint file: a regular file of at most max_bytes (read_input_file, core/files.hpp).
template <class T>
Checkpoint<T> read_checkpoint(const std::string& path, std::size_t max_bytes = max_input_file_bytes) {
  return checkpoint_from_text<T>(read_input_file(path, "the checkpoint file", max_bytes));
}

}  // namespace nystrom
