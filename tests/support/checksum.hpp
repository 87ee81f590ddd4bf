// The checkpoint's checksum line, computed in the tests independently of the library (FNV-1a 64 over the
// content before it), so that a crafted checkpoint can carry a valid checksum.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>

namespace nystrom::test {

/// body followed by its checksum line.
inline std::string with_checksum(const std::string& body) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (unsigned char c : body) {
    h ^= c;
    h *= 0x100000001b3ULL;
  }
  char buf[64];
  std::snprintf(buf, sizeof buf, "checksum fnv1a64 %016llx\n", static_cast<unsigned long long>(h));
  return body + buf;
}

/// A checkpoint's text without its checksum line.
inline std::string body_of(const std::string& text) { return text.substr(0, text.rfind("checksum ")); }

}  // namespace nystrom::test
