"""The flat block pattern for the coplanar pairs of an excavated surface (issue 42, item 1): on a surface
that is not one plane (``-ssi_mesh pit``: ground, walls, bottom) H keeps the blocks whose pairs all lie
in one horizontal plane (the ground's, the bottom's: r . n = 0, the entries outside the flat pattern
exact zeros) in the flat pattern H4 (4 values a block) and the others full (``lagset.SplitBuckets``,
``bsr.SplitBSR``); -ssi_lag_pattern full keeps the general 3x3 everywhere (the comparison).

What is checked: on a small pit the split lags hold the general path's blocks exactly (the flat part's
expanded blocks are the full ones, whose other entries are exact zeros), every flat block joins two
nodes of one horizontal plane, the stored bytes fall, and the Mats' products (matrix-vector and panel)
equal the general path's to 1e-12, and a saved and loaded lag is split again; the estimate counts the flat blocks (its bytes against the stored
ones); a wall's coplanar pairs have the flat pattern in rotated axes (normal x: H couples x with y and z,
G keeps xx, yy, yz, zy, zz; normal y likewise), which the split does not use (only horizontal planes
are split); whole runs of a pit and of a trench equal the general path to 1e-12 on 1 and 2 ranks."""
import numpy as np
import pytest

from helpers import cli, petsc
from test_history_block import same
from test_single import stored_gb

pytestmark = pytest.mark.mpi

OPTS = {"gauss": 2, "singular_order": 6, "subdivisions": 2, "near_factor": 1.0, "max_subdivisions": 8, "cache": True}


def _lagset(pattern, d=1.0, L=6):
    PETSc = petsc()
    from petsc_ssi.mesh.surface import pit
    from petsc_ssi.bem.lagset import Material, Regions, LagSet
    m = pit(6.0, 6.0, 1.0, 1.0, 1.0, d)
    reg = Regions(m, load_elems=m.groups["bottom"])
    return LagSet(PETSc.COMM_SELF, m, Material(548.0, 316.0, 2000.0), 2.5e-3, L, reg, [],
                  dict(OPTS, block_pattern=pattern))


def _blocks(B, lag):
    """{(row, column): full 3x3 block} of a lag of Buckets or SplitBuckets (the free term added)."""
    r, c, v = B.peek(lag)
    return {(int(a), int(b)): blk for a, b, blk in zip(r, c, v)}


def test_the_split_lags_hold_the_general_blocks_and_store_fewer_bytes():
    from petsc_ssi.bem import lagmats, bsr
    from petsc_ssi.bem.lagset import SplitBuckets
    ls, lf = _lagset("auto"), _lagset("full")
    assert ls.split and not lf.split
    H, _ = ls.assemble()
    F, _ = lf.assemble()
    assert isinstance(H, SplitBuckets)
    z = ls.mesh.nodes[:, 2]
    planes = _column_planes(ls)
    nflat = 0
    for lag in range(1, ls.L + 1):
        a, b = _blocks(H, lag), _blocks(F, lag)
        assert a.keys() == b.keys()
        assert all(np.array_equal(a[k], b[k]) for k in a)          # the same blocks, bit for bit
        for part, flat in ((H.flat, True), (H.full, False)):
            ip, c, _ = part.csr(lag)
            rows = np.repeat(part.rows, np.diff(ip))
            if flat:            # a flat block joins two nodes of one horizontal plane (an edge's column too,
                assert np.all(z[rows] == z[c])          # where the wall's elements add nothing at this lag)
            else:               # a coplanar block (the row's plane holds every element of the column's node)
                assert not any(planes[int(j)] == {z[i]} for i, j in zip(rows, c))     # is never full
        nflat += H.flat.count(lag)
    assert nflat > 0.3 * sum(H.count(lag) for lag in range(1, ls.L + 1))
    N = ls.mesh.n_nodes
    Ms, _ = lagmats.build(ls.comm, H, ls.L, ls.node_range, N, N, N, "sparse")
    Mf, _ = lagmats.build(lf.comm, F, lf.L, lf.node_range, N, N, N, "sparse")
    assert isinstance(bsr.context(Ms[0]), bsr.SplitBSR)
    rng = np.random.default_rng(42)
    x = rng.standard_normal(3 * N)
    XT = rng.standard_normal((3 * N, 9))
    for A, B in zip(Ms, Mf):
        ca, cb = bsr.context(A), bsr.context(B)
        ya, yb = np.empty(3 * N), np.empty(3 * N)
        ca.matvec(x, ya)
        cb.matvec(x, yb)
        assert np.abs(ya - yb).max() <= 1e-12 * np.abs(yb).max()
        Ra, Rb = np.zeros((3 * N, 9)), np.zeros((3 * N, 9))
        ca.panel(XT, Ra, -1.0)
        cb.panel(XT, Rb, -1.0)
        assert np.abs(Ra - Rb).max() <= 1e-12 * np.abs(Rb).max()
    ctx = bsr.context(Ms[0])                   # saved (-ssi_lags_save) and loaded: split again, the same bits
    back = bsr.split_flat(bsr.context(bsr.from_aij(ctx.to_aij(), 9, ctx.diag_aij())))
    assert isinstance(back, bsr.SplitBSR) and back.nbytes == ctx.nbytes
    ya, yb = np.empty(3 * N), np.empty(3 * N)
    ctx.matvec(x, ya)
    back.matvec(x, yb)
    assert np.array_equal(ya, yb)
    stored = sum(lagmats.mat_bytes(M) for M in Ms)
    general = sum(lagmats.mat_bytes(M) for M in Mf)
    assert stored < 0.85 * general, (stored, general)
    # the estimate counts the split: its bytes against the general estimate's as the stored ones (10 %)
    est = ls.estimate_memory(ls.L, storage="sparse", load=False)[0]
    est_f = lf.estimate_memory(lf.L, storage="sparse", load=False)[0]
    assert abs((est / est_f) / (stored / general) - 1.0) < 0.1, (est / est_f, stored / general)


def _column_planes(ls):
    """Per node, the set of the horizontal planes' heights of the elements holding it (NaN: a wall)."""
    from petsc_ssi.bem.windows import plane_heights
    pz = plane_heights(ls.VX)
    out = {}
    for e, cell in enumerate(ls.mesh.cells):
        for n in cell:
            out.setdefault(int(n), set()).add(float(pz[e]))
    return out


def _pair_blocks(xc, X, L=4):
    """The full 3x3 blocks P (H), U (G) of lags 1..L of the point xc and the element X, regular pair."""
    from petsc_ssi.bem.assemble import _integrate, SING_TOL
    from petsc_ssi.bem.packs import quad, wave
    gq, gw = np.polynomial.legendre.leggauss(3)
    gr, gwr = np.polynomial.legendre.leggauss(6)
    Ub, Pb = np.zeros((L, 9, 3, 3)), np.zeros((L, 9, 3, 3))
    Us, Ps = np.zeros((9, 3, 3)), np.zeros((9, 3, 3))
    cp, cs, rho, dt = 548.0, 316.0, 2000.0, 2.5e-3
    nu = ((cp / cs) ** 2 - 2) / (2 * ((cp / cs) ** 2 - 1))
    # (the material as the runs pass it, packs.wave's float64 array: a tuple here made numba compile a second
    # version of the whole integration chain, 12 s of a fresh clone's suite)
    _integrate(xc, X, -1, 2, 1, L, True, wave(dt, cp, cs, rho, nu),
               quad(2, 0.0, 2, gq, gw, gr, gwr, SING_TOL, 1.0), (Ub, Pb, Us, Ps, np.zeros(0), np.zeros(0)))
    return Pb, Ub


@pytest.mark.parametrize("normal", [0, 1])
def test_a_walls_coplanar_pairs_have_the_flat_pattern_in_rotated_axes(normal):
    """A point and an element in one vertical plane x = 0.3 (normal x) or y = 0.3 (normal y): H couples
    the normal component n with the in-plane ones only ((n, t), (t, n)), G keeps (n, n) and the in-plane
    2x2 ((t, t')); every other entry is zero (round-off, 1e-14 of the block's largest: the element's mapping
    puts its Gauss points in the plane to round-off), the others not."""
    t1, t2 = [k for k in range(3) if k != normal]
    corners = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [0.5, 0], [1, 0.5], [0.5, 1], [0, 0.5], [0.5, 0.5]])
    X = np.zeros((9, 3))
    X[:, normal] = 0.3
    X[:, t1] = 1.0 + corners[:, 0]
    X[:, t2] = -0.5 + corners[:, 1]
    xc = np.zeros(3)
    xc[normal] = 0.3
    xc[t1], xc[t2] = 0.2, -0.1
    P, U = _pair_blocks(xc, X)
    hkeep = np.zeros((3, 3), bool)
    hkeep[normal, [t1, t2]] = hkeep[[t1, t2], normal] = True
    gkeep = np.zeros((3, 3), bool)
    gkeep[normal, normal] = True
    gkeep[np.ix_([t1, t2], [t1, t2])] = True
    for B, keep in ((P, hkeep), (U, gkeep)):
        big = np.abs(B).max(axis=(0, 1))
        assert big[~keep].max() <= 1e-14 * big.max() and big[keep].min() > 1e-3 * big.max(), big


PIT = ["-ssi_problem", "bem", "-ssi_mesh", "pit", "-ssi_mesh_params", "a=1,b=1,d=1", "-ssi_mesh_size", "6,6",
       "-ssi_mesh_h", "1", "-ssi_load_group", "bottom", "-ssi_load_p0", "1000", "-ssi_dt", "0.0025",
       "-ssi_t_end", "0.015", "-ssi_receivers", "0,0,-1;1,0,-0.5;2,0,0", "-ssi_output_stride", "2",
       "-ssi_warn_beta", "0"]
TRENCH = ["-ssi_problem", "bem", "-ssi_mesh", "pit", "-ssi_mesh_params", "a=0.5,b=2,d=1,x=1.5", "-ssi_mesh_size",
          "6,6", "-ssi_mesh_h", "1", "-ssi_load_group", "ground", "-ssi_load_p0", "1000", "-ssi_dt", "0.0025",
          "-ssi_t_end", "0.015", "-ssi_receivers", "0,0,0;1.5,0,-1;2,1,0", "-ssi_output_stride", "2",
          "-ssi_warn_beta", "0"]


# slow tier: whole pit and trench runs, split against general on 1 and 2 ranks (6 runs, 57 s measured); the
# default tier's sibling is test_the_split_lags_hold_the_general_blocks_and_store_fewer_bytes (the same
# blocks and products on one process)
@pytest.mark.slow
@pytest.mark.parametrize("case", ["pit", "trench"])
def test_excavated_runs_equal_the_general_pattern_on_one_and_two_ranks(tmp_path, case):
    args = PIT if case == "pit" else TRENCH
    g, a, b = (str(tmp_path / f"{k}.h5") for k in ("general", "split1", "split2"))
    est_g, st_g = stored_gb(cli(args + ["-ssi_lag_pattern", "full", "-ssi_output", g]).stdout)
    est_a, st_a = stored_gb(cli(args + ["-ssi_output", a]).stdout)
    cli(args + ["-ssi_output", b], nranks=2)
    same(g, a, 1e-12)
    same(g, b, 1e-12)
    assert st_a < 0.9 * st_g and est_a < 0.9 * est_g, (st_a, st_g, est_a, est_g)     # stored and estimated
