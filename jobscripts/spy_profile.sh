#!/usr/bin/env bash
# Where a run's time goes below the -log_view events: every rank sampled by py-spy (Python and native frames:
# numpy, BLAS, MUMPS, PETSc, MPI), then the samples per function, inclusive (a function's share of the
# samples whose stack holds it), rank 0's by default.
#   bash jobscripts/spy_profile.sh OUT RANKS PETSC-SSI-OPTIONS...
#   e.g. bash jobscripts/spy_profile.sh /tmp/spy 2 -options_file runs/building/ssi-full-bonded.opts -ssi_t_end 0.4
# OUT relative to the repository root (the script works there). Writes OUT/prof.<rank>.txt (py-spy's raw collapsed stacks, 50 samples a second) and OUT/run.log, then
# prints `python jobscripts/spy_table.py OUT/prof.0.txt` (FILTER=name: only the stacks through that
# function, e.g. FILTER=VecScatterCreate; TOP=n lines). Needs py-spy (`.venv/bin/pip install py-spy`: a
# development tool, not installed by `make deps`); sampling slows the ranks by a few per cent.
set -euo pipefail
source "$(dirname "$0")/bench_env.sh"
OUT=${1:?OUT directory}; RANKS=${2:?ranks}; shift 2
SPY=${SPY:-$(dirname "$PY")/py-spy}
if [ ! -x "$SPY" ]; then
  echo "spy_profile.sh: py-spy not found at $SPY (install it: $(dirname "$PY")/pip install py-spy)" >&2
  exit 2
fi
mkdir -p "$OUT"
# absolute paths without resolving symbolic links (the venv's python is a link to the system's: resolved,
# it would lose the venv's packages)
abs() { echo "$(cd "$(dirname "$1")" && pwd)/$(basename "$1")"; }
OUT=$(abs "$OUT"); PYA=$(abs "$PY"); SPY=$(abs "$SPY")
"$PY" -m petsc_ssi.app.warmup > /dev/null
# each rank under py-spy, its output named by the rank (OpenMPI's environment); the paths as arguments
mpirun --allow-run-as-root --oversubscribe -n "$RANKS" bash -c \
  'exec "$1" record --native -r 50 -f raw -o "$2/prof.$OMPI_COMM_WORLD_RANK.txt" -- "$3" -m petsc_ssi "${@:4}"' \
  spy "$SPY" "$OUT" "$PYA" "$@" -ssi_output "$OUT/run.h5" -ssi_output_overwrite -log_view > "$OUT/run.log" 2>&1
"$PY" jobscripts/spy_table.py "$OUT/prof.0.txt" ${FILTER:+--filter "$FILTER"} ${TOP:+--top "$TOP"}
