"""Block-sparse (3x3 node blocks) lag matrices in the package's own arrays, as PETSc Mats of type
python (issue 13, item 1), each block stored with only the entries its pattern can hold (issue 29).

PETSc's MPIBAIJ keeps its values out of reach of petsc4py, and its MatMatMult with a dense panel
(3.18) is one MatMult per column: a time-blocked history sum would read a block-sparse lag b
times per block of b steps, as the per-step sum does. Here each rank keeps its rows of a lag as a
block CSR (``indptr`` over local node rows, ``indices`` global column nodes, ``data`` (nnzb, m):
the m entries of each block its ``pattern`` holds), and compiled kernels work on it:

    matvec     y = A x                  (x all-gathered: every column of the local rows)
    panel      R^T += s A X^T           (X: b combined states, each rank's copy; one pass over A)

and ``panel_states`` forms X (or X^T) from the states, one call per matrix.

Block patterns (``PATTERNS``). For a collocation point and an element in one plane (every soil
surface petsc_ssi accepts is the plane z = 0; symmetry images stay in it), r . n = 0 and the
full-space kernels lose most components: the traction kernel (H) only couples in-plane with
out-of-plane components, entries (x,z), (y,z), (z,x), (z,y) (``H4``), the displacement kernel (G)
keeps (x,x), (x,y), (y,x), (y,y), (z,z) (``G5``); every other entry is exactly zero. A matrix whose
pairs are all coplanar stores 4 (H) or 5 (G) numbers a block instead of 9 (``FULL``, the general
path for surfaces that are not flat); its products skip the zeros: the same products and sums in
the same order as the full kernel minus terms that are exact zeros, so the same bits. Bytes per
block: (m values + one int32 column): H 36, G 44, full 76; in single precision
(-ssi_lag_single_from, products still accumulated in double) 20, 24, 40.

The free term (the jump term c_ij of the collocation equation, block diagonal, lag 1 only) is not
in the block pattern: a Mat of H_1 carries it apart (``diag``, one 3x3 block per local row, added
in its products) so that H_1 too keeps the flat pattern.

The Mat (``BSRMat.mat``, type python) answers MatMult and MatMultAdd, so the per-step path, the
step's known-value terms and every other caller are unchanged; ``march`` finds the context with
``context(M)`` and uses the panel kernel. ``-ssi_lags_save`` writes it as an MPIAIJ holding only the
pattern's entries (``to_aij``, one lag at a time; the free term as its own block-diagonal MPIAIJ), and a
loaded one becomes one again (``from_aij``); a full-pattern MPIBAIJ of an older file is read by
``from_mat``.
"""
import numpy as np
from numba import njit

from .simd import h4_4, h4pair_4

from ..petsc import init

# entries (p, q) of a 3x3 block each pattern keeps, in storage order
PATTERNS = {9: tuple((p, q) for p in range(3) for q in range(3)),
            4: ((0, 2), (1, 2), (2, 0), (2, 1)),
            5: ((0, 0), (0, 1), (1, 0), (1, 1), (2, 2))}
FULL, H4, G5 = 9, 4, 5
NAMES = {FULL: "full", H4: "flat-H", G5: "flat-G"}


def positions(m):
    """(p, q) index arrays of the entries pattern ``m`` keeps."""
    pq = np.array(PATTERNS[m], np.int64)
    return pq[:, 0], pq[:, 1]


def compact(blocks, m):
    """(n, 3, 3) blocks -> (n, m) values of pattern m (no check: ``dropped`` says what is lost)."""
    p, q = positions(m)
    return np.ascontiguousarray(np.asarray(blocks)[:, p, q])


def expand(vals, m):
    """(n, m) values of pattern m -> (n, 3, 3) blocks (zeros where the pattern has none)."""
    vals = np.asarray(vals)
    if m == FULL:
        return vals.reshape(-1, 3, 3)
    out = np.zeros((vals.shape[0], 3, 3), vals.dtype)
    p, q = positions(m)
    out[:, p, q] = vals
    return out


def block_bytes(m, single=False):
    """Bytes of one stored block of pattern m: m values and an int32 column."""
    return (4 if single else 8) * m + 4


@njit(cache=True)
def _matvec(indptr, indices, data, x, y):
    """y = A x, full 3x3 blocks (data (nnzb, 3, 3) or (nnzb, 9))."""
    d = data.reshape((data.shape[0], 9))
    for i in range(indptr.size - 1):
        y0 = 0.0
        y1 = 0.0
        y2 = 0.0
        for k in range(indptr[i], indptr[i + 1]):
            c = 3 * indices[k]
            x0, x1, x2 = x[c], x[c + 1], x[c + 2]
            y0 += d[k, 0] * x0 + d[k, 1] * x1 + d[k, 2] * x2
            y1 += d[k, 3] * x0 + d[k, 4] * x1 + d[k, 5] * x2
            y2 += d[k, 6] * x0 + d[k, 7] * x1 + d[k, 8] * x2
        y[3 * i] = y0
        y[3 * i + 1] = y1
        y[3 * i + 2] = y2


@njit(cache=True)
def _matvec_h4(indptr, indices, d, x, y):
    """y = A x, pattern H4: d[k] = (a02, a12, a20, a21)."""
    for i in range(indptr.size - 1):
        y0 = 0.0
        y1 = 0.0
        y2 = 0.0
        for k in range(indptr[i], indptr[i + 1]):
            c = 3 * indices[k]
            x2 = x[c + 2]
            y0 += d[k, 0] * x2
            y1 += d[k, 1] * x2
            y2 += d[k, 2] * x[c] + d[k, 3] * x[c + 1]
        y[3 * i] = y0
        y[3 * i + 1] = y1
        y[3 * i + 2] = y2


@njit(cache=True)
def _matvec_g5(indptr, indices, d, x, y):
    """y = A x, pattern G5: d[k] = (a00, a01, a10, a11, a22)."""
    for i in range(indptr.size - 1):
        y0 = 0.0
        y1 = 0.0
        y2 = 0.0
        for k in range(indptr[i], indptr[i + 1]):
            c = 3 * indices[k]
            x0, x1 = x[c], x[c + 1]
            y0 += d[k, 0] * x0 + d[k, 1] * x1
            y1 += d[k, 2] * x0 + d[k, 3] * x1
            y2 += d[k, 4] * x[c + 2]
        y[3 * i] = y0
        y[3 * i + 1] = y1
        y[3 * i + 2] = y2


@njit(cache=True)
def _panel(indptr, indices, data, XT, RT, sign):
    """RT[3i+p, t] += sign * sum_k data[k, p, q] XT[3 col_k + q, t] (XT: columns x b, C order): per
    block its nine values in registers and the three rows of XT it meets read once."""
    d = data.reshape((data.shape[0], 9))
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
            a00, a01, a02 = d[k, 0], d[k, 1], d[k, 2]
            a10, a11, a12 = d[k, 3], d[k, 4], d[k, 5]
            a20, a21, a22 = d[k, 6], d[k, 7], d[k, 8]
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
def _panel_h4(indptr, indices, d, XT, RT, sign):
    """``_panel`` for pattern H4 (d[k] = a02, a12, a20, a21); XT, RT C-contiguous."""
    b = XT.shape[1]
    b4 = b - b % 4
    acc0 = np.empty(b)
    acc1 = np.empty(b)
    acc2 = np.empty(b)
    for i in range(indptr.size - 1):
        acc0[:] = 0.0
        acc1[:] = 0.0
        acc2[:] = 0.0
        for k in range(indptr[i], indptr[i + 1]):
            c = 3 * indices[k]
            a02, a12, a20, a21 = d[k, 0], d[k, 1], d[k, 2], d[k, 3]
            x0 = XT[c]
            x1 = XT[c + 1]
            x2 = XT[c + 2]
            for t in range(0, b4, 4):               # four states at a time (simd.h4_4: the same bits)
                h4_4(acc0, acc1, acc2, t, a02, a12, a20, a21, x0, x1, x2)
            for t in range(b4, b):
                u2 = x2[t]
                acc0[t] += a02 * u2
                acc1[t] += a12 * u2
                acc2[t] += a20 * x0[t] + a21 * x1[t]
        for t in range(b):
            RT[3 * i, t] += sign * acc0[t]
            RT[3 * i + 1, t] += sign * acc1[t]
            RT[3 * i + 2, t] += sign * acc2[t]


@njit(cache=True)
def _panel_h4_pair(indptr, indices, d, XT, RT, sign):
    """``_panel_h4`` two rows at a time: a column both rows hold (neighbouring nodes see nearly the same
    columns) has its rows of XT read once for both; each row's sums in the same order as ``_panel_h4``
    (the same bits). With the states four at a time, faster than one row at a time at every width from 8
    (`python jobscripts/panel_widths.py`: 0.36-0.37 against 0.46-0.53 ns per block and state at
    b = 32 on the paper case's lags, 0.51 against 0.66 at b = 12); the scalar kernels before were
    faster for narrow panels one row at a time (``jobscripts/panel_variants.py``)."""
    b = XT.shape[1]
    b4 = b - b % 4                      # states four at a time (simd.h4_4, h4pair_4: the same bits), then the rest
    n = indptr.size - 1
    a0 = np.empty(b); a1 = np.empty(b); a2 = np.empty(b)
    e0 = np.empty(b); e1 = np.empty(b); e2 = np.empty(b)
    i = 0
    while i < n:
        a0[:] = 0.0; a1[:] = 0.0; a2[:] = 0.0
        if i + 1 < n:
            e0[:] = 0.0; e1[:] = 0.0; e2[:] = 0.0
            k, kend = indptr[i], indptr[i + 1]
            l, lend = indptr[i + 1], indptr[i + 2]
            while k < kend or l < lend:
                ck = indices[k] if k < kend else 2147483647
                cl = indices[l] if l < lend else 2147483647
                if ck == cl:
                    c = 3 * ck
                    x0 = XT[c]; x1 = XT[c + 1]; x2 = XT[c + 2]
                    p02, p12, p20, p21 = d[k, 0], d[k, 1], d[k, 2], d[k, 3]
                    q02, q12, q20, q21 = d[l, 0], d[l, 1], d[l, 2], d[l, 3]
                    for t in range(0, b4, 4):
                        h4pair_4(a0, a1, a2, e0, e1, e2, t, p02, p12, p20, p21, q02, q12, q20, q21, x0, x1, x2)
                    for t in range(b4, b):
                        u0 = x0[t]; u1 = x1[t]; u2 = x2[t]
                        a0[t] += p02 * u2; a1[t] += p12 * u2; a2[t] += p20 * u0 + p21 * u1
                        e0[t] += q02 * u2; e1[t] += q12 * u2; e2[t] += q20 * u0 + q21 * u1
                    k += 1; l += 1
                elif ck < cl:
                    c = 3 * ck
                    x0 = XT[c]; x1 = XT[c + 1]; x2 = XT[c + 2]
                    p02, p12, p20, p21 = d[k, 0], d[k, 1], d[k, 2], d[k, 3]
                    for t in range(0, b4, 4):
                        h4_4(a0, a1, a2, t, p02, p12, p20, p21, x0, x1, x2)
                    for t in range(b4, b):
                        u2 = x2[t]
                        a0[t] += p02 * u2; a1[t] += p12 * u2; a2[t] += p20 * x0[t] + p21 * x1[t]
                    k += 1
                else:
                    c = 3 * cl
                    x0 = XT[c]; x1 = XT[c + 1]; x2 = XT[c + 2]
                    q02, q12, q20, q21 = d[l, 0], d[l, 1], d[l, 2], d[l, 3]
                    for t in range(0, b4, 4):
                        h4_4(e0, e1, e2, t, q02, q12, q20, q21, x0, x1, x2)
                    for t in range(b4, b):
                        u2 = x2[t]
                        e0[t] += q02 * u2; e1[t] += q12 * u2; e2[t] += q20 * x0[t] + q21 * x1[t]
                    l += 1
            for t in range(b):
                RT[3 * i + 3, t] += sign * e0[t]; RT[3 * i + 4, t] += sign * e1[t]; RT[3 * i + 5, t] += sign * e2[t]
        else:
            for k in range(indptr[i], indptr[i + 1]):
                c = 3 * indices[k]
                x0 = XT[c]; x1 = XT[c + 1]; x2 = XT[c + 2]
                p02, p12, p20, p21 = d[k, 0], d[k, 1], d[k, 2], d[k, 3]
                for t in range(0, b4, 4):
                    h4_4(a0, a1, a2, t, p02, p12, p20, p21, x0, x1, x2)
                for t in range(b4, b):
                    u2 = x2[t]
                    a0[t] += p02 * u2; a1[t] += p12 * u2; a2[t] += p20 * x0[t] + p21 * x1[t]
        for t in range(b):
            RT[3 * i, t] += sign * a0[t]; RT[3 * i + 1, t] += sign * a1[t]; RT[3 * i + 2, t] += sign * a2[t]
        i += 2


@njit(cache=True)
def _panel_g5(indptr, indices, d, XT, RT, sign):
    """``_panel`` for pattern G5 (d[k] = a00, a01, a10, a11, a22)."""
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
            a00, a01, a10, a11, a22 = d[k, 0], d[k, 1], d[k, 2], d[k, 3], d[k, 4]
            x0 = XT[c]
            x1 = XT[c + 1]
            x2 = XT[c + 2]
            for t in range(b):
                u0, u1 = x0[t], x1[t]
                acc0[t] += a00 * u0 + a01 * u1
                acc1[t] += a10 * u0 + a11 * u1
                acc2[t] += a22 * x2[t]
        for t in range(b):
            RT[3 * i, t] += sign * acc0[t]
            RT[3 * i + 1, t] += sign * acc1[t]
            RT[3 * i + 2, t] += sign * acc2[t]


@njit(cache=True)
def _diag_add(diag, r0, x, y, sign):
    """y[3i + p] += sign * sum_q diag[i, p, q] x[3 (r0 + i) + q] (the free term; x: all columns)."""
    for i in range(diag.shape[0]):
        c = 3 * (r0 + i)
        for p in range(3):
            y[3 * i + p] += sign * (diag[i, p, 0] * x[c] + diag[i, p, 1] * x[c + 1] + diag[i, p, 2] * x[c + 2])


@njit(cache=True)
def _diag_panel(diag, r0, XT, RT, sign):
    """RT[3i + p, t] += sign * sum_q diag[i, p, q] XT[3 (r0 + i) + q, t]."""
    for i in range(diag.shape[0]):
        c = 3 * (r0 + i)
        for p in range(3):
            for t in range(XT.shape[1]):
                RT[3 * i + p, t] += sign * (diag[i, p, 0] * XT[c, t] + diag[i, p, 1] * XT[c + 1, t]
                                            + diag[i, p, 2] * XT[c + 2, t])


def matvec(m, indptr, indices, data, x, y):
    """y = A x for pattern m."""
    (_matvec_h4 if m == H4 else _matvec_g5 if m == G5 else _matvec)(indptr, indices, data, x, y)


PAIR_FROM = 8       # panel width from which H4 panels take two rows at a time (``_panel_h4_pair``; jobscripts/panel_widths.py)


def panel(m, indptr, indices, data, XT, RT, sign):
    """RT += sign * A XT for pattern m (XT, RT C-contiguous: the kernels read and write their rows
    four states at a time)."""
    if not (XT.flags.c_contiguous and RT.flags.c_contiguous):
        raise ValueError("bsr.panel: the panels must be C-contiguous")
    if m == H4:
        f = _panel_h4_pair if XT.shape[1] >= PAIR_FROM else _panel_h4
    else:
        f = _panel_g5 if m == G5 else _panel
    f(indptr, indices, data, XT, RT, float(sign))


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
    """The python Mat's context: MatMult and MatMultAdd through the kernels."""

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
        self.bsr.matvec(self._gather(x), y.getArray())

    def multAdd(self, mat, x, v, y):
        b = self.bsr
        xa = self._gather(x)
        tmp = np.empty(y.getLocalSize())
        b.matvec(xa, tmp)
        if v.handle != y.handle:
            v.copy(y)
        y.getArray()[:] += tmp


class BSRMat:
    """This rank's rows of a block-sparse lag and its python Mat (``mat``): ``data`` (nnzb, m) in
    pattern m (``PATTERNS``); ``diag`` (local rows, 3, 3) or None: the free term (H_1)."""

    kind = "bsr"

    def __init__(self, comm, indptr, indices, data, nrow_loc, ncol_loc, nrow_glob, ncol_glob, pattern=FULL,
                 diag=None, row0=0):
        PETSc = init()
        self.pattern = int(pattern)
        self.indptr = np.ascontiguousarray(indptr, dtype=np.int64)
        self.indices = np.ascontiguousarray(indices, dtype=np.int32)
        dt = np.float32 if np.asarray(data).dtype == np.float32 else np.float64    # single: -ssi_lag_single_from
        self.data = np.ascontiguousarray(np.asarray(data, dtype=dt).reshape(-1, self.pattern))
        self.diag = None if diag is None else np.ascontiguousarray(diag, dtype=np.float64).reshape(-1, 3, 3)
        self.row0 = int(row0)                   # first local node row (the free term's column)
        self.sizes = ((3 * nrow_loc, 3 * nrow_glob), (3 * ncol_loc, 3 * ncol_glob))
        self.comm = comm
        self.mat = PETSc.Mat().createPython(self.sizes, context=_Shell(self), comm=comm)
        self.mat.setBlockSizes(3, 3)            # node blocks: its Vecs (traction histories, checkpoints) keep
        self.mat.setUp()                        # the layout of MATDENSE's and the step matrix's

    @property
    def nbytes(self):
        """Bytes this rank stores (values and indices, the free term)."""
        return self.data.nbytes + self.indices.nbytes + self.indptr.nbytes + (0 if self.diag is None else self.diag.nbytes)

    @property
    def blocks(self):
        return int(self.indices.size)

    def to_single(self):
        """Keep the values in float32 (a loaded lag of a -ssi_lag_single_from run); returns self."""
        self.data = np.ascontiguousarray(self.data, dtype=np.float32)
        return self

    def matvec(self, x, y):
        """y = (local rows) @ x, x all columns."""
        matvec(self.pattern, self.indptr, self.indices, self.data, x, y)
        if self.diag is not None:
            _diag_add(self.diag, self.row0, x, y, 1.0)

    def panel(self, XT, RT, sign):
        """RT += sign * (local rows) @ XT: XT (all columns x b), RT (local rows x b), C order."""
        panel(self.pattern, self.indptr, self.indices, self.data, XT, RT, sign)
        if self.diag is not None:
            _diag_panel(self.diag, self.row0, XT, RT, float(sign))

    def flops(self, w=1):
        """Flops of a product with w columns (2 per stored value)."""
        return 2.0 * self.pattern * w * self.indices.size + (18.0 * w * self.diag.shape[0] if self.diag is not None else 0.0)

    def scalar_csr(self):
        """(indptr, columns, values) of the local rows as a scalar CSR holding only the pattern's entries
        (and the free term's 9 per row where there is one), columns sorted within each row."""
        nloc = self.indptr.size - 1
        p, q = positions(self.pattern)
        nb = np.diff(self.indptr)
        brow = np.repeat(np.arange(nloc, dtype=np.int64), nb)
        R = (3 * brow[:, None] + p[None, :]).ravel()
        C = (3 * self.indices.astype(np.int64)[:, None] + q[None, :]).ravel()
        V = np.asarray(self.data, np.float64).ravel()
        order = np.lexsort((C, R))
        R, C, V = R[order], C[order], V[order]
        ip = np.zeros(3 * nloc + 1, np.int64)
        np.cumsum(np.bincount(R, minlength=3 * nloc), out=ip[1:])
        return ip, C, V

    def to_aij(self):
        """Collective: the pattern's entries as an MPIAIJ (-ssi_lags_save: 12 B a value in the file)."""
        PETSc = init()
        ip, C, V = self.scalar_csr()
        A = PETSc.Mat().createAIJ(size=self.sizes, csr=(ip.astype(PETSc.IntType), C.astype(PETSc.IntType),
                                                        V.astype(PETSc.ScalarType)), comm=self.comm)
        A.assemble()
        return A

    def diag_aij(self):
        """Collective: the free term (block diagonal) as an MPIAIJ of the same rows and columns."""
        PETSc = init()
        nloc = self.diag.shape[0]
        C = (3 * (self.row0 + np.arange(nloc)))[:, None, None] + np.zeros((1, 3, 1), np.int64) + np.arange(3)
        ip = np.arange(0, 9 * nloc + 1, 3, dtype=np.int64)
        A = PETSc.Mat().createAIJ(size=self.sizes, csr=(ip.astype(PETSc.IntType), C.ravel().astype(PETSc.IntType),
                                                        self.diag.ravel().astype(PETSc.ScalarType)), comm=self.comm)
        A.assemble()
        return A


class DenseSplit:
    """A dense lag of a flat surface in its pattern's two dense pieces (this rank's rows, every
    column): H4 as A_xy,z (2 local rows per node x 1 column per node) and A_z,xy (1 x 2), G5 as A_xy,xy
    (2 x 2) and A_z,z (1 x 1), rows and columns node by node (``pieces``: (row components, column
    components, array)); ``diag`` the free term as in BSRMat. Products by BLAS on the gathered
    components: 4 (H) or 5 (G) numbers a node pair instead of MATDENSE's 9."""

    SPLIT = {H4: (((0, 1), (2,)), ((2,), (0, 1))), G5: (((0, 1), (0, 1)), ((2,), (2,)))}
    kind = "dense"

    def __init__(self, comm, pattern, pieces, nrow_loc, ncol_loc, nrow_glob, ncol_glob, diag=None, row0=0):
        PETSc = init()
        self.pattern = int(pattern)
        self.pieces = [(np.array(r), np.array(c), np.ascontiguousarray(A, dtype=np.float64)) for r, c, A in pieces]
        self.nloc, self.ncol = nrow_loc, ncol_glob
        self.diag = None if diag is None else np.ascontiguousarray(diag, dtype=np.float64).reshape(-1, 3, 3)
        self.row0 = int(row0)
        self.sizes = ((3 * nrow_loc, 3 * nrow_glob), (3 * ncol_loc, 3 * ncol_glob))
        self.comm = comm
        self.mat = PETSc.Mat().createPython(self.sizes, context=_Shell(self), comm=comm)
        self.mat.setBlockSizes(3, 3)            # node blocks: its Vecs (traction histories, checkpoints) keep
        self.mat.setUp()                        # the layout of MATDENSE's and the step matrix's

    @classmethod
    def from_csr(cls, comm, pattern, nrow_loc, ncol_loc, nrow_glob, ncol_glob, indptr, cols, vals, diag=None, row0=0):
        """From the block CSR of the local rows in pattern ``pattern`` (4 or 5)."""
        pieces = []
        slot = {pq: k for k, pq in enumerate(PATTERNS[pattern])}
        rows = np.repeat(np.arange(nrow_loc, dtype=np.int64), np.diff(indptr))
        cols = np.asarray(cols, np.int64)
        for rs, cs in cls.SPLIT[pattern]:
            A = np.zeros((nrow_loc, len(rs), ncol_glob, len(cs)))
            for a, p in enumerate(rs):
                for b, q in enumerate(cs):
                    A[rows, a, cols, b] = vals[:, slot[(p, q)]]
            pieces.append((rs, cs, A.reshape(nrow_loc * len(rs), ncol_glob * len(cs))))
        return cls(comm, pattern, pieces, nrow_loc, ncol_loc, nrow_glob, ncol_glob, diag, row0)

    @property
    def blocks(self):
        return self.nloc * self.ncol

    @property
    def nbytes(self):
        return sum(A.nbytes for _, _, A in self.pieces) + (0 if self.diag is None else self.diag.nbytes)

    def matvec(self, x, y):
        X = x.reshape(-1, 3)
        Y = y.reshape(-1, 3)
        for rs, cs, A in self.pieces:
            Y[:, rs] = (A @ X[:, cs].ravel()).reshape(-1, len(rs))
        if self.diag is not None:
            _diag_add(self.diag, self.row0, x, y, 1.0)

    def panel(self, XT, RT, sign):
        """RT += sign * A XT: per piece X_c^T A^T (the panel on the left: OpenBLAS's faster layout for a
        skinny product, as march's MATDENSE panels)."""
        w = XT.shape[1]
        X = XT.reshape(-1, 3, w)
        R = RT.reshape(-1, 3, w)
        for rs, cs, A in self.pieces:
            Xt = np.ascontiguousarray(X[:, cs, :].transpose(2, 0, 1)).reshape(w, -1)
            Pt = Xt @ A.T
            R[:, rs, :] += sign * Pt.reshape(w, -1, len(rs)).transpose(1, 2, 0)
        if self.diag is not None:
            _diag_panel(self.diag, self.row0, XT, RT, float(sign))

    def flops(self, w=1):
        return 2.0 * w * sum(A.size for _, _, A in self.pieces) + (18.0 * w * self.diag.shape[0] if self.diag is not None else 0.0)

    def scalar_csr(self):
        """As BSRMat.scalar_csr: every node pair's pattern entries (zeros included)."""
        nloc, N = self.nloc, self.ncol
        Rs, Cs, Vs = [], [], []
        for rs, cs, A in self.pieces:
            A4 = A.reshape(nloc, len(rs), N, len(cs))
            i, a, j, b = np.meshgrid(np.arange(nloc), np.arange(len(rs)), np.arange(N), np.arange(len(cs)),
                                     indexing="ij")
            Rs.append((3 * i + np.array(rs)[a]).ravel()); Cs.append((3 * j + np.array(cs)[b]).ravel())
            Vs.append(A4.ravel())
        R, C, V = np.concatenate(Rs), np.concatenate(Cs), np.concatenate(Vs)
        order = np.lexsort((C, R))
        ip = np.zeros(3 * nloc + 1, np.int64)
        np.cumsum(np.bincount(R, minlength=3 * nloc), out=ip[1:])
        return ip, C[order], V[order]

    to_aij = BSRMat.to_aij
    diag_aij = BSRMat.diag_aij


def context(M):
    """The BSRMat or DenseSplit behind a python Mat (``kind`` 'bsr' or 'dense'), or None (any other Mat)."""
    if M is None or M.getType() != "python":
        return None
    ctx = M.getPythonContext()
    return ctx.bsr if isinstance(ctx, _Shell) else None


def from_csr(comm, nrow_loc, ncol_loc, nrow_glob, ncol_glob, indptr, indices, values, pattern=FULL, diag=None,
             row0=0):
    """The python Mat of node-block CSR arrays of the local rows (columns sorted or not)."""
    return BSRMat(comm, indptr, indices, values, nrow_loc, ncol_loc, nrow_glob, ncol_glob, pattern, diag, row0).mat


def _local_csr(M):
    r0, r1 = M.getOwnershipRange()
    ai, aj, av = M.getValuesCSR()
    return r0, r1, np.asarray(ai, np.int64), np.asarray(aj, np.int64), np.asarray(av)


def from_aij(M, pattern, diag=None, dense=False):
    """Collective: a loaded MPIAIJ of ``to_aij`` (pattern ``pattern``) as a python Mat of the same rows,
    a BSRMat's or (``dense``) a DenseSplit's (M and ``diag``, the free term's MPIAIJ or None, destroyed)."""
    (m, mg), (n, ng) = M.getSizes()
    r0, r1, ai, aj, av = _local_csr(M)
    nloc = (r1 - r0) // 3
    p, q = positions(pattern)
    rows = np.repeat(np.arange(r1 - r0, dtype=np.int64), np.diff(ai))
    node, comp, cnode, ccomp = rows // 3, rows % 3, aj // 3, aj % 3
    slot = np.full((3, 3), -1, np.int64)
    slot[p, q] = np.arange(len(p))
    k = slot[comp, ccomp]
    if np.any(k < 0):
        raise ValueError("from_aij: an entry outside the block pattern")
    # blocks: distinct (node, cnode) in row-major order
    key = node * ng + cnode
    ub, inv = np.unique(key, return_inverse=True)
    vals = np.zeros((len(ub), len(p)))
    vals[inv, k] = av
    bnode = ub // ng
    indptr = np.zeros(nloc + 1, np.int64)
    np.cumsum(np.bincount(bnode, minlength=nloc), out=indptr[1:])
    cols = (ub % ng).astype(np.int32)
    d = None
    if diag is not None:
        _, _, di, dj, dv = _local_csr(diag)
        d = np.asarray(dv).reshape(nloc, 3, 3)
        diag.destroy()
    comm = M.getComm()
    M.destroy()
    if dense:
        return DenseSplit.from_csr(comm, pattern, nloc, n // 3, mg // 3, ng // 3, indptr, cols, vals, d, r0 // 3).mat
    return from_csr(comm, nloc, n // 3, mg // 3, ng // 3, indptr, cols, vals, pattern, d, r0 // 3)
