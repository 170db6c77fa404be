#!/usr/bin/env bash
# The lag matrices of this checkout against the code at BEFORE (a git worktree, default 0761e15: the
# commit before issue 29's plane kernel and 4-wide kernels), bit for bit: the small Lamb case and the
# demo building at 2 ranks with -ssi_lags_save, then jobscripts/compare_lags.py on each pair.
#   bash jobscripts/lags_bitcheck.sh [BEFORE]      (about 2 minutes)
set -euo pipefail
source "$(dirname "$0")/bench_env.sh"
BEFORE=${1:-0761e15}
OUT=out/bench/lags_bitcheck
mkdir -p "$OUT"
before_worktree "$BEFORE"
MPI="mpirun --allow-run-as-root --oversubscribe -n 2"
for case in small:runs/pekeris/small.opts demo-building:runs/building/demo.opts; do
  name=${case%%:*}; opts=${case#*:}
  (cd "$WT" && PYTHONPATH="$WT" NUMBA_CACHE_DIR="$BEFORE_CACHE" $MPI "$PY" -m petsc_ssi -options_file "$opts" \
     -ssi_output "$ROOT/$OUT/$name-before.h5" -ssi_output_overwrite -ssi_lags_save "$ROOT/$OUT/$name-before.lags" \
     > "$ROOT/$OUT/$name-before.log" 2>&1)
  $MPI "$PY" -m petsc_ssi -options_file "$opts" -ssi_output "$OUT/$name-after.h5" -ssi_output_overwrite \
    -ssi_lags_save "$OUT/$name-after.lags" > "$OUT/$name-after.log" 2>&1
  "$PY" jobscripts/compare_lags.py "$OUT/$name-before.lags" "$OUT/$name-after.lags"
done
