#!/usr/bin/env bash
# The history sum's sub-blocks (-ssi_history_sub, issue 13): one case's lag matrices assembled and
# saved once (-ssi_lags_save), then the same time loop at 2 ranks with blocks of BLOCK steps (default
# 32) in sub-blocks of each SUBS size (default "32 16 8"; 32 = one level) and step by step (b = 1),
# every run loading the same saved lags (-ssi_lags_load: no assembly, the same matrices), all with
# -log_view. The table (jobscripts/subblock_table.py) gives the time loop, the panel products
# (SSI_BEM_HistPanel), the per-step rest (SSI_BEM_HistStep), their flops and the receivers against
# the step-by-step run: jobscripts/results/subblock.csv and <!-- subblock:begin/end --> in
# jobscripts/README.md.
#   bash jobscripts/subblock_bench.sh [CASE]        (default: paper; about 10 minutes, 9 GB per rank
#                                                     and 13 GB of disk for the saved lags)
set -euo pipefail
source "$(dirname "$0")/bench_env.sh"
CASE=${1:-paper}
BLOCK=${BLOCK:-32}
SUBS=${SUBS:-"32 16 8"}
OUT=out/bench/subblock
mkdir -p "$OUT"
"$PY" -m petsc_ssi.app.warmup
LAGS="$OUT/$CASE-lags.h5"
trap 'rm -f "$LAGS"' EXIT
run() {  # name extra...
  local name=$1; shift
  echo "[bench] $CASE $name -> $OUT/$CASE-$name.log"
  mpirun --allow-run-as-root --oversubscribe -n 2 "$PY" -m petsc_ssi -options_file "runs/pekeris/$CASE.opts" \
    -ssi_output "$OUT/$CASE-$name.h5" -ssi_output_overwrite -ssi_output_stride 0 -log_view "$@" \
    > "$OUT/$CASE-$name.log" 2>&1
}
rm -f "$LAGS"
run save -ssi_lags_save "$LAGS"
for s in $SUBS; do
  run "b$BLOCK-s$s" -ssi_lags_load "$LAGS" -ssi_history_block "$BLOCK" -ssi_history_sub "$s"
done
run b1 -ssi_lags_load "$LAGS" -ssi_history_block 1
"$PY" jobscripts/subblock_table.py "$OUT" "$CASE"
