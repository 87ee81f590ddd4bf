#!/usr/bin/env bash
# Command 2 of the README (and what CI runs): install, build everything in Release with warnings as
# errors, run the whole test suite; then build and run it again under AddressSanitizer + UBSan.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
jobs=$(nproc 2>/dev/null || echo 2)
start=$(date +%s)

echo "== Release build and tests"
cmake --preset release -DNYSTROM_BUILD_TESTS=ON -DNYSTROM_BUILD_BENCH=ON -DCMAKE_CXX_FLAGS="-Werror" >/dev/null
cmake --build --preset release -j "$jobs"
ctest --preset release -j "$jobs"

echo "== AddressSanitizer + UndefinedBehaviorSanitizer build and tests"
if [ "${NYSTROM_ASAN_ALL:-0}" = 1 ]; then
  cmake --preset asan -DCMAKE_CXX_FLAGS="-Werror" -DNYSTROM_BUILD_TOOL=ON >/dev/null
else
  # The library's tests only: the command-line tool is the costliest thing to compile and its tests ran
  # in the Release stage. NYSTROM_ASAN_ALL=1 builds and runs everything under the sanitizers.
  cmake --preset asan -DCMAKE_CXX_FLAGS="-Werror" -DNYSTROM_BUILD_TOOL=OFF >/dev/null
fi
cmake --build --preset asan -j "$jobs"
ctest --preset asan -j "$jobs"

echo "== all tests passed in $(( $(date +%s) - start )) s"
