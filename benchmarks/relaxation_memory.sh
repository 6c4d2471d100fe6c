#!/usr/bin/env bash
# Peak resident memory of single moment relaxations (GNU time's %M), the measurements behind the memory model
# of pop/relaxation_size.hpp (tests/relaxation_size_test.cpp holds the figures minus the order-1 process).
# Usage: benchmarks/relaxation_memory.sh [build-dir]   (about 15 minutes; needs /usr/bin/time)
set -euo pipefail
BUILD=${1:-build}
DIR=$(mktemp -d)
trap 'rm -rf "$DIR"' EXIT
echo '{"variables":["x1"],"minimize":"x1^2 - x1","constraints":["x1 >= -1","x1 <= 1"]}' > "$DIR/p1.json"
echo '{"variables":["x1","x2"],"minimize":"x1^2 + x2 - x1*x2","constraints":["x1^2 + x2^2 <= 1"]}' > "$DIR/p2.json"
echo '{"variables":["x1","x2","x3"],"minimize":"x1^2 + x2*x3 - x1","constraints":["x1^2 + x2^2 + x3^2 <= 1"]}' > "$DIR/p3.json"
for solver in csdp sdpa dsdp; do
  for case in "p3 1" "p1 200" "p2 20" "p3 8"; do
    set -- $case
    /usr/bin/time -f "$1 order $2 $solver: peak %M KiB, %e s" "$BUILD/cli/hwbounds" pop "$DIR/$1.json" --order "$2" \
      --solver "$solver" 2>&1 >/dev/null | grep peak
  done
done
/usr/bin/time -f "p2 order 30 csdp: peak %M KiB, %e s" "$BUILD/cli/hwbounds" pop "$DIR/p2.json" --order 30 --solver csdp \
  2>&1 >/dev/null | grep peak
