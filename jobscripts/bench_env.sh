# Environment of the benchmark scripts (sourced, not run): repository root as the
# working directory, the project's python, Debian's PETSc/SLEPc unless set, one
# BLAS thread per rank, OpenMPI as root, the shared numba cache.
cd "$(dirname "${BASH_SOURCE[0]}")/.."
PY=${PY:-.venv/bin/python}
export PETSC_DIR=${PETSC_DIR:-/usr/lib/petscdir/petsc3.18/x86_64-linux-gnu-real}
export SLEPC_DIR=${SLEPC_DIR:-/usr/lib/slepcdir/slepc3.18/x86_64-linux-gnu-real}
export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export NUMBA_CACHE_DIR=${NUMBA_CACHE_DIR:-$PWD/.numba_cache}

# before_worktree COMMIT [CLEANUP]: the code at COMMIT in a git worktree $WT for before/after
# benchmarks (removed on exit, after the shell command CLEANUP), ROOT the repository; the old code's
# numba kernels are cached apart in $BEFORE_CACHE (the worktree's files are new to numba's index:
# without its own cache the first timed run would compile them); both caches are warmed.
before_worktree() {
  ROOT=$PWD
  WT=$(mktemp -d /tmp/petsc_ssi-before.XXXX)
  git worktree add --detach "$WT" "$1" > /dev/null
  # shellcheck disable=SC2064
  trap "git worktree remove --force '$WT'; ${2:-:}" EXIT
  export BEFORE_CACHE="$WT/.numba_cache"
  (cd "$WT" && NUMBA_CACHE_DIR="$BEFORE_CACHE" "$ROOT/$PY" -m petsc_ssi.warmup) && "$PY" -m petsc_ssi.warmup
}
