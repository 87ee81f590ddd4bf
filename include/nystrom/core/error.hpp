// The exceptions of the library: one base class, nystrom::error (a std::runtime_error), and three
// kinds under it. Every engine and solve() report the failure of an integration through them:
//   * invalid_input        the problem or the options cannot be integrated (sizes, NaN, span, ...);
//   * step_size_underflow  an adaptive controller needs a step below the rounding level of t (a
//                          tolerance the precision cannot meet, a singular solution, or a force that
//                          returned NaN or infinity);
//   * too_many_steps       the step budget (max_steps) ran out before the end of the span.
// The messages name the library's concepts (tolerance, step size, state), not command-line flags.
// (Construction-time checks of method data, e.g. a malformed tableau, stay std::invalid_argument.)
#pragma once

#include <stdexcept>
#include <string>

namespace nystrom {

class error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class invalid_input : public error {
 public:
  using error::error;
};

class step_size_underflow : public error {
 public:
  using error::error;
};

class too_many_steps : public error {
 public:
  using error::error;
};

/// CamelCase names of the two integration failures (the same types).
using StepSizeUnderflow = step_size_underflow;
using TooManySteps = too_many_steps;

}  // namespace nystrom
