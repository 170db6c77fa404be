#!/usr/bin/env bash
# Lags in single precision (-ssi_lag_single_from, issue 13 item 3) against the all-double run: the same
# machine, the same session. Per case, at 2 ranks with -log_view -memory_view:
#   double    every lag in double (the default)
#   single    lags from SINGLE_FROM (default 3: all but the step matrix's) as float32 block-sparse
# plus `petsc-ssi estimate` of both (its predicted peak per rank), and a long run of the small case
# (SMALL_LONG_T, default 0.3 s: 400 steps, 7x the lags; the far lags' rounding accumulating, if it
# did, would show here). The table (jobscripts/precision_table.py) gives time, stored GB, measured and
# estimated peak, the receivers' difference single - double, and both runs' error against Pekeris
# (petsc_ssi.verify, tau <= 2.5); and the double runs of small, medium and paper with dense lags from
# 35 % block fill (-ssi_lag_fill 0.35, the default before 0.95; case names *-fill35):
# jobscripts/results/precision.csv, <!-- precision:begin/end --> in
# jobscripts/README.md and runs/pekeris/README.md, and precision.png (difference against time).
#   bash jobscripts/precision_bench.sh [CASES...]      (default: small medium paper paper-interp; ~10 min)
set -euo pipefail
source "$(dirname "$0")/bench_env.sh"
CASES=${*:-"small medium paper paper-interp"}
SINGLE_FROM=${SINGLE_FROM:-3}
SMALL_LONG_T=${SMALL_LONG_T:-0.3}
OUT=out/bench/precision
mkdir -p "$OUT"
"$PY" -m petsc_ssi.app.warmup
run() {  # precision name case extra...
  local prec=$1 name=$2 case=$3; shift 3
  local sf=0
  [ "$prec" = single ] && sf=$SINGLE_FROM
  echo "[bench] $prec $name -> $OUT/$prec-$name.log"
  /usr/bin/time -v mpirun --allow-run-as-root --oversubscribe -n 2 "$PY" -m petsc_ssi \
     -options_file "runs/pekeris/$case.opts" -ssi_output "$OUT/$prec-$name.h5" -ssi_output_overwrite \
     -ssi_output_stride 0 -ssi_lag_single_from $sf -log_view -memory_view "$@" > "$OUT/$prec-$name.log" 2>&1
  "$PY" -m petsc_ssi estimate -options_file "runs/pekeris/$case.opts" -ssi_lag_single_from $sf \
     -estimate_ranks 2 "$@" > "$OUT/$prec-$name.estimate" 2>&1
}
for case in $CASES; do
  run double "$case" "$case"
  run single "$case" "$case"
done
# the storage rule's previous threshold (-ssi_lag_fill 0.35: dense lags from 35 % block fill) for comparison
for case in small medium paper; do
  run double "$case-fill35" "$case" -ssi_lag_fill 0.35
done
run double small-long small -ssi_t_end "$SMALL_LONG_T" -ssi_warn_beta 0
run single small-long small -ssi_t_end "$SMALL_LONG_T" -ssi_warn_beta 0
"$PY" jobscripts/precision_table.py "$OUT" "$SINGLE_FROM"
