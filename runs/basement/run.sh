#!/usr/bin/env bash
# The demo's building under the earthquake founded on the ground and on a 3 m basement (runs/basement/README.md):
# both coupled runs (full model, 1000 steps of 5 ms), then compare.py (CSV, PNG, the README's table).
#   bash runs/basement/run.sh [NRANKS] [extra PETSc/-ssi_ options, e.g. -ssi_t_end 1]
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
PY=${PY:-.venv/bin/python}
N=${1:-1}; shift || true
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OPENBLAS_NUM_THREADS=1
REC=$("$PY" -c "import obspy, os; print(os.path.join(os.path.dirname(obspy.__file__), 'io', 'nied', 'tests', 'data', 'test.knet'))")
mkdir -p out/basement
for c in surface basement; do
  start=$(date +%s.%N)
  mpirun --oversubscribe -n "$N" "$PY" -m petsc_ssi -options_file runs/basement/$c.opts -ssi_seismic_record "$REC" \
    -ssi_output_overwrite -ssi_monitor "$@" | tee out/basement/$c.log
  echo "wall $(echo "$(date +%s.%N) - $start" | bc) s" | tee -a out/basement/$c.log
done
"$PY" runs/basement/compare.py out/basement
