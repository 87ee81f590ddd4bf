#!/usr/bin/env bash
# Command 2 of the README (and what CI runs): install the dependencies; check the formatting; build the tool,
# benchmarks, examples and the Python module in Release with warnings as errors and run the tests of the tool,
# the install check and the Python tests; build the library's tests under AddressSanitizer + UBSan (leak
# detection on) and run them; build the libFuzzer harnesses and run each for a fixed time.
# NYSTROM_ASAN_ALL=1: the whole suite in both builds. NYSTROM_FUZZ_SECONDS: seconds per fuzzer (default 20).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
jobs=$(nproc 2>/dev/null || echo 2)
start=$(date +%s)

echo "== Formatting (clang-format-14, .clang-format)"
bash scripts/check-format.sh

if [ "${NYSTROM_ASAN_ALL:-0}" = 1 ]; then
  # Everything twice: the whole suite in Release, then again under the sanitizers.
  release_scope=all asan_tool=ON
else
  # Every test runs once. The library's tests are built and run under the sanitizers (below); the
  # Release build is the product (the tool, benchmarks, examples, Python module), checked by the tests
  # that run the tool, the Python tests and the install check.
  release_scope=cli asan_tool=OFF
fi

echo "== Release build (tool, benchmarks, examples, Python module; warnings as errors) and the tool's tests"
# Debian's python3 (numpy, pybind11): a python3 earlier on PATH may lack them.
cmake --preset release -DNYSTROM_BUILD_TESTS=ON -DNYSTROM_BUILD_BENCH=ON -DNYSTROM_TEST_SCOPE=$release_scope \
  -DNYSTROM_BUILD_PYTHON=ON -DPython3_EXECUTABLE=/usr/bin/python3 -DCMAKE_CXX_FLAGS="-Werror" >/dev/null
cmake --build --preset release -j "$jobs"
ctest --preset release -j "$jobs"
echo "   ($(( $(date +%s) - start )) s so far)"

echo "== AddressSanitizer + UndefinedBehaviorSanitizer build and the library's tests"
# NYSTROM_BUILD_TOOL=OFF: the tool and the tests that run it were built and run in the Release stage.
cmake --preset asan -DCMAKE_CXX_FLAGS="-Werror" -DNYSTROM_BUILD_TOOL=$asan_tool -DNYSTROM_TEST_SCOPE=all >/dev/null
cmake --build --preset asan -j "$jobs"
ctest --preset asan -j "$jobs"
echo "   ($(( $(date +%s) - start )) s so far)"

echo "== libFuzzer harnesses (clang-14, ASan + UBSan), ${NYSTROM_FUZZ_SECONDS:-20} s each"
NYSTROM_FUZZ_SECONDS=${NYSTROM_FUZZ_SECONDS:-20} NYSTROM_FUZZ_HARNESSES="method_spec method_file particles" \
  bash scripts/fuzz.sh

echo "== all tests passed in $(( $(date +%s) - start )) s"
