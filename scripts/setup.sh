#!/usr/bin/env bash
# Installs the Debian packages hwbounds needs and builds it (Release) into build/.
set -euo pipefail
cd "$(dirname "$0")/.."
PACKAGES=(cmake g++ make libeigen3-dev libsdp-dev coinor-csdp libsdpa-dev sdpa libdsdp-dev libsuitesparse-dev libcli11-dev
          nlohmann-json3-dev libfmt-dev gnuplot-nox libgtest-dev libbenchmark-dev libopenmpi-dev openmpi-bin
          coinor-libipopt-dev coinor-libclp-dev libglpk-dev libcgal-dev libgmp-dev libmpfr-dev libtbb-dev pkg-config libmatio-dev libhdf5-dev
          pybind11-dev python3-dev python3-numpy python3-pytest python3-scipy python3-h5py python3-matplotlib)
missing=()
for p in "${PACKAGES[@]}"; do dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p"); done
if [ ${#missing[@]} -gt 0 ]; then
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${missing[@]}"
fi
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
# The build's lines go to build/build.log (hundreds of them); on a failure its end is shown.
echo "building hwbounds (log: build/build.log) ..."
if ! cmake --build build -j"$(nproc)" > build/build.log 2>&1; then
  tail -n 40 build/build.log
  echo "the build failed: build/build.log has its whole output" >&2
  exit 1
fi
