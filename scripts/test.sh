#!/usr/bin/env bash
# Installs, builds and runs every test (GoogleTest via CTest).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cd build && ctest --output-on-failure -j2 --timeout 1200
