"""``python -m petsc_ssi.app.warmup``: compile the numba kernels into the cache ahead of the first run.

The BEM kernels (``bem/kernels.py``, ``quadrature.py``, ``assemble.py``, ``bsr.py``) are compiled by numba
the first time a version of the sources runs on a machine (about a minute: 68 s in a fresh clone on a 2-core virtual machine, 2026-12-03) and cached under
``NUMBA_CACHE_DIR`` (``~/.cache/petsc_ssi/numba/<hash of the sources>``). This runs tiny BEM
cases on one process (the block-sparse, toeplitz and dense lag stores) so that they are compiled now, while a
second process compiles the kernels those runs do not need first (``--kernels``), says so, and exits at once when the cache is
already warm for this checkout: when the warm-up itself has finished in it for these files at this
path (the file ``WARM_MARK-<checkout key>`` in the cache: numba keys its index by the source file's
path and stamps it with its mtime and size, so a second checkout of the same sources compiles
again; ``petsc_ssi.checkout_key``), not merely when some run compiled some kernels there. ``make
deps`` calls it.
"""
import os
import subprocess
import sys
import tempfile
import time

from ..launch import child_env


WARM_MARK = "warmup-done"
# the warm-up's first run (-ssi_<key> <value>; its output in a scratch directory): a tiny BEM case on the block-sparse
# lag store, time-blocked (the block-sparse kernels, bem/bsr.py, too); the same then on the toeplitz store
# (jobscripts/compile_times.py times these two on an empty cache)
RUN_OPTS = {"problem": "bem", "mesh_size": "4,4", "mesh_h": 1.0, "mesh_patch": "1,1", "load_group": "load",
            "load_p0": 1000, "dt": 0.005, "t_end": 0.02, "output_stride": 0, "warn_beta": 0, "output_overwrite": 1,
            "lag_storage": "sparse", "history_block": 2}


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    if argv == ["--kernels"]:                  # the helper process of a warm-up (below)
        _single_kernels()
        _test_kernels()
        return 0
    import petsc_ssi
    d = os.environ.get("NUMBA_CACHE_DIR", "")
    mark = os.path.join(d, f"{WARM_MARK}-{petsc_ssi.checkout_key()}")
    if os.path.exists(mark) and petsc_ssi.numba_cache_warm():
        print(f"[warmup] numba cache is warm ({d}, this checkout: {os.path.dirname(petsc_ssi.__file__)})")
        return 0
    if petsc_ssi.numba_cache_warm():
        print(f"[warmup] numba cache partly warm ({d}): loading the kernels, compiling what a run has not", flush=True)
    else:
        print(f"[warmup] compiling the BEM kernels with numba into {d} (minutes, once per version of the sources)",
              flush=True)
    os.environ["PETSC_SSI_WARMUP"] = "1"       # the run below does not announce the compile again
    t0 = time.perf_counter()
    # numba compiles on one core: the kernels no run here needs first (the block-sparse products of every
    # pattern and value type, the toeplitz store's lanes, the unit tests' own versions) compile in a second
    # process meanwhile (one core each; the assembly's kernels, most of the time, here). Both write the
    # cache; what the helper compiled is loaded below, and what it did not (it failed, or numba's index
    # lost an entry to the other process's write) is compiled then.
    helper = None
    if (os.cpu_count() or 1) > 1:
        helper = subprocess.Popen([sys.executable, "-m", "petsc_ssi.app.warmup", "--kernels"],
                                  stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, env=child_env())
    try:
        _runs()
    except BaseException:
        if helper is not None:           # (the parent stopped: no helper left compiling behind it)
            helper.kill()
            helper.wait()
        raise
    if helper is not None:
        _, err = helper.communicate()
        if helper.returncode:
            last = (err or "").strip().splitlines()
            print(f"[warmup] the helper process stopped ({helper.returncode}{': ' + last[-1] if last else ''}): "
                  "its kernels compile here", flush=True)
    _single_kernels()                   # loaded (compiled by the helper), or compiled now
    _test_kernels()
    os.makedirs(d, exist_ok=True)
    with open(mark, "w") as fh:
        fh.write(f"petsc_ssi {petsc_ssi.__version__}: every kernel of the warm-up is in this cache for the "
                 f"checkout {os.path.dirname(petsc_ssi.__file__)}\n")
    print(f"[warmup] done in {time.perf_counter() - t0:.0f} s")
    return 0


def _runs():
    """The warm-up's tiny BEM runs (block-sparse, toeplitz and dense lag stores; an area load) and the shared
    element cache's kernels, in this process."""
    from ..petsc import init
    PETSc = init([sys.argv[0]])
    from .. import options
    from .kinds import run_bem
    with tempfile.TemporaryDirectory() as tmp:
        opts = dict(RUN_OPTS, output=os.path.join(tmp, "w.h5"))
        db = PETSc.Options()
        for k, v in opts.items():
            db.setValue("ssi_" + k, str(v))
        run_bem(options.resolve(("common", "bem")))
        db.setValue("ssi_lag_store", "toeplitz")              # the toeplitz store's kernels (bem/toeplitz.py)
        run_bem(options.resolve(("common", "bem")))
        db.delValue("ssi_lag_store")
        db.setValue("ssi_lag_storage", "dense")               # dense lags and a load over an area no cell holds
        db.setValue("ssi_load_group", "")                     # (bem/lagmats.py, sources/area.py)
        db.setValue("ssi_load_area", "0.25,0.75,0.25,0.75")
        run_bem(options.resolve(("common", "bem")))
        for k in list(opts) + ["load_area"]:
            db.delValue("ssi_" + k)
        _shared_cache_kernels(PETSc)


def _shared_cache_kernels(PETSc):
    """The element-cache kernels a run on more than one rank uses (model.LagSet._share_cache, on
    one process here): without this, the first parallel run compiled them in its assembly."""
    import numpy as np
    from ..mesh.surface import grid
    from ..bem.lagset import Material, Regions, LagSet
    from ..bem.assemble import new_cache
    mesh = grid(2.0, 2.0, 1.0, (1.0, 1.0))
    opts = {"gauss": 2, "singular_order": 12, "subdivisions": 4, "near_factor": 2.0, "max_subdivisions": 32,
            "cache": True}
    ls = LagSet(PETSc.COMM_SELF, mesh, Material(548.0, 316.0, 2000.0), 0.005, 3,
                Regions(mesh, load_elems=mesh.groups["load"]), [], opts)
    for flat in (True, False):                   # the flat surface's block patterns and the full one
        ls.mH, ls.mG = (4, 5) if flat else (9, 9)
        pk = ls.kernel_packs(1, 3, 0.0)
        ls._share_cache(new_cache(), pk, ls.kernels(pk[3]), 1.0 / (1e-9 * float(ls.Vh.min())), np.zeros(2),
                        ls.candidates(ls.rows, pk))


def _single_kernels():
    """The block-sparse kernels on float32 values (-ssi_lag_single_from; numba compiles one version
    per value type), the toeplitz store's lane products on single kept states (-ssi_toeplitz_precision
    single), and the block-sparse kernels on a read-only x (the python Mat's products; without this the first coupled
    run compiled one), the toeplitz kernels' fill from real and complex spectra (a grid's point symmetry decides
    which a run takes), a state put on the toeplitz store's grid (read-only or not), triplets appended to a lag's
    blocks (Buckets.add), a dense lag of the full pattern filled (a surface that is not one plane, -ssi_lag_storage
    dense), and the coupled step's product with mirrored interface columns. The helper process of a warm-up
    compiles them while the runs of ``main`` compile the assembly."""
    import numpy as np
    from ..bem import bsr
    indptr, cols = np.array([0, 1], np.int64), np.zeros(1, np.int32)
    x = np.ones(3)
    x.flags.writeable = False                # the python Mat's products read a read-only gathered x
    for m in bsr.PATTERNS:                   # every block pattern (flat H and G, full)
        for dt in (np.float32, np.float64):  # (double lags: the coupled runs)
            data = np.ones((1, m), dt)
            for xx in (np.ones(3), x):
                bsr.matvec(m, indptr, cols, data, xx, np.zeros(3))
            for w in (2, bsr.PAIR_FROM):
                bsr.panel(m, indptr, cols, data, np.ones((3, w)), np.zeros((3, w)), 1.0)
    from ..bem.lanes import lane_products, put_state_grid, unpack_grid, FW
    K, out = np.zeros((1, 9, 1, 2, FW)), np.zeros((1, 1, 1, 2, FW))
    lane_products(K, 0, np.zeros((1, 1, 9, 2, FW), np.float32), 0, 1, 1, 1, out, 0)   # (single kept states)
    for dt in (np.float64, np.float32):          # (the toeplitz store's per-step helpers; single kept states)
        put_state_grid(np.zeros((9, 3, 1, 1), complex), np.zeros((1, 1, 9, 2, FW), dt), np.zeros((1, 1, 18, 2, FW), dt), 0)
    unpack_grid(np.zeros((1, 1, 12, 2, FW)), 8, np.zeros((0, 0), complex), np.zeros((12, 1, 1), complex))
    from ..bem.lanes import put_spectra           # (the toeplitz kernels' fill: real and complex spectra)
    idx, sel = np.zeros((1, 1), np.int64), np.zeros(1, np.int64)
    for kp, dt in ((1, np.float64), (2, np.complex128)):
        put_spectra(np.zeros((1, 1, 1, kp, FW)), 0, np.zeros((1, 1, 1), dt), sel, idx, np.ones(1))
    from ..bem.lanes import scatter_slots         # (a state onto the toeplitz store's grid: read-only or not)
    for xx in (np.ones((1, 3)), x.reshape(1, 3)):
        scatter_slots(xx, np.zeros((1, 9), np.int64), np.ones((1, 3)), np.zeros(1, np.int64), np.zeros(1, np.int64),
                      np.zeros((9, 3, 1, 1)))
    from ..bem.lagset import Buckets              # (triplets appended to a lag's blocks: Buckets.add)
    Buckets(2, np.arange(1), 1).add([0], [1], [0], np.ones((1, 9)))
    from ..bem.lagmats import _scatter_dense      # (a dense lag of the full pattern: a surface not one plane)
    _scatter_dense(np.zeros((3, 3), order="F"), np.zeros(1, np.int64), np.zeros(1, np.int32), np.zeros((1, 3, 3)))
    from ..coupling.columns import _rows4         # (the coupled step's mirrored interface columns)
    _rows4(np.ones((2, 3)), np.ones((4, 3)), np.zeros((2, 4)))
    diag = np.ones((1, 3, 3))
    bsr._diag_add(diag, 0, x, np.zeros(3), 1.0)
    bsr._diag_add(diag, 0, np.ones(3), np.zeros(3), 1.0)
    bsr._diag_panel(diag, 0, np.ones((3, 2)), np.zeros((3, 2)), 1.0)


def _test_kernels():
    """The kernels the unit tests call straight from Python with no run calling them so (tests/bem/test_kernels.py
    and others: numba compiles a function called from Python on its own, apart from its inlined copies in
    the assembly kernels): compiled here, not in a test."""
    import numpy as np
    from ..bem import kernels as K
    g, n, out = np.array([0.6, 0.8, 0.0]), np.array([0.0, 0.0, 1.0]), np.zeros((3, 3))
    A, B, dA, dB = K.ab2(1.0, 0.01, 2.0, 1.0)                      # (r, t, alpha, beta)
    K.f1_tensor(g, 1.0, 0.01, 2.0, 1.0, 1.0, out)                  # (g, r, t, alpha, beta, rho, out)
    K.t2_tensor(g, n, 1.0, 0.01, 2.0, 1.0, 1.0, out)
    K.traction_from_ab(g, n, 1.0, A, B, dA, dB, 2.0, 1.0, out)     # (g, n, r, A, B, dA, dB, lam, mu, out)

if __name__ == "__main__":
    sys.exit(main())
