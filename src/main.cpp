// nystrom: the command-line tool. Each subcommand lives in its own src/cmd_*.cpp and registers itself;
// parsing, validation and the mapping of every failure to one error line are in cli.cpp (run_main).
#include "cli.hpp"
#include "nystrom/analysis/method_file.hpp"

int main(int argc, char** argv) {
  nystrom::analysis::register_method_file_reader();  // `file:PATH` method specifications
  return nystrom::cli::run_main(argc, argv);
}
