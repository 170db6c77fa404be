#!/usr/bin/env bash
# -ssi_huge_pages on against off (the default) in whole runs: each case REPEAT times (default 3) at 1
# and 2 ranks with numpy's transparent-huge-page advice on and off, alternating (on, off, on, off,
# ...) so that a slow spell of the machine hits both, all with -log_view; the table
# (jobscripts/scaling_repeat_table.py, cases named CASE-hpon and CASE-hpoff) gives the fastest and
# median totals, time loops and assembly stages: jobscripts/results/huge_pages.csv and
# <!-- huge_pages:begin/end --> in jobscripts/README.md. jobscripts/first_touch.py measures the
# first writes alone.
#   bash jobscripts/huge_pages_bench.sh [CASES...]      (default: medium; about 3 minutes)
set -euo pipefail
source "$(dirname "$0")/bench_env.sh"
CASES=${*:-"medium"}
REPEAT=${REPEAT:-3}
OUT=out/bench/huge_pages
mkdir -p "$OUT"
"$PY" -m petsc_ssi.warmup
for case in $CASES; do
  for i in $(seq 1 "$REPEAT"); do
    for hp in on off; do
      for n in 1 2; do
        log="$OUT/$case-hp$hp-n$n-r$i.log"
        echo "[bench] $case, -ssi_huge_pages $hp, $n rank(s), run $i -> $log"
        mpirun --allow-run-as-root --oversubscribe -n "$n" "$PY" -m petsc_ssi -options_file "runs/pekeris/$case.opts" \
          -ssi_huge_pages "$hp" -ssi_output "$OUT/$case-hp$hp-n$n-r$i.h5" -ssi_output_overwrite -ssi_output_stride 0 \
          -log_view > "$log" 2>&1
      done
    done
  done
done
"$PY" jobscripts/scaling_repeat_table.py "$OUT" huge_pages
