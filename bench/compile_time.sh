#!/usr/bin/env bash
# Compile time and peak memory of a user's program (examples/pendulum_solve.cpp, g++ -O2, no ccache) on the two
# paths of solve(), in the same run: the compiled path (<nystrom/solve.hpp>, libnystrom) and the inline path (the
# same program calling solve_inline() with <nystrom/solve_inline.hpp>: the driver and engines compiled for its
# force). Prints wall time, CPU time and peak resident memory of each compilation, and their ratios.
# Usage: bash bench/compile_time.sh [REPEATS]   (from the repository root; default 1 repeat each)
set -euo pipefail
cd "$(dirname "$0")/.."
repeats=${1:-1}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cp examples/pendulum_solve.cpp "$work/compiled.cpp"
sed -e 's|#include <nystrom/solve.hpp>|#include <nystrom/solve_inline.hpp>|' -e 's|nystrom::solve(|nystrom::solve_inline(|' \
  examples/pendulum_solve.cpp >"$work/inline.cpp"
measure() {  # prints "wall cpu peak_MB" of the best (least CPU) of $repeats compilations
  local src=$1 best=""
  for _ in $(seq "$repeats"); do
    local line
    line=$(/usr/bin/time -f "%e %U %S %M" g++ -std=gnu++20 -O2 -Iinclude -c "$src" -o "$work/out.o" 2>&1 | tail -1)
    read -r wall user sys kb <<<"$line"
    local cpu
    cpu=$(awk -v u="$user" -v s="$sys" 'BEGIN { printf "%.2f", u + s }')
    if [ -z "$best" ] || awk -v a="$cpu" -v b="${best#* }" 'BEGIN { exit !(a < b) }'; then
      best="$wall $cpu $((kb / 1024))"
    fi
  done
  echo "$best"
}
read -r cw cc cm <<<"$(measure "$work/compiled.cpp")"
read -r iw ic im <<<"$(measure "$work/inline.cpp")"
printf '%-28s %8s %8s %8s\n' "examples/pendulum_solve.cpp" "wall s" "CPU s" "peak MB"
printf '%-28s %8s %8s %8s\n' "compiled path (solve.hpp)" "$cw" "$cc" "$cm"
printf '%-28s %8s %8s %8s\n' "inline path (solve_inline)" "$iw" "$ic" "$im"
awk -v a="$ic" -v b="$cc" -v c="$im" -v d="$cm" 'BEGIN { printf "inline / compiled: CPU %.1fx, memory %.1fx\n", a / b, c / d }'
