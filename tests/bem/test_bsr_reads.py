"""A block-sparse lag's python Mat over the ranks moves only the columns its rows hold blocks in (``bsr.reader``):
a short lag (the step matrix's lags 1-2, the toeplitz store's only Mats) takes its rows' nodes and a halo, not
the whole vector, into a vector of every column (one copy: remapped indices would cost more than they save) or
compacted (many copies, the march's, ``depth``); a lag whose rows read every column, PETSc's all-gather. The
products equal the matrix's with all of x, bit for bit, every way."""
import shutil

import pytest

from helpers import ranks_json

pytestmark = pytest.mark.mpi

CODE = r'''
import json
import numpy as np
from mpi4py import MPI
from petsc_ssi.petsc import init
from petsc_ssi.bem import bsr
PETSc = init()
comm = MPI.COMM_WORLD
N = 240
out = {}
for name, reach in (("short", 5), ("wide", 200)):
    # every rank builds the same global matrix (seeded), keeps its rows
    rng = np.random.default_rng(7)
    cols = [rng.permutation(np.arange(max(0, g - reach), min(N, g + reach + 1))) for g in range(N)]
    vals = [rng.standard_normal((len(c), 9)) for c in cols]
    diag = rng.standard_normal((N, 3, 3))
    x = rng.standard_normal(3 * N)
    lo, hi = (N * comm.rank) // comm.size, (N * (comm.rank + 1)) // comm.size
    ip = np.concatenate([[0], np.cumsum([len(c) for c in cols[lo:hi]])]).astype(np.int64)
    ind = np.concatenate(cols[lo:hi]).astype(np.int32) if hi > lo else np.zeros(0, np.int32)
    val = np.concatenate(vals[lo:hi]) if hi > lo else np.zeros((0, 9))
    M = bsr.from_csr(PETSc.COMM_WORLD, hi - lo, hi - lo, N, N, ip, ind, val, bsr.FULL, diag[lo:hi], lo)
    X = M.createVecRight()
    X.setArray(x[3 * lo:3 * hi])
    Y = M.createVecLeft()
    M.mult(X, Y)
    Z = M.createVecLeft()
    Z.set(1.0)
    M.multAdd(X, Z, Z)
    sh = M.getPythonContext()
    # the columns the scatter wrote: every nonzero of a vector scattered from all ones
    O = M.createVecRight()
    O.set(1.0)
    sh._gather(O)
    wrote = int(np.count_nonzero(sh.xall.getArray()))
    sh._gather(X)
    # many copies (the march's depth): compacted, the context remapped
    C = [bsr.context(M)]
    sc, seq, (rc,), _ = bsr.reader(C, X, depth=37)
    sc.scatter(X, seq, addv=PETSc.InsertMode.INSERT_VALUES)
    yc = np.empty(3 * (hi - lo))
    rc.matvec(seq.getArray(readonly=True), yc)
    # the reference: the same rows' products with every column, as before (a BSRMat's matvec of all of x)
    ref = np.empty(3 * (hi - lo))
    bsr.context(M).matvec(x, ref)
    out[name] = dict(wrote=wrote, size=int(sh.xall.getSize()), compact=int(seq.getSize()), whole=3 * N,
                     same=bool(np.array_equal(Y.getArray(), ref)), same_add=bool(np.array_equal(Z.getArray(), ref + 1.0)),
                     same_compact=bool(np.array_equal(yc, ref)))
every = comm.gather(out, root=0)          # (one line from rank 0: mpirun may run the ranks' lines together)
if comm.rank == 0:
    print("READS" + json.dumps(every), flush=True)
'''


@pytest.mark.skipif(shutil.which("mpirun") is None, reason="needs mpirun")
@pytest.mark.parametrize("n", [2, 3])
def test_a_short_lag_reads_its_halo_and_a_wide_one_every_column(n):
    per_rank = ranks_json(CODE, n, "READS")
    assert len(per_rank) == n
    N = 240
    for r, got in enumerate(per_rank):
        rows = (N * (r + 1)) // n - (N * r) // n
        s, w = got["short"], got["wide"]
        for k in (s, w):
            assert k["same"] and k["same_add"] and k["same_compact"], got
        # the short lag: the rank's rows and at most 5 nodes either side, 3 DOFs a node; one copy: of every column
        # (written there only) or compacted, by the rule; 37 copies: compacted
        assert 3 * rows <= s["wrote"] <= 3 * (rows + 10) and s["size"] in (s["whole"], s["wrote"]), (r, s)
        assert s["compact"] == s["wrote"], (r, s)
        assert w["wrote"] == w["size"] == w["compact"] == w["whole"], (r, w)
