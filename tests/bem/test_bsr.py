"""The block-sparse lag kernels of bem/bsr.py against dense numpy: the matrix-vector product, the
panel product and the panel of combined states (the latter bit for bit: the time-blocked history
sum's restart and truncated-run properties rest on it)."""
import numpy as np
import pytest

from petsc_ssi.bem import bsr

pytestmark = pytest.mark.unit


def random_bsr(rng, nrow, ncol, fill, dtype=np.float64):
    """A random 3x3-block CSR (columns unsorted in each row) and its dense (3 nrow x 3 ncol) matrix."""
    indptr, indices = [0], []
    for _ in range(nrow):
        cols = rng.permutation(ncol)[:max(1, int(fill * ncol))]
        indices.extend(cols)
        indptr.append(len(indices))
    data = rng.standard_normal((len(indices), 3, 3)).astype(dtype)
    A = np.zeros((3 * nrow, 3 * ncol))
    for i in range(nrow):
        for k in range(indptr[i], indptr[i + 1]):
            A[3 * i:3 * i + 3, 3 * indices[k]:3 * indices[k] + 3] += data[k]
    # the blocks as the runs keep them, (blocks, 9) row-major: the kernels' compiled version the runs use
    return np.array(indptr, np.int64), np.array(indices, np.int32), data.reshape(len(indices), 9), A


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_matvec_and_panel_match_dense(dtype):
    rng = np.random.default_rng(3)
    indptr, indices, data, A = random_bsr(rng, 17, 23, 0.4, dtype)
    x = rng.standard_normal(3 * 23)
    y = np.empty(3 * 17)
    bsr._matvec(indptr, indices, data, x, y)
    assert np.abs(y - A @ x).max() <= 1e-13 * np.abs(A).sum(1).max() * np.abs(x).max()
    for b in (1, 5, 32):
        XT = rng.standard_normal((3 * 23, b))
        RT0 = rng.standard_normal((3 * 17, b))
        for sign in (1.0, -1.0):
            RT = RT0.copy()
            bsr._panel(indptr, indices, data, XT, RT, sign)
            ref = RT0 + sign * (A @ XT)
            assert np.abs(RT - ref).max() <= 1e-13 * (np.abs(A) @ np.abs(XT)).max()


def test_panel_states_is_the_numpy_loop_bit_for_bit():
    """X[k] += c * state[slot], term by term in order (both layouts), the loop the time-blocked sum
    used before the kernel: identical bits, repeated rows included."""
    rng = np.random.default_rng(5)
    rep = rng.standard_normal((7, 301)) * 10.0 ** rng.integers(-8, 8, (7, 1))
    rows = np.array([0, 3, 3, 1, 0, 4, 3], np.int64)
    slots = np.array([2, 6, 5, 0, 1, 1, 4], np.int64)
    coefs = np.array([1.0, 2.0, 1.0, 1.0 / 3.0, -0.7, 2.0, 1e-3])
    ref = np.zeros((5, 301))
    for k, s, c in zip(rows, slots, coefs):
        ref[k] += c * rep[s]
    x = np.zeros((5, 301))
    bsr.panel_states(rep, rows, slots, coefs, x, False)
    assert np.array_equal(x, ref)
    xt = np.zeros((301, 5))
    bsr.panel_states(rep, rows, slots, coefs, xt, True)
    assert np.array_equal(xt, ref.T)


def _banded(rng, nrow, ncol, r0, reach, pattern=bsr.FULL, diag=True):
    """A BSRMat of rows r0..r0+nrow-1 (of ncol column nodes) whose blocks lie within ``reach`` nodes of the row's
    own node, columns unsorted, with a free term: a short lag's shape (the step matrix's lags 1-2)."""
    indptr, indices = [0], []
    for i in range(nrow):
        g = r0 + i
        cols = rng.permutation(np.arange(max(0, g - reach), min(ncol, g + reach + 1)))
        indices.extend(cols)
        indptr.append(len(indices))
    data = rng.standard_normal((len(indices), len(bsr.PATTERNS[pattern])))
    d = rng.standard_normal((nrow, 3, 3)) if diag else None
    return bsr.BSRMat(None, np.array(indptr), np.array(indices), data, nrow, nrow, 4 * nrow, ncol, pattern, d, r0,
                      shell=False)


@pytest.mark.parametrize("pattern", [bsr.FULL, bsr.H4, bsr.G5])
def test_a_remapped_lag_reads_its_columns_alone_bit_for_bit(pattern):
    """``remapped`` onto the columns a rank's rows read (``column_nodes``: the blocks' columns and the free term's
    own nodes) gives the matrix-vector and panel products of every column, bit for bit (the same operations on
    the same values), for one matrix and for a SplitBSR of two patterns; a node left out is refused."""
    rng = np.random.default_rng(11)
    ncol, r0, nrow = 200, 80, 30
    A = _banded(rng, nrow, ncol, r0, 6, pattern)
    nodes = bsr.column_nodes(A, ncol)
    assert nodes[0] == r0 - 6 and nodes[-1] == r0 + nrow - 1 + 6 and nodes.size == nrow + 12
    B = _banded(rng, nrow, ncol, r0, 3, bsr.H4, diag=False)
    S = bsr.SplitBSR.__new__(bsr.SplitBSR)        # (a SplitBSR without its python Mat: no PETSc here)
    S.parts, S.comm, S.sizes, S.diag, S.row0, S.mat = [A, B], None, A.sizes, A.diag, A.row0, None
    x = rng.standard_normal(3 * ncol) * 10.0 ** rng.integers(-6, 6, 3 * ncol)
    xc = x.reshape(-1, 3)[nodes].ravel()
    XT = np.ascontiguousarray(rng.standard_normal((3 * ncol, 9)))
    XTc = np.ascontiguousarray(XT.reshape(ncol, 3, 9)[nodes].reshape(-1, 9))
    for M in (A, S):
        Mc = bsr.remapped(M, nodes)
        y, yc = np.empty(3 * nrow), np.empty(3 * nrow)
        M.matvec(x, y)
        Mc.matvec(xc, yc)
        assert np.array_equal(y, yc)
        RT, RTc = np.zeros((3 * nrow, 9)), np.zeros((3 * nrow, 9))
        M.panel(XT, RT, -1.0)
        Mc.panel(XTc, RTc, -1.0)
        assert np.array_equal(RT, RTc)
        assert Mc.data is A.data if M is A else Mc.parts[0].data is A.data      # the values shared, not copied
    with pytest.raises(ValueError, match="not among the nodes"):
        bsr.remapped(A, nodes[1:])


def test_release_frees_the_lag_mats_and_their_values():
    """A python lag Mat and its BSRMat hold each other (the Mat's context; the context's ``mat``), a cycle through
    PETSc that Python's collector does not see: ``Marcher.release`` destroys the Mats, after which their values go
    (``petsc-ssi impedance`` calls it between its modes: each mode's lags had stayed in the process)."""
    import gc
    import weakref
    from helpers import petsc
    from petsc_ssi.bem.march import Marcher
    PETSc = petsc()

    class Lags:
        pass

    M = bsr.from_csr(PETSc.COMM_SELF, 2, 2, 2, 2, np.array([0, 1, 2]), np.array([0, 1], np.int32), np.ones((2, 9)))
    ref = weakref.ref(bsr.context(M))
    lags = Lags()
    lags.H, lags.G, lags.HI, lags.GI = [None, M], [M], [], []
    del M
    gc.collect()
    assert ref() is not None                # (held by the lists)
    Marcher.release(lags)
    gc.collect()
    assert ref() is None and lags.H == [None, None] and lags.G == [None]
