// Runs the command-line tool for the tests that check its contract: the tool is found through the
// environment variable NYSTROM_BIN (set by CTest), its stdout and stderr are captured in a temporary
// folder of the running test, and its exit status is returned (128 + signal when it was killed).
#pragma once

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "support/files.hpp"

namespace cli_test {

struct Result {
  int code = -1;
  std::string out, err;
};

inline std::string tool() {
  const char* b = std::getenv("NYSTROM_BIN");
  return b ? b : "nystrom";
}

using nystrom::test::slurp;

/// A folder of its own for the running test (process id and test name).
inline std::filesystem::path temp_dir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  auto d = std::filesystem::temp_directory_path() /
           ("nystrom-cli-" + std::to_string(::getpid()) + "-" + info->test_suite_name() + "-" + info->name());
  std::filesystem::create_directories(d);
  return d;
}

/// Runs `nystrom ARGS` (the arguments are the test's own, passed through the shell as written), after
/// `launcher` when one is given (e.g. `mpiexec -np 2`); its stdout and stderr go to files in DIR (created if needed).
inline Result run(const std::string& args, const std::filesystem::path& dir, const std::string& launcher = "") {
  std::filesystem::create_directories(dir);
  const auto out = dir / "stdout.txt", err = dir / "stderr.txt";
  const std::string cmd = (launcher.empty() ? "" : launcher + " ") + tool() + " " + args + " >" + out.string() + " 2>" +
                          err.string() + " </dev/null";
  const int status = std::system(cmd.c_str());
  Result r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

/// Runs `nystrom ARGS` with its output files in the running test's own folder (temp_dir()).
inline Result run(const std::string& args) { return run(args, temp_dir()); }

}  // namespace cli_test
