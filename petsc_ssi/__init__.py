"""petsc_ssi: parallel time-domain FEM-BEM soil-structure interaction on PETSc.

Implements Romero, Galvin and Dominguez, "3D non-linear time domain FEM-BEM
approach to soil-structure interaction problems": a time-domain BEM for the
elastic half-space (nine-node quadrilaterals), a FEM structure integrated with
implicit Green's functions, and their coupling with unilateral contact: an
interface-implicit step (the default, ``-ssi_coupling implicit``) or the paper's
staggered step (``-ssi_coupling staggered``).

Import order matters: ``petsc_ssi.petsc.init()`` must run (it calls
``petsc4py.init(sys.argv)``) before anything imports ``petsc4py.PETSc``, so
every command-line option reaches the options database. The command line
``petsc-ssi`` does this; library users call it first.
"""
import hashlib as _hashlib
import os as _os
import warnings as _warnings

# Debian's python3-matplotlib (pulled in by ParaView) puts its mpl_toolkits beside the venv's
# matplotlib; matplotlib then warns on import that it cannot import Axes3D. petsc_ssi draws no 3D
# axes: that warning says nothing about its plots.
_warnings.filterwarnings("ignore", message="Unable to import Axes3D", category=UserWarning)

__version__ = "0.1.0"


def _numba_cache_dir():
    """Key numba's on-disk cache on a hash of this package's sources.

    numba's cache of a compiled function does not notice edits to the
    functions it inlines from other modules, so a stale kernel could run
    after an upgrade. A per-source-hash directory makes that impossible.
    """
    here = _os.path.dirname(_os.path.abspath(__file__))
    h = _hashlib.sha1(__version__.encode())
    for root, _, files in sorted(_os.walk(here)):
        for f in sorted(files):
            if f.endswith(".py"):
                with open(_os.path.join(root, f), "rb") as fh:
                    src = fh.read()
                if b"njit" in src:     # only modules with compiled code matter
                    h.update(f.encode() + src)
    base = _os.environ.get("NUMBA_CACHE_DIR") or _os.path.join(
        _os.path.expanduser("~"), ".cache", "petsc_ssi", "numba")
    key = h.hexdigest()[:12]
    if _os.path.basename(_os.path.normpath(base)) == key:
        return base             # already this version's (inherited from a parent process that set it)
    return _os.path.join(base, key)


if "numba" not in __import__("sys").modules:
    _os.environ["NUMBA_CACHE_DIR"] = _numba_cache_dir()


def numba_cache_warm():
    """Whether numba's cache for this version of the sources holds compiled kernels (else the
    first BEM assembly compiles them: about a minute; ``python -m petsc_ssi.app.warmup`` does it
    ahead, and ``make deps`` runs that)."""
    d = _os.environ.get("NUMBA_CACHE_DIR", "")
    for _, _, files in _os.walk(d):
        if any(f.endswith(".nbi") for f in files):
            return True
    return False
