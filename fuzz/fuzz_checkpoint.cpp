// libFuzzer harness: the checkpoint reader (solve/checkpoint.hpp, checkpoint_from_text), which `--restart FILE`
// and Python's restart= use. Each input is read twice: as it is, and with its last line replaced by the checksum
// of everything before it, so that the fuzzer reaches the field parser and its validation and not only the
// checksum. A malformed checkpoint must end in nystrom::invalid_input. A checkpoint that reads must write back
// to a text that reads to the same checkpoint; one of a Kepler run (4 state values) of a method of the seeds is
// also restarted (a bounded run, at most 2000 steps), which must end normally or in a nystrom::error or
// std::invalid_argument, never in a crash.
#include <array>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "nystrom/problems/kepler.hpp"
#include "nystrom/solve_inline.hpp"  // std::array states: the inline path

namespace {

using V2 = std::array<double, 2>;

void restart(const nystrom::Checkpoint<double>& c) {
  if (c.state.size() != 4) return;
  nystrom::SolveOptions opt;
  opt.max_steps = 2000;
  opt.checkpoint_problem = c.problem;
  if (c.method == "M8")
    opt.steps = 1000;
  else if (c.method == "DP12-adaptive" || c.method == "M10-adaptive" || c.method == "GBS")
    opt.rtol = 1e-8;
  else
    return;
  const auto s = nystrom::KeplerProblem<double>(0.5).initial_state();
  const nystrom::SecondOrderProblem prob(nystrom::KeplerForce{}, s.q, s.v, 0.0, 20.0);
  try {
    nystrom::resume(prob, nystrom::resolve_solve_method(c.method), c, opt);
  } catch (const nystrom::error&) {
  } catch (const std::invalid_argument&) {
  }
}

void read(const std::string& text) {
  try {
    const auto c = nystrom::checkpoint_from_text<double>(text);
    const std::string again = nystrom::to_text(c);
    if (nystrom::to_text(nystrom::checkpoint_from_text<double>(again)) != again) __builtin_trap();
    restart(c);
  } catch (const nystrom::invalid_input&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 1 << 16) return 0;
  const std::string text(reinterpret_cast<const char*>(data), size);
  read(text);
  std::string body = text;
  if (const auto p = body.rfind("\nchecksum "); p != std::string::npos) body.resize(p + 1);
  read(body + nystrom::checkpoint_detail::checksum_line(body));
  return 0;
}
