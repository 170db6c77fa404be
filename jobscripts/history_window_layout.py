"""A/B of the toeplitz history products' window copies (issue 41): the kept states' transforms
time-major (W, slab, c), each step's window gathered by ``sliding_window_view`` (the code before
the change), against frequency-major (slab, W, c), each window one contiguous run of states
(``bem.toeplitz.history_products`` now). The sizes of one rank's block on the paper's quarter
case at 2 ranks (slab 756 frequencies, D = 160 lags, blocks of 8 steps, H's output widths 8 and
4); both give the same numbers (checked, the largest difference printed). Then the same A/B for
the interpolated lags' weighted states (``interp_products``) at the sizes of one rank of the paper's
building on the uniform 72 m grid (3780 frequencies, 20 Chebyshev anchors weighing 207 states, blocks
of 8): one real product over a chunk's frequencies (time-major) against one per frequency
(frequency-major). One BLAS thread.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python jobscripts/history_window_layout.py [REPEATS]
"""
import os
import sys
import time

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from petsc_ssi.bem.toeplitz import WINDOW_BYTES, _spans, history_products, interp_products  # noqa: E402

SLAB, D, B, W, N9, N18 = 756, 160, 8, 192, 8, 4


def time_major(K9, K18, V9, V18, p0, b, D, fchunk):
    """The history products as they were: time-major buffers, windows gathered."""
    slab = K9.shape[0]
    out = np.empty((slab, b, N9 + N18), np.complex128)
    for f0 in range(0, slab, fchunk):
        f1 = min(slab, f0 + fchunk)
        w9 = sliding_window_view(V9[p0:p0 + b - 1 + D, f0:f1], D, axis=0)
        w18 = sliding_window_view(V18[p0:p0 + b - 1 + D, f0:f1], D, axis=0)
        a9 = np.ascontiguousarray(w9.transpose(1, 0, 3, 2), dtype=np.complex128).reshape(f1 - f0, b, 9 * D)
        a18 = np.ascontiguousarray(w18.transpose(1, 0, 3, 2), dtype=np.complex128).reshape(f1 - f0, b, 18 * D)
        np.matmul(a9, K9[f0:f1], out=out[f0:f1, :, :N9])
        np.matmul(a18, K18[f0:f1], out=out[f0:f1, :, N9:])
    return out


def interp_time_major(A9, A18, V9, V18, C, r0, fchunk=64):
    """The weighted states' products as they were: time-major buffers, one real product a span and chunk."""
    slab, n9, n18 = A9.shape[0], A9.shape[2], A18.shape[2]
    b, k, _ = C.shape
    out = np.zeros((slab, b, n9 + n18), np.complex128)
    for f0 in range(0, slab, fchunk):
        f1 = min(slab, f0 + fchunk)
        fc = f1 - f0
        S9 = np.zeros((fc, b, k, 9), np.complex128)
        S18 = np.zeros((fc, b, k, 18), np.complex128)
        for j0, j1, a, e in _spans(C):
            Cj = C[:, j0:j1, a:e].reshape(-1, e - a)
            for V, S in ((V9, S9), (V18, S18)):
                c = V.shape[2]
                Vf = V[r0 + a:r0 + e, f0:f1].view(V.real.dtype).reshape(e - a, fc * 2 * c)
                w = (Cj @ Vf).view(np.complex128).reshape(b, j1 - j0, fc, c)
                S[:, :, j0:j1, :] = w.transpose(2, 0, 1, 3)
        np.matmul(S9.reshape(fc, b, 9 * k), A9[f0:f1], out=out[f0:f1, :, :n9])
        np.matmul(S18.reshape(fc, b, 18 * k), A18[f0:f1], out=out[f0:f1, :, n9:])
    return out


def states(rng, slab, W):
    """Random kept transforms (slab, W, 9) and (slab, W, 18), frequency-major, and their time-major copies."""
    V9 = rng.standard_normal((slab, W, 9)) + 1j * rng.standard_normal((slab, W, 9))
    V18 = rng.standard_normal((slab, W, 18)) + 1j * rng.standard_normal((slab, W, 18))
    return V9, V18, np.ascontiguousarray(V9.transpose(1, 0, 2)), np.ascontiguousarray(V18.transpose(1, 0, 2))


def ab(what, old, new, repeats):
    """Three rounds of ``old()`` (time-major) against ``new()`` (frequency-major): a markdown table of
    their mean seconds and the largest difference of their results."""
    print(f"| round | {what}, time-major [ms] | {what}, frequency-major [ms] | largest difference [-] |")
    print("|---|---|---|---|")
    for r in range(3):
        t = time.perf_counter()
        for _ in range(repeats):
            a = old()
        t_old = (time.perf_counter() - t) / repeats
        t = time.perf_counter()
        for _ in range(repeats):
            n = new()
        t_new = (time.perf_counter() - t) / repeats
        print(f"| {r + 1} | {1e3 * t_old:.0f} | {1e3 * t_new:.0f} | {np.abs(a - n).max() / np.abs(a).max():.1e} |")


def main(repeats=5):
    rng = np.random.default_rng(0)
    K9 = rng.standard_normal((SLAB, 9 * D, N9)) + 0j
    K18 = rng.standard_normal((SLAB, 18 * D, N18)) + 0j
    V9, V18, T9, T18 = states(rng, SLAB, W)
    fchunk = max(1, int(WINDOW_BYTES // (B * 27 * D * 16)))
    ab("windows", lambda: time_major(K9, K18, T9, T18, 10, B, D, fchunk),
       lambda: history_products(K9, K18, V9, V18, 10, B, D), repeats)
    # the interpolated lags' weighted states at the building's sizes (module docstring)
    slab, k, R = 3780, 20, 207
    rng = np.random.default_rng(1)
    A9 = rng.standard_normal((slab, 9 * k, N9)) + 0j
    A18 = rng.standard_normal((slab, 18 * k, N18)) + 0j
    V9, V18, T9, T18 = states(rng, slab, R + 32)
    C = rng.standard_normal((B, k, R))
    print()
    ab("weighted states", lambda: interp_time_major(A9, A18, T9, T18, C, 5),
       lambda: interp_products(A9, A18, V9, V18, C, 5), max(1, repeats // 2))


if __name__ == "__main__":
    main(*(int(a) for a in sys.argv[1:2]))
