#!/usr/bin/env bash
# 1 against 2 workers on order-delta jobs of a finished paper_examples/cerone_tables case. Copies the case's run
# cache twice, forgets in each copy the order-delta relaxation jobs of the named parameters, and runs them again
# with 1 and with 2 workers (every other job, the order-2 pass included, is read back from the cache, so the
# wall time of the order-delta pass is the forgotten jobs' alone). Prints the two wall times and their ratio.
#
# Usage: benchmarks/workers_speedup.sh RUN_DIR "a1 a2" ORDER -- CERONE_TABLES_OPTIONS...
#   RUN_DIR: the --run-dir of the finished case; the options must be that case's (same horizon, SNR, seed, N,
#   --row-block-order), one horizon and one SNR. Example (about 15 minutes on 2 cores):
#   benchmarks/workers_speedup.sh runs/cerone_45 "a1 a2" 3 -- --horizons 2 --orders 2,3 --snr-list 45 --seeds 1 \
#       --samples 1000 --row-block-order 1
# WORKERS="2" runs one of the two configurations only (then no ratio is printed). Run it on an idle machine.
set -euo pipefail
RUN_DIR=$1 PARAMS=$2 ORDER=$3
shift 3
[ "${1:-}" = "--" ] && shift
BUILD=${BUILD:-build}
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT INT TERM
declare -A WALL
for workers in ${WORKERS:-1 2}; do
  cp -r "$RUN_DIR" "$WORK/cache$workers"
  forgotten=0
  for p in $PARAMS; do
    for f in "$WORK/cache$workers"/*/*/jobs/o${ORDER}_*_${p}_m[ai][xn]_*.json; do
      [ -e "$f" ] && rm "$f" && forgotten=$((forgotten + 1))
    done
  done
  [ "$forgotten" -gt 0 ] || { echo "no order-$ORDER jobs of '$PARAMS' in $RUN_DIR" >&2; exit 2; }
  "$BUILD/paper_examples/cerone_tables" "$@" --run-dir "$WORK/cache$workers" --out "$WORK/out$workers" \
    --outer-orders "$ORDER" --inner-starts 0 --inner-restarts 0 --threads "$workers" 2> "$WORK/log$workers" >/dev/null
  WALL[$workers]=$(sed -n "s/.*: order $ORDER done in \([0-9.]*\) s/\1/p" "$WORK/log$workers" | tail -1)
  echo "$workers worker(s): $forgotten order-$ORDER jobs in ${WALL[$workers]} s"
done
[ -n "${WALL[1]:-}" ] && [ -n "${WALL[2]:-}" ] || exit 0
awk -v a="${WALL[1]}" -v b="${WALL[2]}" 'BEGIN { printf "speed-up 1 -> 2 workers: %.2f\n", a / b }'
