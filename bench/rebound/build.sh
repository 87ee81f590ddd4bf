#!/bin/sh
# Builds bench/rebound/ias15_brouwer against a REBOUND source tree (https://github.com/hannorein/rebound, fetched by
# the user; never part of the build or of CI). Run from the repository root:
#   sh bench/rebound/build.sh REBOUND_SOURCE_DIR [OUTPUT (build/ias15_brouwer)]
set -eu
if [ $# -lt 1 ] || [ ! -f "$1/src/rebound.h" ]; then
  echo "usage: sh bench/rebound/build.sh REBOUND_SOURCE_DIR [OUTPUT]: the directory must hold src/rebound.h" >&2
  exit 2
fi
src=$(cd "$1" && pwd)/src
out=${2:-build/ias15_brouwer}
make -C "$src" librebound.so >/dev/null
mkdir -p "$(dirname "$out")"
g++ -std=gnu++20 -O2 -DNDEBUG -Iinclude -Ibench -I"$src" bench/rebound/ias15_brouwer.cpp -o "$out" \
  -L"$src" -lrebound -Wl,-rpath,"$src"
echo "built $out"
