# Environment of the runs/ scripts (sourced, not run): the repository root as the working directory, the
# project's python (PY), one BLAS thread per rank, OpenMPI as root, and REC, the earthquake record of
# runs/seismic and runs/basement (ObsPy's K-NET test record, in ObsPy's installed package).
cd "$(dirname "${BASH_SOURCE[0]}")/.."
PY=${PY:-.venv/bin/python}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OPENBLAS_NUM_THREADS=1
REC=$("$PY" -c "import obspy, os; print(os.path.join(os.path.dirname(obspy.__file__), 'io', 'nied', 'tests', 'data', 'test.knet'))")
