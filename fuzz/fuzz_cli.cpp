// libFuzzer harness: the tool's command line, parsed and validated in-process (parse_command_line). The
// input is split at NUL bytes into arguments (at most 64). Every refusal must be a UsageError whose message is
// one printable line; anything else is a finding. A command line of `run` that parses is also run, with the
// work limit lowered to 2e5 force evaluations (NYSTROM_WORK_LIMIT) and its output discarded, except when it
// could read or write a file (file: specifications, --ic, --checkpoint, --restart) or has no work estimate
// (adaptive methods and GBS: --tol; --output-times). No other subcommand runs: nothing spawns a process
// (gnuplot) or writes a file. The harness works in a private temporary folder, removed at exit.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <iostream>
#include <sstream>
#include <streambuf>
#include <string>
#include <vector>

#include "cli.hpp"
#include "nystrom/analysis/method_file.hpp"

namespace {

struct NullBuffer : std::streambuf {
  int overflow(int c) override { return c; }
  std::streamsize xsputn(const char*, std::streamsize n) override { return n; }
};

std::string g_dir;

void remove_dir() {
  if (!g_dir.empty()) ::rmdir(g_dir.c_str());
}

std::string lower(const std::string& s) {
  std::string out;
  for (char c : s) out += static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
  return out;
}

// A parsed `run` that may be run here: bounded work, no files.
bool safe_to_run(const std::vector<std::string>& args) {
  if (args.size() < 2 || args[1] != "run") return false;
  for (std::size_t i = 2; i < args.size(); ++i) {
    const std::string a = lower(args[i]);
    for (const char* bad : {"file:", "--ic", "checkpoint", "restart", "--tol", "output-times", "adaptive", "gbs"})
      if (a.find(bad) != std::string::npos) return false;
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  const char* tmp = std::getenv("TMPDIR");
  std::string tmpl = std::string(tmp && *tmp == '/' ? tmp : "/tmp") + "/nystrom-fuzz-cli.XXXXXX";
  if (!::mkdtemp(tmpl.data()) || ::chdir(tmpl.c_str()) != 0) std::abort();
  g_dir = tmpl;
  std::atexit(remove_dir);
  ::setenv("NYSTROM_WORK_LIMIT", "2e5", 1);
  ::setenv("NYSTROM_PROGRESS", "0", 1);
  static NullBuffer null;
  std::cout.rdbuf(&null);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const bool reader = (nystrom::analysis::register_method_file_reader(), true);  // as the tool's main()
  (void)reader;
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
  nystrom::cli::Invocation inv;
  try {
    inv = nystrom::cli::parse_command_line(static_cast<int>(argv.size()), argv.data(), help);
    if (inv.exit_now < 0 && !inv.action) __builtin_trap();  // either an action or an exit status
  } catch (const nystrom::cli::UsageError& e) {
    const std::string line = nystrom::cli::printable(e.what());
    if (line.find('\n') != std::string::npos) __builtin_trap();
    return 0;
  }
  if (inv.action && safe_to_run(args)) {
    try {
      inv.action();
    } catch (const std::exception& e) {  // run_main's one error line: any exception is a refusal there
      if (nystrom::cli::printable(e.what()).find('\n') != std::string::npos) __builtin_trap();
    }
  }
  return 0;
}
