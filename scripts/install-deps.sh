#!/usr/bin/env bash
# Installs the Debian 12 packages nystrom needs (as root; uses sudo if available otherwise).
# Does nothing when everything is already installed.
set -euo pipefail
packages=(g++ cmake make pkg-config libgtest-dev libbenchmark-dev libboost-dev libgmp-dev libmpfr-dev
          libqd-dev librandom123-dev libcli11-dev nlohmann-json3-dev libfmt-dev gnuplot-nox
          libfftw3-dev libfftw3-mpi-dev libopenmpi-dev openmpi-bin
          python3-dev pybind11-dev python3-numpy python3-pytest python3-scipy python3-matplotlib
          python3-distributed python3-mpi4py python3-pip python3-venv python3-setuptools python3-wheel
          clang-14 libfuzzer-14-dev clang-format-14)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} Debian packages present"
  exit 0
fi
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
