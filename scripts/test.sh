#!/usr/bin/env bash
# Command 2 of the README (and what CI runs): install the dependencies; check the formatting and the layers of the
# headers (scripts/check-layers.sh); build everything in Release with warnings as errors (the tool, benchmarks,
# examples, Python module and every test) and run the whole suite there (library, tool and Python tests, install
# check); build the tool and every test again under AddressSanitizer + UBSan (leak detection on) and run the whole
# C++ suite and the install check there; build the libFuzzer harnesses and run each for a fixed time.
# NYSTROM_FUZZ_SECONDS: seconds per fuzzer (default 20).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
jobs=$(nproc 2>/dev/null || echo 2)
start=$(date +%s)

echo "== Formatting (clang-format-14, .clang-format)"
bash scripts/check-format.sh
echo "== Layers (inclusions point one way, docs/architecture.md)"
bash scripts/check-layers.sh

echo "== Release build (warnings as errors) and the whole suite at the shipped optimisation level"
# Debian's python3 (numpy, pybind11): a python3 earlier on PATH may lack them.
cmake --preset release -DNYSTROM_BUILD_TESTS=ON -DNYSTROM_BUILD_BENCH=ON -DNYSTROM_TEST_SCOPE=all \
  -DNYSTROM_BUILD_PYTHON=ON -DPython3_EXECUTABLE=/usr/bin/python3 -DCMAKE_CXX_FLAGS="-Werror" >/dev/null
cmake --build --preset release -j "$jobs"
ctest --preset release -j "$jobs"
echo "   ($(( $(date +%s) - start )) s so far)"

echo "== AddressSanitizer + UndefinedBehaviorSanitizer build: the tool and the whole C++ suite again"
cmake --preset asan -DCMAKE_CXX_FLAGS="-Werror" -DNYSTROM_BUILD_TOOL=ON -DNYSTROM_TEST_SCOPE=all >/dev/null
cmake --build --preset asan -j "$jobs"
ctest --preset asan -j "$jobs"
echo "   ($(( $(date +%s) - start )) s so far)"

echo "== libFuzzer harnesses (clang-14, ASan + UBSan), ${NYSTROM_FUZZ_SECONDS:-20} s each"
NYSTROM_FUZZ_SECONDS=${NYSTROM_FUZZ_SECONDS:-20} NYSTROM_FUZZ_HARNESSES="method_spec method_file particles cli" \
  bash scripts/fuzz.sh

echo "== all tests passed in $(( $(date +%s) - start )) s"
