#!/usr/bin/env bash
# The demo's building under the earthquake founded on the ground and on a 3 m basement (runs/basement/README.md):
# both coupled runs (full model, 1000 steps of 5 ms), then compare.py (CSV, PNG, the README's table).
#   [BUILDING=paper] bash runs/basement/run.sh [NRANKS] [extra PETSc/-ssi_ options, e.g. -ssi_t_end 1]
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/../run_env.sh"      # (the repository root, PY, REC)
N=${1:-1}; shift || true
# BUILDING=paper: the paper's building (4 x 3 bays of 3.6 m, three storeys; 14.4 m x 10.8 m on a 24 m x 20.4 m
# ground, the same 4.8 m margin) instead of the demo's, into out/basement-paper (about 12.6 GB on 2 ranks)
OUT=out/basement
declare -A EXTRA=([surface]="" [basement]="")
if [ "${BUILDING:-demo}" = paper ]; then
  OUT=out/basement-paper
  EXTRA[surface]="-ssi_fem_mesh_params nbx=4,nby=3,sx=3.6,sy=3.6,ns=3,half=0 -ssi_mesh_patch 7.2,5.4"
  EXTRA[basement]="-ssi_fem_mesh_params nbx=4,nby=3,sx=3.6,sy=3.6,ns=3,half=0,d=3,nzb=4 -ssi_mesh_params a=7.2,b=5.4,d=3"
  COMMON=(-ssi_mesh_size 24,20.4 -ssi_structure_receivers "0,0,9;0,0,6;0,0,3;0,0,0" -ssi_structure_drift_levels 0,3,6,9)
else
  COMMON=()
fi
mkdir -p "$OUT"
for c in surface basement; do
  start=$(date +%s.%N)
  # shellcheck disable=SC2086
  mpirun --oversubscribe -n "$N" "$PY" -m petsc_ssi -options_file runs/basement/$c.opts -ssi_seismic_record "$REC" \
    ${EXTRA[$c]} "${COMMON[@]}" -ssi_output "$OUT/$c.h5" -ssi_output_overwrite -ssi_monitor "$@" | tee "$OUT/$c.log"
  echo "wall $(echo "$(date +%s.%N) - $start" | bc) s" | tee -a "$OUT/$c.log"
done
"$PY" runs/basement/compare.py "$OUT"
