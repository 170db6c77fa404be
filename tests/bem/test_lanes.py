"""The toeplitz store's products in frequency lanes (bem/lanes.py) against the per-frequency ``matmul``
reference (``toeplitz.history_products``, ``interp_products``) and a plain sum."""
import numpy as np
import pytest

pytestmark = pytest.mark.unit


def _c(rng, *shape):
    return rng.standard_normal(shape) + 1j * rng.standard_normal(shape)


@pytest.mark.parametrize("slab", [1, 63, 64, 130])
def test_lanes_round_trip_and_padding(slab):
    """``to_lanes`` puts frequency g FW + q at lane q of group g, real then imaginary, the last group
    zero-padded; ``from_lanes`` gives the array back exactly; ``padded`` counts each rank's whole groups."""
    from petsc_ssi.bem.lanes import FW, to_lanes, from_lanes, padded, n_groups
    rng = np.random.default_rng(slab)
    X = _c(rng, slab, 3, 2)
    Y = to_lanes(X)
    assert Y.shape == (n_groups(slab), 3, 2, 2, FW)
    f = slab - 1
    assert Y[f // FW, 1, 0, 0, f % FW] == X[f, 1, 0].real and Y[f // FW, 1, 0, 1, f % FW] == X[f, 1, 0].imag
    assert not from_lanes(Y, FW * n_groups(slab))[slab:].any()          # the padding lanes: zeros
    assert np.array_equal(from_lanes(Y, slab), X)
    assert padded(slab) == FW * n_groups(slab)
    assert padded([33, 33, 34]) == FW * (n_groups(33) + n_groups(33) + n_groups(34))


@pytest.mark.parametrize("side", [(8, 4), (4, 8)])        # H's columns (n9, n18), G's
@pytest.mark.parametrize("vdtype", [np.float64, np.float32])
def test_history_lanes_equal_the_matmul_products(side, vdtype):
    """The exact lags' block products (b steps, D lags) and a step's products with the last k lags
    (``r0``) in lanes equal ``history_products`` to 1e-14 of their size, with double and single kept
    states, on a slab that is not a whole number of groups."""
    from petsc_ssi.bem.lanes import to_lanes, from_lanes, history_lanes, FW
    from petsc_ssi.bem.toeplitz import history_products
    n9, n18 = side
    rng = np.random.default_rng(3)
    slab, D, b, W = 45, 7, 4, 20
    K9, K18 = _c(rng, slab, 9 * D, n9), _c(rng, slab, 18 * D, n18)
    V9, V18 = _c(rng, slab, W, 9), _c(rng, slab, W, 18)
    if vdtype == np.float32:
        V9, V18 = V9.astype(np.complex64), V18.astype(np.complex64)
    L = dict(K9=to_lanes(K9), K18=to_lanes(K18), V9=to_lanes(V9, vdtype), V18=to_lanes(V18, vdtype))
    ref = history_products(K9, K18, V9, V18, 2, b, D, fchunk=8)
    got = from_lanes(history_lanes(L["K9"], L["K18"], L["V9"], L["V18"], 2, b, D), slab)
    assert np.abs(got - ref).max() <= 1e-14 * np.abs(ref).max()
    k = 3                                                  # a step's last k lags, added to what is there
    ref1 = history_products(K9[:, 9 * (D - k):], K18[:, 18 * (D - k):], V9, V18, 11, 1, k)
    acc = np.ones((L["K9"].shape[0], 1, n9 + n18, 2, FW))
    history_lanes(L["K9"], L["K18"], L["V9"], L["V18"], 11, 1, k, out=acc, r0=D - k)
    got1 = from_lanes(acc, slab)[:, 0] - (1 + 1j)
    assert np.abs(got1 - ref1[:, 0]).max() <= 1e-14 * np.abs(ref1).max()
    # and a plain sum for one frequency and step
    f, s = 17, 2
    plain = sum(V9[f, 2 + s + r] @ K9[f, 9 * r:9 * r + 9] for r in range(D))
    assert np.abs(got[f, s, :n9] - plain).max() <= 1e-13 * np.abs(plain).max()


def test_history_lanes_refuse_states_out_of_range():
    from petsc_ssi.bem.lanes import history_lanes, FW
    K9, K18 = np.zeros((1, 18, 8, 2, FW)), np.zeros((1, 36, 4, 2, FW))
    V9, V18 = np.zeros((1, 5, 9, 2, FW)), np.zeros((1, 5, 18, 2, FW))
    with pytest.raises(ValueError, match="states 3..6 of a buffer of 5"):
        history_lanes(K9, K18, V9, V18, 3, 3, 2)
    with pytest.raises(ValueError, match="not .* lanes"):
        history_lanes(K9, K18, V9[..., :FW // 2], V18, 0, 1, 2)
    # the compiled loop checks no index: kernel rows and the output's shape are checked before it
    with pytest.raises(ValueError, match="kernel row blocks 1..2 of 2"):
        history_lanes(K9, K18, V9, V18, 0, 1, 2, r0=1)
    with pytest.raises(ValueError, match="output of shape"):
        history_lanes(K9, K18, V9, V18, 0, 3, 2, out=np.zeros((1, 1, 12, 2, FW)))


def test_lanes_of_an_empty_slab():
    """A rank without frequencies: empty lanes, empty products of the right shape."""
    from petsc_ssi.bem.lanes import to_lanes, from_lanes, history_lanes, FW
    z = np.zeros((0, 18, 8), np.complex128)
    K9, K18 = to_lanes(z[:, :18]), to_lanes(np.zeros((0, 36, 4), np.complex128))
    V9, V18 = to_lanes(np.zeros((0, 6, 9), np.complex128)), to_lanes(np.zeros((0, 6, 18), np.complex128))
    assert K9.shape == (0, 18, 8, 2, FW)
    assert from_lanes(history_lanes(K9, K18, V9, V18, 1, 3, 2), 0).shape == (0, 3, 12)


@pytest.mark.parametrize("weights,side,vdtype,gchunk", [("chebyshev", (8, 4), np.float64, 2),
                                                         ("linear", (8, 4), np.float64, 2),
                                                         ("chebyshev", (4, 8), np.float32, 1),
                                                         ("linear", (4, 8), np.float32, 3)])
def test_interp_lanes_equal_the_matmul_products(weights, side, vdtype, gchunk):
    """The interpolating matrices' products in lanes (weighted states per span, through the weights' rank
    where ``_low_rank`` takes it; one span over every anchor used as the product gives it) equal
    ``interp_products`` to 1e-14 of their size: H's and G's columns, double and single kept states, the
    groups in chunks of 1, 2 and 3 on a slab of 3 groups."""
    from petsc_ssi.bem.lanes import to_lanes, from_lanes, interp_lanes, FW
    from petsc_ssi.bem.toeplitz import interp_products, _spans, _low_rank
    rng = np.random.default_rng(5)
    n9, n18 = side
    slab, b, k, ns, W = 2 * FW + 5, 8, 6, 32, 40
    A9, A18 = _c(rng, slab, 9 * k, n9), _c(rng, slab, 18 * k, n18)
    V9, V18 = _c(rng, slab, W, 9), _c(rng, slab, W, 18)
    if vdtype == np.float32:
        V9, V18 = V9.astype(np.complex64), V18.astype(np.complex64)
    if weights == "chebyshev":        # polynomial weights: low rank
        t = np.linspace(-1, 1, ns)
        C = np.stack([np.stack([np.polynomial.chebyshev.chebval(t + 0.01 * s, np.eye(k)[j]) for j in range(k)])
                      for s in range(b)])
    else:                             # hat functions: one product per anchor
        C = np.zeros((b, k, ns))
        for j in range(k):
            C[:, j, 5 * j:5 * j + 6] = rng.random((b, 6))
    ref = interp_products(A9, A18, V9, V18, C, 4, fchunk=16)
    got = from_lanes(interp_lanes(to_lanes(A9), to_lanes(A18), to_lanes(V9, vdtype), to_lanes(V18, vdtype), C, 4,
                                  _low_rank, _spans(C), gchunk=gchunk), slab)
    assert np.abs(got - ref).max() <= 1e-14 * np.abs(ref).max()


@pytest.mark.parametrize("real", [False, True])
@pytest.mark.parametrize("b,no,ss,vdtype", [(7, 3, 1, np.float64), (5, 5, 3, np.float32), (1, 1, 2, np.float64)])
def test_lane_products_tile_edges_equal_a_plain_sum(b, no, ss, vdtype, real):
    """The micro-kernel's tiles (``lanes.MS`` steps x ``lanes.MO`` outputs) and their edges: step counts and
    output columns that are not multiples of the tile, a row stride ss > 1 (the interpolating matrices'),
    single kept states, a kernel row offset and an output column offset, complex and real kernels
    (``to_lanes_real``: one part a column); against a plain loop per frequency, to 1e-14 of the sums' size,
    and nothing written outside the output's columns."""
    from petsc_ssi.bem.lanes import to_lanes, to_lanes_real, from_lanes, lane_products, n_groups, FW
    rng = np.random.default_rng(b * 10 + no)
    slab, c, D, j0, p0, o0 = 2 * FW + 3, 9, 4, 2, 1, 2
    K = _c(rng, slab, j0 + c * D + c, no)
    if real:
        K = K.real.copy()
    X = _c(rng, slab, p0 + ss * (b - 1) + D + 2, c)
    if vdtype == np.float32:
        X = X.astype(np.complex64)
    out = np.zeros((n_groups(slab), b, o0 + no + 1, 2, FW))
    lane_products(to_lanes_real(K) if real else to_lanes(K), j0, to_lanes(X, vdtype), p0, ss, b, D, out, o0)
    got = from_lanes(out, slab)
    ref = np.zeros((slab, b, o0 + no + 1), np.complex128)
    for s in range(b):
        for r in range(D):
            row = X[:, p0 + s * ss + r].astype(np.complex128)                        # (slab, c)
            ref[:, s, o0:o0 + no] += np.einsum("fa,fao->fo", row, K[:, j0 + r * c:j0 + (r + 1) * c])
    assert np.abs(got - ref).max() <= 1e-14 * np.abs(ref).max()
    assert not got[..., :o0].any() and not got[..., o0 + no:].any()


# slow tier: it compiles the lane kernels afresh for another CPU (11 s of make test's budget on 2026-12-02); its
# siblings, the tile and edge tests above on this machine's CPU, stay in make test
@pytest.mark.slow
def test_lane_products_on_a_machine_without_avx512(tmp_path):
    """Compiled for a CPU without AVX-512 (NUMBA_CPU_NAME=haswell: 4-wide vectors, 2 x 2 tiles), the tile and
    edge test above passes too (a cluster's older nodes take that branch of ``lanes._vector_tile``)."""
    import os
    import subprocess
    import sys
    env = dict(os.environ, NUMBA_CPU_NAME="haswell", NUMBA_CACHE_DIR=str(tmp_path))
    code = ("from petsc_ssi.bem import lanes; assert (lanes.VL, lanes.MS, lanes.MO) == (4, 2, 2), "
            "(lanes.VL, lanes.MS, lanes.MO)")
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    r = subprocess.run([sys.executable, "-c", code], env=env, cwd=root, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr[-2000:]
    r = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-k", "tile_edges or equal_the_matmul",
                        os.path.abspath(__file__)], env=env, cwd=root, capture_output=True, text=True)
    assert r.returncode == 0 and " passed" in r.stdout, r.stdout[-2000:] + r.stderr[-2000:]


@pytest.mark.parametrize("vdtype", [np.float64, np.float32])
def test_per_step_helpers_equal_their_numpy_forms(vdtype):
    """The store's compiled per-step helpers against their numpy forms, exactly: ``put_state_grid`` (a
    state's spectra as the distributed transform gives them, (slot, component, k_x, k_y column), into lanes
    in the slab's k_y-major order: ``to_lanes`` of the z components and of the x, y ones), ``unpack_grid`` (a
    step's sums from lanes into the inverse transform's input (class and component, k_x, column), times the
    rotation (to 1e-15: a compiled complex product) or not) and ``scatter_slots`` (a state onto the FFT grid, a slot without a column giving 0)."""
    from petsc_ssi.bem.lanes import to_lanes, put_state_grid, unpack_grid, scatter_slots, n_groups, FW
    rng = np.random.default_rng(9)
    Mx, nk = 7, 3
    slab = Mx * nk                                                    # (21: not whole lane groups)
    S4 = _c(rng, 9, 3, Mx, nk)
    S = S4.transpose(0, 1, 3, 2).reshape(9, 3, slab)                  # (the slab's order: k_y-major)
    G = n_groups(slab)
    V9, V18 = np.full((G, 4, 9, 2, FW), 7.0, vdtype), np.full((G, 4, 18, 2, FW), 7.0, vdtype)
    put_state_grid(S4, V9, V18, 2)
    assert np.array_equal(V9[:, 2], to_lanes(S[:, 2, :].T, vdtype))
    assert np.array_equal(V18[:, 2], to_lanes(S[:, 0:2, :].transpose(2, 0, 1).reshape(-1, 18), vdtype))
    assert (V9[:, 1] == 7.0).all() and (V18[:, 3] == 7.0).all()      # (other rows untouched)
    X = _c(rng, slab, 1, 12)
    acc = to_lanes(X)                                                 # (groups, 1, 12, 2, FW)
    rot = np.exp(1j * rng.standard_normal((4, slab)))
    for n9 in (8, 4):
        for h in (rot, np.zeros((0, 0), np.complex128)):
            out = np.empty((12, Mx, nk), np.complex128)
            unpack_grid(acc, n9, h, out)
            xy, z = (X[:, 0, :8], X[:, 0, 8:]) if n9 == 8 else (X[:, 0, 4:], X[:, 0, :4])
            ref = np.empty((4, 3, slab), np.complex128)
            ref[:, 0:2], ref[:, 2] = xy.T.reshape(4, 2, slab), z.T
            if h.size:
                ref *= h[:, None, :]
            ref = ref.reshape(12, nk, Mx).transpose(0, 2, 1)
            if h.size:                  # (the product with the rotation compiled: to round-off, 1e-15)
                assert np.abs(out - ref).max() <= 1e-15 * np.abs(ref).max(), (n9, np.abs(out - ref).max())
            else:
                assert np.array_equal(out, ref), n9
    U = np.r_[rng.standard_normal((6, 3)), np.zeros((1, 3))]
    vnode = rng.integers(-1, 6, (5, 9))
    vsign = rng.choice([-1.0, 1.0], (5, 3))
    ix, iy = np.array([0, 1, 2, 3, 4]), np.array([4, 3, 2, 1, 0])
    f = np.zeros((9, 3, 6, 5))
    U.flags.writeable = False           # as the runs pass it (a PETSc vector's array read-only)
    scatter_slots(U, vnode, vsign, ix, iy, f)
    ref = np.zeros_like(f)
    for a in range(9):
        for c in range(3):
            ref[a, c, ix, iy] = U[vnode[:, a], c] * vsign[:, c]
    assert np.array_equal(f, ref)


def test_lag_file_layout_is_any_rank_counts():
    """The toeplitz lag file's kernel layout (``lagstore.to_file``/``from_file``): the ranks' slabs of P ranks
    (``pfft.slab_counts``: Mx times each rank's columns of the half spectrum, none beyond min(Mx, My // 2 + 1)
    ranks), each converted from lanes to frequency-major and concatenated, read back as the slabs of Q ranks are
    every rank's own lanes exactly (real and complex kernels, empty kernels, spectra that split unevenly, slabs
    that are not whole lane groups and empty slabs: grids 1 x 2 to 13 x 10; P, Q in 1..5)."""
    from petsc_ssi.bem.lagstore import to_file, from_file
    from petsc_ssi.bem.lanes import to_lanes, to_lanes_real
    from petsc_ssi.bem.pfft import slab_counts
    rng = np.random.default_rng(1)
    seen = set()
    for Mx, My in ((1, 2), (7, 2), (9, 4), (12, 6), (13, 10), (24, 24)):
        F = Mx * (My // 2 + 1)
        for rows in (0, 9):
            for real in (True, False):
                X = rng.standard_normal((F, rows, 4)) + (0 if real else 1j * rng.standard_normal((F, rows, 4)))
                lanes = (lambda Y: to_lanes_real(Y.real)) if real else to_lanes

                def cut(n, r):
                    c = slab_counts(Mx, My, n)
                    seen.update(["empty"] if c[r] == 0 else ["padded"] if c[r] % 8 else ["whole"])
                    return int(c[:r].sum()), int(c[:r + 1].sum())
                for P in (1, 2, 3, 5):
                    whole = np.concatenate([to_file(lanes(X[slice(*cut(P, r))]), cut(P, r)[1] - cut(P, r)[0])
                                            for r in range(P)])
                    assert whole.shape == (F, rows, 4, 1 if real else 2)
                    for Q in (1, 2, 3, 4, 5):
                        for r in range(Q):
                            a, b = cut(Q, r)
                            assert np.array_equal(from_file(whole[a:b]), lanes(X[a:b])), (Mx, My, rows, real, P, Q, r)
    assert seen == {"empty", "padded", "whole"}


@pytest.mark.parametrize("real", [True, False])
@pytest.mark.parametrize("m", [4, 5])
def test_put_spectra_is_the_lanes_of_the_blocks(real, m):
    """``put_spectra`` (the toeplitz build's kernels filled from the lags' spectra without copies) gives the bits of
    the arrays it replaced: ``K[:, r0:r0 + n] = 0; K[:, r0:r0 + n] += c * to_lanes(block)`` of
    ``toeplitz._kernel_blocks``' blocks, term after term, for the H (m = 4) and G (m = 5) patterns, real and complex
    kernels, row blocks weighing one, two and three slots of a ring (one twice), a row block written twice (the
    second write replaces the first: a put, not an add; the build writes each once), a slab that is not whole lane
    groups (its padding lanes stay zero) and an empty slab (a rank without frequencies)."""
    from petsc_ssi.bem.lanes import put_spectra, to_lanes, to_lanes_real, n_groups, FW
    from petsc_ssi.bem.toeplitz import _kernel_blocks
    rng = np.random.default_rng(5)
    slab, D = 3 * FW + 5, 4
    idx = [np.ascontiguousarray(B[0], np.int64) for B in _kernel_blocks(np.arange(36 * m).reshape(4, 9, m, 1))]
    lanes = to_lanes_real if real else to_lanes
    kp = 1 if real else 2
    src = rng.standard_normal((3, 36 * m, slab))
    if not real:
        src = src + 1j * rng.standard_normal(src.shape)
    for B, rows in zip(idx, (9, 18)):
        K = np.zeros((n_groups(slab), D * rows, B.shape[1], kp, FW))
        ref = K.copy()
        for d, sel, c in ((1, [2], [0.75]), (2, [0, 1], [-1.5, 0.3]), (3, [1, 2, 1], [1.0, -0.25, 2.0]), (1, [0], [2.0])):
            put_spectra(K, rows * d, src, np.array(sel, np.int64), B, np.array(c))
            ref[:, rows * d:rows * (d + 1)] = 0.0
            for t, ct in zip(sel, c):
                blk = np.stack([src[t][B, f] for f in range(slab)])     # (slab, rows, columns): the block's values
                ref[:, rows * d:rows * (d + 1)] += ct * lanes(blk)
        assert np.array_equal(K, ref)
        assert K[:, rows:].any() and not K[-1, :, :, :, slab % FW:].any() and not K[:, :rows].any()
        empty = np.zeros((0, D * rows, B.shape[1], kp, FW))
        put_spectra(empty, rows, src[:, :, :0], np.zeros(1, np.int64), B, np.ones(1))     # (nothing to write)
