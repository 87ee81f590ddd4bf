// The whole state of an integration between two steps, written exactly (hexadecimal floating point)
// so that a run restarted from it is bitwise the run that was never interrupted: the engine's state
// (with the time coordinate of a time-dependent force), the compensated-summation carries, the step
// controller's state (adaptive RKN and MPE: next step, step bound, last rejection, predictive
// history; GBS: step and order) and the counters. A format version and the method and problem
// descriptions are part of it, so that a checkpoint is refused for another method or problem.
#pragma once

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <system_error>
#include <type_traits>
#include <vector>

#include "nystrom/core/error.hpp"

namespace nystrom {

/// T: the real type of the state.
template <class T>
struct Checkpoint {
  static constexpr int format_version = 1;
  std::string method;             // the method specification it was taken with
  std::string problem;            // the caller's description of the problem (refused when it differs)
  std::string engine;             // "fixed", "adaptive-rkn", "adaptive-mpe", "gbs"
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
std::string hex(const T& x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%La", static_cast<long double>(x));
  return buf;
}

template <class T>
T parse_hex(const std::string& s) {
  errno = 0;
  char* end = nullptr;
  const long double x = std::strtold(s.c_str(), &end);
  if (end == s.c_str() || *end != '\0' || errno == ERANGE)
    throw invalid_input("checkpoint: malformed number '" + s + "'");
  return static_cast<T>(x);
}

inline std::string escape(const std::string& s) {
  std::string o;
  for (char c : s) o += (c == '\n' || c == '\r') ? ' ' : c;
  return o;
}

}  // namespace checkpoint_detail

/// The checkpoint as text: one "key value..." line per field; floating-point values in hexadecimal.
template <class T>
std::string to_text(const Checkpoint<T>& c) {
  using namespace checkpoint_detail;
  static_assert(exact_text<T>, "checkpoints are written for float, double and long double states");
  std::ostringstream o;
  o << "nystrom-checkpoint " << Checkpoint<T>::format_version << "\n";
  o << "method " << escape(c.method) << "\n";
  o << "problem " << escape(c.problem) << "\n";
  o << "engine " << c.engine << "\n";
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
  o << "end\n";
  return o.str();
}

template <class T>
Checkpoint<T> checkpoint_from_text(const std::string& text) {
  using namespace checkpoint_detail;
  static_assert(exact_text<T>, "checkpoints are read for float, double and long double states");
  std::istringstream in(text);
  std::string line;
  Checkpoint<T> c;
  auto fail = [](const std::string& why) { return invalid_input("malformed checkpoint: " + why); };
  if (!std::getline(in, line)) throw fail("empty");
  {
    std::istringstream l(line);
    std::string magic;
    int version = 0;
    if (!(l >> magic >> version) || magic != "nystrom-checkpoint") throw fail("not a nystrom checkpoint");
    if (version != Checkpoint<T>::format_version)
      throw invalid_input("checkpoint format version " + std::to_string(version) + " is not supported (this is " +
                          std::to_string(Checkpoint<T>::format_version) + ")");
  }
  bool ended = false;
  while (std::getline(in, line)) {
    const auto sp = line.find(' ');
    const std::string key = line.substr(0, sp);
    const std::string rest = sp == std::string::npos ? "" : line.substr(sp + 1);
    std::istringstream l(rest);
    std::string w;
    auto num = [&]() -> T {
      if (!(l >> w)) throw fail("missing value of " + key);
      return parse_hex<T>(w);
    };
    auto vec = [&](std::vector<T>& v) {
      long n = -1;
      if (!(l >> n) || n < 0 || n > 100000000) throw fail("bad length of " + key);
      v.clear();
      for (long i = 0; i < n; ++i) v.push_back(num());
    };
    if (key == "method")
      c.method = rest;
    else if (key == "problem")
      c.problem = rest;
    else if (key == "engine")
      c.engine = rest;
    else if (key == "t")
      c.t = num();
    else if (key == "step_index") {
      if (!(l >> c.step_index)) throw fail("step_index");
    } else if (key == "state")
      vec(c.state);
    else if (key == "carry")
      vec(c.carry);
    else if (key == "h_want")
      c.h_want = num();
    else if (key == "hmax")
      c.hmax = num();
    else if (key == "span")
      c.span = num();
    else if (key == "q_prev")
      c.q_prev = static_cast<double>(parse_hex<long double>((l >> w, w)));
    else if (key == "h_prev")
      c.h_prev = static_cast<double>(parse_hex<long double>((l >> w, w)));
    else if (key == "columns") {
      if (!(l >> c.columns)) throw fail("columns");
    } else if (key == "last_rejected") {
      int b = 0;
      if (!(l >> b)) throw fail("last_rejected");
      c.last_rejected = b != 0;
    } else if (key == "counters") {
      if (!(l >> c.force_evals >> c.output_force_evals >> c.accepted >> c.rejected)) throw fail("counters");
    } else if (key == "end") {
      ended = true;
      break;
    } else {
      throw fail("unknown field '" + key + "'");
    }
  }
  if (!ended) throw fail("truncated (no end line)");
  if (c.state.empty() || c.state.size() % 2 != 0) throw fail("no state");
  return c;
}

/// Writes the checkpoint to `path` atomically: a temporary file beside it, then a rename (a reader
/// never sees a half-written checkpoint; an existing file is replaced only by a complete one).
inline void write_checkpoint_text(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    if (!f) throw error("cannot write the checkpoint file '" + path + "'");
    f << text;
    f.flush();
    if (!f) throw error("cannot write the checkpoint file '" + path + "'");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    throw error("cannot write the checkpoint file '" + path + "'");
  }
}
template <class T>
void write_checkpoint(const std::string& path, const Checkpoint<T>& c) {
  write_checkpoint_text(path, to_text(c));
}

template <class T>
Checkpoint<T> read_checkpoint(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw invalid_input("cannot read the checkpoint file '" + path + "'");
  std::ostringstream ss;
  ss << f.rdbuf();
  return checkpoint_from_text<T>(ss.str());
}

}  // namespace nystrom
