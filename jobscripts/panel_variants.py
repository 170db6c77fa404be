#!/usr/bin/env python3
"""Variants of the flat H lags' panel kernel tried for issue 29's time-loop target (bem/bsr.py's
``_panel_h4`` one row at a time and ``_panel_h4_pair`` two rows at a time against): column tiles over
groups of rows (``tiled``, the panel's rows of a tile read once for G rows), four blocks per pass
over the states (``u4``, the accumulators read and written once for four blocks), a compile-time
panel width (``constB``), and multiply-adds contracted (``fma1``/``fma2``: fastmath 'contract',
bits change). On lags 20, 50 and 78 of the paper's Lamb case (the first 600 rows, one process, the
lags up to 0.06 s assembled), best of 5 calls each; ns per stored block and state, and the largest
difference from ``_panel_h4`` relative to its largest value when the bits differ.

    python jobscripts/panel_variants.py
"""
import sys
import time

import numpy as np
from numba import njit

sys.argv = [sys.argv[0], "-options_file", "runs/pekeris/paper.opts", "-ssi_t_end", "0.06"]
from petsc_ssi.petsc import init  # noqa: E402
PETSc = init(sys.argv)
from petsc_ssi import options  # noqa: E402
import petsc_ssi.app.kinds  # noqa: E402,F401  (every option declared)
from petsc_ssi.bem.halfspace import HalfSpace  # noqa: E402
from petsc_ssi.bem import bsr  # noqa: E402

@njit
def panel_h4_tiled(indptr, indices, d, XT, RT, sign, G, T):
    """_panel_h4 over groups of G rows and column tiles of T nodes: a tile's rows of XT are read
    from memory once for the group's G rows (neighbouring nodes hold nearly the same columns);
    each row's sums in its column order, as _panel_h4 (the same bits)."""
    b = XT.shape[1]
    n = indptr.size - 1
    acc = np.empty((G, 3, b))
    pos = np.empty(G, np.int64)
    for i0 in range(0, n, G):
        g = min(G, n - i0)
        cmin = 2147483647
        cmax = -1
        for r in range(g):
            pos[r] = indptr[i0 + r]
            if indptr[i0 + r + 1] > indptr[i0 + r]:
                cmin = min(cmin, indices[indptr[i0 + r]])
                cmax = max(cmax, indices[indptr[i0 + r + 1] - 1])
            for j in range(3):
                for t in range(b):
                    acc[r, j, t] = 0.0
        c0 = cmin
        while c0 <= cmax:
            c1 = c0 + T
            for r in range(g):
                k = pos[r]
                kend = indptr[i0 + r + 1]
                a0 = acc[r, 0]
                a1 = acc[r, 1]
                a2 = acc[r, 2]
                while k < kend and indices[k] < c1:
                    c = 3 * indices[k]
                    a02, a12, a20, a21 = d[k, 0], d[k, 1], d[k, 2], d[k, 3]
                    x0 = XT[c]
                    x1 = XT[c + 1]
                    x2 = XT[c + 2]
                    for t in range(b):
                        u2 = x2[t]
                        a0[t] += a02 * u2
                        a1[t] += a12 * u2
                        a2[t] += a20 * x0[t] + a21 * x1[t]
                    k += 1
                pos[r] = k
            c0 = c1
        for r in range(g):
            i = i0 + r
            for t in range(b):
                RT[3 * i, t] += sign * acc[r, 0, t]
                RT[3 * i + 1, t] += sign * acc[r, 1, t]
                RT[3 * i + 2, t] += sign * acc[r, 2, t]

@njit
def panel_h4_u4(indptr, indices, d, XT, RT, sign):
    """_panel_h4 with four blocks of a row per pass over the states: the accumulators are read and
    written once for four blocks; each sum in the same order (the same bits)."""
    b = XT.shape[1]
    acc0 = np.empty(b)
    acc1 = np.empty(b)
    acc2 = np.empty(b)
    for i in range(indptr.size - 1):
        acc0[:] = 0.0
        acc1[:] = 0.0
        acc2[:] = 0.0
        k = indptr[i]
        kend = indptr[i + 1]
        while k + 4 <= kend:
            c = 3 * indices[k]; e = 3 * indices[k + 1]; f = 3 * indices[k + 2]; g = 3 * indices[k + 3]
            p02, p12, p20, p21 = d[k, 0], d[k, 1], d[k, 2], d[k, 3]
            q02, q12, q20, q21 = d[k + 1, 0], d[k + 1, 1], d[k + 1, 2], d[k + 1, 3]
            r02, r12, r20, r21 = d[k + 2, 0], d[k + 2, 1], d[k + 2, 2], d[k + 2, 3]
            s02, s12, s20, s21 = d[k + 3, 0], d[k + 3, 1], d[k + 3, 2], d[k + 3, 3]
            x0 = XT[c]; x1 = XT[c + 1]; x2 = XT[c + 2]
            y0 = XT[e]; y1 = XT[e + 1]; y2 = XT[e + 2]
            z0 = XT[f]; z1 = XT[f + 1]; z2 = XT[f + 2]
            w0 = XT[g]; w1 = XT[g + 1]; w2 = XT[g + 2]
            for t in range(b):
                ux = x2[t]; uy = y2[t]; uz = z2[t]; uw = w2[t]
                acc0[t] = (((acc0[t] + p02 * ux) + q02 * uy) + r02 * uz) + s02 * uw
                acc1[t] = (((acc1[t] + p12 * ux) + q12 * uy) + r12 * uz) + s12 * uw
                acc2[t] = (((acc2[t] + (p20 * x0[t] + p21 * x1[t])) + (q20 * y0[t] + q21 * y1[t]))
                           + (r20 * z0[t] + r21 * z1[t])) + (s20 * w0[t] + s21 * w1[t])
            k += 4
        while k < kend:
            c = 3 * indices[k]
            a02, a12, a20, a21 = d[k, 0], d[k, 1], d[k, 2], d[k, 3]
            x0 = XT[c]; x1 = XT[c + 1]; x2 = XT[c + 2]
            for t in range(b):
                u2 = x2[t]
                acc0[t] += a02 * u2
                acc1[t] += a12 * u2
                acc2[t] += a20 * x0[t] + a21 * x1[t]
            k += 1
        for t in range(b):
            RT[3 * i, t] += sign * acc0[t]
            RT[3 * i + 1, t] += sign * acc1[t]
            RT[3 * i + 2, t] += sign * acc2[t]

def make_loc(B):
    @njit
    def panel_h4_loc(indptr, indices, d, XT, RT, sign):
        acc0 = np.empty(B); acc1 = np.empty(B); acc2 = np.empty(B)
        for i in range(indptr.size - 1):
            acc0[:] = 0.0; acc1[:] = 0.0; acc2[:] = 0.0
            for k in range(indptr[i], indptr[i + 1]):
                c = 3 * indices[k]
                a02, a12, a20, a21 = d[k, 0], d[k, 1], d[k, 2], d[k, 3]
                x0 = XT[c]; x1 = XT[c + 1]; x2 = XT[c + 2]
                for t in range(B):
                    u2 = x2[t]
                    acc0[t] += a02 * u2
                    acc1[t] += a12 * u2
                    acc2[t] += a20 * x0[t] + a21 * x1[t]
            for t in range(B):
                RT[3 * i, t] += sign * acc0[t]
                RT[3 * i + 1, t] += sign * acc1[t]
                RT[3 * i + 2, t] += sign * acc2[t]
    return panel_h4_loc
LOC = {16: make_loc(16), 32: make_loc(32)}


FMA1 = njit(fastmath={"contract"})(bsr._panel_h4.py_func)
FMA2 = njit(fastmath={"contract"})(bsr._panel_h4_pair.py_func)

cfg = options.resolve(("common", "bem"))
prob = HalfSpace(cfg, PETSc.COMM_SELF, log=lambda m: None)
ls = prob.lagset(prob.interp_plan())
ls.rows = ls.rows[:600]
ls.node_range = (0, 600)
ls.assemble()
N = prob.mesh.n_nodes
rng = np.random.default_rng(0)
for lag in (20, 50, 78):
    ip, c, v = ls.H.csr(lag)
    for b in (16, 32):
        XT = rng.standard_normal((3 * N, b))
        kern = [("one", bsr._panel_h4), ("two", bsr._panel_h4_pair), ("u4", panel_h4_u4), ("constB", LOC[b]),
                ("fma1", FMA1), ("fma2", FMA2)]
        for G, T in ((4, 64), (8, 64), (16, 128)):
            kern.append((f"tiled G{G} T{T}", (lambda G, T: lambda *a: panel_h4_tiled(*a, G, T))(G, T)))
        res, out = {}, []
        for name, f in kern:
            R = np.zeros((3 * 600, b))
            f(ip, c, v, XT, R, 1.0)
            res[name] = R
            ts = []
            for _ in range(5):
                R = np.zeros((3 * 600, b))
                t = time.perf_counter()
                f(ip, c, v, XT, R, 1.0)
                ts.append(time.perf_counter() - t)
            d = np.abs(R - res["one"]).max() / np.abs(res["one"]).max()
            out.append(f"{name} {min(ts) / b / len(c) * 1e9:.3f}" + ("" if d == 0 else f" (differs {d:.1e})"))
        print(f"lag {lag}, {len(c)} blocks, b = {b}: " + " | ".join(out), flush=True)
