// libFuzzer harness: the method-file reader (analysis/method_file.hpp). Every input is parsed; small parsed
// files (at most 64 sub-steps, order at most 6) are also validated, which runs the BCH order check.
// A malformed file must end in std::invalid_argument; anything else is a finding.
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "nystrom/analysis/method_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 1 << 16) return 0;
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const auto f = nystrom::analysis::parse_method_file(text, "fuzz");
    if (f.steps.empty() || f.name.empty()) __builtin_trap();  // parse_method_file promises both
    if (f.steps.size() <= 64 && f.order <= 6) nystrom::analysis::validate_method_file(f, "fuzz");
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
