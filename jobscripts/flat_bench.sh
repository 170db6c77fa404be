#!/usr/bin/env bash
# Issue 29: the flat surface's block patterns (bem/bsr.py), before and after, on this machine.
# Runs the paper's Lamb case (runs/pekeris/paper.opts) and the paper's building
# (runs/building/ssi-full-bonded.opts) on 2 ranks with the code at BEFORE (default 162a0c5, the
# commit before the change, in a git worktree with its own numba cache) and with this checkout,
# each with -log_view -memory_view; the Lamb case also with -ssi_lag_single_from 3 (every lag
# but the step matrix's in float32); the building's old code twice (its run-to-run spread: the
# yardstick of the differences of a coupled run). Then jobscripts/flat_table.py writes
# results/flat.csv and the table between <!-- flat:begin/end --> in jobscripts/README.md.
#   bash jobscripts/flat_bench.sh [BEFORE]        (about 10 minutes on 2 cores)
set -euo pipefail
source "$(dirname "$0")/bench_env.sh"
BEFORE=${1:-162a0c5}
OUT=out/bench/flat
mkdir -p "$OUT"
before_worktree "$BEFORE"
MPI="mpirun --allow-run-as-root --oversubscribe -n 2"
run_before() {   # NAME OPTS-FILE [OPTIONS...]
  local name=$1 opts=$2
  shift 2
  echo "[bench] $name (code at $BEFORE)"
  (cd "$WT" && PYTHONPATH="$WT" NUMBA_CACHE_DIR="$BEFORE_CACHE" $MPI "$PY" -m petsc_ssi -options_file "$opts" \
     -ssi_output "$ROOT/$OUT/$name.h5" -ssi_output_overwrite -log_view -memory_view "$@" > "$ROOT/$OUT/$name.log" 2>&1)
}
run_after() {
  local name=$1 opts=$2
  shift 2
  echo "[bench] $name (this checkout)"
  $MPI "$PY" -m petsc_ssi -options_file "$opts" -ssi_output "$OUT/$name.h5" -ssi_output_overwrite \
    -log_view -memory_view "$@" > "$OUT/$name.log" 2>&1
}
run_before paper-before runs/pekeris/paper.opts
run_after paper-after runs/pekeris/paper.opts
run_after paper-after-single3 runs/pekeris/paper.opts -ssi_lag_single_from 3
run_before building-before runs/building/ssi-full-bonded.opts
run_before building-before-rerun runs/building/ssi-full-bonded.opts
run_after building-after runs/building/ssi-full-bonded.opts
"$PY" jobscripts/flat_table.py "$OUT" "$BEFORE"
