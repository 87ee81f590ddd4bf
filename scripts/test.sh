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
cmake --preset asan -DCMAKE_CXX_FLAGS="-Werror" >/dev/null
if [ "${NYSTROM_ASAN_ALL:-0}" = 1 ]; then
  cmake --build --preset asan -j "$jobs"
  ctest --preset asan -j "$jobs"
else
  # The library's tests (every test that does not run the command-line tool): the tool is the costliest
  # thing to compile and its tests ran in the Release stage. NYSTROM_ASAN_ALL=1 builds and runs everything.
  targets=()
  for f in tests/test_*.cpp; do
    grep -q NYSTROM_BIN "$f" || targets+=("$(basename "$f" .cpp)")
  done
  cmake --build --preset asan -j "$jobs" --target "${targets[@]}"
  ctest --preset asan -j "$jobs" -E '_NOT_BUILT$'
fi

echo "== all tests passed in $(( $(date +%s) - start )) s"
