r"""Frequency lanes: the toeplitz store's spectra laid out for compiled products (issue 41).

The history sum in Fourier space is, per frequency, a small complex matrix product: b steps' windows
of kept states (b x 9D, b x 18D) times the stacked kernels (9D x 8, 18D x 4 on the H side). Done with
``matmul`` per frequency (``toeplitz.history_products``) each product is one BLAS call on matrices of
8 rows and 4-8 columns: the calls' overhead and the windows' copies (overlapping rows, which BLAS does
not take) cost more than the flops; on the 72 m building's slab it ran at 7-9 GFlop/s a process where
a large GEMM runs at about 60.

Here the arrays keep ``FW`` (8) frequencies side by side as the last axis, real and imaginary parts apart:
a (slab, ...) complex array becomes (groups, ..., 2, FW) real (``to_lanes``; the slab padded with
zeros to whole groups). Every operation of the products is then the same on FW consecutive
numbers: one vector instruction. ``lane_products`` runs, per lane group, a register-blocked micro-kernel
(``simd.cmac_tile``): a tile of steps x outputs whose complex sums stay in vector registers while it walks
the window's rows (a window is a row offset into the kept states, so no copy), each term four fused
multiply-adds. The sums run in the order of ``matmul``'s reference loop only up to round-off: the
products equal ``history_products`` to about 1e-15 of their size (tests/bem/test_lanes.py).

``history_lanes`` and ``interp_lanes`` are the two products the store takes (the exact lags' windows
and the interpolating matrices' weighted states), with array inputs only; a GPU array module would
take them over with its own kernel on the same layout (one thread a lane and tile).
"""
import numpy as np
from numba import njit

from .simd import cmac_tile

# frequencies a lane group holds: one 512-bit vector of doubles (two 256-bit ones). The products' micro-kernel
# (``simd.cmac_tile``) walks the kernels' and states' rows of one group, so a group's rows lie 1 KB apart,
# not 8 KB as with 64 lanes (which mapped every row into the same L1 sets)
FW = 8


def _vector_tile():
    """(VL, MS, MO): the micro-kernel's vector width in doubles and its tile of steps x outputs, whose 2 MS MO
    complex sums stay in vector registers: 8-wide and 4 x 2 (16 of the 32 512-bit registers) where numba
    compiles for AVX-512, else 4-wide and 2 x 2 (8 of 16 256-bit registers)."""
    from numba.core import config
    feats = config.CPU_FEATURES
    if feats is None:
        if config.CPU_NAME not in (None, "host"):
            return 4, 2, 2
        from llvmlite import binding
        feats = binding.get_host_cpu_features().flatten()
    return (8, 4, 2) if "+avx512f" in feats.split(",") else (4, 2, 2)


VL, MS, MO = _vector_tile()
# lane groups of about 128 frequencies: the chunks of the interpolating matrices' weighted states and of the
# kept transforms' moves (``toeplitz._room``)
CHUNK_GROUPS = max(1, 128 // FW)


def n_groups(n):
    """The lane groups of n frequencies."""
    return -(-int(n) // FW)


def padded(counts):
    """Frequencies stored over the ranks whose slabs hold ``counts`` frequencies (``pfft.slab_counts``; an int:
    one rank): each rank's slab in whole lane groups."""
    return FW * sum(n_groups(c) for c in np.atleast_1d(counts))


def to_lanes(X, dtype=np.float64):
    """(slab, *rest) complex -> (groups, *rest, 2, FW) ``dtype``: frequency g FW + q at lane q of group
    g, real part then imaginary part; the last group padded with zeros."""
    X = np.asarray(X)
    slab, rest = X.shape[0], X.shape[1:]
    G = n_groups(slab)
    P = np.zeros((G * FW,) + rest, np.complex128)
    P[:slab] = X
    P = P.reshape((G, FW) + rest)
    Y = np.empty((G,) + rest + (2, FW), dtype)
    Y[..., 0, :] = np.moveaxis(P.real, 1, -1)
    Y[..., 1, :] = np.moveaxis(P.imag, 1, -1)
    return Y


def to_lanes_real(X):
    """(slab, *rest) real -> (groups, *rest, 1, FW) float64: ``to_lanes`` of a real array, its one part (the
    real kernels of ``lane_products``)."""
    return np.ascontiguousarray(to_lanes(np.asarray(X, np.float64))[..., :1, :])


def from_lanes(Y, slab):
    """(groups, *rest, 2, FW) real -> (slab, *rest) complex128 (``to_lanes``'s inverse)."""
    Z = Y[..., 0, :] + 1j * Y[..., 1, :]                     # (G, *rest, FW)
    Z = np.moveaxis(Z, -1, 1)
    return Z.reshape((Z.shape[0] * Z.shape[1],) + Z.shape[2:])[:slab]


@njit(cache=True, boundscheck=False)
def lane_products(K, j0, X, p0, ss, b, D, out, o0):
    """out[g, s, o0 + o] += sum_{r < D, a < c} X[g, p0 + s ss + r, a] K[g, j0 + r c + a, o] for the b steps
    s, complex per lane (K (G, J, no, 2, FW) complex or (G, J, no, 1, FW) real, X (G, rows, c, 2, FW) float64
    or float32, out (G, b', n_out, 2, FW) float64, all C-contiguous): a window of rows of X times a run of D x c
    rows of K, per lane. The exact lags: X the kept states, row p0 + s + r (ss = 1); the interpolating
    matrices: X the weighted states of the b steps, row s k + r (ss = k, D = k). Rows r and a of X are
    consecutive in memory as rows r c + a of K are, so the sum runs over one index i = r c + a: per group and
    vector of VL lanes, tiles of MS steps x MO outputs held in registers over the D c terms
    (``simd.cmac_tile``), the edges in smaller tiles. A real K (``toeplitz``'s kernels of a point-symmetric
    grid) takes half the multiply-adds and half the bytes."""
    if K.shape[3] == 1:
        _lane_products(K, j0, X, p0, ss, b, D, out, o0, 1)
    else:
        _lane_products(K, j0, X, p0, ss, b, D, out, o0, 2)


@njit(cache=True, boundscheck=False)
def _lane_products(K, j0, X, p0, ss, b, D, out, o0, kp):
    G, J, no, _, fw = K.shape
    c = X.shape[2]
    n = D * c
    T2 = 2 * fw
    KC = kp * fw                    # (a kernel column: both parts, or the one of a real kernel)
    KJ, XR, OS = no * KC, c * T2, out.shape[2] * T2
    Kg, Xg, Og = J * KJ, X.shape[1] * XR, out.shape[1] * OS
    for g in range(G):
        for v in range(0, fw, VL):
            kb = g * Kg + j0 * KJ + v
            xb = g * Xg + p0 * XR + v
            ob = g * Og + o0 * T2 + v
            s = 0
            while s + MS <= b:
                o = 0
                while o + MO <= no:
                    _tile(K, kb + o * KC, KJ, X, xb + s * ss * XR, ss * XR, out, ob + s * OS + o * T2, OS, n, fw,
                          MS, MO, kp)
                    o += MO
                while o < no:
                    _tile(K, kb + o * KC, KJ, X, xb + s * ss * XR, ss * XR, out, ob + s * OS + o * T2, OS, n, fw,
                          MS, 1, kp)
                    o += 1
                s += MS
            while s < b:
                o = 0
                while o + MO <= no:
                    _tile(K, kb + o * KC, KJ, X, xb + s * ss * XR, ss * XR, out, ob + s * OS + o * T2, OS, n, fw,
                          1, MO, kp)
                    o += MO
                while o < no:
                    _tile(K, kb + o * KC, KJ, X, xb + s * ss * XR, ss * XR, out, ob + s * OS + o * T2, OS, n, fw,
                          1, 1, kp)
                    o += 1
                s += 1


@njit(inline="always")
def _tile(K, kb, KJ, X, xb, XS, out, ob, OS, n, fw, ms, mo, kp):
    """``simd.cmac_tile`` with the literal kernel parts kp (1 real, 2 complex) the intrinsic takes."""
    if kp == 1:
        cmac_tile(K, kb, KJ, X, xb, XS, out, ob, OS, n, fw, ms, mo, VL, 1)
    else:
        cmac_tile(K, kb, KJ, X, xb, XS, out, ob, OS, n, fw, ms, mo, VL, 2)


def _check(V, p0, rows, c, what):
    if V.ndim != 5 or V.shape[2] != c or V.shape[3] != 2 or V.shape[4] != FW or not V.flags.c_contiguous:
        raise ValueError(f"{what}: states of shape {V.shape} (C-contiguous {V.flags.c_contiguous}), not "
                         f"(groups, W, {c}, 2, {FW}) lanes")
    if p0 < 0 or p0 + rows > V.shape[1]:
        raise ValueError(f"{what}: states {p0}..{p0 + rows - 1} of a buffer of {V.shape[1]}")


def _check_kernel(K, V, r0, D, c, out, b, o0, what):
    """The kernel's rows (r0 + D row blocks of c), the output's shape and the groups of the three agree (the
    compiled loop does not check its indices)."""
    if K.ndim != 5 or K.shape[3] not in (1, 2) or K.shape[4] != FW or not K.flags.c_contiguous \
            or K.shape[0] != V.shape[0]:
        raise ValueError(f"{what}: kernels of shape {K.shape}, not (groups {V.shape[0]}, rows, columns, 2 or 1, "
                         f"{FW}) C-contiguous lanes")
    if r0 < 0 or c * (r0 + D) > K.shape[1]:
        raise ValueError(f"{what}: kernel row blocks {r0}..{r0 + D - 1} of {K.shape[1] // c}")
    if (out.ndim != 5 or out.dtype != np.float64 or out.shape[0] != K.shape[0] or out.shape[1] < b
            or out.shape[2] < o0 + K.shape[2] or out.shape[3:] != (2, FW) or not out.flags.c_contiguous):
        raise ValueError(f"{what}: output of shape {out.shape} ({out.dtype}), not (groups {K.shape[0]}, >= {b} "
                         f"steps, >= {o0 + K.shape[2]} columns, 2, {FW}) C-contiguous float64 lanes")


def history_lanes(K9, K18, V9, V18, p0, b, D, out=None, r0=0):
    """The exact lags' products for b steps in lanes: out[g, k] (+)= sum_{r < D} V[state p0 + k + r] K'
    rows (r0 + r) of K9 (z inputs, 9 a row block) and K18 (x, y inputs, 18): (G, b, n9 + n18, 2, FW),
    columns as ``toeplitz.history_products`` (which this equals to round-off). ``r0`` skips the first row
    blocks (a step's products with the last D of the D0 lags: r0 = D0 - D). Added to ``out`` when given."""
    G, n9, n18 = K9.shape[0], K9.shape[2], K18.shape[2]
    for V, c in ((V9, 9), (V18, 18)):
        _check(V, p0, b - 1 + D, c, "history_lanes")
    if out is None:
        out = np.zeros((G, b, n9 + n18, 2, FW))
    _check_kernel(K9, V9, r0, D, 9, out, b, 0, "history_lanes")
    _check_kernel(K18, V18, r0, D, 18, out, b, n9, "history_lanes")
    if D > 0:
        lane_products(K9, 9 * r0, V9, p0, 1, b, D, out, 0)
        lane_products(K18, 18 * r0, V18, p0, 1, b, D, out, n9)
    return out


def interp_lanes(A9, A18, V9, V18, C, r0, low_rank, spans, log=None, gchunk=None, slab=None):
    """The interpolated lags' products for b steps in lanes: the weighted states s_j = sum_m C[step, j, m]
    v^m (states r0 + m of the kept lanes) per span of ``spans`` (``toeplitz._spans``; ``low_rank`` its
    factors, ``toeplitz._low_rank``: one real matrix product a lane group over all its lanes, components
    and real and imaginary parts at once), then the anchors' kernels: (G, b, n9 + n18, 2, FW), as
    ``toeplitz.interp_products`` to round-off."""
    G, n9, n18 = A9.shape[0], A9.shape[2], A18.shape[2]
    b, k, _ = C.shape
    out = np.zeros((G, b, n9 + n18, 2, FW))
    if not spans:
        return out
    facs = [low_rank(C[:, j0:j1, a:e].reshape(-1, e - a)) for j0, j1, a, e in spans]
    for V, A, c, o0 in ((V9, A9, 9, 0), (V18, A18, 18, n9)):
        for j0, j1, a, e in spans:
            _check(V, r0 + a, e - a, c, "interp_lanes")
        _check_kernel(A, V, 0, k, c, out, b, o0, "interp_lanes")
    gchunk = gchunk or CHUNK_GROUPS
    for g0 in range(0, G, gchunk):              # (128 frequencies at a time: the weighted states stay small)
        g1 = min(G, g0 + gchunk)
        for V, A, c, o0 in ((V9, A9, 9, 0), (V18, A18, 18, n9)):
            whole = len(spans) == 1 and spans[0][:2] == (0, k)       # (Chebyshev: one span, every anchor)
            S = None if whole else np.zeros((g1 - g0, b, k, c * 2 * FW))
            for (j0, j1, a, e), (Cj, US, W) in zip(spans, facs):
                Vf = V[g0:g1, r0 + a:r0 + e].reshape(g1 - g0, e - a, c * 2 * FW)      # (a view)
                if Vf.dtype != np.float64:
                    Vf = Vf.astype(np.float64)
                w = np.matmul(Cj, Vf) if W is None else np.matmul(US, np.matmul(W, Vf))
                if whole:
                    S = w                       # (rows (step, anchor): the weighted states as they are)
                else:
                    S[:, :, j0:j1] = w.reshape(g1 - g0, b, j1 - j0, c * 2 * FW)
            lane_products(A[g0:g1], 0, S.reshape(g1 - g0, b * k, c, 2, FW), 0, k, b, k, out[g0:g1], o0)
    if log is not None:                         # (flops over the rank's frequencies ``slab``, not the padding)
        log.logFlops(interp_flops(G * FW if slab is None else slab, b, k, n9, n18, facs, A9.shape[3]))
    return out


def interp_flops(slab, b, k, n9, n18, facs, kp=2):
    """Flops of the interpolated lags' products over ``slab`` frequencies (``interp_lanes`` and its
    reference ``toeplitz.interp_products``): the anchors' complex products and the weighted states' real
    ones (``facs``: each span's (C, U s, W) of ``toeplitz._low_rank``); kp 1: real anchors' kernels (4 flops
    an entry's product, not 8)."""
    return slab * (4.0 * kp * b * k * 9 * (n9 + 2 * n18)
                   + 2.0 * 54 * sum(Cj.size if W is None else W.shape[0] * (Cj.shape[0] + Cj.shape[1])
                                    for Cj, US, W in facs))


@njit(cache=True, boundscheck=False)
def scatter_slots(U, vnode, vsign, ix, iy, f):
    """f[a, c, ix[v], iy[v]] = U[vnode[v, a], c] vsign[v, c] for the input elements v and their 9 slots a
    (a slot without a column, vnode -1, gives 0): a state's values on the FFT grid, one plane a slot and
    component (``ToeplitzHistory._transform``; f's other entries are not touched)."""
    for v in range(vnode.shape[0]):
        x, y = ix[v], iy[v]
        for a in range(9):
            nd = vnode[v, a]
            for c in range(3):
                f[a, c, x, y] = U[nd, c] * vsign[v, c] if nd >= 0 else 0.0


@njit(cache=True, boundscheck=False)
def put_state_grid(S, V9, V18, i):
    """Row i of the kept transforms in lanes from a state's spectra S (9 slots, 3 components, Mx, k_y columns)
    complex, as the distributed transform gives them (``pfft.SlabFFT.transform``): V9[.., i, a] the z
    components, V18[.., i, 2 a + c] the x and y ones (``to_lanes`` of the slab's z and x, y components), frequency
    f of the slab (k_y-major) from k_x = f % Mx, column f // Mx (no copy into the slab's order); padding lanes
    zero."""
    mx, nk = S.shape[2], S.shape[3]
    slab = mx * nk
    G, fw = V9.shape[0], V9.shape[4]
    for g in range(G):
        for q in range(fw):
            f = g * fw + q
            kx, ky = f % mx, f // mx
            for a in range(9):
                z = S[a, 2, kx, ky] if f < slab else 0j
                V9[g, i, a, 0, q] = z.real
                V9[g, i, a, 1, q] = z.imag
                for c in range(2):
                    w = S[a, c, kx, ky] if f < slab else 0j
                    V18[g, i, 2 * a + c, 0, q] = w.real
                    V18[g, i, 2 * a + c, 1, q] = w.imag


@njit(cache=True, boundscheck=False)
def unpack_grid(acc, n9, rot, out):
    """out[3 t + p, k_x, column] (12, Mx, k_y columns) complex, the inverse transform's input
    (``pfft.SlabFFT.backward_inputs``), from a step's sums acc (groups, 1, 12, 2, FW) lanes (slab frequency f =
    column Mx + k_x) in one pass: column o of the sums (the K9 products' then the K18 products': for n9 = 8 (H)
    the 8 K9 columns are (class t, x or y) and the 4 K18 ones z of class t, for n9 = 4 (G) the other way round)
    to plane 3 t + p, times rot[t, f] (the real kernels' rotation back) where rot has rows, none (shape (0, 0))
    otherwise."""
    mx, nk = out.shape[1], out.shape[2]
    fw = acc.shape[4]
    xy0, z0 = (0, 8) if n9 == 8 else (4, 0)
    for f in range(mx * nk):
        g, q = f // fw, f % fw
        kx, ky = f % mx, f // mx
        for t in range(4):
            h = rot[t, f] if rot.shape[0] else 1.0 + 0j
            for p in range(3):
                o = xy0 + 2 * t + p if p < 2 else z0 + t
                out[3 * t + p, kx, ky] = (acc[g, 0, o, 0, q] + 1j * acc[g, 0, o, 1, q]) * h


@njit(cache=True, boundscheck=False)
def put_spectra(K, r0, src, sel, idx, c):
    """K[g, r0 + r, j, p, q] = sum_t c[t] src[sel[t], idx[r, j], f], the terms t summed one after the other from 0
    (part p: the real part, and for a complex K the imaginary one) at f = g FW + q < slab; K (G, rows, columns, 1
    or 2, FW) float64, src (slots, sources, slab) complex128 or float64, sel (terms,) int64 its slots, c (terms,)
    float64: the lags' kernel spectra that one row block of a kernel weighs, written into its lanes once
    (``toeplitz``'s kernels: each row block is written when its last lag's spectra are made, and never read
    before; the padding lanes are not touched). The same bits as ``K[:, r0:r0 + n] = 0;
    for t: K[:, r0:r0 + n] += c[t] * to_lanes(src[sel[t]][idx].T)``.

    Row by row: each source row's sum is formed along the frequencies, reading ``src`` in its memory order, then
    scattered into the row's lanes, a cache line (FW values) a group. The pass it replaced went group by group,
    reading every source row a cache line at a time and the row block before writing it: `python
    jobscripts/put_spectra_rate.py` (one rank's H kernels of the building on the 72 m and 108 m grids) took 0.65 and
    3.66 s with the kernels' memory written before, 2.08 and 16.5 s in fresh memory, where this takes 0.26 and
    0.95 s, 0.87 and 8.55 s (2026-12-03). In the runs the first write of fresh memory is most of it
    (runs/building/README.md, the kernels' parts)."""
    nt, slab = sel.shape[0], src.shape[2]
    G, kp, fw = K.shape[0], K.shape[3], K.shape[4]
    a = np.empty(max(slab, 1))
    for r in range(idx.shape[0]):
        for j in range(idx.shape[1]):
            s = idx[r, j]
            for p in range(kp):
                for f in range(slab):
                    a[f] = 0.0
                for t in range(nt):
                    ct, st = c[t], sel[t]
                    if p == 0:
                        for f in range(slab):
                            a[f] += ct * src[st, s, f].real
                    else:
                        for f in range(slab):
                            a[f] += ct * src[st, s, f].imag
                for g in range(G):
                    f0 = g * fw
                    for q in range(min(fw, slab - f0)):
                        K[g, r0 + r, j, p, q] = a[f0 + q]
