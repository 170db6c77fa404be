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
