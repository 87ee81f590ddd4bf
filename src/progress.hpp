// The progress line of a long run on stderr.
#pragma once

#include <string>

namespace nystrom::cli {

/// A progress line on stderr for long runs ("label [####----] 12/40 (30.0%), 3 s, ETA 9 s"), only when stderr
/// is a terminal or NYSTROM_PROGRESS=1; redrawn at most ten times a second. An interrupted run leaves its last
/// line as it was drawn (the signal handler ends the process): it shows where the run stopped.
class Progress {
 public:
  Progress(std::string label, long total);
  void tick(long done);
  ~Progress();

 private:
  std::string label_;
  long total_;
  bool enabled_;
  double start_ = 0, last_ = -1;
  bool drawn_ = false;
};

}  // namespace nystrom::cli
