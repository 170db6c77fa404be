#!/usr/bin/env bash
# The cases a moves-only change must leave bit for bit (issue 26): run them with the code of TREE
# (a checkout of petsc_ssi) into OUT; jobscripts/compare_outputs.py OUT_A OUT_B compares every
# dataset and attribute of the HDF5 files the two runs wrote (provenance and timings excepted).
#   bash jobscripts/refactor_cases.sh TREE OUT
# Cases: the medium Pekeris quarter model (2 ranks, -ssi_reproducible: without it reruns of the same code
# differ at 1e-22 m on 2 ranks), the demo's building (1 rank, 0.1 s), the
# paper's foundation with unilateral contact (1 rank), impedance of the square footing (2 ranks,
# two modes), a BEM run checkpointed after step 20 and restarted (2 ranks); the demo building under the
# test K-NET record, vertical and oblique (1 s, 1 rank) and its fixed base (issue 40), and the small
# Lamb case under a box load and a table load (1 rank).
set -euo pipefail
TREE=$(cd "$1" && pwd); OUT=$(mkdir -p "$2" && cd "$2" && pwd)
source "$(dirname "${BASH_SOURCE[0]}")/bench_env.sh"       # cd to this repository, PY, PETSc env
PY=$(cd "$(dirname "$PY")" && pwd)/$(basename "$PY")
export NUMBA_CACHE_DIR="$TREE/.numba_cache"
cd "$TREE"
ssi() { local n=$1; shift; mpirun --allow-run-as-root --oversubscribe -n "$n" "$PY" -m petsc_ssi "$@"; }
"$PY" -m petsc_ssi.warmup >/dev/null 2>&1 || "$PY" -m petsc_ssi.app.warmup >/dev/null
ssi 2 -options_file runs/pekeris/medium.opts -ssi_reproducible -ssi_output "$OUT/pekeris-medium.h5" > "$OUT/pekeris-medium.log"
ssi 1 -options_file runs/building/demo.opts -ssi_t_end 0.1 -ssi_output "$OUT/building.h5" > "$OUT/building.log"
ssi 1 -options_file runs/foundation/sym-unilateral.opts -ssi_t_end 0.2 -ssi_output "$OUT/foundation.h5" \
  > "$OUT/foundation.log"
ssi 2 impedance -options_file runs/impedance/square.opts -ssi_mesh_h 0.5 -ssi_dt 7.92e-4 \
  -ssi_impedance_modes vertical,horizontal -ssi_output "$OUT/square.h5" > "$OUT/impedance.log"
CK=(-options_file runs/pekeris/small.opts -ssi_checkpoint "$OUT/ck-%d.h5" -ssi_checkpoint_every 20 -ssi_reproducible)
ssi 2 "${CK[@]}" -ssi_output "$OUT/full.h5" > "$OUT/full.log"
cp "$OUT/full.h5" "$OUT/restart.h5"
ssi 2 "${CK[@]}" -ssi_output "$OUT/restart.h5" -ssi_restart "$OUT/ck-20.h5" > "$OUT/restart.log"
rm -f "$OUT"/ck-*.h5
REC=$("$PY" -c "import obspy, os; print(os.path.join(os.path.dirname(obspy.__file__), 'io', 'nied', 'tests', 'data', 'test.knet'))")
for c in building building-oblique fixed-base; do
  ssi 1 -options_file runs/seismic/$c.opts -ssi_seismic_record "$REC" -ssi_t_end 1 -ssi_output "$OUT/seismic-$c.h5" \
    > "$OUT/seismic-$c.log"
done
ssi 1 -options_file runs/pekeris/small.opts -ssi_load_history box -ssi_load_t0 0.02 -ssi_output "$OUT/box.h5" > "$OUT/box.log"
printf '0 0\n0.01 1\n0.03 -0.5\n0.05 0\n' > "$OUT/table.txt"
ssi 1 -options_file runs/pekeris/small.opts -ssi_load_history table -ssi_load_table "$OUT/table.txt" \
  -ssi_output "$OUT/table.h5" > "$OUT/table.log"
echo "cases written to $OUT"
