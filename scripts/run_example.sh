#!/usr/bin/env bash
# Installs, builds, and runs the main job on the bundled example: guaranteed bounds of the paper-001
# Hammerstein–Wiener example from a recording (paper_examples/data/cerone2011_N300.csv).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
mkdir -p out
./build/cli/hwbounds bounds --data paper_examples/data/cerone2011_N300.csv --noise-col noise_bound \
  --na 2 --nb 2 --input-basis poly:3 --output-basis poly:3 --horizon 2 --order 2 \
  --truth 0.4,-0.1,0.8,3.2,1.8,0.9,1.6,2.1 --json out/example_bounds.json --plot out/example_bounds.png \
  --set exact --run-dir runs/example
