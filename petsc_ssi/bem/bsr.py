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
(-ssi_lag_single_from, products still accumulated in double) 20, 24, 40. On a surface with an excavation
(ground, walls, bottom) H is kept in two parts (``SplitBSR``): the blocks whose pairs all lie in one
horizontal plane in H4, the others full.

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

from .patterns import PATTERNS, FULL, H4, G5, NAMES  # noqa: F401  (the entries (p, q) each pattern keeps)
from .simd import block_values, block_rows, block_rows4, block_rows4_pair

from ..petsc import init


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


@njit(cache=True, inline="always")
def _add_block(acc0, acc1, acc2, a, XT, c, b4, b):
    """acc_p[t] += row p of a block (values ``a``, simd.block_values) times XT[c + q, t], t < b: states
    four at a time up to b4 (simd.block_rows4), then one at a time (simd.block_rows): the same bits."""
    x0 = XT[c]
    x1 = XT[c + 1]
    x2 = XT[c + 2]
    for t in range(0, b4, 4):
        block_rows4(acc0, acc1, acc2, t, a, x0, x1, x2)
    for t in range(b4, b):
        s0, s1, s2 = block_rows(a, x0[t], x1[t], x2[t])
        acc0[t] += s0
        acc1[t] += s1
        acc2[t] += s2


@njit(cache=True, inline="always")
def _sums(b):
    """Three zeroed arrays of b sums (a row of blocks' three rows)."""
    return np.zeros(b), np.zeros(b), np.zeros(b)


@njit(cache=True, inline="always")
def _zero(a0, a1, a2):
    a0[:] = 0.0
    a1[:] = 0.0
    a2[:] = 0.0


@njit(cache=True, inline="always")
def _flush(RT, r, acc0, acc1, acc2, sign):
    """RT[r + p, t] += sign * acc_p[t]."""
    for t in range(acc0.shape[0]):
        RT[r, t] += sign * acc0[t]
        RT[r + 1, t] += sign * acc1[t]
        RT[r + 2, t] += sign * acc2[t]


def _kernels(m, wide):
    """The block kernels of pattern m, from one template: (matvec, panel, the panel two rows at a time or
    None). Each is compiled for its m (the pattern's entries known to the compiler: a block's values in
    registers, its rows' products written out, simd.py); ``wide``: panels take the states four at a time
    (and two rows at a time from PAIR_FROM states). Every block row's products are summed in storage
    order and added to the row's sum: the same operations in the same order as the block's full 3x3
    product minus the terms that are exact zeros, so the same bits in every kernel and width."""
    return _matvec_of(m), _panel_of(m, wide), (_panel_pair_of(m) if wide else None)


def _matvec_of(m):
    """The template's matrix-vector product of pattern m (``_kernels``)."""

    @njit(cache=True)
    def matvec(indptr, indices, data, x, y):
        """y = A x (data (nnzb, m), or (nnzb, 3, 3) for the full pattern)."""
        d = data.reshape((data.shape[0], m))
        for i in range(indptr.size - 1):
            y0 = 0.0
            y1 = 0.0
            y2 = 0.0
            for k in range(indptr[i], indptr[i + 1]):
                c = 3 * indices[k]
                s0, s1, s2 = block_rows(block_values(d, k, m), x[c], x[c + 1], x[c + 2])
                y0 += s0
                y1 += s1
                y2 += s2
            y[3 * i] = y0
            y[3 * i + 1] = y1
            y[3 * i + 2] = y2
    return matvec


def _panel_of(m, wide):
    """The template's panel product of pattern m, the states four at a time if ``wide`` (``_kernels``)."""

    @njit(cache=True)
    def panel(indptr, indices, data, XT, RT, sign):
        """RT[3i+p, t] += sign * sum_k A_k[p, q] XT[3 col_k + q, t] (XT: columns x b, C order): per block
        its values in registers and the three rows of XT it meets read once."""
        d = data.reshape((data.shape[0], m))
        b = XT.shape[1]
        b4 = b - b % 4 if wide else 0
        a0, a1, a2 = _sums(b)                   # a row of blocks' sums, one array a block row
        for i in range(indptr.size - 1):
            _zero(a0, a1, a2)
            for k in range(indptr[i], indptr[i + 1]):
                _add_block(a0, a1, a2, block_values(d, k, m), XT, 3 * indices[k], b4, b)
            _flush(RT, 3 * i, a0, a1, a2, sign)
    return panel


def _panel_pair_of(m):
    """The template's panel product of pattern m two rows at a time, the states four at a time
    (``_kernels``)."""

    @njit(cache=True)
    def panel_pair(indptr, indices, data, XT, RT, sign):
        """``panel`` two rows at a time: a column both rows hold (neighbouring nodes see nearly the same
        columns) has its rows of XT read once for both; each row's sums in the same order as ``panel``
        (the same bits). For the flat H pattern with the states four at a time, faster than one row at a
        time at every width from 8 (`python jobscripts/panel_widths.py`: 0.36-0.37 against 0.46-0.53 ns
        per block and state at b = 32 on the paper case's lags, 0.51 against 0.66 at b = 12); the scalar
        kernels before were faster for narrow panels one row at a time (``jobscripts/panel_variants.py``)."""
        d = data.reshape((data.shape[0], m))
        b = XT.shape[1]
        b4 = b - b % 4
        n = indptr.size - 1
        a0, a1, a2 = _sums(b)                   # the first row of blocks' sums
        e0, e1, e2 = _sums(b)                   # the second's
        for i in range(0, n, 2):
            _zero(a0, a1, a2)
            if i + 1 < n:
                _zero(e0, e1, e2)
                k, kend = indptr[i], indptr[i + 1]
                l, lend = indptr[i + 1], indptr[i + 2]
                while k < kend or l < lend:
                    ck = indices[k] if k < kend else 2147483647
                    cl = indices[l] if l < lend else 2147483647
                    if ck == cl:
                        c = 3 * ck
                        x0 = XT[c]; x1 = XT[c + 1]; x2 = XT[c + 2]
                        p, q = block_values(d, k, m), block_values(d, l, m)
                        for t in range(0, b4, 4):
                            block_rows4_pair(a0, a1, a2, e0, e1, e2, t, p, q, x0, x1, x2)
                        for t in range(b4, b):
                            s0, s1, s2 = block_rows(p, x0[t], x1[t], x2[t])
                            a0[t] += s0; a1[t] += s1; a2[t] += s2
                            s0, s1, s2 = block_rows(q, x0[t], x1[t], x2[t])
                            e0[t] += s0; e1[t] += s1; e2[t] += s2
                        k += 1; l += 1
                    elif ck < cl:
                        _add_block(a0, a1, a2, block_values(d, k, m), XT, 3 * ck, b4, b)
                        k += 1
                    else:
                        _add_block(e0, e1, e2, block_values(d, l, m), XT, 3 * cl, b4, b)
                        l += 1
                _flush(RT, 3 * i + 3, e0, e1, e2, sign)
            else:
                for k in range(indptr[i], indptr[i + 1]):
                    _add_block(a0, a1, a2, block_values(d, k, m), XT, 3 * indices[k], b4, b)
            _flush(RT, 3 * i, a0, a1, a2, sign)
    return panel_pair


# The kernel table of the block patterns: pattern -> (matvec, panel, panel two rows at a time or None),
# each from the template. The flat H pattern takes the states four at a time (measured faster:
# jobscripts/panel_widths.py); the others one at a time (their loops as before the template).
WIDE = {FULL: False, H4: True, G5: False}
_matvec, _panel, _ = _kernels(FULL, WIDE[FULL])
_matvec_h4, _panel_h4, _panel_h4_pair = _kernels(H4, WIDE[H4])
_matvec_g5, _panel_g5, _ = _kernels(G5, WIDE[G5])
KERNELS = {FULL: (_matvec, _panel, None), H4: (_matvec_h4, _panel_h4, _panel_h4_pair), G5: (_matvec_g5, _panel_g5, None)}


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


@njit(cache=True)
def block_csr(rows, cols, vals, nloc, r0):
    """Scalar CSR (indptr, indices, data) of the sum of 3 x 3 node blocks (local node row ``rows``, global
    node column ``cols``, values ``vals`` (nb, 3, 3)): blocks at the same (row, column) summed in input order,
    each row's columns ascending, exact zeros left out except diagonal entries (kept, zero or not:
    MatZeroRowsColumns of the symmetry planes' DOFs needs them); ``r0`` the first local row's node. The step
    matrix's build (``march.step_matrix``): one pass a block, where a scalar COO with duplicates took about
    2 s on a 45 000-DOF grid."""
    nb = rows.size
    cnt = np.zeros(nloc + 1, np.int64)
    for k in range(nb):
        cnt[rows[k] + 1] += 1
    for r in range(nloc):
        cnt[r + 1] += cnt[r]
    order = np.empty(nb, np.int64)
    pos = cnt[:nloc].copy()
    for k in range(nb):                      # (stable: a row's blocks in input order)
        order[pos[rows[k]]] = k
        pos[rows[k]] += 1
    indptr = np.zeros(3 * nloc + 1, np.int64)
    indices = np.empty(9 * nb, np.int64)
    data = np.empty(9 * nb)
    n = 0
    for r in range(nloc):
        a, e = cnt[r], cnt[r + 1]
        ks = order[a:e]
        cs = cols[ks]
        srt = np.argsort(cs, kind="mergesort")          # (stable: duplicates summed in input order)
        # merged blocks of the row: (column, summed values)
        nm = 0
        mc = np.empty(e - a, np.int64)
        mv = np.zeros((e - a, 3, 3))
        for i in range(e - a):
            k = ks[srt[i]]
            c = cs[srt[i]]
            if nm == 0 or mc[nm - 1] != c:
                mc[nm] = c
                for p in range(3):
                    for q in range(3):
                        mv[nm, p, q] = vals[k, p, q]
                nm += 1
            else:
                for p in range(3):
                    for q in range(3):
                        mv[nm - 1, p, q] += vals[k, p, q]
        for p in range(3):
            row = 3 * r + p
            diag = 3 * (r + r0) + p
            for i in range(nm):
                for q in range(3):
                    col = 3 * mc[i] + q
                    v = mv[i, p, q]
                    if v != 0.0 or col == diag:
                        indices[n] = col
                        data[n] = v
                        n += 1
            indptr[row + 1] = n
    return indptr, indices[:n].copy(), data[:n].copy()


def matvec(m, indptr, indices, data, x, y):
    """y = A x for pattern m."""
    KERNELS[m][0](indptr, indices, data, x, y)


PAIR_FROM = 8       # panel width from which H4 panels take two rows at a time (``_panel_h4_pair``; jobscripts/panel_widths.py)


def panel(m, indptr, indices, data, XT, RT, sign):
    """RT += sign * A XT for pattern m (XT, RT C-contiguous: the kernels read and write their rows
    four states at a time)."""
    if not (XT.flags.c_contiguous and RT.flags.c_contiguous):
        raise ValueError("bsr.panel: the panels must be C-contiguous")
    _, one, two = KERNELS[m]
    (two if two is not None and XT.shape[1] >= PAIR_FROM else one)(indptr, indices, data, XT, RT, float(sign))


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


def mark_columns(ctx, mask):
    """mask[node] = True for the column nodes this rank's rows of ``ctx`` (a BSRMat or SplitBSR) read: its blocks'
    columns and, with a free term, its own rows' nodes; False (mask untouched) for any other context (a
    DenseSplit reads every column)."""
    parts = ctx.parts if isinstance(ctx, SplitBSR) else [ctx] if isinstance(ctx, BSRMat) else None
    if parts is None:
        return False
    for p in parts:
        mask[p.indices] = True
    if ctx.diag is not None:
        mask[ctx.row0:ctx.row0 + ctx.diag.shape[0]] = True
    return True


def column_nodes(ctx, n_nodes):
    """The sorted column nodes (of ``n_nodes``) this rank's rows of ``ctx`` read (``mark_columns``), or None."""
    mask = np.zeros(n_nodes, bool)
    return np.flatnonzero(mask) if mark_columns(ctx, mask) else None


def remapped(ctx, nodes):
    """``ctx`` (a BSRMat or SplitBSR) reading its x at the positions of ``nodes`` (sorted, holding every column node
    it reads, ``column_nodes``, ``mark_columns``) instead of at the global column nodes: the values, row pointers and free term
    shared, the column indices (and the free term's first row) remapped; its products are the same operations
    in the same order, the same bits. No python Mat of its own (``mat`` None)."""
    nodes = np.asarray(nodes, np.int64)

    def one(p):
        q = BSRMat.__new__(BSRMat)
        q.__dict__.update(p.__dict__)
        q.indices = np.searchsorted(nodes, p.indices).astype(np.int32)
        if q.indices.size and not np.array_equal(nodes[q.indices], p.indices):
            raise ValueError("bsr.remapped: a column node of the matrix is not among the nodes")
        if p.diag is not None:
            q.row0 = int(np.searchsorted(nodes, p.row0))
            n = p.diag.shape[0]
            if n and not np.array_equal(nodes[q.row0:q.row0 + n], np.arange(p.row0, p.row0 + n)):
                raise ValueError("bsr.remapped: the free term's nodes are not among the nodes")
        q.sizes = (p.sizes[0], (3 * nodes.size, 3 * nodes.size))
        q.mat = None
        return q

    if isinstance(ctx, SplitBSR):
        s = SplitBSR.__new__(SplitBSR)
        s.parts = [one(p) for p in ctx.parts]
        s.comm, s.sizes = ctx.comm, s.parts[0].sizes
        s.diag, s.row0 = s.parts[0].diag, s.parts[0].row0
        s.mat = None
        return s
    return one(ctx)


def reader(ctxs, tmpl, depth=1):
    """Collective over ``tmpl``'s ranks: how this rank reads the x of the contexts ``ctxs`` (python Mats' BSRMat,
    SplitBSR, DenseSplit; all of one column layout, ``tmpl`` a Vec of it), of which it keeps ``depth`` copies:
    (scatter, seq Vec, [the context reading the seq Vec's array] per ``ctxs``, the DOFs it moves). The scatter moves only the
    columns this rank's rows read (``mark_columns``' union): a short lag (the step matrix's lags 1-2, the toeplitz
    store's only Mats) takes its rows' nodes and a halo, not the whole vector. The seq Vec holds them compacted
    and the contexts ``remapped`` to them where the remapped column indices (4 bytes a block) cost less than the
    ``depth`` copies of the columns left out save (24 bytes a node), on every rank; otherwise every column, of
    which only those are written (the contexts as they are). Where a context reads every column (a DenseSplit)
    or the union is every column: PETSc's all-gather. The products are the same bits every way."""
    from mpi4py import MPI
    PETSc = init()
    N = tmpl.getSize() // 3
    mask = np.zeros(N, bool)
    every = False
    for c in ctxs:                        # (stops at the first that reads every column: a far lag)
        if not mark_columns(c, mask) or np.count_nonzero(mask) == N:
            every = True
            break
    blocks = sum(c.blocks for c in ctxs) if not every else 0
    n = int(np.count_nonzero(mask))
    every = tmpl.getComm().tompi4py().allreduce(every or n == N, op=MPI.LOR)
    if every:
        sc, seq = PETSc.Scatter.toAll(tmpl)
        return sc, seq, list(ctxs), 3 * N
    remap = tmpl.getComm().tompi4py().allreduce(4.0 * blocks < depth * 24.0 * (N - n), op=MPI.LAND)
    nodes = np.flatnonzero(mask)
    dofs = (3 * nodes[:, None] + np.arange(3)).ravel().astype(PETSc.IntType)
    iset = PETSc.IS().createGeneral(dofs, comm=PETSc.COMM_SELF)
    if remap:
        seq = PETSc.Vec().createSeq(dofs.size, comm=PETSc.COMM_SELF)
        sc = PETSc.Scatter().create(tmpl, iset, seq, None)
        read = [remapped(c, nodes) for c in ctxs]
    else:
        seq = PETSc.Vec().createSeq(3 * N, comm=PETSc.COMM_SELF)
        seq.set(0.0)                      # (the columns no row reads stay zero)
        sc = PETSc.Scatter().create(tmpl, iset, seq, iset)
        read = list(ctxs)
    iset.destroy()
    return sc, seq, read, int(dofs.size)


class _Shell:
    """The python Mat's context: MatMult and MatMultAdd through the kernels, on the columns this rank's rows
    read (``reader``)."""

    def __init__(self, bsr):
        self.bsr = bsr
        self.scatter = None

    def _gather(self, x):
        PETSc = init()
        if self.scatter is None:
            self.scatter, self.xall, (self.ctx,), _ = reader([self.bsr], x)
        self.scatter.scatter(x, self.xall, addv=PETSc.InsertMode.INSERT_VALUES)
        return self.xall.getArray(readonly=True)

    def mult(self, mat, x, y):
        xa = self._gather(x)
        self.ctx.matvec(xa, y.getArray())

    def multAdd(self, mat, x, v, y):
        xa = self._gather(x)
        b = self.ctx
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
                 diag=None, row0=0, shell=True):
        self.pattern = int(pattern)
        self.indptr = np.ascontiguousarray(indptr, dtype=np.int64)
        self.indices = np.ascontiguousarray(indices, dtype=np.int32)
        dt = np.float32 if np.asarray(data).dtype == np.float32 else np.float64    # single: -ssi_lag_single_from
        self.data = np.ascontiguousarray(np.asarray(data, dtype=dt).reshape(-1, self.pattern))
        self.diag = None if diag is None else np.ascontiguousarray(diag, dtype=np.float64).reshape(-1, 3, 3)
        self.row0 = int(row0)                   # first local node row (the free term's column)
        self.sizes = ((3 * nrow_loc, 3 * nrow_glob), (3 * ncol_loc, 3 * ncol_glob))
        self.comm = comm
        self.mat = _python_mat(self) if shell else None     # (shell False: a part of a SplitBSR)

    @property
    def nbytes(self):
        """Bytes this rank stores (values and indices, the free term)."""
        return self.data.nbytes + self.indices.nbytes + self.indptr.nbytes + (0 if self.diag is None else self.diag.nbytes)

    @property
    def blocks(self):
        return int(self.indices.size)

    @property
    def entries(self):
        """Values this rank stores (blocks times the pattern's entries)."""
        return self.blocks * self.pattern

    @property
    def dtype(self):
        return self.data.dtype

    def to_single(self):
        """Keep the values in float32 (a loaded lag of a -ssi_lag_single_from run); returns self."""
        self.data = np.ascontiguousarray(self.data, dtype=np.float32)
        return self

    def matvec(self, x, y):
        """y = (local rows) @ x, x all columns."""
        matvec(self.pattern, self.indptr, self.indices, self.data, x, y)
        if self.diag is not None:
            _diag_add(self.diag, self.row0, x, y, 1.0)

    def columns(self, dofs):
        """The local rows of the global columns ``dofs`` (DOF numbers) as a dense (local rows,
        len(dofs)) array: the products A e_j with unit vectors, read off the blocks instead of one
        matvec over every block per column (a block's entry alone, then the free term added: the
        matvec's own sum, the same bits); None if a row holds a column node twice (the matvec would
        sum such blocks)."""
        if not hasattr(self, "_unique"):
            rows = np.repeat(np.arange(self.indptr.size - 1), np.diff(self.indptr))
            o = np.lexsort((self.indices, rows))
            self._unique = bool(np.all((np.diff(rows[o]) > 0) | (np.diff(self.indices[o]) > 0)))
        if not self._unique:
            return None
        dofs = np.asarray(dofs, np.int64)
        back = None
        if dofs.size > 1 and not np.all(np.diff(dofs) > 0):        # (unsorted, or a column asked twice)
            dofs, back = np.unique(dofs, return_inverse=True)
        nloc = self.indptr.size - 1
        out = np.zeros((3 * nloc, dofs.size))
        want = np.full(self.sizes[1][1], -1, np.int64)
        want[dofs] = np.arange(dofs.size)
        wn = want.reshape(-1, 3)
        hit = np.flatnonzero(np.any(wn >= 0, axis=1)[self.indices])       # blocks in a wanted column node
        rows = np.searchsorted(self.indptr, hit, side="right") - 1
        d = self.data                           # (nnzb, m)
        for s, (p, q) in enumerate(PATTERNS[self.pattern]):
            j = wn[self.indices[hit], q]
            k = j >= 0
            out[3 * rows[k] + p, j[k]] = d[hit[k], s]
        if self.diag is not None:               # the free term: column node row0 + i of local row i
            i = np.arange(nloc)
            for q in range(3):
                j = wn[self.row0 + i, q]
                k = j >= 0
                for p in range(3):
                    out[3 * i[k] + p, j[k]] += self.diag[i[k], p, q]
        return out if back is None else out[:, back]

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


def _python_mat(ctx):
    """The python Mat (MatMult, MatMultAdd by ``ctx``'s kernels) of a BSRMat, DenseSplit or SplitBSR."""
    PETSc = init()
    M = PETSc.Mat().createPython(ctx.sizes, context=_Shell(ctx), comm=ctx.comm)
    M.setBlockSizes(3, 3)            # node blocks: its Vecs (traction histories, checkpoints) keep
    M.setUp()                        # the layout of MATDENSE's and the step matrix's
    return M


class SplitBSR:
    """A block-sparse lag kept in parts, each a BSRMat of its own pattern over the same rows and
    columns, a block in one part: H of a surface that is not one plane (an excavation), its blocks
    whose pairs all lie in one horizontal plane in the flat pattern H4 (4 values) and the others full
    (9) (``lagset.SplitBuckets``); the free term with the first part. Products are the parts' products
    summed (each block's the same bits as in one full matrix; a row's sum over blocks in another
    order: round-off). Saved (``to_aij``) as the full pattern's entries it holds: a loaded lag is one
    full-pattern BSRMat."""

    kind = "bsr"
    pattern = FULL

    def __init__(self, comm, parts):
        self.parts = list(parts)
        self.comm = comm
        self.sizes = self.parts[0].sizes
        self.diag, self.row0 = self.parts[0].diag, self.parts[0].row0
        self.mat = _python_mat(self)

    @property
    def nbytes(self):
        return sum(p.nbytes for p in self.parts)

    @property
    def blocks(self):
        return sum(p.blocks for p in self.parts)

    @property
    def entries(self):
        return sum(p.entries for p in self.parts)

    @property
    def dtype(self):
        return self.parts[0].dtype

    def to_single(self):
        for p in self.parts:
            p.to_single()
        return self

    def matvec(self, x, y):
        self.parts[0].matvec(x, y)
        tmp = np.empty_like(y)
        for p in self.parts[1:]:
            p.matvec(x, tmp)
            y += tmp

    def columns(self, dofs):
        """As BSRMat.columns: the parts' columns summed in the matvec's order."""
        out = self.parts[0].columns(dofs)
        for p in self.parts[1:]:
            c = p.columns(dofs) if out is not None else None
            if c is None:
                return None
            out += c
        return out

    def panel(self, XT, RT, sign):
        for p in self.parts:
            p.panel(XT, RT, sign)

    def flops(self, w=1):
        return sum(p.flops(w) for p in self.parts)

    def scalar_csr(self):
        """As BSRMat.scalar_csr, the parts' entries together (columns sorted within each row)."""
        ips, Cs, Vs = zip(*(p.scalar_csr() for p in self.parts))
        R = np.concatenate([np.repeat(np.arange(len(ip) - 1, dtype=np.int64), np.diff(ip)) for ip in ips])
        C, V = np.concatenate(Cs), np.concatenate(Vs)
        order = np.lexsort((C, R))
        ip = np.zeros(len(ips[0]), np.int64)
        np.cumsum(np.bincount(R, minlength=len(ip) - 1), out=ip[1:])
        return ip, C[order], V[order]

    to_aij = BSRMat.to_aij
    diag_aij = BSRMat.diag_aij


def split_flat(ctx):
    """A full-pattern BSRMat whose blocks outside the flat pattern H4 are exact zeros in places (a split lag
    saved and loaded, ``from_aij``) as a SplitBSR again (the full part first, with the free term): those
    blocks in H4, the others as they are; ``ctx`` itself when it has none or is not full."""
    if ctx.pattern != FULL or not ctx.blocks:
        return ctx
    p, q = positions(H4)
    off = np.ones((3, 3), bool)
    off[p, q] = False
    B = ctx.data.reshape(-1, 3, 3)
    flat = ~np.any(B[:, off] != 0, axis=1)
    if not flat.any():
        return ctx
    nloc = ctx.indptr.size - 1
    rows = np.repeat(np.arange(nloc, dtype=np.int64), np.diff(ctx.indptr))
    (ml, mg), (nl, ng) = ctx.sizes
    parts = []
    for keep, m in ((~flat, FULL), (flat, H4)):
        ip = np.zeros(nloc + 1, np.int64)
        np.cumsum(np.bincount(rows[keep], minlength=nloc), out=ip[1:])
        vals = ctx.data[keep] if m == FULL else B[keep][:, p, q]
        parts.append(BSRMat(ctx.comm, ip, ctx.indices[keep], vals, ml // 3, nl // 3, mg // 3, ng // 3, m,
                            ctx.diag if m == FULL else None, ctx.row0, shell=False))
    ctx.mat.destroy()
    return SplitBSR(ctx.comm, parts)


class DenseSplit:
    """A dense lag of a flat surface in its pattern's two dense pieces (this rank's rows, every
    column): H4 as A_xy,z (2 local rows per node x 1 column per node) and A_z,xy (1 x 2), G5 as A_xy,xy
    (2 x 2) and A_z,z (1 x 1), rows and columns node by node (``pieces``: (row components, column
    components, array)); ``diag`` the free term as in BSRMat. Products by BLAS on the gathered
    components: 4 (H) or 5 (G) numbers a node pair instead of MATDENSE's 9."""

    SPLIT = {H4: (((0, 1), (2,)), ((2,), (0, 1))), G5: (((0, 1), (0, 1)), ((2,), (2,)))}
    kind = "dense"

    def __init__(self, comm, pattern, pieces, nrow_loc, ncol_loc, nrow_glob, ncol_glob, diag=None, row0=0):
        self.pattern = int(pattern)
        self.pieces = [(np.array(r), np.array(c), np.ascontiguousarray(A, dtype=np.float64)) for r, c, A in pieces]
        self.nloc, self.ncol = nrow_loc, ncol_glob
        self.diag = None if diag is None else np.ascontiguousarray(diag, dtype=np.float64).reshape(-1, 3, 3)
        self.row0 = int(row0)
        self.sizes = ((3 * nrow_loc, 3 * nrow_glob), (3 * ncol_loc, 3 * ncol_glob))
        self.comm = comm
        self.mat = _python_mat(self)

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

    def columns(self, dofs):
        """As BSRMat.columns: the pieces' entries of the columns ``dofs``, the free term added."""
        dofs = np.asarray(dofs, np.int64)
        out = np.zeros((3 * self.nloc, dofs.size))
        O = out.reshape(self.nloc, 3, dofs.size)
        node, comp = dofs // 3, dofs % 3
        for rs, cs, A in self.pieces:
            A4 = A.reshape(self.nloc, len(rs), self.ncol, len(cs))
            for b, q in enumerate(cs):
                k = np.flatnonzero(comp == q)
                for a, p in enumerate(rs):
                    O[:, p, k] = A4[:, a, node[k], b]
        if self.diag is not None:
            for j in range(dofs.size):
                r = node[j] - self.row0
                if 0 <= r < self.nloc:
                    O[r, :, j] += self.diag[r, :, comp[j]]
        return out

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


def columns(M, dofs):
    """The local rows of the global columns ``dofs`` of a lag Mat as a dense (local rows, len(dofs))
    array (the products M e_j with unit vectors, the same bits), or None: not a Mat of this module's, or
    one whose columns it does not read off (the caller multiplies unit vectors)."""
    ctx = context(M)
    return None if ctx is None or not hasattr(ctx, "columns") else ctx.columns(dofs)


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
