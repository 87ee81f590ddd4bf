#include "progress.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include <fmt/core.h>

namespace nystrom::cli {

namespace {

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::string duration_text(double s) {
  if (s < 120) return fmt::format("{:.0f} s", s);
  if (s < 7200) return fmt::format("{:.0f} min", s / 60);
  return fmt::format("{:.1f} h", s / 3600);
}

}  // namespace

Progress::Progress(std::string label, long total) : label_(std::move(label)), total_(total) {
  const char* env = std::getenv("NYSTROM_PROGRESS");
  enabled_ = (env && std::string(env) == "1") || (!env && ::isatty(STDERR_FILENO));
  start_ = now_seconds();
}

void Progress::tick(long done) {
  if (!enabled_ || total_ <= 0) return;
  const double t = now_seconds();
  if (done < total_ && last_ >= 0 && t - last_ < 0.1) return;
  last_ = t;
  done = std::clamp(done, 0L, total_);
  const int width = 30;
  const int filled = static_cast<int>(width * static_cast<double>(done) / static_cast<double>(total_));
  const double elapsed = t - start_;
  std::string eta;
  if (done > 0 && done < total_)
    eta = ", ETA " + duration_text(elapsed * static_cast<double>(total_ - done) / static_cast<double>(done));
  // the percentage rounded down: 100.0% only for a complete run
  const double percent = std::floor(1000.0 * static_cast<double>(done) / static_cast<double>(total_)) / 10;
  std::fprintf(stderr, "\r%s [%s%s] %ld/%ld (%.1f%%), %s%s   ", label_.c_str(), std::string(filled, '#').c_str(),
               std::string(width - filled, '-').c_str(), done, total_, percent, duration_text(elapsed).c_str(),
               eta.c_str());
  std::fflush(stderr);
  drawn_ = true;
}

Progress::~Progress() {
  if (enabled_ && drawn_) std::fprintf(stderr, "\n");
}

}  // namespace nystrom::cli
