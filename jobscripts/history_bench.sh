#!/usr/bin/env bash
# The time-blocked history sum against the code before it (issue 13): the same machine, the same
# runs, side by side. Checks out BEFORE (default e52d7a2, the last commit with the per-step sum
# over PETSc BAIJ/dense Mats) into a git worktree, warms both numba caches, then runs each case at
# 2 ranks with the old code and with this one (default -ssi_history_block, block-sparse lags in
# bem/bsr.py), and this one at 1 rank (strong scaling), all with -log_view -memory_view; measures
# this machine's dgemm rate (jobscripts/dgemm_rate.py); writes the table (jobscripts/history_table.py)
# into jobscripts/results/history_block.csv, jobscripts/README.md and runs/pekeris/README.md.
#   bash jobscripts/history_bench.sh [CASES...]        (default: medium paper paper-interp; ~25 min)
# The paper case needs about 9 GB per rank.
set -euo pipefail
source "$(dirname "$0")/bench_env.sh"
BEFORE=${BEFORE:-e52d7a2}
CASES=${*:-"medium paper paper-interp"}
OUT=out/bench/history
mkdir -p "$OUT"
before_worktree "$BEFORE"
run() {  # version ranks case extra...
  local version=$1 n=$2 case=$3; shift 3
  local dir=$ROOT cache=$NUMBA_CACHE_DIR
  [ "$version" = before ] && dir=$WT && cache=$BEFORE_CACHE
  local log="$ROOT/$OUT/$version-$case-n$n.log"
  echo "[bench] $version $case on $n rank(s) -> $log"
  (cd "$dir" && NUMBA_CACHE_DIR="$cache" /usr/bin/time -v mpirun --allow-run-as-root --oversubscribe -n "$n" "$PY" -m petsc_ssi \
     -options_file "$ROOT/runs/pekeris/$case.opts" -ssi_output "$ROOT/$OUT/$version-$case-n$n.h5" \
     -ssi_output_overwrite -ssi_output_stride 0 -log_view -memory_view "$@") > "$log" 2>&1
}
# one untimed run of each version first: numba compiles what the warm-up case did not need
run before 2 medium -ssi_t_end 0.003 && run after 2 medium -ssi_t_end 0.003
rm -f "$OUT"/*-medium-n2.*
for case in $CASES; do
  run before 2 "$case"
  run after 2 "$case"
  run after 1 "$case"
done
"$PY" jobscripts/dgemm_rate.py > "$OUT/dgemm_rate.txt"
"$PY" jobscripts/history_table.py "$OUT"
