"""Block-sparse (3x3 node blocks) lag matrices in the package's own arrays, as PETSc Mats of type
python (issue 13, item 1).

PETSc's MPIBAIJ keeps its values out of reach of petsc4py, and its MatMatMult with a dense panel
(3.18) is one MatMult per column: a time-blocked history sum would read a block-sparse lag b
times per block of b steps, as the per-step sum does. Here each rank keeps its rows of a lag as a
block CSR (``indptr`` over local node rows, ``indices`` global column nodes, ``data`` (nnzb, 3, 3)),
the same bytes as MPIBAIJ (9 doubles and one int per block; 9 floats and one int, 40 B, for a lag
kept in single precision, ``-ssi_lag_single_from``, whose products still accumulate in double), and
two compiled kernels work on it:

    matvec     y = A x                  (x all-gathered: every column of the local rows)
    panel      R^T += s A X^T           (X: b combined states, each rank's copy; one pass over A)

and ``panel_states`` forms X (or X^T) from the states, one call per matrix.

The Mat (``BSRMat.mat``, type python) answers MatMult and MatMultAdd, so the per-step path, the
step's known-value terms and every other caller are unchanged; ``march`` finds the context with
``context(M)`` and uses the panel kernel. ``-ssi_lags_save`` writes it as MPIBAIJ (``to_baij``,
one lag at a time) and a loaded MPIBAIJ becomes one again (``from_mat``).
"""
import numpy as np
from numba import njit

from ..petsc import init


@njit(cache=True)
def _matvec(indptr, indices, data, x, y):
    for i in range(indptr.size - 1):
        y0 = 0.0
        y1 = 0.0
        y2 = 0.0
        for k in range(indptr[i], indptr[i + 1]):
            c = 3 * indices[k]
            x0, x1, x2 = x[c], x[c + 1], x[c + 2]
            y0 += data[k, 0, 0] * x0 + data[k, 0, 1] * x1 + data[k, 0, 2] * x2
            y1 += data[k, 1, 0] * x0 + data[k, 1, 1] * x1 + data[k, 1, 2] * x2
            y2 += data[k, 2, 0] * x0 + data[k, 2, 1] * x1 + data[k, 2, 2] * x2
        y[3 * i] = y0
        y[3 * i + 1] = y1
        y[3 * i + 2] = y2


@njit(cache=True)
def _panel(indptr, indices, data, XT, RT, sign):
    """RT[3i+p, t] += sign * sum_k data[k, p, q] XT[3 col_k + q, t] (XT: columns x b, C order): per
    block its nine values in registers and the three rows of XT it meets read once."""
    b = XT.shape[1]
    acc0 = np.empty(b)
    acc1 = np.empty(b)
    acc2 = np.empty(b)
    for i in range(indptr.size - 1):
        acc0[:] = 0.0
        acc1[:] = 0.0
        acc2[:] = 0.0
        for k in range(indptr[i], indptr[i + 1]):
            c = 3 * indices[k]
            a00, a01, a02 = data[k, 0, 0], data[k, 0, 1], data[k, 0, 2]
            a10, a11, a12 = data[k, 1, 0], data[k, 1, 1], data[k, 1, 2]
            a20, a21, a22 = data[k, 2, 0], data[k, 2, 1], data[k, 2, 2]
            x0 = XT[c]
            x1 = XT[c + 1]
            x2 = XT[c + 2]
            for t in range(b):
                u0, u1, u2 = x0[t], x1[t], x2[t]
                acc0[t] += a00 * u0 + a01 * u1 + a02 * u2
                acc1[t] += a10 * u0 + a11 * u1 + a12 * u2
                acc2[t] += a20 * u0 + a21 * u1 + a22 * u2
        for t in range(b):
            RT[3 * i, t] += sign * acc0[t]
            RT[3 * i + 1, t] += sign * acc1[t]
            RT[3 * i + 2, t] += sign * acc2[t]


@njit(cache=True)
def panel_states(rep, rows, slots, coefs, out, transposed):
    """The panel of combined states: out[rows[t]] += coefs[t] * rep[slots[t]] for t in order
    (``transposed``: out is columns x b, out[:, rows[t]] instead). The same operations, in the
    same order, as the numpy loop it replaces (a product rounded, then a sum rounded; numba
    contracts no multiply-add without fastmath), so the bits are those of that loop; one call per
    matrix instead of one numpy call per term."""
    n = rep.shape[1]
    for t in range(rows.size):
        k = rows[t]
        s = slots[t]
        c = coefs[t]
        if transposed:
            for i in range(n):
                out[i, k] += c * rep[s, i]
        else:
            for i in range(n):
                out[k, i] += c * rep[s, i]


class _Shell:
    """The python Mat's context: MatMult and MatMultAdd through ``_matvec``."""

    def __init__(self, bsr):
        self.bsr = bsr
        self.scatter = None

    def _gather(self, x):
        PETSc = init()
        if self.scatter is None:
            self.scatter, self.xall = PETSc.Scatter.toAll(x)
        self.scatter.scatter(x, self.xall, addv=PETSc.InsertMode.INSERT_VALUES)
        return self.xall.getArray(readonly=True)

    def mult(self, mat, x, y):
        b = self.bsr
        _matvec(b.indptr, b.indices, b.data, self._gather(x), y.getArray())

    def multAdd(self, mat, x, v, y):
        b = self.bsr
        xa = self._gather(x)
        tmp = np.empty(3 * (b.indptr.size - 1))
        _matvec(b.indptr, b.indices, b.data, xa, tmp)
        if v.handle != y.handle:
            v.copy(y)
        y.getArray()[:] += tmp


class BSRMat:
    """This rank's rows of a block-sparse lag and its python Mat (``mat``)."""

    def __init__(self, comm, indptr, indices, data, nrow_loc, ncol_loc, nrow_glob, ncol_glob):
        PETSc = init()
        self.indptr = np.ascontiguousarray(indptr, dtype=np.int64)
        self.indices = np.ascontiguousarray(indices, dtype=np.int32)
        dt = np.float32 if np.asarray(data).dtype == np.float32 else np.float64    # single: -ssi_lag_single_from
        self.data = np.ascontiguousarray(np.asarray(data, dtype=dt).reshape(-1, 3, 3))
        self.sizes = ((3 * nrow_loc, 3 * nrow_glob), (3 * ncol_loc, 3 * ncol_glob))
        self.comm = comm
        self.mat = PETSc.Mat().createPython(self.sizes, context=_Shell(self), comm=comm)
        self.mat.setUp()

    @property
    def nbytes(self):
        """Bytes this rank stores (values and indices)."""
        return self.data.nbytes + self.indices.nbytes + self.indptr.nbytes

    def to_single(self):
        """Keep the values in float32 (a loaded lag of a -ssi_lag_single_from run); returns self."""
        self.data = np.ascontiguousarray(self.data, dtype=np.float32)
        return self

    def panel(self, XT, RT, sign):
        """RT += sign * (local rows) @ XT: XT (all columns x b), RT (local rows x b), C order."""
        _panel(self.indptr, self.indices, self.data, XT, RT, float(sign))

    def to_baij(self):
        """Collective: the same rows as a PETSc MPIBAIJ (bs 3), for -ssi_lags_save."""
        PETSc = init()
        A = PETSc.Mat().createBAIJ(size=self.sizes, bsize=3,
                                   csr=(self.indptr.astype(np.int32), self.indices,
                                        np.asarray(self.data.reshape(-1), dtype=PETSc.ScalarType)),
                                   comm=self.comm)
        A.assemble()
        return A


def context(M):
    """The BSRMat behind a python Mat, or None (any other Mat)."""
    if M is None or M.getType() != "python":
        return None
    ctx = M.getPythonContext()
    return ctx.bsr if isinstance(ctx, _Shell) else None


def from_csr(comm, nrow_loc, ncol_loc, nrow_glob, ncol_glob, indptr, indices, values):
    """The python Mat of node-block CSR arrays of the local rows (columns sorted or not)."""
    return BSRMat(comm, indptr, indices, values, nrow_loc, ncol_loc, nrow_glob, ncol_glob).mat


def from_mat(M):
    """Collective: a loaded MPIBAIJ (bs 3) as a python Mat of the same rows (M destroyed)."""
    (m, mg), (n, ng) = M.getSizes()
    r0, r1 = M.getOwnershipRange()
    ai, aj, av = M.getValuesCSR()           # scalar CSR of the local rows: each 3x3 block spans
    nloc = (r1 - r0) // 3                   # three rows with the same column pattern
    ai = np.asarray(ai, np.int64)
    rl = np.diff(ai).reshape(nloc, 3)
    if np.any(rl != rl[:, :1]) or np.any(rl[:, 0] % 3):
        raise ValueError("from_mat: not a 3x3 block matrix")
    nbr = rl[:, 0] // 3                     # blocks per node row
    indptr = np.zeros(nloc + 1, np.int64)
    np.cumsum(nbr, out=indptr[1:])
    row = np.repeat(np.arange(nloc), nbr)
    off = 3 * (np.arange(indptr[-1]) - indptr[row])          # a block's place in its scalar rows
    start = ai[3 * row[:, None] + np.arange(3)] + off[:, None]    # (blocks, p): its first entry in row p
    cols = (np.asarray(aj)[start[:, 0]] // 3).astype(np.int32)
    vals = np.asarray(av)[start[:, :, None] + np.arange(3)]       # (blocks, p, q)
    comm = M.getComm()
    M.destroy()
    return from_csr(comm, nloc, n // 3, mg // 3, ng // 3, indptr, cols, vals)
