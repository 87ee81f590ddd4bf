# Precompiled third-party headers for the programs of this build (not for installed users).
#
# Parsing the standard library, Boost.Multiprecision (MPFR, float128), GMP, libqd and the tool's or the
# tests' own libraries (CLI11, nlohmann-json, fmt; GoogleTest) takes about half of the compile time of a
# typical file here (13 of 26 s for src/cmd_methods.cpp, measured with -ftime-report); the tool has 25
# files and there are 20+ test programs. nystrom_precompile(TARGET GROUP [HEADERS...]) gives TARGET one
# precompiled header per GROUP: the first target of a group builds it, the others reuse it (they share
# compile flags). Only system and third-party headers are precompiled, never nystrom's own, so the
# warnings of our headers are reported as usual. NYSTROM_PCH=OFF compiles without.
include_guard(GLOBAL)

set(NYSTROM_PCH_COMMON
  <algorithm> <array> <cmath> <complex> <cstdint> <functional> <iostream> <limits> <map> <memory> <mutex>
  <optional> <sstream> <stdexcept> <string> <utility> <variant> <vector>
  <gmpxx.h> <mpfr.h> <qd/dd_real.h> <qd/qd_real.h>
  <boost/multiprecision/mpfr.hpp> <boost/multiprecision/float128.hpp>)

function(nystrom_precompile target group)
  if(NOT NYSTROM_PCH)
    return()
  endif()
  get_property(owner GLOBAL PROPERTY NYSTROM_PCH_OWNER_${group})
  if(owner)
    target_precompile_headers(${target} REUSE_FROM ${owner})
  else()
    target_precompile_headers(${target} PRIVATE ${NYSTROM_PCH_COMMON} ${ARGN})
    set_property(GLOBAL PROPERTY NYSTROM_PCH_OWNER_${group} ${target})
  endif()
endfunction()
