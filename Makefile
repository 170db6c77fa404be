# petsc_ssi: everything a fresh Debian 12 machine needs, then demo and tests.
#   make demo   install what is missing, run the Pekeris demo (HDF5, XDMF, PNG)
#   make test   install what is missing, run the test suite
SHELL := /bin/bash
VENV ?= .venv
PY := $(VENV)/bin/python
PETSC_DIR ?= /usr/lib/petscdir/petsc3.18/x86_64-linux-gnu-real
SLEPC_DIR ?= /usr/lib/slepcdir/slepc3.18/x86_64-linux-gnu-real
export PETSC_DIR SLEPC_DIR
export OMPI_ALLOW_RUN_AS_ROOT := 1
export OMPI_ALLOW_RUN_AS_ROOT_CONFIRM := 1
export OPENBLAS_NUM_THREADS ?= 1
export OMP_NUM_THREADS ?= 1
# numba's cache: ~/.cache/petsc_ssi/numba/<hash of the sources> (petsc_ssi/__init__.py), the same
# for make and for direct calls; `make deps` fills it (petsc_ssi/app/warmup.py)
APT_PKGS := python3-petsc4py python3-petsc4py-real3.18 python3-mpi4py python3-h5py-mpi \
            python3-slepc4py python3-slepc4py-real3.18 python3-scipy python3-venv \
            openmpi-bin libglu1-mesa libxcursor1 libxft2 libxinerama1 libfftw3-dev
# mpi4py-fft: the toeplitz store's distributed FFTs (petsc_ssi/bem/pfft.py); it builds against FFTW
# (libfftw3-dev above)
PIP_PKGS := numba gmsh "matplotlib>=3.7" pytest pytest-timeout pytest-xdist obspy pyflakes mpi4py-fft
# pytest workers of `make test` (pytest-xdist, whole test files to a worker): the suite is mostly
# serial Python and short mpiruns, so 2 workers on a 2-core machine took it from 900-940 s to 545 s.
# Its processes wait (mpirun's launch, file locks, I/O) a fifth of the time: on the 2-core machine of
# 2026-12-03 (16:28-17:14, one after another, 1542 tests) 2 workers took 881 s, 3 took 790 s, 4 took 807 s
# (`.venv/bin/python -m pytest -q -m "not slow" -n N --dist loadfile tests`), so 3.
# The workers start one mpirun at a time (tests/bin/mpirun, first on the tests' PATH): two-rank runs sharing the
# 2 cores with another's ranks spun in their waits (the fixed-base modes at -n 2: 33 s in
# the suite without it, 3.9 s with it; the suites' junit times). On
# 2026-12-03 (20:13-20:44, one after another) 3 workers took 584 s without it, 545 s with it (user+sys 1032 s,
# 905 s); 4 workers with it 552 s.
# The slow tier stays serial (its cases hold GBs each). TEST_JOBS=0: no workers, one process.
TEST_JOBS ?= 3
XDIST = $(if $(filter 0,$(TEST_JOBS)),,-n $(TEST_JOBS) --dist loadfile)

.PHONY: all deps demo test test-unit test-mpi test-slow test-all bench clean help-options

all: test

# System packages (PETSc 3.18 with MUMPS/hypre/HDF5 from Debian), then the venv.
.deps/apt.stamp:
	@mkdir -p .deps
	@if ! /usr/bin/python3 -c "import petsc4py, mpi4py, h5py, scipy, slepc4py" 2>/dev/null \
	    || [ ! -f /usr/include/fftw3.h ]; then \
	  echo "[deps] installing Debian packages: $(APT_PKGS)"; \
	  SUDO=$$( [ $$(id -u) -eq 0 ] || echo sudo ); \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq $(APT_PKGS) >/dev/null; \
	fi
	@touch $@

$(VENV)/.stamp: .deps/apt.stamp setup.py Makefile
	@[ -x $(PY) ] || /usr/bin/python3 -m venv --system-site-packages $(VENV)
	@# the list printed through a make variable: its quotes ("matplotlib>=3.7") inside an echo's own
	@# quotes had made the shell redirect into a file named '=3.7 pytest ...'
	@echo '[deps] installing into $(VENV): $(subst ",,$(PIP_PKGS)) (numpy kept at Debian'"'"'s 1.x)'
	@NPV=$$(/usr/bin/python3 -c "import numpy; print(numpy.__version__)"); \
	  $(PY) -m pip install -q --disable-pip-version-check "numpy==$$NPV" $(PIP_PKGS)
	@$(PY) -m pip install -q --disable-pip-version-check --no-deps --no-build-isolation -e .
	@# gmsh's pip script starts '#!/usr/bin/env python' (the system python without the venv active):
	@# point it at the venv's python, so .venv/bin/gmsh runs as it is
	@[ ! -f $(VENV)/bin/gmsh ] || sed -i '1s|^#!.*python.*$$|#!$(abspath $(PY))|' $(VENV)/bin/gmsh
	@$(PY) -c "import petsc4py, mpi4py, mpi4py_fft, numba, gmsh, matplotlib; print('[deps] ok: petsc4py', petsc4py.__version__, 'numba', numba.__version__, 'gmsh', gmsh.__version__)"
	@touch $@

deps: $(VENV)/.stamp
	@$(PY) -m petsc_ssi.app.warmup

demo: deps
	$(PY) -m petsc_ssi.app.demo

# Tiers (pytest.ini, tests/conftest.py): `make test` is every tier but slow (what CI runs);
# the slow tier holds the heavy cases and runs before a release.
# (the 30 slowest tests listed at the end: where the suite's 15-minute budget goes, in every CI log)
test: deps
	$(PY) -m pytest -q -m "not slow" --durations=30 $(XDIST) tests

test-unit: deps
	$(PY) -m pytest -q -m "unit and not slow" $(XDIST) tests

test-mpi: deps
	$(PY) -m pytest -q -m "mpi and not slow" $(XDIST) tests

test-slow: deps
	$(PY) -m pytest -q -m slow tests

test-all: deps
	$(PY) -m pytest -q tests

bench: deps
	bash jobscripts/pekeris_bench.sh

help-options: deps
	$(PY) -m petsc_ssi -help

clean:
	rm -rf .venv .deps .numba_cache build *.egg-info out
