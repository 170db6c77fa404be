#!/usr/bin/env bash
# The demo's building under an earthquake (runs/seismic/README.md): the coupled run, its fixed-base
# twin, the response spectra engineers read (roof and free field, SSI over fixed base) and the
# glance (petsc-ssi post --glance: what the soil changes).
#   bash runs/seismic/run.sh [NRANKS] [extra PETSc/-ssi_ options, e.g. -ssi_t_end 1]
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/../run_env.sh"      # (the repository root, PY, REC)
N=${1:-2}; shift || true
mkdir -p out/seismic
mpirun --oversubscribe -n "$N" "$PY" -m petsc_ssi -options_file runs/seismic/building.opts -ssi_seismic_record "$REC" \
  -ssi_output_overwrite -ssi_monitor -log_view :out/seismic/building-n$N.log_view -memory_view "$@" \
  | tee out/seismic/building-n$N.log
mpirun --oversubscribe -n "$N" "$PY" -m petsc_ssi -options_file runs/seismic/building-oblique.opts -ssi_seismic_record "$REC" \
  -ssi_output_overwrite -ssi_monitor -log_view :out/seismic/building-oblique-n$N.log_view -memory_view "$@" \
  | tee out/seismic/building-oblique-n$N.log
mpirun --oversubscribe -n "$N" "$PY" -m petsc_ssi -options_file runs/seismic/fixed-base.opts -ssi_seismic_record "$REC" \
  -ssi_output_overwrite -log_view :out/seismic/fixed-base-n$N.log_view -memory_view "$@" \
  | tee out/seismic/fixed-base-n$N.log
# roof (structure receiver 0) with SSI, on a fixed base, and their ratio; the free field (soil receiver 0)
post() { "$PY" -m petsc_ssi post "$@" --overwrite; }
post out/seismic/building_structure.h5 --response-spectrum --receiver 0 --component x --damping 0.05 \
  --csv out/seismic/roof-ssi.csv --png out/seismic/roof-ssi.png
post out/seismic/fixed-base.h5 --response-spectrum --receiver 0 --component x --damping 0.05 \
  --csv out/seismic/roof-fixed.csv --png out/seismic/roof-fixed.png
post out/seismic/building_structure.h5 --response-spectrum --receiver 0 --component x --ratio out/seismic/fixed-base.h5 \
  --csv out/seismic/roof-ratio.csv --png out/seismic/roof-ratio.png
post out/seismic/building.h5 --response-spectrum --receiver 0 --component x \
  --csv out/seismic/free-field.csv --png out/seismic/free-field.png
# SSI at a glance: first frequency and damping with and without the soil (roof / ground transfer
# functions), period lengthening, peak roof acceleration, drift and base shear (when recorded)
post out/seismic/building.h5 --glance out/seismic/fixed-base.h5 --receiver 0 --component x \
  --csv out/seismic/glance.csv --png out/seismic/glance.png | tee out/seismic/glance.txt
"$PY" runs/seismic/report.py out/seismic
