"""Assembly of the lag matrices H_l, G_l, one collocation node (row) at a time.

Each rank assembles the rows it owns. For a row i the contributions of all
virtual elements (mesh elements and their symmetry images) are accumulated
into a sparse (lag, column node) -> 3x3 block map, so only non-zero blocks
are stored; the result is a list of triplets (row, lag, col, block) that
``lagmats`` turns into PETSc matrices. Column transformation of an image:
H_l[i, node] += P S, with S the diagonal sign matrix of the image (symmetry
module). G is assembled only for traction columns (loaded or prescribed-
displacement regions): a traction-free surface multiplies zeros.
"""
import math

import numpy as np
from numba import njit, types
from numba.typed import Dict, List

from . import packs
from .patterns import FULL, H4, G5, PATTERNS
from .packs import DT, CP, CS, NU, MU, TOFF
from .quadrature import integrate_pair, singular_static, plane_points, integrate_plane


SING_TOL = 1e-8      # a collocation point within SING_TOL * h of an element node is that node (singular pair)


@njit(cache=True)
def _grow(a, n):
    if n < a.shape[0]:
        return a
    shape = (max(2 * a.shape[0], n + 1, 16),) + a.shape[1:]
    b = np.zeros(shape, a.dtype)
    b[:a.shape[0]] = a
    return b


@njit(cache=True)
def _geom_key(X, xc, qinv, key):
    """Quantised coordinates of an element relative to the collocation point
    and their hash: equal keys mean the same pair geometry to within 1/qinv."""
    hsh = np.int64(1469598103934665603)
    for a in range(9):
        for k in range(3):
            q = np.int64(round((X[a, k] - xc[k]) * qinv))
            key[3 * a + k] = q
            hsh = (hsh ^ q) * np.int64(1099511628211)
    return hsh


@njit(cache=True)
def _pair_window(xc, X, c, R, h, reach, alpha, beta, dt, L, lag_lo, toff, tol, ns_base, ns_max, near_factor):
    """(lo, hi, sing, ns) of a (collocation point, element) pair: the lags its wave window touches
    (lo > hi: none), the local node at the point (-1: regular) and the subdivisions."""
    dcen = math.sqrt((c[0] - xc[0]) ** 2 + (c[1] - xc[1]) ** 2 + (c[2] - xc[2]) ** 2)
    dmin = max(dcen - R, 0.0)
    if dmin >= reach:
        return 1, 0, -1, 0
    dmax = dcen + R
    lo = max(lag_lo, int(math.floor((dmin / alpha - toff) / dt)) + 1)
    hi = min(L, int(math.floor((dmax / beta - toff) / dt)) + 2)
    sing = -1
    for a in range(9):
        d = math.sqrt((X[a, 0] - xc[0]) ** 2 + (X[a, 1] - xc[1]) ** 2 + (X[a, 2] - xc[2]) ** 2)
        if d < tol * h:
            sing = a
    if sing >= 0:
        ns = min(ns_max, 2 * ns_base)
        if lag_lo == 1:
            lo = 1
        else:
            sing = -1   # lags >= 2 vanish near xi: regular
    else:
        ns = ns_base
        if near_factor > 0.0:
            dd = max(dmin, 1e-3 * h)
            ns = min(ns_max, max(ns_base, int(math.ceil(near_factor * h / dd))))
    return lo, hi, sing, ns


@njit(cache=True, inline="always")
def _window(xc, v, mesh, reach, lags, phys, quad):
    """``_pair_window`` of the point xc and virtual element v of ``mesh`` (``assemble_rows``), from the
    packs: lags = (lag_lo, L), phys (``packs.wave``), quad (``packs.Quad``)."""
    VX, Vc, VR, Vh = mesh[1], mesh[5], mesh[6], mesh[7]
    return _pair_window(xc, VX[v], Vc[v], VR[v], Vh[v], reach, phys[CP], phys[CS], phys[DT], lags[1], lags[0],
                        phys[TOFF], quad.tol, quad.ns_base, quad.ns_max, quad.near_factor)


# ---------------------------------------------------------------------------
# The kernel table (issue 40): which kernels a (surface kind, block patterns) takes. Surface kinds:
# "plane" (every node and element in z = 0), "flat" (in one plane z = z0 != 0), "general" (any other);
# block patterns (H's, G's): patterns.PATTERNS, the flat ones (H4, G5) or the full 3x3 (``patterns``).
# Values: (the integrator of a regular pair: PLANE, quadrature.integrate_plane on the element's
# precomputed geometry (``plane``), the patterns' entries only; GENERAL, quadrature.integrate_pair on
# full blocks, the entries a pattern drops checked to be zero, then compacted; the row emitters of H and
# G: 4 or 5, ``_accumulate`` at that constant width (unrolled), 0 at the pattern's width).
PLANE, GENERAL = 0, 1
KERNELS = {("plane", (H4, G5)): (PLANE, H4, G5),
           ("plane", (FULL, FULL)): (GENERAL, 0, 0),
           ("flat", (H4, G5)): (GENERAL, H4, G5),
           ("flat", (FULL, FULL)): (GENERAL, 0, 0),
           ("general", (H4, G5)): (GENERAL, H4, G5),        # (forced: a test of the dropped-entry check)
           ("general", (FULL, FULL)): (GENERAL, 0, 0)}


def surface_kind(nodes, VX):
    """The kind of a soil surface for the kernel table: its collocation points ``nodes`` and virtual
    elements ``VX`` (mesh elements and their symmetry images) all in z = 0 ("plane"), all in one plane
    z = z0 ("flat"), or not ("general")."""
    z0 = float(nodes[0, 2]) if len(nodes) else 0.0
    if not (bool(np.all(nodes[:, 2] == z0)) and bool(np.all(VX[..., 2] == z0))):
        return "general"
    return "plane" if z0 == 0.0 else "flat"


def patterns(kind, choice="auto"):
    """(H's, G's block pattern) of a surface kind: the flat patterns where every point and element lies
    in one plane, unless ``choice`` (-ssi_lag_pattern) is "full" (the check of both paths)."""
    return (H4, G5) if kind != "general" and choice != "full" else (FULL, FULL)


def kernels(kind, pattern, plane_geo):
    """The kernels' pack of ``assemble_rows`` and ``integrate_batch``: (the table's codes for the surface
    kind and the patterns of ``pattern`` (H's p, q, G's p, q, H's keep mask, G's: LagSet.pattern), the
    pattern, the plane geometry (``plane``))."""
    return KERNELS[(kind, (len(pattern[0]), len(pattern[2])))], pattern, plane_geo


@njit(cache=True)
def buffers(L, sP, sU):
    """The scratch of a pair's integrals (``bufs`` of ``_pair_integrals``): full blocks of L lags Ub,
    Pb (L, 9, 3, 3), the static singular parts Us, Ps (9, 3, 3), compacted Pc (L sP), Uc (L sU)."""
    return (np.zeros((L, 9, 3, 3)), np.zeros((L, 9, 3, 3)), np.zeros((9, 3, 3)), np.zeros((9, 3, 3)),
            np.zeros(L * sP), np.zeros(L * sU))


@njit(cache=True)
def _integrate(xc, X, sing, ns, lo, hi, want_u, phys, quad, bufs):
    """Element integrals of one pair into Ub, Pb[:hi-lo+1] of ``bufs`` (the static singular part
    added at the first lag of a singular pair); returns the kernel evaluations. Packs: ``phys`` the
    material and the step (``packs.wave``), ``quad`` the quadrature (``packs.Quad``), ``bufs`` from
    ``buffers``."""
    Ub, Pb, Us, Ps, _, _ = bufs
    nl = hi - lo + 1
    Ub[:nl] = 0.0
    Pb[:nl] = 0.0
    nev = integrate_pair(xc, X, sing, ns, lo, hi, phys, quad.gq, quad.gw, Ub, Pb, want_u)
    if sing >= 0:
        Us[:] = 0.0
        Ps[:] = 0.0
        gr, gwr = quad.gr, quad.gwr
        singular_static(X, sing, gr.shape[0], gr.shape[0], gr, gwr, gr, gwr, phys[NU], phys[MU], Us, Ps, quad.h_ref)
        Ub[0] += Us
        Pb[0] += Ps
    return nev


@njit(cache=True)
def plane_geometry(VX, ns, gq, gw):
    """``quadrature.plane_points`` of every virtual element at ``ns`` subdivisions: (sub (nv, ns^2, 4),
    pts (nv, ns^2 ng^2, 4), Ntab (ns^2 ng^2, 9)), computed once per assembly (``plane``)."""
    ng2 = gq.shape[0] ** 2
    nv = VX.shape[0]
    sub = np.zeros((nv, ns * ns, 4))
    pts = np.zeros((nv, ns * ns * ng2, 4))
    Ntab = np.zeros((ns * ns * ng2, 9))
    for v in range(nv):
        plane_points(VX[v], ns, gq, gw, sub[v], pts[v], Ntab)
    return sub, pts, Ntab


def plane(flat, VX, ns, gq, gw, ns_max):
    """The plane geometry of the kernels' pack (``kernels``) and of ``integrate_records``: (flat, the
    elements' geometry at the base subdivisions, scratch for other subdivisions): with ``flat`` (every
    node and element in the plane z = 0) regular pairs take ``quadrature.integrate_plane`` (the kernel
    table's PLANE)."""
    ng2 = len(gq) ** 2
    if flat:
        sub, pts, Ntab = plane_geometry(VX, ns, gq, gw)
    else:
        sub, pts, Ntab = np.zeros((0, 1, 4)), np.zeros((0, 1, 4)), np.zeros((0, 9))
    m = ns_max * ns_max if flat else 0
    return (bool(flat), sub, pts, Ntab, np.zeros((m, 4)), np.zeros((m * ng2, 4)), np.zeros((m * ng2, 9)))


@njit(cache=True)
def _plane_integrals(xc, v, X, ns, lo, hi, want_u, phys, quad, plane, bufs, mH, mG, want_p):
    """The PLANE integrator of the kernel table: a regular pair of the plane z = 0 by
    ``integrate_plane`` into Pc[:9 mH nl] (and Uc; without ``want_p`` Uc alone) of ``bufs``, the element's
    geometry from ``plane`` at the base subdivisions, else computed into its scratch. Returns the kernel
    evaluations."""
    _, gsub, gpts, Ntab, ssub, spts, sN = plane
    Pc, Uc = bufs[4], bufs[5]
    nl = hi - lo + 1
    ng2 = quad.gq.shape[0] ** 2
    P = Pc[:nl * 9 * mH].reshape((nl, 9, mH))
    U = Uc[:nl * 9 * mG].reshape((nl, 9, mG))
    if want_p or not want_u:
        P[:] = 0.0
    if want_u:
        U[:] = 0.0
    if ns == quad.ns_base:
        return integrate_plane(xc, gsub[v], gpts[v], Ntab, ng2, lo, hi, phys, P, U, want_u, want_p)
    m = ns * ns
    plane_points(X, ns, quad.gq, quad.gw, ssub[:m], spts[:m * ng2], sN[:m * ng2])
    return integrate_plane(xc, ssub[:m], spts[:m * ng2], sN[:m * ng2], ng2, lo, hi, phys, P, U, want_u, want_p)


@njit(cache=True)
def _pair_integrals(xc, v, X, sing, ns, lo, hi, want_u, phys, quad, kern, bufs, dropped, want_p):
    """A pair's integrals of lags lo..hi in the patterns' layout (``_compact``): Pc[:9 m_H nl] and, with
    ``want_u``, Uc[:9 m_G nl] of ``bufs``, by the integrator of the kernel table (``kern``, as from
    ``kernels``): a regular pair by PLANE (``_plane_integrals``; with ``want_u`` and not ``want_p`` Uc
    alone, Pc left as it is), any other by ``_integrate`` (the full blocks, the entries a flat pattern
    drops checked into dropped[0] (H), dropped[1] (G), then compacted; Pc always). Returns the kernel
    evaluations. Packs as ``_integrate``'s."""
    codes, pattern, plane = kern
    hp, hq, gp, gq_, hkeep, gkeep = pattern
    mH, mG = hp.shape[0], gp.shape[0]
    if codes[0] == PLANE and sing < 0:
        return _plane_integrals(xc, v, X, ns, lo, hi, want_u, phys, quad, plane, bufs, mH, mG, want_p)
    Ub, Pb, _, _, Pc, Uc = bufs
    nl = hi - lo + 1
    nev = _integrate(xc, X, sing, ns, lo, hi, want_u, phys, quad, bufs)
    if mH < 9:
        _check_dropped(Pb, nl, hkeep, dropped[0:1])
    _compact(Pc, 0, Pb, nl, hp, hq)
    if want_u:
        if mG < 9:
            _check_dropped(Ub, nl, gkeep, dropped[1:2])
        _compact(Uc, 0, Ub, nl, gp, gq_)
    return nev


@njit(cache=True)
def _lookup(cidx, ckeys, cmeta, hsh, key, lo, hi):
    """The cache entry of a pair (its hash, key and lag window lo..hi; cmeta[:, 0:2] = lo, hi), or -1
    (absent, or a different key or window under the same hash)."""
    if hsh not in cidx:
        return -1
    c = cidx[hsh]
    if cmeta[c, 0] != lo or cmeta[c, 1] != hi:
        return -1
    for k in range(27):
        if ckeys[c, k] != key[k]:
            return -1
    return c


@njit(cache=True)
def _new_index():
    """The cache's hash -> entry map. Made in compiled code: ``numba.typed.Dict.empty`` called from
    Python compiles its constructor in every process (numba does not cache it), and ``len`` of it
    from Python another helper (``index_len``); tests/test_warmup.py counts what a warm process
    compiles."""
    return Dict.empty(key_type=types.int64, value_type=types.int64)


@njit(cache=True)
def index_len(cidx):
    """Entries of the cache's hash map (compiled and cached: see ``_new_index``)."""
    return len(cidx)


_COLS, _VALS, _VALS32 = (types.Array(types.int32, 1, "C"), types.Array(types.float64, 2, "C"),
                         types.Array(types.float32, 2, "C"))


@njit(cache=True)
def new_lists(n, m):
    """(columns, values, float32 values): typed Lists of n empty per-lag arrays (int32; n x m float64;
    float32), the lag arrays the kernel writes (``_emit_lag``). Made, read and changed in compiled code
    only (``set_lag``, ``get_lag``): typed Lists made or used from Python compile their methods in
    every process (numba caches none of them; tests/test_warmup.py counts)."""
    c = List.empty_list(_COLS)
    v = List.empty_list(_VALS)
    v32 = List.empty_list(_VALS32)
    for _ in range(n):
        c.append(np.empty(0, np.int32))
        v.append(np.empty((0, m)))
        v32.append(np.empty((0, m), np.float32))
    return c, v, v32


@njit(cache=True)
def set_lag(c, v, v32, i, ci, vi, v32i):
    """Lag i's arrays of the typed lists of ``new_lists``."""
    c[i] = ci
    v[i] = vi
    v32[i] = v32i


@njit(cache=True)
def get_lag(c, v, v32, i):
    """(columns, values, float32 values) of lag i (the arrays themselves, not copies)."""
    return c[i], v[i], v32[i]


def new_cache():
    """An element-integral cache (kept across calls of ``assemble_rows``)."""
    return (_new_index(), np.zeros((16, 27), np.int64), np.zeros((16, 5), np.int64),
            np.zeros(1024), np.zeros(1024))


@njit(cache=True)
def _pool_end(cmeta, ncache):
    """First free lag slots of the cache pools, (P, U): entry k = cmeta[k] (lo, hi, P slot, has U,
    U slot) holds hi - lo + 1 lag slots from its P slot, and as many from its U slot if it has U
    blocks (only pairs with a traction column do): 9 m doubles a slot in a pool of a pattern of m
    values (``_compact``)."""
    pool_n = 0
    upool_n = 0
    for k in range(ncache):
        nl = cmeta[k, 1] - cmeta[k, 0] + 1
        if cmeta[k, 2] + nl > pool_n:
            pool_n = cmeta[k, 2] + nl
        if cmeta[k, 3] == 1 and cmeta[k, 4] + nl > upool_n:
            upool_n = cmeta[k, 4] + nl
    return pool_n, upool_n


@njit(cache=True)
def _compact(dst, off, B, nl, pp, pq):
    """dst[off + (9 li + a) m + j] = B[li, a, pp[j], pq[j]] (m = len(pp)): the pattern's entries of a
    pair's blocks, lag slot by lag slot, node by node (the layout of the cache pools and scratch)."""
    m = pp.shape[0]
    k = off
    for li in range(nl):
        for a in range(9):
            for j in range(m):
                dst[k] = B[li, a, pp[j], pq[j]]
                k += 1


@njit(cache=True)
def _check_dropped(B, nl, keep, dropped):
    """dropped[0] = max(dropped[0], largest |B[li, a, p, q]| outside the pattern (keep False)): the
    entries a flat pattern leaves out, exact zeros on a plane; every integral is checked once, where
    it is computed, whatever path (cache, scratch, shared cache) it then takes."""
    for li in range(nl):
        for a in range(9):
            for p in range(3):
                for q in range(3):
                    if not keep[p, q]:
                        v = abs(B[li, a, p, q])
                        if v > dropped[0]:
                            dropped[0] = v


@njit(cache=True)
def _cached(use_cache, cidx, ckeys, cmeta, VXv, xc, qinv, key, lo, hi, want_u):
    """(found, fill_u, hsh) for a pair: the cache entry holding all it needs (found >= 0), or one
    holding its P blocks but not the U blocks it wants (fill_u >= 0)."""
    if not use_cache:
        return -1, -1, np.int64(0)
    hsh = _geom_key(VXv, xc, qinv, key)
    c = _lookup(cidx, ckeys, cmeta, hsh, key, lo, hi)
    if c >= 0:
        if cmeta[c, 3] == 1 or not want_u:
            return c, -1, hsh
        return -1, c, hsh
    return -1, -1, hsh


def new_work(n_nodes, n_tcols, n_virtual, mH=9, mG=9):
    """Work arrays of ``assemble_rows``, kept from one call to the next: the pair list of a row
    (element, lags lo..hi, where its integrals are), the integrals of pairs not in the element
    cache (grown as needed), and per matrix one row of blocks by column (``mH``, ``mG`` values a
    block: bsr.PATTERNS), its touched flags and list. A row's blocks of one lag are summed there (a
    few tens of KB: in cache) and written once, where they are kept."""
    nt = max(n_tcols, 1)
    return (np.zeros((max(n_virtual, 1), 7), np.int64), np.zeros(1024), np.zeros(1024),
            np.zeros((n_nodes, mH)), np.zeros((nt, mG)), np.zeros(n_nodes, np.bool_), np.zeros(nt, np.bool_),
            np.zeros(n_nodes, np.int64), np.zeros(nt, np.int64))


@njit(cache=True)
def _room(out, lag, n):
    """Make room for ``n`` more blocks in lag ``lag`` of ``out`` (growing its arrays by half, in
    place of the typed lists' entries, when it has none)."""
    cols, vals, vals32, fill, counts, single_from = out
    f = fill[lag]
    c = cols[lag]
    if f + n <= c.shape[0]:
        return
    cap = max(int(1.5 * (f + n)), 1024)
    c2 = np.empty(cap, np.int32)
    c2[:f] = c[:f]
    cols[lag] = c2
    if single_from > 0 and lag >= single_from:
        v = vals32[lag]
        v2 = np.empty((cap, v.shape[1]), np.float32)
        v2[:f] = v[:f]
        vals32[lag] = v2
    else:
        v = vals[lag]
        w2 = np.empty((cap, v.shape[1]))
        w2[:f] = v[:f]
        vals[lag] = w2


@njit(cache=True)
def _emit_lag(lag, n, cl, buf, li, out):
    """Append the blocks buf[cl[k]] (k < n, columns ascending) of one row to lag ``lag`` of ``out`` =
    (columns, values, float32 values, fill, counts, single_from): typed Lists of per-lag arrays (values
    from ``single_from`` > 0 on in float32, rounded as they are written), fill[l] the blocks lag l
    holds, counts[l, li] += the row's (li: its place among the rank's rows); single_from < 0: a matrix
    not kept (the G-only assembly of ``build._traction_g``), nothing written."""
    if n == 0 or out[5] < 0:
        return
    _room(out, lag, n)
    cols, vals, vals32, fill, counts, single_from = out
    f = fill[lag]
    c = cols[lag]
    m = buf.shape[1]
    if single_from > 0 and lag >= single_from:
        v32 = vals32[lag]
        for k in range(n):
            col = cl[k]
            c[f + k] = col
            for j in range(m):
                v32[f + k, j] = buf[col, j]
    else:
        v = vals[lag]
        for k in range(n):
            col = cl[k]
            c[f + k] = col
            for j in range(m):
                v[f + k, j] = buf[col, j]
    fill[lag] = f + n
    counts[lag, li] += n


# The flat H pattern's entries (patterns.H4) in a full block's row-major layout (3 p + q), and the others:
# a full block whose others are exact zeros is stored in the flat pattern (``_emit_split``).
H4_AT = np.array([3 * p + q for p, q in PATTERNS[H4]], np.int64)
H4_OFF = np.array([k for k in range(9) if k not in H4_AT], np.int64)


@njit(cache=True)
def _emit_split(lag, n, cl, buf, li, out, flat):
    """``_emit_lag`` of one row's full blocks (buf (columns, 9)) split in two (a surface that is not one
    plane, -ssi_lag_pattern auto): the blocks whose entries outside the flat H pattern are exact zeros
    (every block whose pairs all lie in one horizontal plane: the point on the element's plane, r . n =
    0) to ``flat`` in that pattern (4 values), the others to ``out`` (9). Each list in column order:
    the same blocks, a product of either part the same bits block by block (the dropped entries are
    exact zeros)."""
    if n == 0 or out[5] < 0:
        return
    sel = np.empty(n, cl.dtype)
    nf = np.int64(0)
    for k in range(n):                      # the flat blocks first, in column order
        col = cl[k]
        z = True
        for j in range(H4_OFF.shape[0]):
            if buf[col, H4_OFF[j]] != 0.0:
                z = False
        if z:
            sel[nf] = col
            nf += 1
    ng = nf
    for k in range(n):                      # then the others, in column order
        col = cl[k]
        z = True
        for j in range(H4_OFF.shape[0]):
            if buf[col, H4_OFF[j]] != 0.0:
                z = False
        if not z:
            sel[ng] = col
            ng += 1
    _emit_lag(lag, n - nf, sel[nf:], buf, li, out)
    if nf == 0:
        return
    _room(flat, lag, nf)
    cols, vals, vals32, fill, counts, single_from = flat
    f = fill[lag]
    c = cols[lag]
    for k in range(nf):
        c[f + k] = sel[k]
    if single_from > 0 and lag >= single_from:
        v32 = vals32[lag]
        for k in range(nf):
            for j in range(4):
                v32[f + k, j] = buf[sel[k], H4_AT[j]]
    else:
        v = vals[lag]
        for k in range(nf):
            for j in range(4):
                v[f + k, j] = buf[sel[k], H4_AT[j]]
    fill[lag] = f + nf
    counts[lag, li] += nf


@njit(cache=True)
def emit_row(n, tlag, tcol, tval, li, out):
    """Append one row's blocks given as triplets 0..n (in (lag, column) order) to ``out`` (as
    ``_emit_lag``; ``Buckets.add``)."""
    cols, vals, vals32, fill, counts, single_from = out
    m = tval.shape[1]
    k = 0
    while k < n:
        lag = tlag[k]
        k2 = k
        while k2 < n and tlag[k2] == lag:
            k2 += 1
        _room(out, lag, k2 - k)
        f = fill[lag]
        c = cols[lag]
        if single_from > 0 and lag >= single_from:
            v32 = vals32[lag]
            for e in range(k, k2):
                c[f + e - k] = tcol[e]
                for j in range(m):
                    v32[f + e - k, j] = tval[e, j]
        else:
            v = vals[lag]
            for e in range(k, k2):
                c[f + e - k] = tcol[e]
                for j in range(m):
                    v[f + e - k, j] = tval[e, j]
        fill[lag] = f + (k2 - k)
        counts[lag, li] += k2 - k
        k = k2


@njit(cache=True, inline="always")
def _accumulate(src, base, m, cols, sg, buf, touch, lst, n, skip_zero):
    """Add one pair's blocks of one lag (src[base + m a + j]: node a, the j-th entry of the pattern,
    ``_compact``) times the element's image signs (sg[j]: the sign of entry j's column component) into
    the row buffer ``buf`` by column (cols[a] < 0: no column). Inlined, so that a constant m (the flat
    patterns' 4 and 5) gives loops of known length, unrolled (the same operations in the same order). A column met for the first time is zeroed
    and listed (``touch``, ``lst``[:n]). With ``skip_zero`` a block whose entries are all zero adds
    nothing (H: only blocks with a non-zero contribution are stored; G keeps every traction column).
    Returns n."""
    for a in range(9):
        col = cols[a]
        if col < 0:
            continue
        b = base + m * a
        if skip_zero:
            nz = False
            for j in range(m):
                if src[b + j] != 0.0:
                    nz = True
            if not nz:
                continue
        if not touch[col]:
            touch[col] = True
            lst[n] = col
            n += 1
            for j in range(m):
                buf[col, j] = 0.0
        for j in range(m):
            buf[col, j] += src[b + j] * sg[j]
    return n


@njit(cache=True)
def _ordered(lst, n, touch):
    """The n touched columns listed in lst, ascending, their flags cleared: a scan of the flags when
    they are many (n log n sorting of most of the row costs more), else a sort of the list."""
    if 16 * n > touch.shape[0]:
        k = 0
        for c in range(touch.shape[0]):
            if touch[c]:
                lst[k] = c
                touch[c] = False
                k += 1
        return lst[:n]
    cl = np.sort(lst[:n])
    for k in range(n):
        touch[cl[k]] = False
    return cl


@njit(cache=True)
def _image_signs(Vsign, pp):
    """sg[v, j]: element v's image sign of the column component of pattern entry j (pp: the entries'
    column components)."""
    nv = Vsign.shape[0]
    sg = np.empty((nv, pp.shape[0]))
    for v in range(nv):
        for j in range(pp.shape[0]):
            sg[v, j] = Vsign[v, pp[j]]
    return sg


@njit(cache=True)
def assemble_rows(rows, mesh, lags, phys, quad, kern, cache, work, dropped, out, cand):
    """Collective-free numba kernel: the blocks of H and G of ``rows``, written where they are kept.

    mesh = (xnodes, VX, Vnode, Vsign, Vtcol, Vc, VR, Vh): collocation points and the virtual elements
    (nodes, global columns, image signs, traction columns, bounding spheres, sizes); lags = (lag_lo, L);
    phys: the material and the step (``packs.wave``, with the kernel time offset toff); quad: the
    quadrature (``packs.Quad``); kern: the kernel table's choice, patterns and plane geometry
    (``kernels``); cache = (use_cache, cidx, ckeys, cmeta, cpoolP, cpoolU, qinv, cache_max): the element
    cache (``new_cache``); work: ``new_work``; ``dropped`` (2,) the largest dropped magnitude of H and of
    G; out = (hout, gout, loc, hflat): the per-lag block CSR arrays of H and G (``_emit_lag``), a node's place
    among the rank's rows and those of H's flat part (``_emit_split``; hflat[5] < 0: H not split); cand =
    (ptr, elements, r0): row ii's candidate elements elements[ptr[r0 + ii]:ptr[r0 + ii + 1]] (``windows.candidates``,
    ascending; an empty ptr: every element).

    Per row: first every pair (row, virtual element) whose wave window reaches lags lag_lo..L is
    listed with where its element integrals are (the element cache, or integrated now: into the
    cache, or the work's scratch when the cache is off or full); then lag by lag the pairs'
    blocks are summed in a row buffer by column (in element order: the sums of a block are those of
    the literal loop, bit for bit) and written, columns ascending, straight into the lag's arrays:
    rows ascending, no sort or copy after. The free term is not added (the Buckets and Mats of H_1
    carry it apart).

    Returns (work, nev, hits, cache): ``nev`` counts (point, lag) kernel evaluations, ``hits`` the pairs
    taken from the cache. With ``use_cache`` the element integrals of a pair are reused for every later
    pair with the same relative geometry (quantised to 1/qinv): translated copies of an element on a
    structured mesh are integrated once. The key includes the node order, so images and singular pairs
    are keyed correctly; the integrals depend on nothing else (material, dt and lags are fixed). Only
    lags lag_lo..L are computed, at kernel times l dt + toff (a cache must not be shared between calls
    with different lag_lo, L or toff). The cache stops growing at ``cache_max`` bytes per pool (reuse
    goes on).
    """
    use_cache, cidx, ckeys, cmeta, cpoolP, cpoolU, qinv, cache_max = cache
    pattern = kern[1]
    sP, sU = 9 * pattern[0].shape[0], 9 * pattern[2].shape[0]     # doubles a lag slot of the P (H), U (G) pools
    pairs, scP, scU, bufH, bufG, touchH, touchG, lstH, lstG = work
    cfg = (use_cache, cidx, qinv, cache_max)
    bufs = buffers(lags[1], sP, sU)
    nev = 0
    hits = 0
    ncache = len(cidx)
    pool_n, upool_n = _pool_end(cmeta, ncache)
    key = np.zeros(27, np.int64)
    sg = (_image_signs(mesh[3], pattern[1]), _image_signs(mesh[3], pattern[3]))
    cptr, cel, r0 = cand
    use_c = cptr.shape[0] > 0
    for ii in range(rows.shape[0]):
        i = rows[ii]
        store = (ckeys, cmeta, cpoolP, cpoolU, pool_n, upool_n, ncache, scP, scU, np.int64(0))
        vl = cel[cptr[r0 + ii]:cptr[r0 + ii + 1]] if use_c else cel[:0]
        npair, n_ev, n_hit, store = _row_pairs(mesh[0][i], mesh, lags, phys, quad, kern, cfg, key, dropped, bufs,
                                               pairs, store, vl, use_c)
        ckeys, cmeta, cpoolP, cpoolU, pool_n, upool_n, ncache, scP, scU, _ = store
        nev += n_ev
        hits += n_hit
        _row_blocks(out[2][i], npair, pairs, lags, mesh, sg, kern, (scP, scU, cpoolP, cpoolU),
                    (bufH, bufG, touchH, touchG, lstH, lstG), out)
    return ((pairs, scP, scU, bufH, bufG, touchH, touchG, lstH, lstG), nev, hits,
            (use_cache, cidx, ckeys, cmeta, cpoolP, cpoolU, qinv, cache_max))


@njit(cache=True)
def _row_pairs(xc, mesh, lags, phys, quad, kern, cfg, key, dropped, bufs, pairs, store, vl, use_vl):
    """The pairs (collocation point xc, virtual element) of one row whose wave window reaches lags
    lag_lo..L, listed in ``pairs`` (element, lo, hi, want_u, where (0: cache pools, 1: scratch), P slot,
    U slot) with their integrals found in the cache or integrated now and stored (``_store_pair``);
    cfg = (use_cache, cidx, qinv, cache_max); the elements visited: ``vl`` (ascending) with ``use_vl``, else
    every one. Returns (pairs listed, kernel evaluations, cache hits, ``store`` updated)."""
    VX, Vtcol = mesh[1], mesh[4]
    use_cache, cidx, qinv, _ = cfg
    reach = phys[CP] * (phys[DT] * lags[1] + phys[TOFF])
    npair = nev = hits = 0
    for t in range(vl.shape[0] if use_vl else VX.shape[0]):
        v = np.int64(vl[t]) if use_vl else np.int64(t)
        lo, hi, sing, ns = _window(xc, v, mesh, reach, lags, phys, quad)
        if lo > hi:
            continue
        ncol = 0                           # (want_u from a count, not a literal False: numba typed the calls
        for a in range(9):                 # below once for Literal[bool](False), once for bool; compiled twice)
            if Vtcol[v, a] >= 0:
                ncol += 1
        want_u = ncol > 0
        found, fill_u, hsh = _cached(use_cache, cidx, store[0], store[1], VX[v], xc, qinv, key, lo, hi, want_u)
        where = 0
        if found >= 0:
            off = store[1][found, 2]
            offU = store[1][found, 4]
            hits += 1
        else:
            nev += _pair_integrals(xc, v, VX[v], sing, ns, lo, hi, want_u, phys, quad, kern, bufs, dropped,
                                   np.bool_(True))        # (a bool, as integrate_batch's: one compiled version)
            store, where, off, offU = _store_pair((fill_u, hsh, lo, hi, want_u), cfg, key, bufs, kern[1], store)
        pairs[npair, 0] = v; pairs[npair, 1] = lo; pairs[npair, 2] = hi
        pairs[npair, 3] = 1 if want_u else 0; pairs[npair, 4] = where; pairs[npair, 5] = off
        pairs[npair, 6] = offU
        npair += 1
    return npair, nev, hits, store


@njit(cache=True, inline="always")
def _put(pool, n, nl, s, src):
    """pool[n s:(n + nl) s] = src[:nl s], the pool grown (doubling) as needed; returns the pool."""
    while (n + nl) * s > pool.shape[0]:
        pool = _grow(pool, pool.shape[0])
    pool[n * s:(n + nl) * s] = src[:nl * s]
    return pool


@njit(cache=True)
def _store_pair(pair, cfg, key, bufs, pattern, store):
    """Where a pair's freshly integrated blocks (Pc, Uc of ``bufs``) go: pair = (fill_u, hsh, lo, hi,
    want_u); into the cache entry ``fill_u`` (its U blocks), a new cache entry while the pools stay
    under ``cache_max`` bytes, or else the row's scratch. ``store`` = (ckeys, cmeta, cpoolP, cpoolU,
    pool_n, upool_n, ncache, scP, scU, sc_n). Returns (``store`` updated, where (0: cache pools, 1:
    scratch), P slot, U slot)."""
    ckeys, cmeta, cpoolP, cpoolU, pool_n, upool_n, ncache, scP, scU, sc_n = store
    fill_u, hsh, lo, hi, want_u = pair
    use_cache, cidx, _, cache_max = cfg
    Pc, Uc = bufs[4], bufs[5]
    sP, sU = 9 * pattern[0].shape[0], 9 * pattern[2].shape[0]
    nl = hi - lo + 1
    where = 0
    offU = 0
    if fill_u >= 0:                         # complete the entry with its U blocks
        off = cmeta[fill_u, 2]
        cpoolU = _put(cpoolU, upool_n, nl, sU, Uc)
        cmeta[fill_u, 3] = 1
        cmeta[fill_u, 4] = upool_n
        offU = upool_n
        upool_n += nl
    elif use_cache and hsh not in cidx and 8 * (pool_n + nl) * max(sP, sU) <= cache_max:
        c = ncache
        ckeys = _grow(ckeys, c)
        cmeta = _grow(cmeta, c)
        ckeys[c] = key
        cmeta[c, 0] = lo; cmeta[c, 1] = hi; cmeta[c, 2] = pool_n
        cmeta[c, 3] = 1 if want_u else 0
        cpoolP = _put(cpoolP, pool_n, nl, sP, Pc)
        if want_u:
            cpoolU = _put(cpoolU, upool_n, nl, sU, Uc)
            cmeta[c, 4] = upool_n
            offU = upool_n
            upool_n += nl
        off = pool_n
        pool_n += nl
        cidx[hsh] = c
        ncache += 1
    else:                                   # no cache (or full): the row's scratch
        scP = _put(scP, sc_n, nl, sP, Pc)
        while (sc_n + nl) * sU > scU.shape[0]:
            scU = _grow(scU, scU.shape[0])
        if want_u:
            scU[sc_n * sU:(sc_n + nl) * sU] = Uc[:nl * sU]
        where = 1
        off = sc_n
        offU = sc_n
        sc_n += nl
    return (ckeys, cmeta, cpoolP, cpoolU, pool_n, upool_n, ncache, scP, scU, sc_n), where, off, offU


@njit(cache=True)
def _row_blocks(li, npair, pairs, lags, mesh, sg, kern, src, rowbuf, out):
    """Lag by lag, one row's blocks summed by column from its ``pairs`` (in element order: the sums
    of a block are those of the literal loop, bit for bit) and written where they are kept (row
    ``li`` of the rank's rows; out = (hout, gout, ...)) by the kernel table's emitters (``kern``: H's
    and G's width when constant, the flat patterns' loops unrolled); sg = (H's, G's image signs by
    element and entry), src = (scP, scU, cpoolP, cpoolU), rowbuf = (bufH, bufG, touchH, touchG, lstH,
    lstG)."""
    bufH, bufG, touchH, touchG, lstH, lstG = rowbuf
    scP, scU, cpoolP, cpoolU = src
    sgH, sgG = sg
    Vnode, Vtcol = mesh[2], mesh[4]
    codes, pattern = kern[0], kern[1]
    mH, mG = pattern[0].shape[0], pattern[2].shape[0]
    sP, sU = 9 * mH, 9 * mG
    for lag in range(lags[0], lags[1] + 1):
        nH = np.int64(0)                  # (not literal 0s: the emitters compiled once, for int64)
        nG = np.int64(0)
        for k in range(npair):
            lo = pairs[k, 1]
            if lag < lo or lag > pairs[k, 2]:
                continue
            v = pairs[k, 0]
            srcP = scP if pairs[k, 4] == 1 else cpoolP
            bP = (pairs[k, 5] + lag - lo) * sP
            if codes[1] == H4:                  # the flat pattern: a constant width, loops unrolled
                nH = _accumulate(srcP, bP, H4, Vnode[v], sgH[v], bufH, touchH, lstH, nH, True)
            else:
                nH = _accumulate(srcP, bP, mH, Vnode[v], sgH[v], bufH, touchH, lstH, nH, True)
            if pairs[k, 3] == 1:
                srcU = scU if pairs[k, 4] == 1 else cpoolU
                bU = (pairs[k, 6] + lag - lo) * sU
                if codes[2] == G5:
                    nG = _accumulate(srcU, bU, G5, Vtcol[v], sgG[v], bufG, touchG, lstG, nG, False)
                else:
                    nG = _accumulate(srcU, bU, mG, Vtcol[v], sgG[v], bufG, touchG, lstG, nG, False)
        if nH and out[3][5] >= 0:              # H of a surface that is not one plane: flat and full parts
            _emit_split(lag, nH, _ordered(lstH, nH, touchH), bufH, li, out[0], out[3])
        elif nH:
            _emit_lag(lag, nH, _ordered(lstH, nH, touchH), bufH, li, out[0])
        if nG:
            _emit_lag(lag, nG, _ordered(lstG, nG, touchG), bufG, li, out[1])


# ---------------------------------------------------------------------------
# Element cache shared between ranks (model.LagSet.assemble): each rank lists
# the distinct pair geometries its rows meet (enumerate_pairs), an owner rank
# per geometry (its hash modulo the ranks) integrates it once (integrate_batch)
# and sends it back, and each rank fills its cache with what it asked for
# (cache_index: the blocks are received in place) before assemble_rows runs, which then finds every
# pair there.

@njit(cache=True)
def enumerate_pairs(rows, mesh, lags, phys, quad, qinv, cache_max, stride, cand):
    """The distinct pair geometries that ``assemble_rows`` with a cache would store for ``rows`` (packs
    as its, ``cand`` its candidate elements), in the order it meets them, up to the same cache cap: (keys
    (m, 27), hashes (m,), meta (m, 6) = [lo, hi, sing, ns, want_u, element], points (m, 3)). A hash met
    again with a different key or lag window is left out (assemble_rows integrates such pairs itself, as it
    does now)."""
    VX, Vtcol = mesh[1], mesh[4]
    nv = VX.shape[0]
    cidx = Dict.empty(key_type=types.int64, value_type=types.int64)
    keys = np.zeros((64, 27), np.int64)
    hs = np.zeros(64, np.int64)
    meta = np.zeros((64, 6), np.int64)
    pts = np.zeros((64, 3))
    m = np.int64(0)
    pool_n = 0
    key = np.zeros(27, np.int64)
    reach = phys[CP] * (phys[DT] * lags[1] + phys[TOFF])
    cptr, cel, r0 = cand
    use_c = cptr.shape[0] > 0
    for ii in range(rows.shape[0]):
        xc = mesh[0][rows[ii]]
        for t in range(cptr[r0 + ii + 1] - cptr[r0 + ii] if use_c else nv):
            v = np.int64(cel[cptr[r0 + ii] + t]) if use_c else np.int64(t)
            lo, hi, sing, ns = _window(xc, v, mesh, reach, lags, phys, quad)
            if lo > hi:
                continue
            want_u = 0
            for a in range(9):
                if Vtcol[v, a] >= 0:
                    want_u = 1
            hsh = _geom_key(VX[v], xc, qinv, key)
            if hsh in cidx:
                c = _lookup(cidx, keys, meta, hsh, key, lo, hi)
                if c >= 0 and want_u == 1:
                    meta[c, 4] = 1
                continue
            nl = hi - lo + 1
            if 8 * (pool_n + nl) * stride > cache_max:
                continue
            keys = _grow(keys, m); hs = _grow(hs, m); meta = _grow(meta, m); pts = _grow(pts, m)
            keys[m] = key
            hs[m] = hsh
            meta[m, 0] = lo; meta[m, 1] = hi; meta[m, 2] = sing; meta[m, 3] = ns; meta[m, 4] = want_u
            meta[m, 5] = v
            pts[m] = xc
            cidx[hsh] = m
            pool_n += nl
            m += 1
    return keys[:m], hs[:m], meta[:m], pts[:m]


@njit(cache=True)
def integrate_batch(meta, pts, VX, L, phys, quad, kern, dropped):
    """Integrals of the listed pairs (meta, points as from enumerate_pairs) of lags up to L, the
    patterns' entries (the others checked into ``dropped``, ``_check_dropped``), by the kernels of
    ``kern`` (``kernels``; its plane geometry for quad.ns_base subdivisions): (offsets (m + 1,) into
    the P pool, P pool, offsets (m + 1,) into the U pool, U pool, kernel evaluations); a lag slot takes
    9 m doubles (``_compact``). meta[r, 4] (want_u) 0: H alone, 1: H and G, 2: G alone (the records of 1 and
    2 take room in the U pool, those of 0 and 1 in the P pool; a regular pair of the plane alone forms no H
    integrals for a record of 2, ``_pair_integrals``)."""
    pattern = kern[1]
    sP, sU = 9 * pattern[0].shape[0], 9 * pattern[2].shape[0]
    m = meta.shape[0]
    off = np.zeros(m + 1, np.int64)
    uoff = np.zeros(m + 1, np.int64)
    for r in range(m):
        nl = meta[r, 1] - meta[r, 0] + 1
        off[r + 1] = off[r] + (nl * sP if meta[r, 4] != 2 else 0)
        uoff[r + 1] = uoff[r] + (nl * sU if meta[r, 4] >= 1 else 0)
    P = np.zeros(off[m])
    U = np.zeros(uoff[m])
    bufs = buffers(L, sP, sU)
    Pc, Uc = bufs[4], bufs[5]
    nev = 0
    for r in range(m):
        lo, hi = meta[r, 0], meta[r, 1]
        nl = hi - lo + 1
        v = meta[r, 5]
        want_u, want_p = meta[r, 4] >= 1, meta[r, 4] != 2
        nev += _pair_integrals(pts[r], v, VX[v], meta[r, 2], meta[r, 3], lo, hi, want_u, phys, quad, kern,
                               bufs, dropped, want_p)
        if want_p:
            P[off[r]:off[r] + nl * sP] = Pc[:nl * sP]
        if want_u:
            U[uoff[r]:uoff[r] + nl * sU] = Uc[:nl * sU]
    return off, P, uoff, U, nev


def integrate_records(meta, pts, VX, L, dt, alpha, beta, rho, nu, gq, gw, gr, gwr, toff, h_ref, pattern, dropped,
                      ns_base, plane):
    """``integrate_batch`` from positional arguments (bem/toeplitz.py's form): ``pattern`` as
    LagSet.pattern, ``plane`` as from ``plane`` (its flag: the surface is the plane z = 0, else the
    general kernels), ``ns_base`` the subdivisions its geometry is for."""
    kind = "plane" if plane[0] else "general"
    quad = packs.quad(ns_base, 0.0, ns_base, gq, gw, gr, gwr, SING_TOL, h_ref)     # (the windows are given)
    return integrate_batch(meta, pts, VX, L, packs.wave(dt, alpha, beta, rho, nu, toff), quad,
                           kernels(kind, pattern, plane), dropped)


@njit(cache=True)
def cache_index(cidx, ckeys, cmeta, keys, hs, meta, pslot, uslot):
    """Index records (keys, hashes, meta as from enumerate_pairs) whose blocks already lie in an
    empty element cache's pools: record r's P blocks at lag slot pslot[r] of the P pool, its U blocks
    at uslot[r] of the U pool (uslot[r] < 0: none); a record whose hash is already indexed is
    skipped (its blocks are unused). Returns (ckeys, cmeta)."""
    ncache = len(cidx)
    ckeys = _grow(ckeys, ncache + keys.shape[0])
    cmeta = _grow(cmeta, ncache + keys.shape[0])
    for r in range(keys.shape[0]):
        if hs[r] in cidx:
            continue
        c = ncache
        ckeys[c] = keys[r]
        cmeta[c, 0] = meta[r, 0]; cmeta[c, 1] = meta[r, 1]; cmeta[c, 2] = pslot[r]
        cmeta[c, 3] = 1 if uslot[r] >= 0 else 0
        cmeta[c, 4] = uslot[r] if uslot[r] >= 0 else 0
        cidx[hs[r]] = c
        ncache += 1
    return ckeys, cmeta
