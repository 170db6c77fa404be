"""Lag matrices as PETSc Mats: MATMPIDENSE for dense lags, block-sparse ones (3x3 node
blocks; ``bsr``: the package's block CSR behind a python Mat) for shell-sparse ones, chosen
per lag by global block fill
(``-ssi_lag_storage auto|dense|sparse``, threshold ``-ssi_lag_fill``). Lags kept in single
precision (``-ssi_lag_single_from``: the buckets hold them as float32) are block-sparse whatever
their fill: 4 m + 4 B per stored block against 8 m B per block of a dense double lag (m: the
entries of the block pattern).

The block CSR of the local rows, lag by lag, comes from ``model.Buckets`` (``assemble``);
rows are the locally owned nodes, columns global node (or traction) ids. Blocks hold the entries
of the matrix's pattern (``bsr.PATTERNS``: on a flat surface H 4 and G 5 of 9): a block-sparse lag
keeps them as they are, a dense one of a flat surface becomes a ``bsr.DenseSplit`` (its two dense
pieces), a dense one of the full pattern a MATMPIDENSE. The free term of H_1 (``Buckets.diag``) goes
with its Mat (added to MATMPIDENSE's diagonal blocks; carried apart by the python Mats).
"""
import numpy as np
from numba import njit

from ..petsc import init, release_memory


@njit(cache=True)
def _scatter_dense(arr, rl, cols, vals):
    """arr[3 rl + p, 3 col + q] = block[p, q] for each triplet (arr: local rows x all columns)."""
    for k in range(rl.shape[0]):
        r = 3 * rl[k]
        c = 3 * cols[k]
        for p in range(3):
            for q in range(3):
                arr[r + p, c + q] = vals[k, p, q]


def baij(comm, nrow_loc, ncol_loc, nrow_glob, ncol_glob, indptr, cols, vals, pattern=9, diag=None, row0=0):
    """Block-sparse (3x3 node blocks, ``bsr``: the package's block CSR behind a python Mat) from the
    block CSR of the local rows (``Buckets.take_csr``: columns sorted within a row), blocks in
    ``pattern``, ``diag`` the free term of the rows (node ``row0`` first) or None."""
    from . import bsr
    return bsr.from_csr(comm, nrow_loc, ncol_loc, nrow_glob, ncol_glob, indptr, cols, vals, pattern, diag, row0)


def dense(comm, nrow_loc, ncol_loc, nrow_glob, ncol_glob, indptr, cols, vals, pattern=9, diag=None, row0=0):
    """A dense lag from the block CSR of the local rows: MPIDENSE (full pattern; the free term added
    to its diagonal blocks) or a ``bsr.DenseSplit`` (a flat pattern)."""
    from . import bsr
    if pattern != bsr.FULL:
        return bsr.DenseSplit.from_csr(comm, pattern, nrow_loc, ncol_loc, nrow_glob, ncol_glob, indptr, cols, vals,
                                       diag, row0).mat
    PETSc = init()
    A = PETSc.Mat().createDense(size=((3 * nrow_loc, 3 * nrow_glob), (3 * ncol_loc, 3 * ncol_glob)),
                                bsize=3, comm=comm)          # bs 3 as BAIJ and loaded Mats: the traction
                                                             # Vecs (and their checkpoints) keep one layout
    A.setUp()
    arr = A.getDenseArray()
    arr[...] = 0.0
    _scatter_dense(arr, np.repeat(np.arange(nrow_loc, dtype=np.int64), np.diff(indptr)), cols,
                   np.asarray(vals).reshape(-1, 3, 3))
    if diag is not None:
        for p in range(3):
            for q in range(3):
                arr[3 * np.arange(nrow_loc) + p, 3 * (row0 + np.arange(nrow_loc)) + q] += diag[:, p, q]
    A.restoreDenseArray() if hasattr(A, "restoreDenseArray") else None
    A.assemble()
    return A


def build(comm, buckets, L, node_range, n_rows_glob, n_cols_glob, col_loc, storage="auto", fill=0.95):
    """Collective: one Mat per lag 1..L (None where the lag is empty
    everywhere), freeing each lag's triplets once its Mat is built.
    Returns (mats, info) with info rows (lag, type, blocks), type 'dense', 'baij', 'single'
    (float32 block-sparse) or 'empty'."""
    r0, r1 = node_range
    nloc = r1 - r0
    mpi = comm.tompi4py()
    counts = np.array([buckets.count(l) for l in range(1, L + 1)], dtype=np.int64)
    gcounts = np.zeros_like(counts)
    mpi.Allreduce(counts, gcounts)
    mats, info = [], []
    for li in range(L):
        F = buckets.diag(li + 1)
        csr, pattern = _take(buckets, li + 1)
        A, kind = _make(comm, int(gcounts[li]), nloc, col_loc, n_rows_glob, n_cols_glob, csr, storage, fill,
                        pattern, F, r0)
        mats.append(A)
        info.append((li + 1, kind, int(gcounts[li])))
        del csr
        release_memory()
    return mats, info


def _take(buckets, lag):
    """(block CSR, pattern) of one lag, freed from ``buckets``: a Buckets' own, or a SplitBuckets' two
    parts as ([CSR, CSR], [pattern, pattern]) (the full part first)."""
    if not hasattr(buckets, "parts"):
        return buckets.take_csr(lag), buckets.m
    parts = buckets.parts(lag)
    return [c for c, _ in parts], [m for _, m in parts]


def merged(parts, patterns, nloc):
    """One full-pattern block CSR (indptr, columns, (n, 9) blocks) of the parts of a split lag (each
    row's blocks in column order; a column is in one part)."""
    from . import bsr
    rows = np.concatenate([np.repeat(np.arange(nloc, dtype=np.int64), np.diff(ip)) for ip, _, _ in parts])
    cols = np.concatenate([c for _, c, _ in parts]).astype(np.int32)
    vals = np.concatenate([bsr.expand(v, m).reshape(-1, 9).astype(v.dtype) for (_, _, v), m in zip(parts, patterns)])
    o = np.lexsort((cols, rows))
    indptr = np.zeros(nloc + 1, np.int64)
    np.cumsum(np.bincount(rows, minlength=nloc), out=indptr[1:])
    return indptr, cols[o], np.ascontiguousarray(vals[o])


def split(comm, nrow_loc, ncol_loc, nrow_glob, ncol_glob, parts, patterns, diag=None, row0=0):
    """A block-sparse lag kept in parts of their own patterns (``bsr.SplitBSR``: a split H of an
    excavated surface), the free term with the first."""
    from . import bsr
    return bsr.SplitBSR(comm, [bsr.BSRMat(comm, *csr, nrow_loc, ncol_loc, nrow_glob, ncol_glob, m,
                                          diag if k == 0 else None, row0, shell=False)
                               for k, (csr, m) in enumerate(zip(parts, patterns))]).mat


def _make(comm, nb, nloc, col_loc, n_rows_glob, n_cols_glob, csr, storage, fill, pattern=9, diag=None, row0=0):
    if nb == 0 and diag is None:
        return None, "empty"
    if isinstance(pattern, list):       # a split lag: its parts (block-sparse), or merged (dense)
        f = nb / float(n_rows_glob * n_cols_glob)
        if csr[0][2].dtype == np.float32 or not (storage == "dense" or (storage == "auto" and f > fill)):
            kind = "single" if csr[0][2].dtype == np.float32 else "baij"
            return split(comm, nloc, col_loc, n_rows_glob, n_cols_glob, csr, pattern, diag, row0), kind
        csr, pattern = merged(csr, pattern, nloc), 9
    extra = (pattern, diag, row0)
    if csr[2].dtype == np.float32:       # -ssi_lag_single_from: block-sparse whatever the fill (a dense
        return baij(comm, nloc, col_loc, n_rows_glob, n_cols_glob, *csr, *extra), "single"    # lag: every block)
    f = nb / float(n_rows_glob * n_cols_glob)
    use_dense = storage == "dense" or (storage == "auto" and f > fill)
    mk = dense if use_dense else baij
    return mk(comm, nloc, col_loc, n_rows_glob, n_cols_glob, *csr, *extra), ("dense" if use_dense else "baij")


def build_one(comm, buckets, lag, node_range, n_rows_glob, n_cols_glob, col_loc, storage="auto", fill=0.95):
    """Collective: the Mat of one lag of ``buckets`` (an interpolating matrix)."""
    r0, r1 = node_range
    F = buckets.diag(lag)
    csr, pattern = _take(buckets, lag)
    nb = comm.tompi4py().allreduce(buckets_count(csr, pattern))
    return _make(comm, nb, r1 - r0, col_loc, n_rows_glob, n_cols_glob, csr, storage, fill, pattern, F, r0)


def buckets_count(csr, pattern):
    """Blocks of a lag's CSR as ``_take`` gives it (one, or a split lag's parts)."""
    return sum(len(c[1]) for c in csr) if isinstance(pattern, list) else len(csr[1])


def mat_bytes(A):
    """Bytes a Mat stores (values and indices), from MatGetInfo."""
    if A is None:
        return 0
    from . import bsr
    if bsr.context(A) is not None:
        return bsr.context(A).nbytes
    PETSc = init()
    inf = A.getInfo(PETSc.Mat.InfoType.LOCAL)   # the caller sums over ranks
    return int(inf.get("memory", 0)) or int(inf.get("nz_allocated", 0) * 8)
