#!/usr/bin/env bash
# Benchmark of the Lamb/Pekeris cases at 1 and 2 ranks (issue 2).
# Runs each case with -log_view and -memory_view, then writes the table into
# runs/pekeris/README.md and the CSV runs/pekeris/bench.csv from the logs.
#   bash jobscripts/pekeris_bench.sh [CASES...]     (default: small medium paper)
# On a cluster, put the mpirun line in a job script (see jobscripts/README.md).
set -euo pipefail
source "$(dirname "$0")/bench_env.sh"
RANKS=${RANKS:-"1 2"}
CASES=${*:-"small medium paper"}
OUT=out/bench
mkdir -p "$OUT"
for case in $CASES; do
  for n in $RANKS; do
    log="$OUT/pekeris-$case-n$n.log"
    echo "[bench] $case on $n rank(s) -> $log"
    mpirun --allow-run-as-root --oversubscribe -n "$n" "$PY" -m petsc_ssi \
      -options_file "runs/pekeris/$case.opts" -ssi_output "$OUT/pekeris-$case-n$n.h5" -ssi_output_overwrite \
      -ssi_output_stride 0 -ssi_plot -log_view -memory_view > "$log" 2>&1
  done
done
"$PY" jobscripts/pekeris_table.py "$OUT" runs/pekeris/README.md runs/pekeris/bench.csv
