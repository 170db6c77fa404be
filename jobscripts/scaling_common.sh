# Shared by strong_scaling.sh and weak_scaling.sh (sourced, not run).
# Environment (all optional):
#   PY        python with petsc_ssi            (default .venv/bin/python if present, else python3)
#   MPIEXEC   launcher: mpirun | srun | mpiexec (default: srun inside a SLURM job, else mpirun)
#   MPIFLAGS  extra launcher flags
#   OUT       log directory                    (default out/scaling)
#   CORES     cores per node, to flag oversubscribed runs (default: SLURM/PBS value or nproc)
#   LOCK      command prefix for each run, e.g. "flock /tmp/ssi_cpu.lock" on a shared machine
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
if [ -z "${PY:-}" ]; then
  if [ -x .venv/bin/python ]; then PY=.venv/bin/python; else PY=python3; fi
fi
if [ -z "${MPIEXEC:-}" ]; then
  if [ -n "${SLURM_JOB_ID:-}" ]; then MPIEXEC=srun; else MPIEXEC=mpirun; fi
fi
MPIFLAGS=${MPIFLAGS:-}
OUT=${OUT:-out/scaling}
# (nproc without OMP_NUM_THREADS/OMP_THREAD_LIMIT: GNU nproc reports those instead of the cores)
CORES=${CORES:-${SLURM_CPUS_ON_NODE:-${NCPUS:-$(env -u OMP_NUM_THREADS -u OMP_THREAD_LIMIT nproc)}}}
LOCK=${LOCK:-}
mkdir -p "$OUT"
export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1
if [ -d /usr/lib/petscdir/petsc3.18/x86_64-linux-gnu-real ]; then
  export PETSC_DIR=${PETSC_DIR:-/usr/lib/petscdir/petsc3.18/x86_64-linux-gnu-real}
fi
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export NUMBA_CACHE_DIR=${NUMBA_CACHE_DIR:-$PWD/.numba_cache}

# run_case LOG NRANKS NODES_PER_RANK_INFO -- petsc_ssi arguments...
# Writes a header line (study, case, ranks, cores, oversubscribed) and the
# -log_view/-memory_view output of one run to LOG.
run_case() {
  local log=$1 n=$2 study=$3 case=$4; shift 4
  local launch=() over=0
  local nodes=${SLURM_JOB_NUM_NODES:-${PBS_NUM_NODES:-1}}
  if [ $((n)) -gt $((CORES * nodes)) ]; then over=1; fi
  case "$MPIEXEC" in
    *mpirun*|*mpiexec*)
      launch=("$MPIEXEC" -n "$n")
      if "$MPIEXEC" --version 2>&1 | grep -qi "open mpi"; then
        launch+=(--allow-run-as-root)
        [ "$over" = 1 ] && launch+=(--oversubscribe)
      fi ;;
    *srun*) launch=("$MPIEXEC" -n "$n") ;;
    *) launch=("$MPIEXEC" -n "$n") ;;
  esac
  # shellcheck disable=SC2206
  launch+=($MPIFLAGS)
  echo "[scaling] $study $case on $n rank(s)$([ "$over" = 1 ] && echo " (oversubscribed: $CORES cores per node)") -> $log"
  {
    echo "# scaling: study=$study case=$case ranks=$n nodes=$nodes cores_per_node=$CORES oversubscribed=$over host=$(hostname) date=$(date -u +%FT%TZ)"
    $LOCK "${launch[@]}" "$PY" -m petsc_ssi "$@" -ssi_output_overwrite -log_view -memory_view 2>&1
  } > "$log"
}
