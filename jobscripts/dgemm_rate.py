"""This machine's BLAS rates on one core (one OpenBLAS thread), for the history sum's report
(issue 13): square dgemm, the skinny products of the time-blocked history sum (a rank's rows of a
dense lag, 2054 x 4107 as in the paper case on 2 ranks, times a panel of b states, both layouts),
the matrix-vector product of the per-step sum (memory bound: its GB/s) and the block-sparse panel
kernel of bem/bsr.py on a fully dense 3x3-block pattern of the same size, with double and with
single-precision (float32) blocks.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python jobscripts/dgemm_rate.py

prints 'name value unit' lines (jobscripts/history_bench.sh keeps them in out/bench/history)."""
import os
import sys
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
import numpy as np  # noqa: E402


def best(f, reps=5):
    f()
    ts = []
    for _ in range(reps):
        t = time.perf_counter()
        f()
        ts.append(time.perf_counter() - t)
    return min(ts)


def main():
    rng = np.random.default_rng(0)
    n = 2000
    A, B = rng.random((n, n)), rng.random((n, n))
    print(f"dgemm_square {2 * n ** 3 / best(lambda: A @ B) / 1e9:.1f} GF/s")
    m, k = 2054, 4107
    H = np.asfortranarray(rng.random((m, k)))          # a dense lag's local rows (PETSc: column major)
    x = rng.random(k)
    t = best(lambda: H @ x)
    print(f"matvec {2 * m * k / t / 1e9:.2f} GF/s")
    print(f"matvec_bandwidth {8 * m * k / t / 1e9:.1f} GB/s")
    for b in (8, 16, 32):
        X = rng.random((b, k))
        print(f"panel_xAt_b{b} {2 * m * k * b / best(lambda: X @ H.T) / 1e9:.1f} GF/s")
        print(f"panel_AxT_b{b} {2 * m * k * b / best(lambda: H @ X.T) / 1e9:.1f} GF/s")
    sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    from petsc_ssi.bem import bsr
    nb_r, nb_c = m // 3, k // 3
    indptr = np.arange(nb_r + 1, dtype=np.int64) * nb_c
    indices = np.tile(np.arange(nb_c, dtype=np.int32), nb_r)
    data = rng.random((nb_r * nb_c, 3, 3))
    for b in (8, 16, 32):
        XT = rng.random((3 * nb_c, b))
        RT = np.zeros((3 * nb_r, b))
        t = best(lambda: bsr._panel(indptr, indices, data, XT, RT, 1.0), reps=3)
        print(f"bsr_panel_b{b} {18 * b * indices.size / t / 1e9:.1f} GF/s")
    data32 = data.astype(np.float32)              # lags in single precision (-ssi_lag_single_from)
    for b in (8, 16, 32):
        XT = rng.random((3 * nb_c, b))
        RT = np.zeros((3 * nb_r, b))
        t = best(lambda: bsr._panel(indptr, indices, data32, XT, RT, 1.0), reps=3)
        print(f"bsr_panel_single_b{b} {18 * b * indices.size / t / 1e9:.1f} GF/s")


if __name__ == "__main__":
    main()
