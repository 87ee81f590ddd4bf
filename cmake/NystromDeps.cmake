# Dependencies of the header-only library, all from Debian's archive:
#   Boost (Multiprecision), GMP + gmpxx (exact MPE coefficients), MPFR (reference precision),
#   libquadmath (float128), libqd (double-double, quad-double).
include_guard(GLOBAL)
find_package(Boost 1.74 REQUIRED)
find_path(GMPXX_INCLUDE_DIR gmpxx.h REQUIRED)
find_library(GMPXX_LIBRARY gmpxx REQUIRED)
find_library(GMP_LIBRARY gmp REQUIRED)
find_path(MPFR_INCLUDE_DIR mpfr.h REQUIRED)
find_library(MPFR_LIBRARY mpfr REQUIRED)
find_path(QD_INCLUDE_DIR qd/dd_real.h REQUIRED)
find_library(QD_LIBRARY qd REQUIRED)
if(NOT TARGET nystrom_deps)
  add_library(nystrom_deps INTERFACE)
  target_include_directories(nystrom_deps INTERFACE ${GMPXX_INCLUDE_DIR} ${MPFR_INCLUDE_DIR} ${QD_INCLUDE_DIR})
  # libquadmath ships with GCC (not in the default library path): link it by name.
  target_link_libraries(nystrom_deps INTERFACE Boost::headers ${QD_LIBRARY} ${MPFR_LIBRARY} ${GMPXX_LIBRARY} ${GMP_LIBRARY} quadmath)
endif()
