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
  target_link_libraries(nystrom_deps INTERFACE Boost::headers ${QD_LIBRARY} ${MPFR_LIBRARY} ${GMPXX_LIBRARY}
                                                ${GMP_LIBRARY} quadmath)
endif()

# FFTW for the quantum layer (include/nystrom/quantum): fftw3 (double) and fftw3l (long double), with
# threaded plans when fftw3_threads is found. Optional: without it the quantum tool, tests and benchmark
# are not built.
find_path(FFTW3_INCLUDE_DIR fftw3.h)
find_library(FFTW3_LIBRARY fftw3)
find_library(FFTW3L_LIBRARY fftw3l)
find_library(FFTW3_THREADS_LIBRARY fftw3_threads)
find_library(FFTW3L_THREADS_LIBRARY fftw3l_threads)
if(FFTW3_INCLUDE_DIR AND FFTW3_LIBRARY AND FFTW3L_LIBRARY AND NOT TARGET nystrom_fftw)
  add_library(nystrom_fftw INTERFACE)
  add_library(nystrom::fftw ALIAS nystrom_fftw)
  target_include_directories(nystrom_fftw INTERFACE ${FFTW3_INCLUDE_DIR})
  if(FFTW3_THREADS_LIBRARY AND FFTW3L_THREADS_LIBRARY)
    target_compile_definitions(nystrom_fftw INTERFACE NYSTROM_HAVE_FFTW_THREADS)
    target_link_libraries(nystrom_fftw INTERFACE ${FFTW3_THREADS_LIBRARY} ${FFTW3L_THREADS_LIBRARY})
  endif()
  target_link_libraries(nystrom_fftw INTERFACE ${FFTW3_LIBRARY} ${FFTW3L_LIBRARY})
  set(NYSTROM_HAVE_FFTW ON)
endif()
