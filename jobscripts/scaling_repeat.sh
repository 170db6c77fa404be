#!/usr/bin/env bash
# Strong scaling 1 -> 2 ranks measured against this machine's run-to-run spread (issue 13's target:
# 85 % or better on the medium and paper cases): each case REPEAT times (default 3) at 1 and at 2
# ranks, alternating (1, 2, 1, 2, ...) so that a slow spell of the machine hits both, all with
# -log_view; the table (jobscripts/scaling_repeat_table.py) gives each rank count's fastest and
# median total and time loop and the efficiencies T_1 / (2 T_2) of both:
# jobscripts/results/scaling_repeat.csv and <!-- scaling_repeat:begin/end --> in jobscripts/README.md.
#   bash jobscripts/scaling_repeat.sh [CASES...]      (default: medium paper; about 8 minutes,
#                                                      the paper case needs about 13 GB)
set -euo pipefail
source "$(dirname "$0")/bench_env.sh"
CASES=${*:-"medium paper"}
REPEAT=${REPEAT:-3}
OUT=out/bench/scaling_repeat
mkdir -p "$OUT"
"$PY" -m petsc_ssi.warmup
for case in $CASES; do
  for i in $(seq 1 "$REPEAT"); do
    for n in 1 2; do
      log="$OUT/$case-n$n-r$i.log"
      echo "[bench] $case on $n rank(s), run $i -> $log"
      mpirun --allow-run-as-root --oversubscribe -n "$n" "$PY" -m petsc_ssi -options_file "runs/pekeris/$case.opts" \
        -ssi_output "$OUT/$case-n$n-r$i.h5" -ssi_output_overwrite -ssi_output_stride 0 -log_view > "$log" 2>&1
    done
  done
done
"$PY" jobscripts/scaling_repeat_table.py "$OUT"
