// Reading the files that the code under test writes.
#pragma once

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace nystrom::test {

/// The whole content of the file `p` (empty when it cannot be read).
inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace nystrom::test
