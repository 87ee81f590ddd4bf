// The command line of the nystrom tool: subcommand registration, the checks of option values, and the main
// function that maps every failure to one line.
//
// Each src/cmd_*.cpp registers its subcommand with a static Registrar, so a new command is one new
// file and nothing else changes:
//
//   static nystrom::cli::Registrar reg("run", "Integrate one problem with one method", [](CLI::App& app) {
//     auto opt = std::make_shared<Options>();   // options live as long as the app
//     app.add_option(...);
//     return [opt] { ...; return 0; };          // the action, run when this subcommand is chosen
//   });
//
// Errors: throw nystrom::cli::UsageError (or std::invalid_argument) with one clear sentence; run_main()
// prints "nystrom: error: <sentence>" on stderr (one line, non-printable bytes escaped) and exits with status 2.
// Every other failure (any exception, out of memory) ends the same way: one line, status 2.
//
// Input validation: every numeric option is checked as a whole string before CLI11 converts it (finite,
// no empty string, no trailing characters, integers without exponent or fraction; parse.hpp), and every text
// option given explicitly must be non-empty; ranges are checked by each command. SIGINT/SIGTERM end the process
// cleanly (signals.hpp).
//
// This header brings what every subcommand uses: UsageError, the parsers of option values (parse.hpp) and the
// work limits (work_limit.hpp). The progress line (progress.hpp), plots (plot.hpp) and result files
// (output_file.hpp) have headers of their own.
#pragma once

#include <cstddef>
#include <functional>
#include <iosfwd>
#include <string>
#include <string_view>
#include <vector>

#include <CLI/CLI.hpp>

#include "parse.hpp"
#include "usage_error.hpp"
#include "work_limit.hpp"

namespace nystrom::cli {

using Action = std::function<int()>;
using Setup = std::function<Action(CLI::App&)>;

struct Command {
  std::string name, help;
  Setup setup;
};

/// The registered subcommands, in the order of registration.
std::vector<Command>& commands();

/// Registers a subcommand (a static object of each src/cmd_*.cpp).
struct Registrar {
  Registrar(std::string name, std::string help, Setup setup) {
    commands().push_back({std::move(name), std::move(help), std::move(setup)});
  }
};

/// The result of parsing a command line: the chosen subcommand's action, or an exit status to return
/// at once (help was printed).
struct Invocation {
  Action action;
  int exit_now = -1;
};

/// Parses and validates a command line against the registered subcommands without running anything.
/// Throws UsageError (with one printable line) on any error; help goes to `help_out`.
Invocation parse_command_line(int argc, const char* const* argv, std::ostream& help_out);

/// The whole tool: installs the signal handlers, parses, runs the subcommand and maps every failure to
/// one line "nystrom: error: ..." on stderr and exit status 2.
int run_main(int argc, char** argv);

/// `text` with every byte outside printable ASCII written as \xNN (and \n, \t, \\), cut to `max` characters.
std::string printable(std::string_view text, std::size_t max = 400);

/// CLI11 checks of an eccentricity (0 <= e < 1) and of a tolerance (positive, at least 1e-300).
CLI::Validator eccentricity_check();
CLI::Validator tolerance_check();

/// CLI11 range checks with one short message each ("must be positive, got '-5'", "must be between 2 and
/// 1000000, got '0'"), used instead of CLI::PositiveNumber, CLI::NonNegativeNumber and CLI::Range (whose
/// messages print the bounds of a double with hundreds of digits). Each checks the number's syntax first.
CLI::Validator positive_check();
CLI::Validator non_negative_check();
CLI::Validator range_check(double lo, double hi);

}  // namespace nystrom::cli
