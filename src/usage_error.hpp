// The error of a bad command line or bad input: one clear sentence, printed by run_main() (cli.hpp) as
// "nystrom: error: <sentence>" with exit status 2.
#pragma once

#include <stdexcept>

namespace nystrom::cli {

struct UsageError : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

}  // namespace nystrom::cli
