#!/usr/bin/env bash
# The runs behind runs/building/README.md "On the half-space" (Figs. 15-16, the comparisons and the
# benchmark table): every runs/building/ssi-*.opts case at 1 and 2 ranks (the full twin of the half
# model and the released slabs at 2 only), each under /usr/bin/time -v with -log_view -memory_view,
# into out/building/<case>-n<ranks>.h5 and out/building/logs/<case>-n<ranks>.log; then
# runs/building/ssi_figures.py writes the figures, the CSVs and the README's tables.
#   bash runs/building/ssi_runs.sh [CASE...]     (default: all; about 15 minutes on 2 cores, 8 GB)
set -euo pipefail
cd "$(dirname "$0")/../.."
source jobscripts/bench_env.sh
OUT=out/building
mkdir -p "$OUT/logs"
"$PY" -m petsc_ssi.app.warmup > /dev/null
CASES=("$@")
[ ${#CASES[@]} -gt 0 ] || CASES=(ssi-full-bonded ssi-full-unilateral ssi-half-bonded ssi-half-unilateral
                                ssi-full-bonded-ny4 ssi-full-bonded-released)
for case in "${CASES[@]}"; do
  case $case in
    ssi-full-bonded-ny4|ssi-full-bonded-released) ranks="2" ;;
    *) ranks="1 2" ;;
  esac
  for n in $ranks; do
    echo "[building] $case on $n rank(s) -> $OUT/logs/$case-n$n.log"
    /usr/bin/time -v mpirun --allow-run-as-root --oversubscribe -n "$n" "$PY" -m petsc_ssi \
      -options_file "runs/building/$case.opts" -ssi_output "$OUT/$case-n$n.h5" -ssi_output_overwrite \
      -log_view -memory_view > "$OUT/logs/$case-n$n.log" 2>&1
  done
done
"$PY" runs/building/ssi_figures.py
