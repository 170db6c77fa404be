#!/usr/bin/env python3
"""The toeplitz build's kernel fill (``lanes.put_spectra``: the lags' spectra written into the kernels' lanes, the
build's 'weights' part) against the pass it replaced (group by group, each source row read a cache line at a time
and the row block read before it is written; kept here as ``by_groups``), on one rank's H kernels of a grid:
the same bits, and the seconds with the kernels' memory already written once (the fill's own work) and fresh
(np.zeros: the first write of every page is in it, which on this VM is most of it).

    python jobscripts/put_spectra_rate.py [SLAB] [LAGS]      (defaults 3800 207: the building on the 72 m grid,
                                                              one of 2 ranks; 8700 301: the 108 m grid)
"""
import os
import sys
import time

import numpy as np
from numba import njit

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from petsc_ssi.bem.lanes import put_spectra, FW  # noqa: E402


@njit(cache=False, boundscheck=False)
def by_groups(K, r0, src, sel, idx, c):
    """The fill before 2026-12-03 (``add_spectra``): K[g, r0 + r, j, p, q] += sum_t c[t] src[sel[t], idx[r, j], f],
    group by group."""
    nt, slab = sel.shape[0], src.shape[2]
    kp, fw = K.shape[3], K.shape[4]
    a = np.empty(fw)
    for g in range(K.shape[0]):
        f0 = g * fw
        q1 = min(fw, slab - f0)
        for r in range(idx.shape[0]):
            for j in range(idx.shape[1]):
                s = idx[r, j]
                for p in range(kp):
                    for q in range(q1):
                        a[q] = K[g, r0 + r, j, p, q]
                    for t in range(nt):
                        ct, st = c[t], sel[t]
                        if p == 0:
                            for q in range(q1):
                                a[q] += ct * src[st, s, f0 + q].real
                        else:
                            for q in range(q1):
                                a[q] += ct * src[st, s, f0 + q].imag
                    for q in range(q1):
                        K[g, r0 + r, j, p, q] = a[q]


def main(slab=3800, lags=207):
    G = (slab + FW - 1) // FW
    rng = np.random.default_rng(0)
    src = rng.standard_normal((4, 144, slab))         # (a ring of 4 lags' real spectra: H's 4 x 9 x 4 rows)
    idx9 = np.arange(72).reshape(9, 8)                # (the 9-row and 18-row kernels' blocks)
    idx18 = np.arange(72, 144).reshape(18, 4)
    sel, c = np.array([0, 1, 2]), np.array([0.5, -1.0, 0.5])     # (three lags a distance: the stabilised scheme)
    for f in (by_groups, put_spectra):                # (compiled first)
        f(np.zeros((1, 18, 8, 1, FW)), 0, src[:, :, :FW].copy(), sel, idx9, c)

    def fill(f, K9, K18):
        t0 = time.perf_counter()
        for d in range(lags):
            f(K9, 9 * d, src, sel, idx9, c)
            f(K18, 18 * d, src, sel, idx18, c)
        return time.perf_counter() - t0

    shape9, shape18 = (G, lags * 9, 8, 1, FW), (G, lags * 18, 4, 1, FW)
    gb = 8 * (np.prod(shape9) + np.prod(shape18)) / 1e9
    print(f"[put_spectra_rate] slab {slab}, {lags} lags: {gb:.2f} GB of kernels")
    print("| fill | written before [s] | fresh memory [s] |")
    print("|---|---|---|")
    out = {}
    for name, f in (("by groups (before)", by_groups), ("put_spectra", put_spectra)):
        K9, K18 = np.ones(shape9), np.ones(shape18)          # (written once: resident)
        K9[...] = 0.0
        K18[...] = 0.0
        warm = fill(f, K9, K18)
        out[name] = (K9.copy(), K18.copy())
        del K9, K18
        K9, K18 = np.zeros(shape9), np.zeros(shape18)        # (fresh: every page's first write in the fill)
        fresh = fill(f, K9, K18)
        del K9, K18
        print(f"| {name} | {warm:.2f} | {fresh:.2f} |", flush=True)
    a, b = out.values()
    same = all(np.array_equal(x, y) for x, y in zip(a, b))
    print(f"[put_spectra_rate] the same bits: {same}")
    return 0 if same else 1


if __name__ == "__main__":
    args = [int(a) for a in sys.argv[1:3]]
    sys.exit(main(*args))
