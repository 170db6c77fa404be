#!/usr/bin/env bash
# The estimate against measured coupled runs (issue 43: "within 30 % on the demo building, the paper's
# building and a user-style building, on 1 and 2 ranks of an idle machine"), and the BEM runs on the
# building soils that fit the assembly's integration term (a_int) to interface meshes:
#   1. each building at 1 and 2 ranks with -log_view, and `petsc-ssi estimate` of the same options:
#        demo      runs/building/demo.opts (2 x 2 bays, 2 storeys, 200 steps)
#        paper     runs/building/ssi-half-bonded.opts (the paper's building, 300 steps)
#        seismic   runs/seismic/building.opts cut to T s (default 2 s: 400 steps; a record's building,
#                  as an engineer runs one; the record is ObsPy's AKT013 test file, found as run.sh finds it)
#      -> out/bench/buildings/NAME-nN.log and NAME.estimate
#   2. (FIT=1) the building soils alone (-ssi_problem bem, the paper's pulse on the whole slab: as many
#      traction nodes as the coupled run's interface, so that the traction history's panels are fitted too) and the Pekeris small, medium
#      and paper cases at 1 and 2 ranks -> out/bench/buildings/soil-NAME-nN.log, pekeris-CASE-nN.log, for
#      `calibrate.py --assembly-only` (the assembly's kernel line fitted on both kinds of mesh)
# then building_estimate_table.py writes the table into jobscripts/README.md. Run it on an idle machine:
# the measured walls are the reference.
#   bash jobscripts/building_estimate.sh            (about 6 minutes on the 2-core development machine)
# OUT (default out/bench/buildings) and EXTRA (options appended to every run and estimate, e.g. a shorter
# -ssi_t_end for a smoke test of the scripts) may be set; CONSTANTS=FILE.json gives the estimates other
# constants (-ssi_estimate_constants), ESTIMATE_ONLY=1 redoes the estimates against the runs' logs already
# in OUT, and TAG names the README block the table goes to (default buildings). The committed table
# (jobscripts/README.md, "The estimate on buildings") was made on a quiet machine:
#   FIT=1 bash jobscripts/quiet.sh bash jobscripts/building_estimate.sh     (the runs; the soils' logs)
#   bash jobscripts/calibration_runs.sh --fit-only                          (constants from all the logs)
#   ESTIMATE_ONLY=1 bash jobscripts/quiet.sh bash jobscripts/building_estimate.sh   (the table with them)
set -euo pipefail
source "$(dirname "$0")/bench_env.sh"
OUT=${OUT:-out/bench/buildings}
EXTRA=${EXTRA:-}
EST=${CONSTANTS:+-ssi_estimate_constants $CONSTANTS}
T=${T:-2}
mkdir -p "$OUT"
"$PY" -m petsc_ssi.app.warmup
REC=$("$PY" -c "import obspy, os; print(os.path.join(os.path.dirname(obspy.__file__), 'io', 'nied', 'tests', 'data', 'test.knet'))")
declare -A CASE=(
  [demo]="-options_file runs/building/demo.opts"
  [paper]="-options_file runs/building/ssi-half-bonded.opts"
  [seismic]="-options_file runs/seismic/building.opts -ssi_seismic_record $REC -ssi_t_end $T"
)
for name in demo paper seismic; do
  # shellcheck disable=SC2086
  "$PY" -m petsc_ssi estimate ${CASE[$name]} $EXTRA $EST -ssi_estimate_ranks 1,2 > "$OUT/$name.estimate" 2>&1
  [ "${ESTIMATE_ONLY:-0}" = 1 ] && continue
  for n in 1 2; do
    echo "[bench] $name on $n rank(s) -> $OUT/$name-n$n.log"
    # shellcheck disable=SC2086
    mpirun --allow-run-as-root --oversubscribe -n "$n" "$PY" -m petsc_ssi ${CASE[$name]} $EXTRA \
      -ssi_output "$OUT/$name-n$n.h5" -ssi_output_overwrite -log_view -memory_view > "$OUT/$name-n$n.log" 2>&1
    # the machine's 1-minute load average at the end of the run (the table marks a loaded machine)
    echo "# load average after the run: $(cut -d' ' -f1 /proc/loadavg)" >> "$OUT/$name-n$n.log"
  done
done
if [ "${FIT:-0}" = 1 ] && [ "${ESTIMATE_ONLY:-0}" != 1 ]; then
  # the flat Pekeris grids beside them, so that the assembly's kernel line (a0 + a_blk B + a_int I) is fitted
  # jointly (calibrate.py --assembly-only): few distinct pair geometries there, many on the building soils
  for case in small medium paper; do
    for n in 1 2; do
      echo "[bench] pekeris $case on $n rank(s) -> $OUT/pekeris-$case-n$n.log"
      mpirun --allow-run-as-root --oversubscribe -n "$n" "$PY" -m petsc_ssi -options_file "runs/pekeris/$case.opts" \
        -ssi_output "$OUT/pekeris-$case-n$n.h5" -ssi_output_overwrite -ssi_output_stride 0 -log_view -memory_view \
        > "$OUT/pekeris-$case-n$n.log" 2>&1
    done
  done
  for name in demo paper; do
    for n in 1 2; do
      echo "[bench] the $name building's soil alone on $n rank(s) -> $OUT/soil-$name-n$n.log"
      # shellcheck disable=SC2086
      mpirun --allow-run-as-root --oversubscribe -n "$n" "$PY" -m petsc_ssi ${CASE[$name]} $EXTRA -ssi_problem bem -ssi_load_group slab \
        -ssi_output "$OUT/soil-$name-n$n.h5" -ssi_output_overwrite -log_view -memory_view > "$OUT/soil-$name-n$n.log" 2>&1
    done
  done
fi
"$PY" jobscripts/building_estimate_table.py "$OUT" "${TAG:-buildings}"
