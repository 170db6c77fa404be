"""The step matrix's mirror-symmetric blocks (bem/mirror.py) on small matrices: the basis Q is orthogonal and
splits the reflections' characters, the folded blocks equal Q^T A Q for a matrix that commutes with the
reflections, and a matrix or a node set that is not symmetric is refused with the reason."""
import numpy as np
import pytest
import scipy.sparse as sp

pytestmark = pytest.mark.unit


def _nodes(nx, ny, h=0.6):
    x, y = np.meshgrid(np.arange(nx) * h - 0.5 * (nx - 1) * h, np.arange(ny) * h - 0.3 * (ny - 1) * h)
    return np.c_[x.ravel(), y.ravel(), np.zeros(x.size)]


def _perm(nmap, sign):
    n = len(nmap)
    d = np.arange(3 * n)
    return sp.csr_matrix((sign[d % 3], (d, 3 * nmap[d // 3] + d % 3)), shape=(3 * n, 3 * n))


def _symmetric_matrix(X, refl, seed=1):
    """A sparse matrix coupling nodes within 1.3 m, averaged over the group: it commutes with every reflection."""
    from scipy.spatial import cKDTree
    from petsc_ssi.bem.mirror import group
    rng = np.random.default_rng(seed)
    pairs = cKDTree(X).query_pairs(1.3, output_type="ndarray")
    pairs = np.r_[pairs, pairs[:, ::-1], np.c_[np.arange(len(X)), np.arange(len(X))]]
    blocks = rng.standard_normal((len(pairs), 3, 3))
    r = (3 * pairs[:, 0])[:, None, None] + np.arange(3)[None, :, None] + 0 * np.arange(3)[None, None, :]
    c = (3 * pairs[:, 1])[:, None, None] + 0 * np.arange(3)[None, :, None] + np.arange(3)[None, None, :]
    A = sp.csr_matrix((blocks.ravel(), (r.ravel(), c.ravel())), shape=(3 * len(X),) * 2)
    A = A + 8.0 * sp.eye(3 * len(X))
    maps, signs, _ = group(refl)
    S = sum(_perm(m, s) @ A @ _perm(m, s).T for m, s in zip(maps, signs)) / len(maps)
    return S.tocsr(), maps, signs


@pytest.mark.parametrize("nx,ny,both", [(7, 5, True), (6, 5, True), (7, 4, False)])
def test_basis_is_orthogonal_and_splits_the_characters(nx, ny, both):
    from petsc_ssi.bem.mirror import reflections, group, basis
    X = _nodes(nx, ny)
    if not both:
        X[:, 1] += 0.05 * X[:, 0] ** 2       # (not symmetric about y = c any more; still about x = 0)
    pres = np.zeros(len(X), bool)
    refl = reflections(X, pres, [])
    assert [a for a, _, _ in refl] == ([0, 1] if both else [0])
    maps, signs, chars = group(refl)
    col, val, rep_dof, sig_of = basis(maps, signs, chars)
    n = 3 * len(X)
    assert rep_dof.size == n
    Q = sp.csr_matrix((val[col >= 0], (np.nonzero(col >= 0)[0], col[col >= 0])), shape=(n, n))
    assert abs(Q.T @ Q - sp.eye(n)).max() < 1e-15
    for g in range(len(maps)):                # R_g q = sigma(g) q for each column's block sigma
        RQ = _perm(maps[g], signs[g]) @ Q
        assert abs(RQ - Q @ sp.diags(chars[sig_of, g])).max() < 1e-15


def test_folded_blocks_are_q_transpose_a_q():
    from petsc_ssi.bem.mirror import reflections, group, basis, fold
    X = _nodes(7, 5)
    refl = reflections(X, np.zeros(len(X), bool), [])
    A, maps, signs = _symmetric_matrix(X, refl)
    _, _, chars = group(refl)
    col, val, rep_dof, sig_of = basis(maps, signs, chars)
    n = A.shape[0]
    Q = sp.csr_matrix((val[col >= 0], (np.nonzero(col >= 0)[0], col[col >= 0])), shape=(n, n))
    ref = (Q.T @ A @ Q).toarray()
    blk = sig_of[:, None] != sig_of[None, :]
    assert abs(ref[blk]).max() < 1e-13 * abs(ref).max()      # block diagonal
    for r0, r1 in ((0, n), (0, 3 * 17), (3 * 17, n)):          # a rank's rows: its representatives' block rows
        own = np.flatnonzero((rep_dof >= r0) & (rep_dof < r1))
        k0, k1 = own[0], own[-1] + 1
        assert np.array_equal(own, np.arange(k0, k1))
        loc = A[r0:r1]
        ip, ix, dv = fold(loc.indptr.astype(np.int64), loc.indices.astype(np.int64), loc.data, r0, k0,
                          rep_dof[k0:k1].astype(np.int64), sig_of[k0:k1].astype(np.int64), col, val)
        got = sp.csr_matrix((dv, ix, ip), shape=(k1 - k0, n)).toarray()
        assert np.abs(got - ref[k0:k1]).max() < 1e-13 * np.abs(ref).max()
        assert np.all(np.diff(ip) > 0)


def test_mirror_blocks_solve_and_refusals():
    from petsc_ssi.petsc import init
    from petsc_ssi.bem.mirror import reflections, MirrorBlocks
    PETSc = init()
    comm = PETSc.COMM_SELF
    X = _nodes(7, 5)
    pres = np.zeros(len(X), bool)
    refl = reflections(X, pres, [])
    A, _, _ = _symmetric_matrix(X, refl, seed=3)
    n = A.shape[0]

    def mat(S):
        S = S.tocsr()
        S.sort_indices()
        M = PETSc.Mat().createAIJ(size=S.shape, csr=(S.indptr.astype(PETSc.IntType),
                                                     S.indices.astype(PETSc.IntType), S.data), comm=comm)
        M.assemble()
        return M
    M = mat(A)
    mb = MirrorBlocks(PETSc, comm, M, X, pres, [])
    assert mb.why == "" and mb.defect < 1e-14 and sum(mb.sizes) == n and len(mb.sizes) == 4
    b = np.sin(np.arange(n) + 0.5)
    Ap = sp.csr_matrix(mb.Ap.getValuesCSR()[::-1], shape=(n, n)).toarray()
    qi, qj, qv = mb.Q.getValuesCSR()
    Q = sp.csr_matrix((qv, qj, qi), shape=(n, n))
    x = Q @ np.linalg.solve(Ap, Q.T @ b)
    assert np.abs(A @ x - b).max() < 1e-13 * np.abs(b).max()
    mb.destroy()
    # a matrix that does not commute: refused, with its defect
    P = A.tolil()
    P[0, 5] += 0.5
    Mp = mat(P)
    mb = MirrorBlocks(PETSc, comm, Mp, X, pres, [])
    assert "does not commute" in mb.why and mb.defect > 1e-3 and mb.Ap is None
    # prescribed nodes that do not mirror: refused before any product
    pres[0] = True
    mb = MirrorBlocks(PETSc, comm, M, X, pres, [])
    assert "not mirror-symmetric" in mb.why and np.isnan(mb.defect)
    for o in (M, Mp):
        o.destroy()


def test_step_lu_model_and_blocks_of():
    """The estimate's model of the step matrix's LU (toeplitz.step_lu): more entries with more DOFs and a longer
    reach, fewer in mirror blocks; on the 72 m building's numbers (44 649 DOFs, reach 6.3 node spacings, 4
    blocks) within 30 % of the 50.3 M entries MUMPS reported (runs/building/README.md). ``mirror.blocks_of``: 4 for
    a centred rigid footing, 2 for one centred in y only, 1 for neither (from the nodes and regions alone)."""
    from types import SimpleNamespace
    from petsc_ssi.bem.toeplitz import step_lu
    from petsc_ssi.bem.mirror import blocks_of
    e1, f1, s1 = step_lu(44649, 6.3, 1)
    e4, f4, s4 = step_lu(44649, 6.3, 4)
    assert e4 < e1 and f4 < f1 and s4 < s1
    assert step_lu(44649, 4.0, 4)[0] < e4 < step_lu(60000, 6.3, 4)[0]
    assert abs(e4 / 50.33e6 - 1) < 0.3
    assert step_lu(44649, 6.3, 4, ranks=4)[2] > s4          # (MUMPS's solve does not speed up with ranks)
    X = _nodes(9, 9, 0.5)
    X[:, 1] -= X[:, 1].mean()

    def prob(sel):
        nodes = np.flatnonzero(sel)
        reg = SimpleNamespace(disp_nodes=nodes, tnode=nodes, n_load=0, n_t=nodes.size)
        return SimpleNamespace(regions=reg, mesh=SimpleNamespace(nodes=X, n_nodes=len(X)), planes=[])
    x, y = np.round(X[:, 0], 9), np.round(X[:, 1], 9)
    assert blocks_of(prob((abs(x) <= 0.5) & (abs(y) <= 0.5))) == 4
    assert blocks_of(prob((x >= 0.5) & (x <= 1.5) & (abs(y) <= 0.5))) == 2
    assert blocks_of(prob((x >= 0.5) & (x <= 1.5) & (y >= 0) & (y <= 1.0))) == 1
