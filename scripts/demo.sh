#!/usr/bin/env bash
# Command 1 of the README: install, build in Release, and run the main job (`nystrom demo`).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
jobs=$(nproc 2>/dev/null || echo 2)
cmake --preset release -DNYSTROM_BUILD_TESTS=OFF -DNYSTROM_BUILD_BENCH=OFF >/dev/null
cmake --build --preset release -j "$jobs" --target nystrom_tool
./build/release/src/nystrom demo "$@"
