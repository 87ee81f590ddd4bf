# Dependencies of the header-only library, all from Debian's archive:
#   Boost (Multiprecision), GMP + gmpxx (exact MPE coefficients), MPFR (reference precision),
#   libquadmath (float128), libqd (double-double, quad-double), Random123 (counter-based random numbers of
#   the Langevin paths, header-only).
include_guard(GLOBAL)
find_package(Boost 1.74 REQUIRED)
find_path(GMPXX_INCLUDE_DIR gmpxx.h REQUIRED)
find_library(GMPXX_LIBRARY gmpxx REQUIRED)
find_library(GMP_LIBRARY gmp REQUIRED)
find_path(MPFR_INCLUDE_DIR mpfr.h REQUIRED)
find_library(MPFR_LIBRARY mpfr REQUIRED)
find_path(QD_INCLUDE_DIR qd/dd_real.h REQUIRED)
find_library(QD_LIBRARY qd REQUIRED)
find_path(RANDOM123_INCLUDE_DIR Random123/philox.h REQUIRED)
if(NOT TARGET nystrom_deps)
  add_library(nystrom_deps INTERFACE)
  target_include_directories(nystrom_deps INTERFACE ${GMPXX_INCLUDE_DIR} ${MPFR_INCLUDE_DIR} ${QD_INCLUDE_DIR}
                                                    ${RANDOM123_INCLUDE_DIR})
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

# MPI for grids distributed over ranks (include/nystrom/quantum/fftw_mpi.hpp, `mpirun -np N nystrom quantum`):
# FFTW's MPI transforms (fftw3_mpi, fftw3l_mpi) and MPI's C interface. NYSTROM_MPI defaults to ON when both are
# found; without it the tool runs on one process. Library users who do not include fftw_mpi.hpp never need MPI.
if(TARGET nystrom_fftw AND NOT TARGET nystrom_fftw_mpi)
  set(MPI_CXX_SKIP_MPICXX ON)
  find_package(MPI COMPONENTS CXX QUIET)
  find_library(FFTW3_MPI_LIBRARY fftw3_mpi)
  find_library(FFTW3L_MPI_LIBRARY fftw3l_mpi)
  set(nystrom_mpi_found OFF)
  if(MPI_CXX_FOUND AND FFTW3_MPI_LIBRARY AND FFTW3L_MPI_LIBRARY)
    set(nystrom_mpi_found ON)
  endif()
  option(NYSTROM_MPI "Distributed grids for the quantum solver (MPI + FFTW's MPI transforms)" ${nystrom_mpi_found})
  if(NYSTROM_MPI)
    if(NOT nystrom_mpi_found)
      message(FATAL_ERROR "NYSTROM_MPI needs MPI and fftw3_mpi, fftw3l_mpi (libopenmpi-dev, libfftw3-mpi-dev)")
    endif()
    add_library(nystrom_fftw_mpi INTERFACE)
    add_library(nystrom::fftw_mpi ALIAS nystrom_fftw_mpi)
    target_compile_definitions(nystrom_fftw_mpi INTERFACE NYSTROM_HAVE_MPI)
    target_link_libraries(nystrom_fftw_mpi INTERFACE ${FFTW3_MPI_LIBRARY} ${FFTW3L_MPI_LIBRARY} nystrom_fftw
                                                     MPI::MPI_CXX)
  endif()
endif()
