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
def lag_order(lag, L):
    """Stable counting sort by lag (1..L): the permutation and the bucket
    bounds. Triplets come out row-major, so within a lag rows stay sorted."""
    cnt = np.zeros(L + 2, np.int64)
    for x in lag:
        cnt[x + 1] += 1
    for l in range(1, L + 2):
        cnt[l] += cnt[l - 1]
    bounds = cnt.copy()
    order = np.empty(lag.shape[0], np.int64)
    pos = cnt[:-1].copy()
    for i in range(lag.shape[0]):
        order[pos[lag[i]]] = i
        pos[lag[i]] += 1
    return order, bounds[1:]


def new_cache():
    """An element-integral cache (kept across calls of ``assemble_rows``)."""
    return (Dict.empty(key_type=types.int64, value_type=types.int64),
            np.zeros((16, 27), np.int64), np.zeros((16, 4), np.int64),
            np.zeros(1024), np.zeros(1024))


@njit(cache=True)
def assemble_rows(rows, xnodes, VX, Vnode, Vsign, Vtcol, Vc, VR, Vh, L, dt, alpha, beta,
                  rho, nu, ns_base, near_factor, ns_max, gq, gw, gr, gwr, n_nodes, n_tcols,
                  free_term, tol, use_cache, cidx, ckeys, cmeta, cpoolP, cpoolU, qinv,
                  lag_lo=1, toff=0.0, h_ref=1.0, cache_max=1 << 62):
    """Collective-free numba kernel: triplets of H and G for ``rows``.

    Returns (hrow, hlag, hcol, hval, grow, glag, gcol, gval, nev, hits, cache
    arrays) with lags 1-based, ``nev`` the number of (point, lag) kernel
    evaluations and ``hits`` the pairs taken from the cache. With
    ``use_cache`` the element integrals of a pair are reused for every later
    pair with the same relative geometry (quantised to 1/qinv): translated
    copies of an element on a structured mesh are integrated once. The key
    includes the node order, so images and singular pairs are keyed correctly;
    the integrals depend on nothing else (material, dt and lags are fixed).
    Only lags lag_lo..L are computed, at kernel times l dt + toff (a cache
    must not be shared between calls with different lag_lo, L or toff).
    The cache stops growing at ``cache_max`` bytes per pool (reuse goes on).
    """
    mu = rho * beta * beta
    nv = VX.shape[0]
    slotH = np.full((L + 1, n_nodes), -1, np.int64)
    slotG = np.full((L + 1, max(n_tcols, 1)), -1, np.int64)
    hrow = np.zeros(1024, np.int64); hlag = np.zeros(1024, np.int64); hcol = np.zeros(1024, np.int64)
    hval = np.zeros((1024, 3, 3))
    grw = np.zeros(256, np.int64); glag = np.zeros(256, np.int64); gcol = np.zeros(256, np.int64)
    gval = np.zeros((256, 3, 3))
    nh = 0
    ng_ = 0
    Ub = np.zeros((L, 9, 3, 3))
    Pb = np.zeros((L, 9, 3, 3))
    Us = np.zeros((9, 3, 3)); Ps = np.zeros((9, 3, 3))
    nev = 0
    hits = 0
    ncache = len(cidx)
    pool_n = 0
    for k in range(ncache):
        e = cmeta[k, 2] + (cmeta[k, 1] - cmeta[k, 0] + 1) * 81
        if e > pool_n:
            pool_n = e
    key = np.zeros(27, np.int64)
    reach = alpha * (dt * L + toff)
    for ii in range(rows.shape[0]):
        i = rows[ii]
        xc = xnodes[i]
        h0 = nh
        g0 = ng_
        for v in range(nv):
            dcen = math.sqrt((Vc[v, 0] - xc[0]) ** 2 + (Vc[v, 1] - xc[1]) ** 2 + (Vc[v, 2] - xc[2]) ** 2)
            dmin = max(dcen - VR[v], 0.0)
            if dmin >= reach:
                continue
            dmax = dcen + VR[v]
            lo = max(lag_lo, int(math.floor((dmin / alpha - toff) / dt)) + 1)
            hi = min(L, int(math.floor((dmax / beta - toff) / dt)) + 2)
            sing = -1
            for a in range(9):
                d = math.sqrt((VX[v, a, 0] - xc[0]) ** 2 + (VX[v, a, 1] - xc[1]) ** 2 + (VX[v, a, 2] - xc[2]) ** 2)
                if d < tol * Vh[v]:
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
                    dd = max(dmin, 1e-3 * Vh[v])
                    ns = min(ns_max, max(ns_base, int(math.ceil(near_factor * Vh[v] / dd))))
            if lo > hi:
                continue
            want_u = False
            for a in range(9):
                if Vtcol[v, a] >= 0:
                    want_u = True
            nl = hi - lo + 1
            found = -1
            if use_cache:
                hsh = _geom_key(VX[v], xc, qinv, key)
                if hsh in cidx:
                    c = cidx[hsh]
                    same = cmeta[c, 0] == lo and cmeta[c, 1] == hi and (cmeta[c, 3] == 1 or not want_u)
                    for k in range(27):
                        if ckeys[c, k] != key[k]:
                            same = False
                    if same:
                        found = c
            if found >= 0:
                off = cmeta[found, 2]
                Psrc = cpoolP[off:off + nl * 81].reshape((nl, 9, 3, 3))
                Usrc = cpoolU[off:off + nl * 81].reshape((nl, 9, 3, 3)) if want_u else Ub[:nl]
                hits += 1
            else:
                Ub[:nl] = 0.0
                Pb[:nl] = 0.0
                nev += integrate_pair(xc, VX[v], sing, ns, gq, gw, lo, hi, dt, alpha, beta, rho, nu,
                                      Ub, Pb, want_u, toff)
                if sing >= 0:
                    Us[:] = 0.0
                    Ps[:] = 0.0
                    singular_static(VX[v], sing, gr.shape[0], gr.shape[0], gr, gwr, gr, gwr, nu, mu, Us, Ps,
                                    h_ref)
                    Ub[0] += Us
                    Pb[0] += Ps
                if use_cache and hsh not in cidx and 8 * (pool_n + nl * 81) <= cache_max:
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
            # capacity for every block this pair can add, checked once per pair
            # (array views or calls per block cost ~200 ns each in numba)
            need = nh + nl * 9
            hrow = _grow(hrow, need); hlag = _grow(hlag, need); hcol = _grow(hcol, need)
            hval = _grow(hval, need)
            needg = ng_ + nl * 9
            grw = _grow(grw, needg); glag = _grow(glag, needg); gcol = _grow(gcol, needg)
            gval = _grow(gval, needg)
            for li in range(nl):
                lag = lo + li
                for a in range(9):
                    nz = False
                    for p in range(3):
                        for q in range(3):
                            if Psrc[li, a, p, q] != 0.0:
                                nz = True
                    if nz:
                        col = Vnode[v, a]
                        s = slotH[lag, col]
                        if s < 0:
                            s = nh
                            slotH[lag, col] = s
                            hrow[s] = i; hlag[s] = lag; hcol[s] = col
                            for p in range(3):
                                for q in range(3):
                                    hval[s, p, q] = 0.0
                            nh += 1
                        for p in range(3):
                            for q in range(3):
                                hval[s, p, q] += Psrc[li, a, p, q] * Vsign[v, q]
                    tc = Vtcol[v, a]
                    if tc >= 0:
                        s = slotG[lag, tc]
                        if s < 0:
                            s = ng_
                            slotG[lag, tc] = s
                            grw[s] = i; glag[s] = lag; gcol[s] = tc
                            for p in range(3):
                                for q in range(3):
                                    gval[s, p, q] = 0.0
                            ng_ += 1
                        for p in range(3):
                            for q in range(3):
                                gval[s, p, q] += Usrc[li, a, p, q] * Vsign[v, q]
        # free term c_lk (I/2 at smooth points; freeterm module at edges/corners)
        if lag_lo == 1:
            s = slotH[1, i]
            if s < 0:
                hrow = _grow(hrow, nh); hlag = _grow(hlag, nh); hcol = _grow(hcol, nh)
                hval = _grow(hval, nh)
                s = nh
                hrow[s] = i; hlag[s] = 1; hcol[s] = i
                for p in range(3):
                    for q in range(3):
                        hval[s, p, q] = 0.0
                nh += 1
            for p in range(3):
                for q in range(3):
                    hval[s, p, q] += free_term[i, p, q]
        for k in range(h0, nh):
            slotH[hlag[k], hcol[k]] = -1
        for k in range(g0, ng_):
            slotG[glag[k], gcol[k]] = -1
    return (hrow[:nh], hlag[:nh], hcol[:nh], hval[:nh], grw[:ng_], glag[:ng_], gcol[:ng_],
            gval[:ng_], nev, hits, ckeys, cmeta, cpoolP, cpoolU)
