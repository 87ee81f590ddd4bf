// nystrom: the command-line tool. Each subcommand lives in its own src/cmd_*.cpp and registers itself.
#include <exception>
#include <iostream>
#include <memory>
#include <vector>

#include "cli.hpp"

int main(int argc, char** argv) {
  using nystrom::cli::commands;
  CLI::App app{"nystrom: high-order splitting, Runge-Kutta-Nystrom and multi-product integrators for q'' = a(q)"};
  app.name("nystrom");
  app.require_subcommand(1);
  std::vector<std::pair<CLI::App*, nystrom::cli::Action>> actions;
  for (const auto& c : commands()) {
    CLI::App* sub = app.add_subcommand(c.name, c.help);
    actions.emplace_back(sub, c.setup(*sub));
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "nystrom: error: " << e.what() << " (see nystrom --help)\n";
    return 2;
  }
  try {
    for (auto& [sub, action] : actions)
      if (sub->parsed()) return action();
  } catch (const std::invalid_argument& e) {
    std::cerr << "nystrom: error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "nystrom: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
