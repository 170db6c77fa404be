import os
import sys

os.environ.setdefault("PETSC_DIR", "/usr/lib/petscdir/petsc3.18/x86_64-linux-gnu-real")
os.environ.setdefault("SLEPC_DIR", "/usr/lib/slepcdir/slepc3.18/x86_64-linux-gnu-real")
os.environ.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")
os.environ.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
# `make test` runs three pytest workers (pytest-xdist), so mpiruns may share the 2 cores: their
# ranks yield in MPI waits instead of spinning against each other (results do not depend on it)
os.environ.setdefault("OMPI_MCA_mpi_yield_when_idle", "1")
# After a rank exits non-zero, OpenMPI's mpirun signals the job's processes and waits
# odls_base_sigkill_timeout (1 s, twice) before it returns: 2.0 of the 3.7 s of every refused two-rank
# run (`time mpirun -n 1 python -c "import sys; sys.exit(2)"`: 2.1 s, 0.1 s with 0). The refusal tests
# (about a hundred) assert the exit status, which mpirun still returns (2); the ranks of a refused run
# exit by themselves (the Barrier in app/cli.py, then MPI_Finalize's fence), so nothing they print is cut.
# Where a run calls MPI_Abort (an I/O failure: app/cli.py, petsc.collective_io) the other ranks are now
# killed at once, before rank 0's SIGTERM handler can remove the output's lock (io/lock.py): the next run
# takes the stale lock over with a warning, as after a kill. (Tests that time mpirun's own signal
# forwarding set the timeout on their command line, which overrides this: test_checkpoint.py.)
os.environ.setdefault("OMPI_MCA_odls_base_sigkill_timeout", "0")
# A one-rank run started without mpirun (most of the suite's CLI tests, and the workers' in-process runs) is an MPI
# singleton. Not isolated (OMPI_MCA_ess_singleton_isolated, set here from 2026-12-02 to 12-03, for about a tenth of
# a second a refused run that a later timing did not confirm): isolated singletons all take the one session
# directory /tmp/ompi.<host>.0/jf.0/1, where MPI-IO's shared file pointers keep a file named after the file opened
# (p000000.h5_cid--1-0.sm for every output's first part), so concurrent workers' runs overwrite and remove each
# other's; most likely why H5Fcreate once failed in MPI_File_open (MPI_ERR_OTHER) in an in-process run of a CI
# run of 2026-12-03 with three workers. `python jobscripts/singleton_mpiio.py` (6 concurrent singletons, 300 HDF5
# files each, of the same names): isolated, 0-48 "unable to open file for mmap" lines a process in 3.25 s; not
# isolated, none, in 2.74 s.
os.environ.pop("OMPI_MCA_ess_singleton_isolated", None)
# The suite starts about a thousand petsc-ssi processes (mpirun ranks counted). Where the shell sets
# PYTHONDONTWRITEBYTECODE (this machine and CI's do), each one compiled the ~90 modules it imports from
# source again: 0.24 s of every start (cProfile of a 3-step run: 102 compile() calls, 2.0 s in all).
# The tests' processes keep their bytecode outside the tree instead (Python writes .pyc atomically, so
# concurrent workers and ranks are safe); the results do not depend on it.
os.environ.pop("PYTHONDONTWRITEBYTECODE", None)
os.environ.setdefault("PYTHONPYCACHEPREFIX", os.path.join(os.path.expanduser("~"), ".cache", "petsc_ssi", "pycache"))
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# One mpirun at a time across the pytest workers (tests/bin/mpirun, first on PATH, which runs the mpirun found
# here: see that file), where there is an mpirun (without one, the tests that need it skip as before).
_BIN = os.path.join(ROOT, "tests", "bin")
if not os.environ.get("PETSC_SSI_REAL_MPIRUN"):
    for _d in os.environ.get("PATH", "").split(os.pathsep):      # the first mpirun that is not a shim like ours
        _m = os.path.join(_d or ".", "mpirun")
        if os.path.isfile(_m) and os.access(_m, os.X_OK):
            with open(_m, "rb") as _fh:
                if b"PETSC_SSI_REAL_MPIRUN" not in _fh.read(4096):
                    os.environ["PETSC_SSI_REAL_MPIRUN"] = os.path.abspath(_m)
                    break
if os.environ.get("PETSC_SSI_REAL_MPIRUN"):
    os.environ["PATH"] = _BIN + os.pathsep + os.environ.get("PATH", "")
if ROOT not in sys.path:
    sys.path.insert(0, ROOT)


# ---------------------------------------------------------------- test tiers (pytest.ini)
# Each test file declares its tier (``pytestmark = pytest.mark.unit``, ``run`` or ``mpi``), and a heavy
# case carries ``@pytest.mark.slow`` (or ``pytest.param(..., marks=pytest.mark.slow)``) beside a
# comment naming the smaller sibling that stays in ``make test``. A test without a tier is an error.
import pytest as _pytest

TIERS = ("unit", "run", "mpi")


def pytest_collection_modifyitems(config, items):
    """Refuse a test file that declares no tier (or more than one)."""
    bad = {}
    for item in items:
        tiers = [t for t in TIERS if item.get_closest_marker(t)]
        if len(tiers) != 1:
            bad[str(item.fspath)] = tiers
    if bad:
        raise _pytest.UsageError("test files must declare exactly one tier (pytestmark = pytest.mark.unit, run or "
                                 "mpi): " + "; ".join(f"{os.path.relpath(k, ROOT)} {v}" for k, v in sorted(bad.items())))
