#!/usr/bin/env python3
"""ns per kernel evaluation of a regular pair's integrals on the paper's building (one process): the
general kernel (bem/quadrature.py ``integrate_pair``, all 81 entries, the geometry per point) against
the plane's (``integrate_plane``, the element's geometry from ``plane_points`` computed once, the flat
patterns' entries 4-wide: bem/simd.py), on the pairs of every 40th soil node with every element
whose wave window reaches it, the exact lags 1..54; the entries both keep compared bit for bit. Then
the plane's on the same pairs with and without the displacement kernel G (want_u) and G alone
(want_p False: the area loads' and the toeplitz store's G side), the G of both compared bit for bit.
Best of 3 passes each.

    python jobscripts/plane_kernel_rate.py
"""
import sys
import time

import numpy as np

sys.argv = [sys.argv[0], "-options_file", "runs/building/ssi-full-bonded.opts"]
from petsc_ssi.petsc import init  # noqa: E402
PETSc = init(sys.argv)
from petsc_ssi.app.kinds import resolve  # noqa: E402
from petsc_ssi.coupling import model as cm  # noqa: E402
from petsc_ssi.bem.assemble import _pair_window, SING_TOL  # noqa: E402
from petsc_ssi.bem.bsr import positions  # noqa: E402
from petsc_ssi.bem.quadrature import integrate_pair, integrate_plane, plane_points  # noqa: E402
from petsc_ssi.bem.packs import wave  # noqa: E402

cm.printf = lambda *a, **k: None
prob = cm.build_coupled(resolve("ssi"), PETSc.COMM_SELF)[0]
plan = prob.interp_plan()
ls = prob.lagset(plan)
o, L, dt, al, be, rho, nu = ls.opts, plan.Lx, ls.dt, ls.mat.cp, ls.mat.cs, ls.mat.rho, ls.mat.nu
gq, gw = np.polynomial.legendre.leggauss(o["gauss"])
pairs, geo = [], {}
for i in range(0, ls.mesh.n_nodes, 40):
    xc = ls.mesh.nodes[i]
    for v in range(len(ls.VX)):
        lo, hi, sing, ns = _pair_window(xc, ls.VX[v], ls.Vc[v], ls.VR[v], ls.Vh[v], al * dt * L, al, be, dt, L, 1, 0.0,
                                        SING_TOL, o["subdivisions"], o["max_subdivisions"], o["near_factor"])
        if lo <= hi and sing < 0:
            pairs.append((xc, v, lo, hi, ns, bool((ls.VT[v] >= 0).any())))
            if (v, ns) not in geo:
                g = (np.zeros((ns * ns, 4)), np.zeros((ns * ns * len(gq) ** 2, 4)), np.zeros((ns * ns * len(gq) ** 2, 9)))
                plane_points(ls.VX[v], ns, gq, gw, *g)
                geo[(v, ns)] = g
Ub, Pb = np.zeros((L, 9, 3, 3)), np.zeros((L, 9, 3, 3))
P, U = np.zeros((L, 9, 4)), np.zeros((L, 9, 5))
hp, hq = positions(4)
gp, gqi = positions(5)


def general(xc, v, lo, hi, ns, wu):
    Ub[:] = 0.0; Pb[:] = 0.0
    return integrate_pair(xc, ls.VX[v], -1, ns, lo, hi, wave(dt, al, be, rho, nu), gq, gw, Ub, Pb, wu)


def plane(xc, v, lo, hi, ns, wu, wp=True):
    P[:] = 0.0; U[:] = 0.0
    return integrate_plane(xc, *geo[(v, ns)], len(gq) ** 2, lo, hi, wave(dt, al, be, rho, nu), P, U, wu, wp)


for p in pairs[::50]:                                    # the same numbers (and both compiled)
    general(*p); plane(*p)
    nl = p[3] - p[2] + 1
    assert np.array_equal(P[:nl], Pb[:nl][:, :, hp, hq]) and (not p[5] or np.array_equal(U[:nl], Ub[:nl][:, :, gp, gqi]))
print(f"{len(pairs)} pairs ({sum(p[5] for p in pairs)} with G), the same bits on every 50th")
for name, f in (("integrate_pair", general), ("integrate_plane", plane)):
    best = np.inf
    for _ in range(3):
        t = time.perf_counter()
        n = sum(f(*p) for p in pairs)
        best = min(best, time.perf_counter() - t)
    print(f"{name}: {best:.3f} s, {n:.3g} kernel evaluations, {1e9 * best / n:.1f} ns per evaluation")
U2 = U.copy()
for p in pairs[::50]:                                    # G alone: the same G
    nl = p[3] - p[2] + 1
    plane(p[0], p[1], p[2], p[3], p[4], True)
    U2[:nl] = U[:nl]
    plane(p[0], p[1], p[2], p[3], p[4], True, False)
    assert np.array_equal(U[:nl], U2[:nl])
print("every pair's G: the same bits alone as beside H on every 50th")
for name, wu, wp in (("integrate_plane H", False, True), ("integrate_plane H and G", True, True),
                     ("integrate_plane G alone", True, False)):
    best = np.inf
    for _ in range(3):
        t = time.perf_counter()
        n = sum(plane(p[0], p[1], p[2], p[3], p[4], wu, wp) for p in pairs)
        best = min(best, time.perf_counter() - t)
    print(f"{name}: {best:.3f} s, {n:.3g} kernel evaluations, {1e9 * best / n:.1f} ns per evaluation")
