// libFuzzer harness: the tool's command line, parsed and validated in-process (parse_command_line) without
// running the chosen subcommand. The input is split at NUL bytes into arguments. Every refusal must be a
// UsageError whose message is one printable line; anything else is a finding.
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "cli.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 4096) return 0;
  std::vector<std::string> args{"nystrom"};
  std::string cur;
  for (std::size_t i = 0; i < size; ++i) {
    if (data[i] == 0) {
      args.push_back(cur);
      cur.clear();
    } else {
      cur += static_cast<char>(data[i]);
    }
  }
  args.push_back(cur);
  if (args.size() > 64) return 0;
  std::vector<const char*> argv;
  for (const auto& a : args) argv.push_back(a.c_str());
  std::ostringstream help;
  try {
    const auto inv = nystrom::cli::parse_command_line(static_cast<int>(argv.size()), argv.data(), help);
    if (inv.exit_now < 0 && !inv.action) __builtin_trap();  // either an action or an exit status
  } catch (const nystrom::cli::UsageError& e) {
    const std::string line = nystrom::cli::printable(e.what());
    if (line.find('\n') != std::string::npos) __builtin_trap();
  }
  return 0;
}
