// The tool's one error line, and bad input whose line was already printed: rank 0 of an MPI run prints it before
// any rank may exit (a rank that exited first would make the launcher stop rank 0 before it printed);
// run_main() (cli.hpp) then only returns exit status 2.
#pragma once

#include <stdexcept>
#include <string>
#include <string_view>

#include "cli.hpp"

namespace nystrom::cli {

/// "nystrom: error: <why>" with its newline, `why` made printable on one line (cli.hpp: printable).
inline std::string error_line(std::string_view why) { return "nystrom: error: " + printable(why) + "\n"; }

struct ReportedUsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace nystrom::cli
