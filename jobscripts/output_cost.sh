#!/usr/bin/env bash
# Issue 30: what the output's parts cost (io/output.py: snapshots into parts closed at each flush,
# FILE.h5 written anew and renamed, the final close copying everything into it) against the
# in-place writes before them (the code at BEFORE, default 751e934, in a git worktree with its own
# numba cache). Cases at 2 ranks with -ssi_reproducible (so the two codes' files can be compared
# bit for bit: jobscripts/compare_outputs.py) and -log_view: the medium Lamb case with a snapshot
# every step and a flush every 0.2 s (the output's worst case), the same with its defaults, and the
# demo's building (coupled, frames and shells: runs/building/demo.opts) flushed every second.
# Then jobscripts/output_cost_table.py writes results/output_cost.csv and the table between
# <!-- output_cost:begin/end --> in jobscripts/README.md.
#   bash jobscripts/output_cost.sh [BEFORE]        (about 6 minutes on 2 cores)
set -euo pipefail
source "$(dirname "$0")/bench_env.sh"
BEFORE=${1:-751e934}
OUT=out/bench/output_cost
rm -rf "$OUT"
mkdir -p "$OUT/before" "$OUT/after"
before_worktree "$BEFORE"
MPI="mpirun --allow-run-as-root --oversubscribe -n 2"
CASES=(
  "medium-every-step|runs/pekeris/medium.opts|-ssi_output_stride 1 -ssi_output_flush 0.2"
  "medium|runs/pekeris/medium.opts|"
  "demo-building|runs/building/demo.opts|-ssi_output_flush 1"
)
for c in "${CASES[@]}"; do
  IFS='|' read -r name opts extra <<< "$c"
  for code in before after; do
    echo "[bench] $name ($code)"
    if [ "$code" = before ]; then
      # shellcheck disable=SC2086
      (cd "$WT" && PYTHONPATH="$WT" NUMBA_CACHE_DIR="$BEFORE_CACHE" $MPI "$PY" -m petsc_ssi -options_file "$opts" \
         -ssi_output "$ROOT/$OUT/before/$name.h5" -ssi_output_overwrite -ssi_reproducible -log_view $extra \
         > "$ROOT/$OUT/before/$name.log" 2>&1)
    else
      # shellcheck disable=SC2086
      $MPI "$PY" -m petsc_ssi -options_file "$opts" -ssi_output "$OUT/after/$name.h5" -ssi_output_overwrite \
        -ssi_reproducible -log_view $extra > "$OUT/after/$name.log" 2>&1
    fi
  done
done
"$PY" jobscripts/output_cost_table.py "$OUT" "$BEFORE"
