// What the benchmark programs share: a console reporter that also keeps the minimum over repetitions of
// each benchmark's time per unit of work (robust on a shared machine), and a default repetition count.
#pragma once

#include <benchmark/benchmark.h>

#include <algorithm>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace nystrom::bench {

/// Console output as usual, plus, per benchmark (by function name), the minimum over its repetitions of
/// the time per iteration divided by `units_per_iteration`, in `scale` units of a second (1e9: ns).
class MinTimeReporter : public benchmark::ConsoleReporter {
 public:
  enum class Clock { cpu, real };
  MinTimeReporter(Clock clock, double units_per_iteration, double scale)
      : clock_(clock), units_(units_per_iteration), scale_(scale) {}

  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const auto& r : runs) {
      if (r.run_type != Run::RT_Iteration || r.error_occurred || r.iterations == 0) continue;
      const double t = clock_ == Clock::cpu ? r.cpu_accumulated_time : r.real_accumulated_time;
      const double per_unit = t * scale_ / (static_cast<double>(r.iterations) * units_);
      const std::string name = r.run_name.function_name;
      auto it = best_.find(name);
      if (it == best_.end() || per_unit < it->second) best_[name] = per_unit;
    }
  }
  /// The minimum time of benchmark `name`, or nullptr if it did not run.
  const double* best(const std::string& name) const {
    const auto it = best_.find(name);
    return it == best_.end() ? nullptr : &it->second;
  }

 private:
  Clock clock_;
  double units_, scale_;
  std::map<std::string, double> best_;
};

/// benchmark::Initialize with --benchmark_repetitions=`repetitions` unless the command line gives it.
/// False (after printing the error) when an argument is not recognized.
/// (The argument strings live as long as the program: the library may keep pointers into them.)
inline bool initialize(std::vector<char*> arguments, int repetitions) {
  static std::vector<char*> args;
  static std::string reps;
  args = std::move(arguments);
  reps = "--benchmark_repetitions=" + std::to_string(repetitions);
  if (std::none_of(args.begin() + 1, args.end(),
                   [](const char* a) { return std::string(a).rfind("--benchmark_repetitions", 0) == 0; }))
    args.push_back(reps.data());
  int n = static_cast<int>(args.size());
  benchmark::Initialize(&n, args.data());
  return !benchmark::ReportUnrecognizedArguments(n, args.data());
}

}  // namespace nystrom::bench
