// Bad input whose one line was already printed: rank 0 of an MPI run prints it before any rank may exit (a rank
// that exited first would make the launcher stop rank 0 before it printed); run_main() (cli.hpp) then only
// returns exit status 2.
#pragma once

#include <stdexcept>

namespace nystrom::cli {

struct ReportedUsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace nystrom::cli
