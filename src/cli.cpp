#include "cli.hpp"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>
#include <new>
#include <stdexcept>
#include <utility>

#include <fmt/core.h>

#include "reported_error.hpp"
#include "signals.hpp"

namespace nystrom::cli {

std::vector<Command>& commands() {
  static std::vector<Command> all;
  return all;
}

std::string printable(std::string_view text, std::size_t max) {
  std::string out;
  for (unsigned char c : text) {
    if (out.size() >= max) {
      out += "...";
      break;
    }
    if (c == '\n')
      out += "\\n";
    else if (c == '\t')
      out += "\\t";
    else if (c == '\\')
      out += "\\\\";
    else if (c < 0x20 || c >= 0x7f)
      out += fmt::format("\\x{:02x}", c);
    else
      out += static_cast<char>(c);
  }
  return out;
}

// ---------------------------------------------------------------------------------------------------------
// The checks of option values (the syntax of every number: option_number_error, parse.hpp).

namespace {

// A bound as written in a message: a whole number in full up to 1e15, otherwise %g.
std::string bound_text(double x) {
  return x == std::floor(x) && std::abs(x) < 1e15 ? fmt::format("{:.0f}", x) : fmt::format("{:g}", x);
}

// Whether the lower end of a range check belongs to the range.
enum class LowerEnd { closed, open };

// A range check: the syntax of a number, then lo <= x <= hi (LowerEnd::open: lo < x).
CLI::Validator bounded(double lo, LowerEnd end, double hi, std::string description) {
  const bool lo_open = end == LowerEnd::open;
  return CLI::Validator(
      [lo, lo_open, hi](std::string& v) -> std::string {
        if (auto err = option_number_error(v, {}); !err.empty()) return err;
        const double x = std::strtod(v.c_str(), nullptr);
        if ((lo_open ? x > lo : x >= lo) && x <= hi) return "";
        if (lo == 0 && std::isinf(hi))
          return (lo_open ? "must be positive, got " : "must not be negative, got ") + quoted_value(v);
        return "must be between " + bound_text(lo) + " and " + bound_text(hi) + ", got " + quoted_value(v);
      },
      std::move(description), "range");
}

}  // namespace

CLI::Validator positive_check() { return bounded(0, LowerEnd::open, HUGE_VAL, "POSITIVE"); }
CLI::Validator non_negative_check() { return bounded(0, LowerEnd::closed, HUGE_VAL, "NONNEGATIVE"); }
CLI::Validator range_check(double lo, double hi) {
  return bounded(lo, LowerEnd::closed, hi, "[" + bound_text(lo) + " - " + bound_text(hi) + "]");
}

CLI::Validator eccentricity_check() {
  return CLI::Validator(
      [](std::string& v) -> std::string {
        if (auto err = option_number_error(v, {}); !err.empty()) return err;
        const double e = std::strtod(v.c_str(), nullptr);
        return e >= 0 && e < 1 ? "" : "the eccentricity must satisfy 0 <= e < 1, got " + quoted_value(v);
      },
      "0 <= e < 1", "eccentricity");
}

CLI::Validator tolerance_check() {
  return CLI::Validator(
      [](std::string& v) -> std::string {
        if (auto err = option_number_error(v, {}); !err.empty()) return err;
        const double t = std::strtod(v.c_str(), nullptr);
        return t >= 1e-300 && t < 1e300 ? ""
                                        : "the tolerance must be positive (at least 1e-300), got " + quoted_value(v);
      },
      "positive", "tolerance");
}

// ---------------------------------------------------------------------------------------------------------
// The command line.

namespace {

// Checks the text of every numeric option before CLI11 converts it (CLI11 reads "" as 0 and accepts
// "inf", "nan" and trailing garbage in some conversions), and refuses an explicitly empty text option.
void add_strict_validators(CLI::App& app) {
  for (CLI::Option* opt : app.get_options()) {
    if (opt->get_expected_min() == 0) continue;  // flags
    // "FLOAT", or "FLOAT:POSITIVE" etc. once a validator with a description is attached
    const std::string full_type = opt->get_type_name();
    const std::string type = full_type.substr(0, full_type.find(':'));
    if (type == "FLOAT" || type == "INT" || type == "UINT") {
      const bool integer = type != "FLOAT";
      const bool unsigned_ = type == "UINT";
      opt->check(CLI::Validator(
          [integer, unsigned_](std::string& v) -> std::string {
            return option_number_error(
                v, {.syntax = integer ? NumberSyntax::integer : NumberSyntax::decimal, .non_negative = unsigned_});
          },
          "", "strict number"));
    } else if (type == "TEXT") {
      opt->check(CLI::Validator([](std::string& v) -> std::string { return v.empty() ? "must not be empty" : ""; }, "",
                                "non-empty"));
    }
  }
}

struct ParsedApp {
  std::unique_ptr<CLI::App> app;
  std::vector<std::pair<CLI::App*, Action>> actions;
};

ParsedApp make_app() {
  ParsedApp p;
  p.app = std::make_unique<CLI::App>(
      "nystrom: high-order splitting, Runge-Kutta-Nystrom and multi-product integrators for q'' = a(q)");
  p.app->name("nystrom");
  p.app->set_version_flag("--version", NYSTROM_VERSION, "Print the version (the CMake project version) and exit");
  p.app->require_subcommand(1);
  for (const auto& c : commands()) {
    CLI::App* sub = p.app->add_subcommand(c.name, c.help);
    p.actions.emplace_back(sub, c.setup(*sub));
    add_strict_validators(*sub);
  }
  return p;
}

}  // namespace

Invocation parse_command_line(int argc, const char* const* argv, std::ostream& help_out) {
  ParsedApp p = make_app();
  try {
    p.app->parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return {{}, p.app->exit(e, help_out, help_out)};
  } catch (const CLI::CallForAllHelp& e) {
    return {{}, p.app->exit(e, help_out, help_out)};
  } catch (const CLI::CallForVersion& e) {
    return {{}, p.app->exit(e, help_out, help_out)};
  } catch (const CLI::ParseError& e) {
    throw UsageError(std::string(e.what()) + " (see nystrom --help)");
  }
  // CLI11 runs no validator on an empty argument and converts it to 0: refuse it here.
  for (auto& [sub, action] : p.actions)
    if (sub->parsed())
      for (const CLI::Option* opt : sub->get_options())
        for (const std::string& r : opt->results())
          if (r.empty() && opt->get_expected_min() > 0) throw UsageError(opt->get_name() + ": must not be empty");
  for (auto& [sub, action] : p.actions)
    if (sub->parsed()) return {action, -1};
  throw UsageError("no subcommand given (see nystrom --help)");
}

int run_main(int argc, char** argv) {
  install_signal_handlers();
  auto fail = [](const std::string& msg) {
    std::cout.flush();
    std::cerr << error_line(msg);
    return 2;
  };
  try {
    const Invocation inv = parse_command_line(argc, argv, std::cout);
    if (inv.exit_now >= 0) return inv.exit_now;
    return inv.action();
  } catch (const ReportedUsageError&) {
    std::cout.flush();
    return 2;
  } catch (const std::bad_alloc&) {
    return fail("out of memory: the request is too large for this machine");
  } catch (const std::filesystem::filesystem_error& e) {
    std::string what = e.code().message();
    if (!e.path1().empty()) what = "'" + e.path1().string() + "': " + what;
    return fail("cannot access " + what);
  } catch (const std::out_of_range& e) {
    // std::stol and friends say only their own name
    const std::string w = e.what();
    return fail(w.rfind("sto", 0) == 0 ? "a number is out of range" : w);
  } catch (const std::exception& e) {
    const std::string w = e.what();
    return fail(w.rfind("sto", 0) == 0 && w.size() < 8 ? "a number is malformed or out of range" : w);
  } catch (...) {
    return fail("unexpected failure");
  }
}

}  // namespace nystrom::cli
