"""The flat surface's block patterns (issue 29; bem/bsr.py PATTERNS): where every collocation point
and element lie in one plane, H keeps 4 of the 9 entries of each 3x3 block and G 5, and the
products skip the exact zeros.

What is checked: the pattern kernels (matrix-vector product and panel product, float64 and
float32 values) give the full 3x3 kernels' numbers on the expanded blocks (the same products and
sums minus exact zeros: equal arrays); the split dense storage of a flat surface and the free term
carried apart give the dense numpy products to round-off; whole runs with the flat pattern equal
the general path (-ssi_lag_pattern full) to 1e-12 for every storage (block-sparse, dense, single
precision, interpolating matrices, a prescribed-displacement region's G) on 1 and 2 ranks; a lag
file of the flat pattern is smaller than the full one and reloads on another rank count. The
general path on a surface that is not flat is tests/bem/test_assembly_layout.py's."""
import json
import os

import numpy as np
import pytest

from helpers import cli, petsc
from test_history_block import BEM, INTERP, DISP, same
from test_single import stored_gb

pytestmark = pytest.mark.mpi


def _random_pattern_csr(rng, m, nrow, ncol, fill, dtype=np.float64):
    indptr, indices = [0], []
    for _ in range(nrow):
        cols = np.sort(rng.permutation(ncol)[:max(1, int(fill * ncol))])
        indices.extend(cols)
        indptr.append(len(indices))
    data = rng.standard_normal((len(indices), m)).astype(dtype)
    return np.array(indptr, np.int64), np.array(indices, np.int32), data


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
@pytest.mark.parametrize("m", [4, 5])
def test_pattern_kernels_give_the_full_kernels_numbers(m, dtype):
    from petsc_ssi.bem import bsr
    rng = np.random.default_rng(m)
    indptr, indices, data = _random_pattern_csr(rng, m, 23, 31, 0.4, dtype)
    full = bsr.expand(data, m)                        # (n, 3, 3), zeros outside the pattern
    assert np.array_equal(bsr.compact(full, m), data)
    x = rng.standard_normal(3 * 31)
    y, yf = np.empty(3 * 23), np.empty(3 * 23)
    bsr.matvec(m, indptr, indices, data, x, y)
    bsr.matvec(9, indptr, indices, np.ascontiguousarray(full.reshape(-1, 9)), x, yf)
    assert np.array_equal(y, yf) and np.abs(y).max() > 0
    for b in (1, 7, 32):                              # (32: H4 two rows at a time, bsr.PAIR_FROM)
        XT = rng.standard_normal((3 * 31, b))
        R0 = rng.standard_normal((3 * 23, b))
        R, Rf = R0.copy(), R0.copy()
        bsr.panel(m, indptr, indices, data, XT, R, -1.0)
        bsr.panel(9, indptr, indices, np.ascontiguousarray(full.reshape(-1, 9)), XT, Rf, -1.0)
        assert np.array_equal(R, Rf)


def _dense_of(m, indptr, indices, data, nrow, ncol, diag=None, row0=0):
    from petsc_ssi.bem import bsr
    A = np.zeros((3 * nrow, 3 * ncol))
    full = bsr.expand(data, m)
    for i in range(nrow):
        for k in range(indptr[i], indptr[i + 1]):
            A[3 * i:3 * i + 3, 3 * indices[k]:3 * indices[k] + 3] = full[k]
        if diag is not None:
            A[3 * i:3 * i + 3, 3 * (row0 + i):3 * (row0 + i) + 3] += diag[i]
    return A


@pytest.mark.parametrize("m", [4, 5])
def test_split_dense_and_the_free_term_give_the_dense_products(m):
    """A flat surface's dense lag in two dense pieces (bsr.DenseSplit), and a block-sparse one with the
    free term carried apart, against numpy's dense products of the same matrix: 1e-13."""
    PETSc = petsc()
    from petsc_ssi.bem import bsr
    rng = np.random.default_rng(10 + m)
    nrow, ncol, row0 = 13, 29, 5
    indptr, indices, data = _random_pattern_csr(rng, m, nrow, ncol, 0.6)
    diag = rng.standard_normal((nrow, 3, 3))
    A = _dense_of(m, indptr, indices, data, nrow, ncol, diag, row0)
    x = rng.standard_normal(3 * ncol)
    XT = rng.standard_normal((3 * ncol, 6))
    for ctx in (bsr.DenseSplit.from_csr(PETSc.COMM_SELF, m, nrow, ncol, nrow, ncol, indptr, indices, data, diag,
                                        row0),
                bsr.BSRMat(PETSc.COMM_SELF, indptr, indices, data, nrow, ncol, nrow, ncol, m, diag, row0)):
        y = np.empty(3 * nrow)
        ctx.matvec(x, y)
        tol = 1e-13 * np.abs(A).sum(1).max() * np.abs(x).max()
        assert np.abs(y - A @ x).max() <= tol
        RT = np.zeros((3 * nrow, 6))
        ctx.panel(XT, RT, -1.0)
        assert np.abs(RT + A @ XT).max() <= 1e-13 * (np.abs(A) @ np.abs(XT)).max()
        # the stored bytes: m of 9 entries a block (dense: every node pair)
        values = ctx.data.size if ctx.kind == "bsr" else sum(P.size for _, _, P in ctx.pieces)
        assert values == m * (len(indices) if ctx.kind == "bsr" else nrow * ncol)


@pytest.mark.parametrize("m", [4, 5, 9])
def test_columns_are_the_products_with_unit_vectors_bit_for_bit(m):
    """bsr.columns (the coupled set-up's right-hand sides H_s e_j read off the blocks instead of a
    product per column) equals the matvec with each unit vector exactly, for a block-sparse lag with the
    free term, its dense pieces, a split lag (two parts, their products summed) and a lag that holds a
    column twice in a row (not read off: None, the caller multiplies); columns in any order, with
    repeats and the free term's own column among them."""
    PETSc = petsc()
    from petsc_ssi.bem import bsr
    rng = np.random.default_rng(40 + m)
    nrow, ncol, row0 = 11, 26, 7
    indptr, indices, data = _random_pattern_csr(rng, m, nrow, ncol, 0.5)
    diag = rng.standard_normal((nrow, 3, 3))
    ctxs = [bsr.BSRMat(PETSc.COMM_SELF, indptr, indices, data, nrow, ncol, nrow, ncol, m, diag, row0)]
    if m in (4, 5):
        ctxs.append(bsr.DenseSplit.from_csr(PETSc.COMM_SELF, m, nrow, ncol, nrow, ncol, indptr, indices, data,
                                            diag, row0))
    else:                       # a split lag: the blocks of even columns in H4, the others full
        rows = np.repeat(np.arange(nrow), np.diff(indptr))
        parts = []
        for keep, mm in ((indices % 2 == 0, 4), (indices % 2 == 1, 9)):
            ip = np.zeros(nrow + 1, np.int64)
            np.cumsum(np.bincount(rows[keep], minlength=nrow), out=ip[1:])
            vals = bsr.compact(bsr.expand(data[keep], 9), mm) if mm == 4 else data[keep]
            parts.append(bsr.BSRMat(PETSc.COMM_SELF, ip, indices[keep], vals, nrow, ncol, nrow, ncol, mm,
                                    diag if mm == 4 else None, row0, shell=False))
        ctxs.append(bsr.SplitBSR(PETSc.COMM_SELF, parts))
    dofs = np.concatenate([rng.permutation(3 * ncol)[:20], [3 * (row0 + 2) + 1, 5, 5]])
    for ctx in ctxs:
        got = bsr.columns(ctx.mat, dofs)
        ref = np.zeros((3 * nrow, dofs.size))
        x = np.zeros(3 * ncol)
        for j, d in enumerate(dofs):
            x[:] = 0.0
            x[d] = 1.0
            y = np.zeros(3 * nrow)                  # (contiguous, as a run's: a column view compiles its own kernel)
            ctx.matvec(x, y)
            ref[:, j] = y
        assert got is not None and np.array_equal(got, ref) and np.abs(ref).max() > 0, type(ctx).__name__
    empty = bsr.BSRMat(PETSc.COMM_SELF, np.zeros(nrow + 1, np.int64), np.zeros(0, np.int32), np.zeros((0, m)),
                       nrow, ncol, nrow, ncol, m)                   # (a split lag's part can hold no block)
    assert np.array_equal(empty.columns(dofs), np.zeros((3 * nrow, dofs.size)))
    twice = indices.copy()
    twice[indptr[3] + 1] = twice[indptr[3]]           # row 3 holds a column node twice
    dup = bsr.BSRMat(PETSc.COMM_SELF, indptr, twice, data, nrow, ncol, nrow, ncol, m, diag, row0)
    assert bsr.columns(dup.mat, dofs) is None
    assert bsr.columns(None, dofs) is None


CASES = {        # (options, ranks): every storage the lags have, a G of traction columns, interpolation
    "block-sparse, interpolated, 2 ranks": (BEM + INTERP + ["-ssi_lag_storage", "sparse"], 2),
    "dense, prescribed motion, 2 ranks": (DISP + ["-ssi_lag_storage", "dense", "-ssi_t_end", "0.03"], 2),
    "single precision, symmetry, 2 ranks": (BEM + INTERP + ["-ssi_lag_single_from", "5", "-ssi_symmetry",
                                                             "x=sym,y=sym"], 2),
    "auto storage, prescribed motion, 1 rank": (DISP + ["-ssi_t_end", "0.03"], 1),
}


# slow tier: every whole run (11-14 s each); make test keeps the patterns' kernels against the full kernels
# (test_pattern_kernels_give_the_full_kernels_numbers), the split dense and free term
# (test_split_dense_and_the_free_term_give_the_dense_products) and the lag files' round trip above and below
SLOW_CASES = ("single precision, symmetry, 2 ranks", "auto storage, prescribed motion, 1 rank",
              "block-sparse, interpolated, 2 ranks", "dense, prescribed motion, 2 ranks")


@pytest.mark.parametrize("case", [pytest.param(c, marks=[pytest.mark.slow] if c in SLOW_CASES else []) for c in CASES])
def test_the_flat_pattern_is_the_general_path(case, tmp_path):
    args, n = CASES[case]
    out = {}
    for pattern in ("auto", "full"):
        path = str(tmp_path / f"{pattern}.h5")
        r = cli(args + ["-ssi_output", path, "-ssi_lag_pattern", pattern], nranks=n)
        out[pattern] = (path, stored_gb(r.stdout)[1])
    same(out["full"][0], out["auto"][0], rtol=1e-12)
    # the flat pattern stores fewer bytes (H 36 B a block against 76, G 40 against 72 dense)
    assert out["auto"][1] < 0.75 * out["full"][1]


@pytest.mark.parametrize("m", [4, 5])
def test_the_stored_entries_go_through_a_lag_files_aij_and_back(m):
    """A lag file holds each python Mat as an MPIAIJ of its stored entries (and H_1's free term as
    one of its own): from it, the same blocks, free term and products, block-sparse or split dense."""
    PETSc = petsc()
    from petsc_ssi.bem import bsr
    rng = np.random.default_rng(20 + m)
    nrow, ncol = 11, 17
    indptr, indices, data = _random_pattern_csr(rng, m, nrow, ncol, 0.5)
    diag = rng.standard_normal((nrow, 3, 3))
    x = rng.standard_normal(3 * ncol)
    for dense in (False, True):
        cls = bsr.DenseSplit.from_csr if dense else None
        ctx = (cls(PETSc.COMM_SELF, m, nrow, ncol, nrow, ncol, indptr, indices, data, diag, 0) if dense else
               bsr.BSRMat(PETSc.COMM_SELF, indptr, indices, data, nrow, ncol, nrow, ncol, m, diag, 0))
        A, D = ctx.to_aij(), ctx.diag_aij()
        assert A.getInfo()["nz_used"] == m * (nrow * ncol if dense else len(indices))
        back = bsr.context(bsr.from_aij(A, m, D, dense=dense))
        assert back.kind == ctx.kind and back.pattern == m and np.array_equal(back.diag, diag)
        y, y2 = np.empty(3 * nrow), np.empty(3 * nrow)
        ctx.matvec(x, y)
        back.matvec(x, y2)
        assert np.array_equal(y, y2)
        if not dense:
            assert np.array_equal(back.indptr, indptr) and np.array_equal(back.indices, indices)
            assert np.array_equal(back.data, data)


# slow tier: a flat lag file saved at -n 2 and reloaded at -n 1 (16 s; the in-process round trip of the stored
#  entries through MPIAIJ and test_lagstore's bitwise reload stay)
@pytest.mark.slow
def test_a_lag_file_holds_the_pattern_and_reloads(tmp_path):
    """Saved at 2 ranks with dense lags (split pieces, H_1's free term apart) and with block-sparse
    ones: the file lists those kinds, is smaller than the general path's, and a run loading it at 1
    rank equals the run that assembled to 1e-12."""
    args = DISP + ["-ssi_lag_storage", "dense", "-ssi_t_end", "0.03"]
    sizes = {}
    for pattern in ("auto", "full"):
        lags = str(tmp_path / f"{pattern}.lags")
        cli(args + ["-ssi_output", str(tmp_path / f"save-{pattern}.h5"), "-ssi_lags_save", lags,
                    "-ssi_lag_pattern", pattern], nranks=2)
        sizes[pattern] = os.path.getsize(lags)
        kinds = [k for _, k in json.load(open(lags + ".json"))["mats"]]
        if pattern == "auto":
            assert "split4+diag" in kinds and "split5" in kinds
        else:
            assert "dense" in kinds
    assert sizes["auto"] < 0.7 * sizes["full"]
    r = cli(args + ["-ssi_output", str(tmp_path / "load.h5"), "-ssi_lags_load", str(tmp_path / "auto.lags")])
    assert "loaded from" in r.stdout
    same(str(tmp_path / "save-auto.h5"), str(tmp_path / "load.h5"), rtol=1e-12)
