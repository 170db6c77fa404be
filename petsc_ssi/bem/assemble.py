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
from numba.typed import Dict

from .quadrature import integrate_pair, singular_static


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


@njit(cache=True)
def _integrate(xc, X, sing, ns, gq, gw, gr, gwr, lo, hi, dt, alpha, beta, rho, nu, mu, want_u, toff, h_ref,
               Ub, Pb, Us, Ps):
    """Element integrals of one pair into Ub, Pb[:hi-lo+1] (the static singular part added at the
    first lag of a singular pair); returns the kernel evaluations."""
    nl = hi - lo + 1
    Ub[:nl] = 0.0
    Pb[:nl] = 0.0
    nev = integrate_pair(xc, X, sing, ns, gq, gw, lo, hi, dt, alpha, beta, rho, nu, Ub, Pb, want_u, toff)
    if sing >= 0:
        Us[:] = 0.0
        Ps[:] = 0.0
        singular_static(X, sing, gr.shape[0], gr.shape[0], gr, gwr, gr, gwr, nu, mu, Us, Ps, h_ref)
        Ub[0] += Us
        Pb[0] += Ps
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


def new_cache():
    """An element-integral cache (kept across calls of ``assemble_rows``)."""
    return (_new_index(), np.zeros((16, 27), np.int64), np.zeros((16, 4), np.int64),
            np.zeros(1024), np.zeros(1024))


@njit(cache=True)
def _pool_end(cmeta, ncache):
    """First free position of the cache pools (entry k holds (hi - lo + 1) * 81 doubles from cmeta[k, 2])."""
    pool_n = 0
    for k in range(ncache):
        e = cmeta[k, 2] + (cmeta[k, 1] - cmeta[k, 0] + 1) * 81
        if e > pool_n:
            pool_n = e
    return pool_n


@njit(cache=True)
def _add_pair(src, nl, lo, cols, sign, i, slot, trow, tlag, tcol, tval, n, skip_zero):
    """Add one pair's blocks src[li, a] * diag(sign) (lag lo + li, column cols[a]; cols[a] < 0: no
    column) to row i's entries: slot[lag, col] is the entry of a block already met in this row
    (-1: none yet), else a new one is made. With ``skip_zero`` an all-zero block makes no entry
    (H: only non-zero blocks are stored; G keeps every traction column). Returns the entry count.
    The triplet arrays have room for nl * 9 more entries (the caller grows them once per pair)."""
    for li in range(nl):
        lag = lo + li
        for a in range(9):
            col = cols[a]
            if col < 0:
                continue
            if skip_zero:
                nz = False
                for p in range(3):
                    for q in range(3):
                        if src[li, a, p, q] != 0.0:
                            nz = True
                if not nz:
                    continue
            s = slot[lag, col]
            if s < 0:
                s = n
                slot[lag, col] = s
                trow[s] = i
                tlag[s] = lag
                tcol[s] = col
                for p in range(3):
                    for q in range(3):
                        tval[s, p, q] = 0.0
                n += 1
            for p in range(3):
                for q in range(3):
                    tval[s, p, q] += src[li, a, p, q] * sign[q]
    return n


@njit(cache=True)
def _sort_row(slot, lag_lo, L, e0, n, tlag, tcol, tval, tmp):
    """Put row entries e0..n in (lag, column) order by one pass over the slot map, which is cleared on
    the way (ready for the next row); ``tmp`` (at least n - e0 blocks) is scratch. Rows of a chunk
    then come out sorted as block CSR needs them, lag by lag, with no sort afterwards."""
    tmp[:n - e0] = tval[e0:n]
    k = e0
    for lag in range(lag_lo, L + 1):
        for col in range(slot.shape[1]):
            s = slot[lag, col]
            if s >= 0:
                tval[k] = tmp[s - e0]
                tlag[k] = lag
                tcol[k] = col
                slot[lag, col] = -1
                k += 1


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


def new_work(L, n_nodes, n_tcols, blocks=1 << 16):
    """Work arrays of ``assemble_rows``, kept from one call to the next (a call's triplets are used
    before the next): triplets of H (row, lag, column, block) and of G, scratch blocks, and the slot
    maps (-1) of lags 0..L by column. Reusing them spares each call its page faults (made anew, the
    paper case's 3 GB per rank of triplet buffers cost more in the kernel than the assembly itself)."""
    g = max(blocks // 64, 256)
    return (np.zeros(blocks, np.int64), np.zeros(blocks, np.int64), np.zeros(blocks, np.int64),
            np.zeros((blocks, 3, 3)), np.zeros(g, np.int64), np.zeros(g, np.int64), np.zeros(g, np.int64),
            np.zeros((g, 3, 3)), np.zeros((1024, 3, 3)), np.full((L + 1, n_nodes), -1, np.int64),
            np.full((L + 1, max(n_tcols, 1)), -1, np.int64))


@njit(cache=True)
def assemble_rows(rows, mesh, wave, quad, free_term, use_cache, cidx, ckeys, cmeta, cpoolP, cpoolU, qinv,
                  work, cache_max=1 << 62):
    """Collective-free numba kernel: triplets of H and G for ``rows``.

    mesh = (xnodes, VX, Vnode, Vsign, Vtcol, Vc, VR, Vh): collocation points and the virtual elements
    (nodes, global columns, image signs, traction columns, bounding spheres, sizes);
    wave = (L, dt, alpha, beta, rho, nu, lag_lo, toff); quad = (ns_base, near_factor, ns_max, gq, gw,
    gr, gwr, tol, h_ref); work: ``new_work`` (its slot maps size the columns).

    Returns (work, nh, ng, nev, hits, cache arrays): the triplets are work[0:4][:nh] (H) and
    work[4:8][:ng] (G), lags 1-based, row by row and within a row by (lag, column): split by lag,
    each lag is block CSR with sorted columns. ``nev`` counts (point, lag) kernel evaluations,
    ``hits`` the pairs taken from the cache. With ``use_cache`` the element integrals of a pair are
    reused for every later pair with the same relative geometry (quantised to 1/qinv): translated
    copies of an element on a structured mesh are integrated once. The key includes the node order,
    so images and singular pairs are keyed correctly; the integrals depend on nothing else
    (material, dt and lags are fixed). Only lags lag_lo..L are computed, at kernel times l dt + toff
    (a cache must not be shared between calls with different lag_lo, L or toff). The cache stops
    growing at ``cache_max`` bytes per pool (reuse goes on). Each block sums its pairs in element
    order, then the free term.
    """
    xnodes, VX, Vnode, Vsign, Vtcol, Vc, VR, Vh = mesh
    L, dt, alpha, beta, rho, nu, lag_lo, toff = wave
    ns_base, near_factor, ns_max, gq, gw, gr, gwr, tol, h_ref = quad
    hrow, hlag, hcol, hval, grw, glag, gcol, gval, tmp, slotH, slotG = work
    mu = rho * beta * beta
    nv = VX.shape[0]
    nh = 0
    ng_ = 0
    Ub = np.zeros((L, 9, 3, 3))
    Pb = np.zeros((L, 9, 3, 3))
    Us = np.zeros((9, 3, 3)); Ps = np.zeros((9, 3, 3))
    nev = 0
    hits = 0
    ncache = len(cidx)
    pool_n = _pool_end(cmeta, ncache)
    key = np.zeros(27, np.int64)
    fcol = np.full(9, -1, np.int64)         # the free term: one block at (lag 1, column i)
    ones = np.ones(3)
    reach = alpha * (dt * L + toff)
    for ii in range(rows.shape[0]):
        i = rows[ii]
        xc = xnodes[i]
        h0 = nh
        g0 = ng_
        for v in range(nv):
            lo, hi, sing, ns = _pair_window(xc, VX[v], Vc[v], VR[v], Vh[v], reach, alpha, beta, dt, L, lag_lo,
                                            toff, tol, ns_base, ns_max, near_factor)
            if lo > hi:
                continue
            want_u = False
            for a in range(9):
                if Vtcol[v, a] >= 0:
                    want_u = True
            nl = hi - lo + 1
            found, fill_u, hsh = _cached(use_cache, cidx, ckeys, cmeta, VX[v], xc, qinv, key, lo, hi, want_u)
            if found >= 0:
                off = cmeta[found, 2]
                Psrc = cpoolP[off:off + nl * 81].reshape((nl, 9, 3, 3))
                Usrc = cpoolU[off:off + nl * 81].reshape((nl, 9, 3, 3)) if want_u else Ub[:nl]
                hits += 1
            else:
                nev += _integrate(xc, VX[v], sing, ns, gq, gw, gr, gwr, lo, hi, dt, alpha, beta, rho, nu, mu,
                                  want_u, toff, h_ref, Ub, Pb, Us, Ps)
                if fill_u >= 0:                 # complete the entry with its U blocks
                    off = cmeta[fill_u, 2]
                    cpoolU[off:off + nl * 81] = Ub[:nl].ravel()
                    cmeta[fill_u, 3] = 1
                elif use_cache and hsh not in cidx and 8 * (pool_n + nl * 81) <= cache_max:
                    c = ncache
                    ckeys = _grow(ckeys, c)
                    cmeta = _grow(cmeta, c)
                    while pool_n + nl * 81 > cpoolP.shape[0]:
                        cpoolP = _grow(cpoolP, cpoolP.shape[0])
                        cpoolU = _grow(cpoolU, cpoolU.shape[0])
                    ckeys[c] = key
                    cmeta[c, 0] = lo; cmeta[c, 1] = hi; cmeta[c, 2] = pool_n
                    cmeta[c, 3] = 1 if want_u else 0
                    cpoolP[pool_n:pool_n + nl * 81] = Pb[:nl].ravel()
                    if want_u:
                        cpoolU[pool_n:pool_n + nl * 81] = Ub[:nl].ravel()
                    pool_n += nl * 81
                    cidx[hsh] = c
                    ncache += 1
                Psrc = Pb[:nl]
                Usrc = Ub[:nl]
            # room for every block this pair can add, made once per pair
            # (array views or calls per block cost ~200 ns each in numba)
            need = nh + nl * 9
            hrow = _grow(hrow, need); hlag = _grow(hlag, need); hcol = _grow(hcol, need)
            hval = _grow(hval, need)
            nh = _add_pair(Psrc, nl, lo, Vnode[v], Vsign[v], i, slotH, hrow, hlag, hcol, hval, nh, True)
            if want_u:
                needg = ng_ + nl * 9
                grw = _grow(grw, needg); glag = _grow(glag, needg); gcol = _grow(gcol, needg)
                gval = _grow(gval, needg)
                ng_ = _add_pair(Usrc, nl, lo, Vtcol[v], Vsign[v], i, slotG, grw, glag, gcol, gval, ng_, False)
        # free term c_lk (I/2 at smooth points; freeterm module at edges/corners)
        if lag_lo == 1:
            hrow = _grow(hrow, nh); hlag = _grow(hlag, nh); hcol = _grow(hcol, nh)
            hval = _grow(hval, nh)
            fcol[0] = i
            nh = _add_pair(free_term[i:i + 1].reshape((1, 1, 3, 3)), 1, 1, fcol, ones, i, slotH, hrow, hlag,
                           hcol, hval, nh, False)
        tmp = _grow(tmp, max(nh - h0, ng_ - g0))
        _sort_row(slotH, lag_lo, L, h0, nh, hlag, hcol, hval, tmp)
        _sort_row(slotG, lag_lo, L, g0, ng_, glag, gcol, gval, tmp)
    return ((hrow, hlag, hcol, hval, grw, glag, gcol, gval, tmp, slotH, slotG), nh, ng_, nev, hits,
            ckeys, cmeta, cpoolP, cpoolU)


@njit(cache=True)
def lag_sort(row, lag, col, val, L, loc, counts, scol, sval):
    """Stable counting sort of a chunk's triplets by lag into ``scol``, ``sval`` (reused buffers at
    least as long); ``counts[lag, loc[row]]`` += blocks of that row and lag (loc: position of a row
    among the rank's rows). Returns the bounds:
    lag l (1..L) is scol[b[l]:b[l + 1]], rows ascending (and columns within a row, as emitted)."""
    b = np.zeros(L + 2, np.int64)
    for k in range(lag.shape[0]):
        b[lag[k] + 1] += 1
        counts[lag[k], loc[row[k]]] += 1
    for l in range(1, L + 2):
        b[l] += b[l - 1]
    pos = b.copy()
    for k in range(lag.shape[0]):
        j = pos[lag[k]]
        scol[j] = col[k]
        sval[j] = val[k]
        pos[lag[k]] = j + 1
    return b


# ---------------------------------------------------------------------------
# Element cache shared between ranks (model.LagSet.assemble): each rank lists
# the distinct pair geometries its rows meet (enumerate_pairs), an owner rank
# per geometry (its hash modulo the ranks) integrates it once (integrate_records)
# and sends it back, and each rank fills its cache with what it asked for
# (cache_insert) before assemble_rows runs, which then finds every pair there.

@njit(cache=True)
def enumerate_pairs(rows, xnodes, VX, Vtcol, Vc, VR, Vh, L, dt, alpha, beta, ns_base, near_factor, ns_max,
                    tol, qinv, lag_lo=1, toff=0.0, cache_max=1 << 62):
    """The distinct pair geometries that ``assemble_rows`` with a cache would store for ``rows``, in the
    order it meets them, up to the same cache cap: (keys (m, 27), hashes (m,), meta (m, 6) = [lo, hi,
    sing, ns, want_u, element], points (m, 3)). A hash met again with a different key or lag window is
    left out (assemble_rows integrates such pairs itself, as it does now)."""
    nv = VX.shape[0]
    cidx = Dict.empty(key_type=types.int64, value_type=types.int64)
    keys = np.zeros((64, 27), np.int64)
    hs = np.zeros(64, np.int64)
    meta = np.zeros((64, 6), np.int64)
    pts = np.zeros((64, 3))
    m = 0
    pool_n = 0
    key = np.zeros(27, np.int64)
    reach = alpha * (dt * L + toff)
    for ii in range(rows.shape[0]):
        xc = xnodes[rows[ii]]
        for v in range(nv):
            lo, hi, sing, ns = _pair_window(xc, VX[v], Vc[v], VR[v], Vh[v], reach, alpha, beta, dt, L, lag_lo,
                                            toff, tol, ns_base, ns_max, near_factor)
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
            if 8 * (pool_n + nl * 81) > cache_max:
                continue
            keys = _grow(keys, m); hs = _grow(hs, m); meta = _grow(meta, m); pts = _grow(pts, m)
            keys[m] = key
            hs[m] = hsh
            meta[m, 0] = lo; meta[m, 1] = hi; meta[m, 2] = sing; meta[m, 3] = ns; meta[m, 4] = want_u
            meta[m, 5] = v
            pts[m] = xc
            cidx[hsh] = m
            pool_n += nl * 81
            m += 1
    return keys[:m], hs[:m], meta[:m], pts[:m]


@njit(cache=True)
def integrate_records(meta, pts, VX, L, dt, alpha, beta, rho, nu, gq, gw, gr, gwr, toff=0.0, h_ref=1.0):
    """Integrals of the listed pairs (meta, points as from enumerate_pairs): (offsets (m + 1,) into the
    P pool, P pool, offsets (m + 1,) into the U pool (only records with want_u take room), U pool,
    kernel evaluations)."""
    m = meta.shape[0]
    off = np.zeros(m + 1, np.int64)
    uoff = np.zeros(m + 1, np.int64)
    for r in range(m):
        n = (meta[r, 1] - meta[r, 0] + 1) * 81
        off[r + 1] = off[r] + n
        uoff[r + 1] = uoff[r] + (n if meta[r, 4] == 1 else 0)
    P = np.zeros(off[m])
    U = np.zeros(uoff[m])
    mu = rho * beta * beta
    Ub = np.zeros((L, 9, 3, 3))
    Pb = np.zeros((L, 9, 3, 3))
    Us = np.zeros((9, 3, 3)); Ps = np.zeros((9, 3, 3))
    nev = 0
    for r in range(m):
        lo, hi = meta[r, 0], meta[r, 1]
        nl = hi - lo + 1
        nev += _integrate(pts[r], VX[meta[r, 5]], meta[r, 2], meta[r, 3], gq, gw, gr, gwr, lo, hi, dt, alpha,
                          beta, rho, nu, mu, meta[r, 4] == 1, toff, h_ref, Ub, Pb, Us, Ps)
        P[off[r]:off[r + 1]] = Pb[:nl].ravel()
        if meta[r, 4] == 1:
            U[uoff[r]:uoff[r + 1]] = Ub[:nl].ravel()
    return off, P, uoff, U, nev


@njit(cache=True)
def cache_insert(cidx, ckeys, cmeta, cpoolP, cpoolU, keys, hs, meta, buf, poffs, uoffs):
    """Add records (keys, hashes, meta as from enumerate_pairs) to an element cache, their P blocks at
    buf[poffs[r]:] and U blocks at buf[uoffs[r]:] (uoffs[r] < 0: no U); returns the cache arrays."""
    ncache = len(cidx)
    pool_n = 0
    for k in range(ncache):
        e = cmeta[k, 2] + (cmeta[k, 1] - cmeta[k, 0] + 1) * 81
        if e > pool_n:
            pool_n = e
    total = pool_n
    for r in range(keys.shape[0]):
        total += (meta[r, 1] - meta[r, 0] + 1) * 81
    if total > cpoolP.shape[0]:                  # sized once (not by doubling): the pools hold what was asked
        P2 = np.zeros(total)
        P2[:cpoolP.shape[0]] = cpoolP
        U2 = np.zeros(total)
        U2[:cpoolU.shape[0]] = cpoolU
        cpoolP, cpoolU = P2, U2
    ckeys = _grow(ckeys, ncache + keys.shape[0])
    cmeta = _grow(cmeta, ncache + keys.shape[0])
    for r in range(keys.shape[0]):
        if hs[r] in cidx:
            continue
        n = (meta[r, 1] - meta[r, 0] + 1) * 81
        c = ncache
        ckeys[c] = keys[r]
        cmeta[c, 0] = meta[r, 0]; cmeta[c, 1] = meta[r, 1]; cmeta[c, 2] = pool_n
        cmeta[c, 3] = 1 if uoffs[r] >= 0 else 0
        cpoolP[pool_n:pool_n + n] = buf[poffs[r]:poffs[r] + n]
        if uoffs[r] >= 0:
            cpoolU[pool_n:pool_n + n] = buf[uoffs[r]:uoffs[r] + n]
        pool_n += n
        cidx[hs[r]] = c
        ncache += 1
    return ckeys, cmeta, cpoolP, cpoolU
