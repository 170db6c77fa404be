#!/usr/bin/env bash
# The long-record benchmark (issue 28): the paper's building (half model) under 30 s of the K-NET
# record (runs/seismic/paper-building.opts, 6000 steps of 5 ms) at each rank count given, with
# -log_view and -memory_view, and `petsc-ssi estimate` of the same case beside it; then
# jobscripts/long_record.py writes the table (stages, memory, estimate against measured) into
# jobscripts/README.md and the per-step wall time into jobscripts/results/long_record_steps.png.
#   bash jobscripts/long_record.sh 1 2            (about 10 + 6 minutes on the 2-core machine)
#   T_END=5 bash jobscripts/long_record.sh 2      (a shorter record: -ssi_t_end 5)
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/bench_env.sh"
RANKS=${*:-"1 2"}
OUT=out/bench/long_record
mkdir -p "$OUT"
REC=$("$PY" -c "import obspy, os; print(os.path.join(os.path.dirname(obspy.__file__), 'io', 'nied', 'tests', 'data', 'test.knet'))")
EXTRA=()
[ -n "${T_END:-}" ] && EXTRA+=(-ssi_t_end "$T_END")
"$PY" -m petsc_ssi.app.warmup
"$PY" -m petsc_ssi estimate -options_file runs/seismic/paper-building.opts -ssi_seismic_record "$REC" \
  -ssi_estimate_ranks "$(echo $RANKS | tr ' ' ',')" "${EXTRA[@]}" | tee "$OUT/estimate.log"
for n in $RANKS; do
  /usr/bin/time -v mpirun --oversubscribe -n "$n" "$PY" -m petsc_ssi -options_file runs/seismic/paper-building.opts \
    -ssi_seismic_record "$REC" -ssi_output "$OUT/paper-building-n$n.h5" -ssi_output_overwrite "${EXTRA[@]}" \
    -log_view ":$OUT/paper-building-n$n.log_view" -memory_view 2> "$OUT/paper-building-n$n.time" \
    | tee "$OUT/paper-building-n$n.log"
done
"$PY" jobscripts/long_record.py "$OUT"
