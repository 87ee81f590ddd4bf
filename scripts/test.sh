#!/usr/bin/env bash
# Command 2 of the README (and what CI runs): install the dependencies; check the formatting and the layers of the
# headers (scripts/check-layers.sh); build the tool, examples and Python module in Release with warnings
# as errors and run the tests that need the optimised build there (the tool's tests, the Python tests, the install
# check); build the tool, every C++ test, the benchmarks (compiled and linked, not run) and the libFuzzer harnesses
# with clang-14 under AddressSanitizer + UBSan (leak detection on), run the whole C++ suite there (the library's test programs are built only there) and each
# harness for a fixed time; a small fixed sample of mechanically generated mutants (scripts/mutants.py).
# NYSTROM_FUZZ_SECONDS: seconds per fuzzer (default 12).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
jobs=$(nproc 2>/dev/null || echo 2)
start=$(date +%s)

echo "== Formatting (clang-format-14, .clang-format)"
bash scripts/check-format.sh
echo "== Layers (inclusions point one way, docs/architecture.md)"
bash scripts/check-layers.sh

echo "== Release build (warnings as errors): the tool's, Python and install tests at the shipped optimisation level"
# Debian's python3 (numpy, pybind11): a python3 earlier on PATH may lack them.
# test_discover and test_splitting_law, library test programs, are built here too: test_discover's two method
# searches take 1-2 s each in Release and 30-90 s each under the sanitizers at -O0 (its other tests, which reach the
# same search code, run there as well); likewise test_splitting_law's double-well orders (4-5 s in Release).
cmake --preset release -DNYSTROM_BUILD_TESTS=ON -DNYSTROM_BUILD_BENCH=OFF -DNYSTROM_TEST_SCOPE=cli \
  "-DNYSTROM_TEST_EXTRA=test_discover;test_splitting_law" -DNYSTROM_BUILD_PYTHON=ON -DPython3_EXECUTABLE=/usr/bin/python3 \
  -DCMAKE_CXX_FLAGS="-Werror" >/dev/null
cmake --build --preset release -j "$jobs"
ctest --preset release -j "$jobs"
echo "   ($(( $(date +%s) - start )) s so far)"

echo "== AddressSanitizer + UndefinedBehaviorSanitizer build (clang-14): the tool, the whole C++ suite, the benchmarks, the fuzzers"
# One compilation serves the tests and the libFuzzer harnesses (fuzz_cli links the tool's own objects). The
# benchmarks are compiled here (at -O0, where they cost a third of g++'s -O3) to check that they build without
# warnings; they are measured from an optimised build (docs/performance.md), never in CI.
cmake --preset asan-fuzz -DNYSTROM_BUILD_BENCH=ON -DCMAKE_CXX_FLAGS="-Werror" >/dev/null
cmake --build --preset asan-fuzz -j "$jobs"
# Left to the Release stage, where they also run: test_bench_peers (timed benchmark runs), the round-off floors
# of the adaptive engines (the rounding of GCC's -O3 build is the one they assert, and at -O0 they take minutes),
# the quick reproduction of both papers (5 s in Release, about 290 s at -O0 under the sanitizers), and the
# tool's method search and Langevin contract runs (about 1 s each in Release, 14-47 s each here: numerical work
# whose tool code the other command-line tests and fuzz_cli cover under the sanitizers), test_discover's two
# searches (above), and the double-well runs of the Langevin scheme's law on a phase-space grid (2-5 s each in
# Release, minutes here; its harmonic and refusal tests run here).
ctest --preset asan-fuzz -j "$jobs" \
  -E '^(test_bench_peers|AdaptiveFloorCli\..*|Reproduce\.AllQuick.*|BchCli\.SixStageFromPublishedMethod|BchCli\.DiscoverWritesMethodsThatRun|LangevinCli\.ContractJsonAgreesWithTheBoltzmannDensityForAnyThreadCount|Discover\.SmallSeededSearchFindsAR1AndAC1|Discover\.SixStageSearchFromAC1ReachesThePublishedLevel|SplittingLaw\.DoubleWellWeakOrdersTwoFourAndSix|LangevinCli\.StationaryLawIsExactWithoutPaths)$'
echo "   ($(( $(date +%s) - start )) s so far)"

echo "== Mutation sample: 3 mechanically generated mutants (scripts/mutants.py, seed 35), about 3 minutes"
# A fixed sample of the operator and planetary layers, whose test programs link no compiled solve() (the
# scratch library is the catalog alone): each mutant is rebuilt at -O0 in build/mutants-ci and its layer's
# programs run whole. Fails when a mutant that compiles survives and is not listed as equivalent in the script;
# no mutant is started after 170 s.
python3 scripts/mutants.py --seed 35 --count 3 --layers operators,planetary --lib-solve none --max-seconds 170 \
  --build build/mutants-ci --jobs "$jobs"
echo "   ($(( $(date +%s) - start )) s so far)"

echo "== libFuzzer harnesses (ASan + UBSan), ${NYSTROM_FUZZ_SECONDS:-12} s each"
NYSTROM_FUZZ_BUILD=build/asan-fuzz NYSTROM_FUZZ_SECONDS=${NYSTROM_FUZZ_SECONDS:-12} \
  NYSTROM_FUZZ_HARNESSES="method_spec method_file particles checkpoint cli" bash scripts/fuzz.sh

echo "== all tests passed in $(( $(date +%s) - start )) s"
