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

# numba's error highlighting (colorama, initialised when numba's compiler machinery loads) writes a
# terminal reset, ESC[0m, at exit whenever stdout is a terminal: under mpirun, which gives every rank
# a pseudo-terminal, each run's output ended with one per rank (issue 30). Messages carry no colours.
_os.environ.setdefault("NUMBA_DISABLE_ERROR_MESSAGE_HIGHLIGHTING", "1")

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


# the modules with numba kernels cached on disk (njit(cache=True)); see numba_cache_status
KERNEL_MODULES = ("petsc_ssi.bem.kernels", "petsc_ssi.bem.quadrature", "petsc_ssi.bem.assemble",
                  "petsc_ssi.bem.lagmats", "petsc_ssi.bem.bsr", "petsc_ssi.bem.lanes")


def numba_cache_status():
    """(fresh, total): of the cached numba kernels (``njit(cache=True)`` in ``KERNEL_MODULES``), how
    many have an entry numba will load for THIS checkout of the sources. numba files its cache
    index under the source file's directory path (``<cache>/<dir>_<sha1 of the path>/``) and
    keeps an entry only while the source's mtime and size match its stamp, so a second checkout
    of the same sources (another path, or files rewritten by git) finds nothing in the cache that
    the first one filled, and compiles every kernel again (30 to 80 s) even though the directory
    of the sources' hash holds kernels. This asks numba's own index of each kernel (imports the
    kernel modules: numba, no compile)."""
    import importlib
    fresh = total = 0
    for name in KERNEL_MODULES:
        mod = importlib.import_module(name)
        for obj in vars(mod).values():
            cf = getattr(getattr(obj, "_cache", None), "_cache_file", None)
            py = getattr(obj, "py_func", None)
            if cf is None or py is None or py.__module__ != name:
                continue
            total += 1
            try:
                fresh += bool(cf._load_index())
            except Exception:          # an unreadable index: numba compiles (and rewrites it)
                pass
    return fresh, total


def numba_cache_warm():
    """Whether numba's cache holds compiled kernels for this checkout of the sources (else the
    first BEM assembly compiles them: about a minute; ``python -m petsc_ssi.app.warmup`` does it
    ahead, and ``make deps`` runs that). Kernels a run of another checkout compiled do not count
    (``numba_cache_status``)."""
    return numba_cache_status()[0] > 0


def checkout_key():
    """A key of this checkout as numba's cache sees it: the package's path and the (mtime, size)
    of every module with cached kernels (what numba's index entries are stamped with)."""
    h = _hashlib.sha1(_os.path.dirname(_os.path.abspath(__file__)).encode())
    for name in KERNEL_MODULES:
        path = _os.path.join(_os.path.dirname(_os.path.abspath(__file__)), *name.split(".")[1:]) + ".py"
        st = _os.stat(path)
        h.update(f"{name} {st.st_mtime!r} {st.st_size}".encode())
    return h.hexdigest()[:12]
