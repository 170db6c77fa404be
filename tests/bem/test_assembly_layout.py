"""The assembly's accumulation and layout (bem/assemble.py, model.Buckets; issue 13 item 2) against a
literal sum: for every row and every virtual element (symmetry images included), the element
integrals of the pair (the same quadrature call the kernel makes) times the image's column signs are
added into dense H_l and G_l (the free term of H_1 apart). The kernel keeps a slot map per row, emits each row
by (lag, column), and the Buckets append chunks into per-lag block CSR: the stored blocks must equal
the literal sums exactly (same additions in the same order), be exactly the blocks that received a
non-zero contribution (H) or a traction column (G), and come in CSR order. Chunks of one and of
several rows give the same arrays bit for bit; the element cache (integrals of a translated copy of
a pair) changes them by round-off only. On the flat surface the blocks keep only their pattern's
entries (bem/bsr.py: H 4, G 5 of 9), and the literal sums are exactly zero in the others; the
general 3x3 path (``block_pattern`` "full") stores the same sums with the zeros."""
import numpy as np
import pytest

from helpers import petsc

pytestmark = pytest.mark.run


def _lagset(planes, chunk_cache, pattern="auto", bump=0.0):
    PETSc = petsc()
    from petsc_ssi.mesh.surface import grid
    from petsc_ssi.bem.lagset import Material, Regions, LagSet
    from petsc_ssi.bem import symmetry
    mesh = grid(4.0, 4.0, 1.0, (1.0, 1.0), **({"xmin": 0.0, "ymin": 0.0} if planes else {}))
    if bump:           # a surface not in a plane z = const (the CLI refuses it; the kernels take any geometry):
        x, y = mesh.nodes[:, 0], mesh.nodes[:, 1]      # a tilted plane (a kink-free surface: free term I/2),
        mesh.nodes[:, 2] = bump * x + 0.5 * bump * y   # whose blocks are full in the x, y, z frame
    reg = Regions(mesh, load_elems=mesh.groups["load"])
    opts = {"gauss": 2, "singular_order": 12, "subdivisions": 4, "near_factor": 2.0, "max_subdivisions": 32,
            "cache": chunk_cache, "block_pattern": pattern}
    pl = symmetry.parse("x=sym,y=anti") if planes else []
    return LagSet(PETSc.COMM_SELF, mesh, Material(548.0, 316.0, 2000.0), 1.5e-3, 7, reg, pl, opts)


def _literal(ls):
    """Dense H (L+1, N, N, 3, 3), G (L+1, N, nt, 3, 3) and the touched-block masks, by plain loops."""
    from petsc_ssi.bem.assemble import _pair_window, _integrate, SING_TOL
    from petsc_ssi.bem.packs import quad, wave
    o, m = ls.opts, ls.mat
    gq, gw = np.polynomial.legendre.leggauss(o["gauss"])
    gr, gwr = np.polynomial.legendre.leggauss(o["singular_order"])
    L, N, nt = ls.L, ls.mesh.n_nodes, ls.regions.n_t
    H = np.zeros((L + 1, N, N, 3, 3)); G = np.zeros((L + 1, N, nt, 3, 3))
    hm = np.zeros((L + 1, N, N), bool); gm = np.zeros((L + 1, N, nt), bool)
    Ub = np.zeros((L, 9, 3, 3)); Pb = np.zeros((L, 9, 3, 3)); Us = np.zeros((9, 3, 3)); Ps = np.zeros((9, 3, 3))
    Pc = Uc = np.zeros(0)                                   # (the compacted blocks: not used here)
    reach = m.cp * ls.dt * L
    # the material pack as the runs pass it (an array, packs.wave): a tuple here compiled a signature of its
    # own, about a minute in every fresh CI
    phys = wave(ls.dt, m.cp, m.cs, m.rho, m.nu)
    for i in ls.rows:
        xc = ls.mesh.nodes[i]
        for v in range(len(ls.VX)):
            lo, hi, sing, ns = _pair_window(xc, ls.VX[v], ls.Vc[v], ls.VR[v], ls.Vh[v], reach, m.cp, m.cs, ls.dt, L,
                                            1, 0.0, SING_TOL, o["subdivisions"], o["max_subdivisions"],
                                            o["near_factor"])
            if lo > hi:
                continue
            want_u = bool((ls.VT[v] >= 0).any())
            _integrate(xc, ls.VX[v], sing, ns, lo, hi, want_u, phys,
                       quad(o["subdivisions"], 0.0, o["subdivisions"], gq, gw, gr, gwr, SING_TOL, float(ls.Vh.min())),
                       (Ub, Pb, Us, Ps, Pc, Uc))
            for li in range(hi - lo + 1):
                for a in range(9):
                    if np.any(Pb[li, a] != 0.0):
                        H[lo + li, i, ls.VN[v, a]] += Pb[li, a] * ls.VS[v]
                        hm[lo + li, i, ls.VN[v, a]] = True
                    if ls.VT[v, a] >= 0:
                        G[lo + li, i, ls.VT[v, a]] += Ub[li, a] * ls.VS[v]
                        gm[lo + li, i, ls.VT[v, a]] = True
    return H, G, hm, gm


# slow tier: the whole surface without planes (19 s); the same sums with symmetry planes, the full pattern and a
# bumped (non-flat) surface stay in make test
@pytest.mark.parametrize("planes,pattern,bump", [pytest.param(False, "auto", 0.0, marks=pytest.mark.slow),
                                                 (True, "auto", 0.0), (True, "full", 0.0), (False, "auto", 0.2)])
def test_blocks_equal_the_literal_sums_in_csr_order(planes, pattern, bump):
    """Flat (with and without symmetry images), flat on the general path, and a surface not in a plane
    z = const: there the general path is taken and the entries a flat pattern leaves out are not zero."""
    from petsc_ssi.bem.bsr import positions, FULL
    ls = _lagset(planes, False, pattern, bump)
    assert ls.flat == (pattern == "auto" and not bump)
    H, G, hm, gm = _literal(ls)
    ls.assemble(chunk=3)
    nblocks = 0
    for B, D, M in ((ls.H, H, hm), (ls.G, G, gm)):
        assert B.m == ((4 if B is ls.H else 5) if ls.flat else FULL)
        p, q = positions(B.m)
        off = np.ones((3, 3), bool)
        off[p, q] = False
        for l in range(1, ls.L + 1):
            indptr, cols, vals = B.csr(l)
            assert indptr[-1] == len(cols) == M[l].sum()
            rows = np.repeat(ls.rows, np.diff(indptr))
            key = rows.astype(np.int64) * D.shape[2] + cols
            assert np.all(np.diff(key) > 0)                       # rows ascending, columns ascending in a row
            assert np.all(M[l][rows, cols])                        # exactly the touched blocks
            assert np.array_equal(vals, D[l][rows, cols][:, p, q])  # the same sums, bit for bit
            if ls.flat:
                assert not np.any(D[l][..., off])                  # the pattern's zeros are exact zeros
            nblocks += len(cols)
        if bump:                                                   # what the general path is for
            from petsc_ssi.bem.bsr import positions as pos
            flat_off = np.ones((3, 3), bool)
            flat_off[pos(4 if B is ls.H else 5)] = False
            assert np.abs(D[2:][..., flat_off]).max() > 1e-3 * np.abs(D[2:]).max()
        # the blocks of the collocation equations (free term of H_1 added): literal sum, then c_ij
        r, c, v = B.peek(1)
        ref = D[1].copy()
        if B is ls.H:
            ref[ls.rows, ls.rows] += ls.cfree[ls.rows]
        mask = M[1].copy()
        if B is ls.H:
            mask[ls.rows, ls.rows] = True
        assert len(c) == mask.sum() and np.array_equal(v, ref[r, c])
    assert nblocks > 1000 and np.abs(G).max() > 0 and ls.regions.n_t > 0


def test_a_flat_pattern_on_a_surface_that_is_not_flat_is_refused():
    """The assembly checks every integral's entries outside the pattern: forced onto a bumped surface,
    the flat pattern stops with an error instead of dropping them."""
    from petsc_ssi.petsc import SSIError
    ls = _lagset(False, True, bump=0.2)
    ls.mH, ls.mG = 4, 5
    with pytest.raises(SSIError, match="outside its pattern"):
        ls.assemble()


def test_chunks_and_cache_do_not_change_the_arrays():
    ref = _lagset(True, True)
    ref.assemble(chunk=1000)
    nocache = _lagset(True, False)
    nocache.assemble(chunk=2)
    scale = max(np.abs(ref.H.csr(l)[2]).max() for l in range(1, ref.L + 1))
    for chunk in (1, 5):
        ls = _lagset(True, True)
        ls.assemble(chunk=chunk)
        for B, R, C in ((ls.H, ref.H, nocache.H), (ls.G, ref.G, nocache.G)):
            for l in range(1, ls.L + 1):
                for a, b in zip(B.csr(l), R.csr(l)):
                    assert np.array_equal(a, b), (chunk, l)
                ip, c, v = C.csr(l)
                assert np.array_equal(ip, R.csr(l)[0]) and np.array_equal(c, R.csr(l)[1])
                assert np.abs(v - R.csr(l)[2]).max() <= 1e-12 * scale
