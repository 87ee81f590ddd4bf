// `nystrom run` on the built-in problems with velocity-dependent forces (through solve(), double precision):
//   arenstorf            the Arenstorf orbit in the rotating frame (problems/arenstorf.hpp): return_error =
//                        |q(T) - q0| after --periods periods, and the error of the Jacobi constant;
//   damped-oscillator    q'' + 2 gamma q' + omega0^2 q = F cos(omega t) (problems/damped_oscillator.hpp) over
//                        --periods periods of the drive: position and velocity errors against the exact solution.
// Only the methods for y'' = f(t, y, y') run them (MethodInfo::velocity); any other is refused with one line.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "nystrom/methods/method.hpp"
#include "runner.hpp"

namespace nystrom::cli {

/// Whether `problem` is one of the problems above.
bool is_velocity_problem(const std::string& problem);

/// Runs one of them (UsageError for bad input) and returns the report as JSON.
nlohmann::json run_velocity_problem(const RunRequest& req, const MethodDef& def);

/// The report as a table.
void print_velocity_report(const nlohmann::json& r);

}  // namespace nystrom::cli
