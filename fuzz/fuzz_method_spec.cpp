// libFuzzer harness: method specifications (resolve_method), e.g. "M8", "mpe:1,2,4", "adjoint:adjoint:FR".
// A malformed specification must end in std::invalid_argument; any other exception, a crash, a leak, undefined
// behaviour or a slow input is a finding. Specifications that read files (file:PATH) are skipped.
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "nystrom/analysis/method_file.hpp"
#include "nystrom/core/error.hpp"
#include "nystrom/methods/catalog.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 4096) return 0;
  const std::string spec(reinterpret_cast<const char*>(data), size);
  if (spec.find("file:") != std::string::npos || spec.find("FILE:") != std::string::npos) return 0;
  std::string lower;
  for (char c : spec) lower += static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
  if (lower.find("file:") != std::string::npos) return 0;
  try {
    const nystrom::MethodDef d = nystrom::resolve_method(spec);
    if (d.info.name.empty() || d.info.order <= 0) __builtin_trap();  // a resolved method is complete
  } catch (const nystrom::invalid_input&) {                          // the one refusal of the catalog
  }
  return 0;
}
