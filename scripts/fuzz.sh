#!/usr/bin/env bash
# Builds the libFuzzer harnesses of fuzz/ with clang-14 (ASan + UBSan) and runs each for a fixed time,
# starting from the seed corpus in fuzz/corpus/<harness>/. Fails on any crash, leak, UB report, timeout or
# out-of-memory. Environment: NYSTROM_FUZZ_SECONDS (per harness, default 30), NYSTROM_FUZZ_HARNESSES (default
# all five), NYSTROM_FUZZ_JOBS (build jobs, and harnesses run at once, each on its own core; default nproc),
# NYSTROM_FUZZ_BUILD (a build folder configured with
# NYSTROM_BUILD_FUZZERS=ON, e.g. by the asan-fuzz preset, to build and run the harnesses there; default: build/fuzz,
# configured here). New inputs found go to build/fuzz/corpus/<harness>/,
# never into the repository's seed corpus. docs/fuzzing.md: how to run longer and how to keep a finding.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${NYSTROM_FUZZ_SECONDS:-30}
harnesses=${NYSTROM_FUZZ_HARNESSES:-"method_spec method_file particles checkpoint cli"}
jobs=${NYSTROM_FUZZ_JOBS:-$(nproc 2>/dev/null || echo 2)}
build=${NYSTROM_FUZZ_BUILD:-build/fuzz}
san="-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"

if [ -z "${NYSTROM_FUZZ_BUILD:-}" ]; then
  # Ninja and ccache when present (a folder configured before keeps its generator).
  extra=()
  if [ ! -f "$build/CMakeCache.txt" ] && command -v ninja >/dev/null; then extra+=(-G Ninja); fi
  if command -v ccache >/dev/null; then extra+=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
  CXX=clang++-14 cmake -S . -B "$build" "${extra[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g" -DCMAKE_CXX_FLAGS="$san -Werror" -DNYSTROM_BUILD_FUZZERS=ON \
    -DNYSTROM_BUILD_TOOL=ON -DNYSTROM_BUILD_TESTS=OFF -DNYSTROM_BUILD_BENCH=OFF -DNYSTROM_BUILD_EXAMPLES=OFF \
    -DNYSTROM_PCH=OFF >/dev/null
fi
targets=()
for h in $harnesses; do targets+=("fuzz_$h"); done
cmake --build "$build" -j "$jobs" --target "${targets[@]}"

export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$PWD/tests/lsan.supp}
# Absolute paths: a harness may change its working folder (fuzz_cli runs in a private temporary one).
root=$PWD
# One harness: libFuzzer's log in $build/fuzz_<h>.log, its exit status in $build/fuzz_<h>.status.
fuzz_one() {
  local h=$1 corpus="$root/$build/corpus/$1" rc=0
  mkdir -p "$corpus" "$build/findings/$h"
  # -timeout: one input running longer than 10 s is a finding (a hang); -rss_limit_mb: so is 2 GB of memory.
  "$build/fuzz/fuzz_$h" "$corpus" "$root/fuzz/corpus/$h" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
    -max_len=4096 -print_final_stats=1 -artifact_prefix="$root/$build/findings/$h/" >"$build/fuzz_$h.log" 2>&1 || rc=$?
  echo "$rc" >"$build/fuzz_$h.status"
}
# The harnesses run $jobs at a time, each one process on one core for the full time; they report in order.
running=0
for h in $harnesses; do
  echo "== fuzz_$h for ${seconds} s"
  rm -f "$build/fuzz_$h.status"
  fuzz_one "$h" &
  running=$((running + 1))
  if [ "$running" -ge "$jobs" ]; then
    wait -n || true
    running=$((running - 1))
  fi
done
wait
status=0
for h in $harnesses; do
  log="$build/fuzz_$h.log"
  if [ "$(cat "$build/fuzz_$h.status" 2>/dev/null)" = 0 ]; then
    # libFuzzer's last status line: "#N DONE cov: C ft: F corp: ... exec/s: E"
    echo "== fuzz_$h"
    grep -E '^#[0-9]+.*(DONE|pulse)' "$log" | tail -1 | sed 's/^/   /'
    grep -E '^stat::number_of_executed_units|^stat::average_exec_per_sec' "$log" | sed 's/^/   /'
  else
    status=1
    echo "== fuzz_$h FAILED: it found a problem (input saved in $build/findings/$h/); last lines of $log:"
    tail -30 "$log" | sed 's/^/   /'
  fi
done
exit $status
