// libFuzzer harness: the N-body initial-condition reader (problems/plummer.hpp, load_particles), which
// `--ic FILE` uses. The input is written to a private temporary file and read back; a malformed file must end
// in std::invalid_argument; a file that loads has finite coordinates and positive masses.
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "nystrom/problems/plummer.hpp"

namespace {

const std::string& scratch() {
  static const std::string path = [] {
    char tmpl[] = "/tmp/nystrom-fuzz-particles.XXXXXX";
    const int fd = ::mkstemp(tmpl);
    if (fd < 0) __builtin_trap();
    ::close(fd);
    return std::string(tmpl);
  }();
  return path;
}

struct Cleanup {
  ~Cleanup() { std::remove(scratch().c_str()); }
} cleanup;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 1 << 16) return 0;
  std::FILE* f = std::fopen(scratch().c_str(), "wb");
  if (!f) __builtin_trap();
  std::fwrite(data, 1, size, f);
  std::fclose(f);
  try {
    const auto p = nystrom::load_particles<double>(scratch());
    for (double m : p.m)
      if (!(m > 0) || !std::isfinite(m)) __builtin_trap();
    for (double x : p.s.q)
      if (!std::isfinite(x)) __builtin_trap();
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
