# Installs the built project into a scratch prefix, then configures, builds and runs examples/ against it
# with find_package(nystrom CONFIG), as a downstream project would. DOWNSTREAM_FLAGS (may be empty): compiler and
# linker flags of the downstream build (the sanitizers, when the project itself is built with them).
file(REMOVE_RECURSE ${WORK_DIR})
execute_process(COMMAND ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${WORK_DIR}/prefix
                RESULT_VARIABLE rc OUTPUT_QUIET)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "install failed")
endif()
if(NOT EXISTS ${WORK_DIR}/prefix/include/nystrom/nystrom.hpp)
  message(FATAL_ERROR "headers were not installed")
endif()
# With DOWNSTREAM_FLAGS the build type is left empty, so that its optimisation flags do not override them.
set(build_type Release)
if(DOWNSTREAM_FLAGS)
  set(build_type "")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -S ${SOURCE_DIR}/examples -B ${WORK_DIR}/build
                        -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix -DCMAKE_BUILD_TYPE=${build_type} -DCMAKE_CXX_COMPILER=${CXX}
                        "-DCMAKE_CXX_FLAGS=${DOWNSTREAM_FLAGS}" "-DCMAKE_EXE_LINKER_FLAGS=${DOWNSTREAM_FLAGS}"
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "configuring the examples against the installed package failed")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build ${WORK_DIR}/build RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "building the examples against the installed package failed")
endif()
execute_process(COMMAND ${WORK_DIR}/build/kepler_orders RESULT_VARIABLE rc OUTPUT_VARIABLE out)
if(NOT rc EQUAL 0 OR NOT out MATCHES "M16")
  message(FATAL_ERROR "the example kepler_orders failed: ${out}")
endif()
execute_process(COMMAND ${WORK_DIR}/build/pendulum_solve RESULT_VARIABLE rc OUTPUT_VARIABLE out2)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the example pendulum_solve failed: ${out2}")
endif()
# The one-line build of the README: a program that uses solve() in double needs the headers and libnystrom only.
separate_arguments(flags UNIX_COMMAND "${DOWNSTREAM_FLAGS}")
if(NOT DOWNSTREAM_FLAGS)
  set(flags -O2)
endif()
execute_process(COMMAND ${CXX} -std=c++20 ${flags} -I${WORK_DIR}/prefix/include ${SOURCE_DIR}/examples/pendulum_solve.cpp
                        -o ${WORK_DIR}/pendulum_one_line -L${WORK_DIR}/prefix/lib -Wl,-rpath,${WORK_DIR}/prefix/lib
                        -lnystrom
                RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the one-line build of examples/pendulum_solve.cpp failed: ${err}")
endif()
execute_process(COMMAND ${WORK_DIR}/pendulum_one_line RESULT_VARIABLE rc OUTPUT_VARIABLE out3)
if(NOT rc EQUAL 0 OR NOT out3 STREQUAL out2)
  message(FATAL_ERROR "the one-line build of pendulum_solve runs differently: ${out3}")
endif()
message(STATUS "installed package works:\n${out}${out2}")
