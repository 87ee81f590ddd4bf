#!/usr/bin/env bash
# Command 2 of the README (and what CI runs): install the dependencies; build the tool, benchmarks and
# examples in Release with warnings as errors and run the tests of the tool; build the library's tests
# under AddressSanitizer + UBSan and run them. NYSTROM_ASAN_ALL=1: the whole suite in both builds.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
jobs=$(nproc 2>/dev/null || echo 2)
start=$(date +%s)

if [ "${NYSTROM_ASAN_ALL:-0}" = 1 ]; then
  # Everything twice: the whole suite in Release, then again under the sanitizers.
  release_scope=all asan_tool=ON
else
  # Every test runs once. The library's tests are built and run under the sanitizers (below); the
  # Release build is the product (the tool, benchmarks, examples), checked by the tests that run the
  # tool and by the install check. Building the library tests twice doubled CI's time.
  release_scope=cli asan_tool=OFF
fi

echo "== Release build (tool, benchmarks, examples; warnings as errors) and the command-line tests"
cmake --preset release -DNYSTROM_BUILD_TESTS=ON -DNYSTROM_BUILD_BENCH=ON -DNYSTROM_TEST_SCOPE=$release_scope \
  -DCMAKE_CXX_FLAGS="-Werror" >/dev/null
cmake --build --preset release -j "$jobs"
ctest --preset release -j "$jobs"
echo "   ($(( $(date +%s) - start )) s so far)"

echo "== AddressSanitizer + UndefinedBehaviorSanitizer build and the library's tests"
# NYSTROM_BUILD_TOOL=OFF: the tool and the tests that run it were built and run in the Release stage.
cmake --preset asan -DCMAKE_CXX_FLAGS="-Werror" -DNYSTROM_BUILD_TOOL=$asan_tool -DNYSTROM_TEST_SCOPE=all >/dev/null
cmake --build --preset asan -j "$jobs"
ctest --preset asan -j "$jobs"

echo "== all tests passed in $(( $(date +%s) - start )) s"
