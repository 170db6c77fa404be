#!/usr/bin/env bash
# What -ssi_lags_save/-ssi_lags_load save on the foundation cases (issue 14, item 3): the three
# symmetric cases share one soil (the half model with a symmetry plane), the three antisymmetric
# ones another. Per soil and rank count: the first case assembles and saves the lag matrices;
# then every case runs twice, assembling its own matrices and loading the saved ones. The table
# (jobscripts/lags_reuse_table.py) compares wall time, BEM set-up and the results.
#   bash jobscripts/lags_reuse.sh          (~6 minutes on 2 cores; RANKS="2" for one rank count)
set -euo pipefail
source "$(dirname "$0")/bench_env.sh"
RANKS=${RANKS:-"1 2"}
OUT=out/bench/lags
mkdir -p "$OUT"
declare -A CASES=([sym]="sym-bonded sym-unilateral sym-bonded-staggered"
                  [anti]="anti-bonded anti-unilateral anti-unilateral-cohesive")
for n in $RANKS; do
  for soil in sym anti; do
    lags="$OUT/$soil-n$n.lags"
    rm -f "$lags" "$lags.json"
    first=1
    for case in ${CASES[$soil]}; do
      save=()
      [ $first = 1 ] && save=(-ssi_lags_save "$lags")
      for how in assembled loaded; do
        extra=("${save[@]}")
        [ $how = loaded ] && extra=(-ssi_lags_load "$lags")
        echo "[bench] $case $how on $n rank(s)"
        mpirun --allow-run-as-root --oversubscribe -n "$n" "$PY" -m petsc_ssi -options_file "runs/foundation/$case.opts" \
          -ssi_output "$OUT/$case-$how-n$n.h5" -ssi_output_overwrite "${extra[@]}" > "$OUT/$case-$how-n$n.log" 2>&1
      done
      first=0
    done
  done
done
"$PY" jobscripts/lags_reuse_table.py "$OUT" runs/foundation/README.md runs/foundation/lags_reuse.csv
