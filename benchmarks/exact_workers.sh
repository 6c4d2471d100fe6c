#!/usr/bin/env bash
# The exact set's stage 2 on the bundled example (N = 300) with 1 and 2 fork workers and with `mpirun -np 3`
# (one coordinator, two worker ranks): the intervals must be identical to the last digit; prints each stage-2
# wall time and the 1 -> 2 worker speed-up. Stage 1 (D^ss(2)) runs once and is read back from a shared run
# directory by every configuration, so only stage 2 is timed. Run it on an idle machine (about 10 minutes on 2
# cores).
#   benchmarks/exact_workers.sh            (BUILD=build by default; CONFIGS="fork1 fork2 mpi3" by default)
set -euo pipefail
BUILD=${BUILD:-build}
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT INT TERM
ARGS=(bounds --data paper_examples/data/cerone2011_N300.csv --noise-col noise_bound --na 2 --nb 2
      --input-basis poly:3 --output-basis poly:3 --horizon 2 --order 2 --quiet)
"$BUILD/cli/hwbounds" "${ARGS[@]}" --run-dir "$WORK/stage1" >/dev/null
ARGS+=(--set exact)
declare -A WALL
for config in ${CONFIGS:-fork1 fork2 mpi3}; do
  cp -r "$WORK/stage1" "$WORK/$config"
  case $config in
    fork1) "$BUILD/cli/hwbounds" "${ARGS[@]}" --threads 1 --run-dir "$WORK/$config" --json "$WORK/$config.json" >/dev/null ;;
    fork2) "$BUILD/cli/hwbounds" "${ARGS[@]}" --threads 2 --run-dir "$WORK/$config" --json "$WORK/$config.json" >/dev/null ;;
    mpi3) mpirun --allow-run-as-root --oversubscribe -np 3 "$BUILD/cli/hwbounds" "${ARGS[@]}" --executor mpi \
            --run-dir "$WORK/$config" --json "$WORK/$config.json" >/dev/null ;;
    *) echo "unknown configuration $config (fork1, fork2, mpi3)" >&2; exit 2 ;;
  esac
  WALL[$config]=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['stage2']['wall_seconds'])" "$WORK/$config.json")
  echo "$config: stage 2 wall ${WALL[$config]} s"
done
python3 - "$WORK" ${CONFIGS:-fork1 fork2 mpi3} <<'PY'
import json, sys
work, configs = sys.argv[1], sys.argv[2:]
ends = {c: [(iv["lower"]["value"], iv["upper"]["value"]) for iv in json.load(open(f"{work}/{c}.json"))["intervals"]]
        for c in configs}
first = configs[0]
for c in configs[1:]:
    print(f"{c} intervals identical to {first}: {ends[c] == ends[first]}")
if not all(ends[c] == ends[first] for c in configs):
    sys.exit(1)
PY
if [ -n "${WALL[fork1]:-}" ] && [ -n "${WALL[fork2]:-}" ]; then
  python3 -c "import sys; print(f'speed-up 1 -> 2 workers: {float(sys.argv[1]) / float(sys.argv[2]):.2f}')" "${WALL[fork1]}" "${WALL[fork2]}"
fi
