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
from numba import njit

from .quadrature import integrate_pair, singular_static


@njit(cache=True)
def _grow(a, n):
    if n < a.shape[0]:
        return a
    shape = (max(2 * a.shape[0], 16),) + a.shape[1:]
    b = np.zeros(shape, a.dtype)
    b[:a.shape[0]] = a
    return b


@njit(cache=True)
def assemble_rows(rows, xnodes, VX, Vnode, Vsign, Vtcol, Vc, VR, Vh, L, dt, alpha, beta,
                  rho, nu, ns_base, near_factor, ns_max, gq, gw, gr, gwr, n_nodes, n_tcols,
                  free_term, tol):
    """Collective-free numba kernel: triplets of H and G for ``rows``.

    Returns (hrow, hlag, hcol, hval, grow, glag, gcol, gval, nev) with lags
    1-based and ``nev`` the number of kernel evaluations.
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
    reach = alpha * dt * L
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
            lo = max(1, int(math.floor(dmin / (alpha * dt))) + 1)
            hi = min(L, int(math.floor(dmax / (beta * dt))) + 2)
            sing = -1
            for a in range(9):
                d = math.sqrt((VX[v, a, 0] - xc[0]) ** 2 + (VX[v, a, 1] - xc[1]) ** 2 + (VX[v, a, 2] - xc[2]) ** 2)
                if d < tol * Vh[v]:
                    sing = a
            if sing >= 0:
                lo = 1
                ns = min(ns_max, 2 * ns_base)
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
            Ub[:nl] = 0.0
            Pb[:nl] = 0.0
            nev += integrate_pair(xc, VX[v], sing, ns, gq, gw, lo, hi, dt, alpha, beta, rho, nu,
                                  Ub, Pb, want_u)
            if sing >= 0:
                Us[:] = 0.0
                Ps[:] = 0.0
                singular_static(VX[v], sing, gr.shape[0], gr.shape[0], gr, gwr, gr, gwr, nu, mu, Us, Ps)
                Ub[0] += Us
                Pb[0] += Ps
            for li in range(nl):
                lag = lo + li
                for a in range(9):
                    nz = False
                    for p in range(3):
                        for q in range(3):
                            if Pb[li, a, p, q] != 0.0:
                                nz = True
                    if nz:
                        col = Vnode[v, a]
                        s = slotH[lag, col]
                        if s < 0:
                            hrow = _grow(hrow, nh); hlag = _grow(hlag, nh); hcol = _grow(hcol, nh)
                            hval = _grow(hval, nh)
                            s = nh
                            slotH[lag, col] = s
                            hrow[s] = i; hlag[s] = lag; hcol[s] = col
                            hval[s] = 0.0
                            nh += 1
                        for p in range(3):
                            for q in range(3):
                                hval[s, p, q] += Pb[li, a, p, q] * Vsign[v, q]
                    tc = Vtcol[v, a]
                    if tc >= 0:
                        s = slotG[lag, tc]
                        if s < 0:
                            grw = _grow(grw, ng_); glag = _grow(glag, ng_); gcol = _grow(gcol, ng_)
                            gval = _grow(gval, ng_)
                            s = ng_
                            slotG[lag, tc] = s
                            grw[s] = i; glag[s] = lag; gcol[s] = tc
                            gval[s] = 0.0
                            ng_ += 1
                        for p in range(3):
                            for q in range(3):
                                gval[s, p, q] += Ub[li, a, p, q] * Vsign[v, q]
        # free term c_lk = delta_lk / 2 (smooth surface point)
        s = slotH[1, i]
        if s < 0:
            hrow = _grow(hrow, nh); hlag = _grow(hlag, nh); hcol = _grow(hcol, nh)
            hval = _grow(hval, nh)
            s = nh
            hrow[s] = i; hlag[s] = 1; hcol[s] = i
            hval[s] = 0.0
            nh += 1
        for p in range(3):
            hval[s, p, p] += free_term
        for k in range(h0, nh):
            slotH[hlag[k], hcol[k]] = -1
        for k in range(g0, ng_):
            slotG[glag[k], gcol[k]] = -1
    return (hrow[:nh], hlag[:nh], hcol[:nh], hval[:nh], grw[:ng_], glag[:ng_], gcol[:ng_],
            gval[:ng_], nev)
