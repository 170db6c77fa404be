#!/usr/bin/env bash
# The runs the committed cost-model constants (petsc_ssi/estimate_constants.json) are fitted to, the
# fit and its check (issue 13, item 5). On this machine about 12 minutes:
#   1. the Pekeris benchmark, small medium paper paper-interp at 1 and 2 ranks (pekeris_bench.sh;
#      out/bench/pekeris-*.log; also rewrites its table in runs/pekeris/README.md);
#   2. small and medium with the per-step history sum (-ssi_history_block 1) at 1 and 2 ranks
#      (out/bench/perstep), so that the per-step streaming rates stay identified;
#   3. the runs of precision_bench.sh (out/bench/precision/*.log: single-precision lags, and the
#      *-fill35 runs, whose dense lags keep the dense rates identified now that the default
#      storage is block-sparse; run `bash jobscripts/precision_bench.sh` first, else they are left out);
# then `calibrate.py` (the fit, MACHINE names the table) and `calibrate.py --check` (the table of
# model against logs in jobscripts/README.md).
#   bash jobscripts/calibration_runs.sh [--fit-only]
set -euo pipefail
source "$(dirname "$0")/bench_env.sh"
MACHINE=${MACHINE:-"dev-vm-2core (2 cores, 24 GB)"}
if [ "${1:-}" != "--fit-only" ]; then
  "$PY" -m petsc_ssi.app.warmup
  RANKS="1 2" bash jobscripts/pekeris_bench.sh small medium paper paper-interp
  mkdir -p out/bench/perstep
  for case in small medium; do
    for n in 1 2; do
      echo "[bench] $case per step on $n rank(s) -> out/bench/perstep/pekeris-$case-n$n.log"
      mpirun --allow-run-as-root --oversubscribe -n "$n" "$PY" -m petsc_ssi -options_file "runs/pekeris/$case.opts" \
        -ssi_output "out/bench/perstep/pekeris-$case-n$n.h5" -ssi_output_overwrite -ssi_output_stride 0 \
        -ssi_history_block 1 -log_view -memory_view > "out/bench/perstep/pekeris-$case-n$n.log" 2>&1
    done
  done
fi
LOGS=(out/bench/pekeris-*.log out/bench/perstep/*.log)
compgen -G "out/bench/precision/*.log" > /dev/null && LOGS+=(out/bench/precision/*.log)
# the building soils (graded gmsh meshes: many distinct pair geometries, the integration term a_int;
# FIT=1 bash jobscripts/building_estimate.sh makes them)
compgen -G "out/bench/buildings/soil-*.log" > /dev/null && LOGS+=(out/bench/buildings/soil-*.log)
"$PY" jobscripts/calibrate.py --machine "$MACHINE" "${LOGS[@]}"
"$PY" jobscripts/calibrate.py --check "${LOGS[@]}"
