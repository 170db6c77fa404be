#!/usr/bin/env bash
# The BEM assembly against the code before its rework (issue 13, item 2): the same machine, the same
# runs, side by side. Checks out BEFORE (default 9be1e80: per-chunk triplets split into per-lag
# pieces, concatenated, sorted and turned into CSR lag by lag) into a git worktree, warms both numba
# caches, then
#  1. assembles small cases with both versions at 2 ranks and saves their lag matrices
#     (-ssi_lags_save); jobscripts/compare_lags.py says whether they are the same bit for bit:
#     small (block-sparse lags, quarter model), medium (dense lags), small with a prescribed
#     horizontal displacement under x=anti,y=sym (traction columns of G) and with interpolation;
#  2. times the Pekeris cases (medium, paper, paper-interp) with both at 2 ranks and with this
#     code at 1 rank, with -log_view -memory_view;
# and writes the table (jobscripts/assembly_table.py) into jobscripts/results/assembly.csv,
# jobscripts/README.md and runs/pekeris/README.md.
#   bash jobscripts/assembly_bench.sh [CASES...]        (default: medium paper paper-interp; ~15 min)
# The paper case needs about 10 GB per rank; the saved medium lags take 2 x 2.4 GB of disk.
set -euo pipefail
source "$(dirname "$0")/bench_env.sh"
BEFORE=${BEFORE:-9be1e80}
CASES=${*:-"medium paper paper-interp"}
OUT=out/bench/assembly
mkdir -p "$OUT"
before_worktree "$BEFORE" "rm -f '$PWD/$OUT'/*.lags*"
run() {  # version ranks name opts-case extra...
  local version=$1 n=$2 name=$3 case=$4; shift 4
  local dir=$ROOT cache=$NUMBA_CACHE_DIR
  [ "$version" = before ] && dir=$WT && cache=$BEFORE_CACHE
  local log="$ROOT/$OUT/$version-$name-n$n.log"
  echo "[bench] $version $name on $n rank(s) -> $log"
  (cd "$dir" && NUMBA_CACHE_DIR="$cache" /usr/bin/time -v mpirun --allow-run-as-root --oversubscribe -n "$n" "$PY" -m petsc_ssi \
     -options_file "$ROOT/runs/pekeris/$case.opts" -ssi_output "$ROOT/$OUT/$version-$name-n$n.h5" \
     -ssi_output_overwrite -ssi_output_stride 0 -log_view -memory_view "$@") > "$log" 2>&1
}
# 1. the same matrices (the first runs also compile what the warm-up case did not need)
: > "$OUT/matrices.txt"
same() {  # name case extra...
  local name=$1 case=$2; shift 2
  for v in before after; do
    run $v 2 "lags-$name" "$case" -ssi_lags_save "$ROOT/$OUT/$v-$name.lags" "$@"
  done
  "$PY" jobscripts/compare_lags.py "$OUT/before-$name.lags" "$OUT/after-$name.lags" | tee -a "$OUT/matrices.txt"
  rm -f "$OUT"/*-"$name".lags* "$OUT"/*-lags-"$name"-n2.*
}
same small small
same medium medium
same anti-disp small -ssi_load_group "" -ssi_disp_group load -ssi_disp_value 1e-6,0,0 -ssi_symmetry x=anti,y=sym
same interp small -ssi_interp chebyshev -ssi_interp_tl 0.02 -ssi_interp_k 4
# 2. timings
for case in $CASES; do
  run before 2 "$case" "$case"
  run after 2 "$case" "$case"
  run after 1 "$case" "$case"
done
"$PY" jobscripts/assembly_table.py "$OUT"
