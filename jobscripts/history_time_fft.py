"""A fast convolution in time for the toeplitz history sum's block products, against the products as they
are (``toeplitz.history_products``), on one rank's slab of the 72 m building (issue 41: "a fast
convolution in time would cut their flops several times").

The block products of ``ToeplitzHistory`` give, for the b steps n0 + 1 .. n0 + b and per frequency, the
terms sum_d K_d v^{n-d} of the states m <= n0 (d = 1..D): each block reads every kernel once (16 x 144 F D
bytes for the H pattern) for 8 x 144 F D b flops. The uniformly partitioned convolution (overlap-save in
time, segments of b states) does the same sum exactly in exact arithmetic: per state block q back
(delta = 1..Q, Q = floor((D + b - 1) / b)) the kernel segment K_{delta b + u - (b - 1)}, u = 0..2b - 2, is kept as
its 2b-point FFT in time, each block's states are transformed once (2b points), and per frequency and time
frequency the products are one (1 x 9 Q)(9 Q x 8) and one (1 x 18 Q)(18 Q x 4)
row-by-matrix product (compiled here: BLAS would take each as one gemv call); one inverse FFT of 12
channels gives the b steps. Its flops are 2 Q / D of the direct products' (3.9 times fewer at
D = 54, b = 8: Q = 7) but its kernels are 2 b Q / D times the bytes (2.07 times), read every block.

Prints the kernels' bytes, each variant's milliseconds a block (best of REPEAT), the compiled products'
own share, and the largest difference of the two over the largest term (round-off: the FFT in time is
exact in exact arithmetic). Under ``mpirun -n 2`` each rank times its own copy at once (as the run's two
ranks share the memory bus) and rank 0 prints every rank's times.
    .venv/bin/python jobscripts/history_time_fft.py [--slab 3780 --lags 54 --block 8 --repeat 5]
    mpirun --allow-run-as-root -n 2 .venv/bin/python jobscripts/history_time_fft.py
Defaults: the 72 m building's H side on 2 ranks (FFT grid 120 x 125: 120 x 63 = 7560 frequencies, 3780 a rank; D = 54
exact lags: T_L = 0.27 s of ssi-common.opts over dt = 5 ms, as its log says: "54 exact lags")."""
import argparse
import os
import sys
import time

import numpy as np
from numba import njit
from scipy.fft import fft, ifft

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from petsc_ssi.bem.toeplitz import history_products  # noqa: E402


@njit(cache=True)
def _tf_products(Xh, Gh, out, j0):
    """out[f, w, j0 + j] = sum_q sum_c Xh[f, w, q, c] Gh[f, w, q, c, j]."""
    F, N, Q, C, n = Gh.shape
    for f in range(F):
        for w in range(N):
            for j in range(n):
                out[f, w, j0 + j] = 0.0
            for q in range(Q):
                for c in range(C):
                    x = Xh[f, w, q, c]
                    for j in range(n):
                        out[f, w, j0 + j] += x * Gh[f, w, q, c, j]


def segment_spectra(K, c, D, b, Q):
    """(F, 2b, Q, c, n): per state block delta = 1..Q back, the FFT in time (2b points) of the kernel
    segment u -> K_{delta b + u - (b - 1)} (zero outside d = 1..D), K (F, c D, n) the direct store (row
    block D - d holds lag d)."""
    F, _, n = K.shape
    G = np.zeros((F, Q, 2 * b, c, n), np.complex128)
    for q in range(1, Q + 1):
        for u in range(2 * b - 1):
            d = q * b + u - (b - 1)
            if 1 <= d <= D:
                G[:, q - 1, u] = K[:, c * (D - d):c * (D - d + 1)]
    return np.ascontiguousarray(fft(G, axis=2).transpose(0, 2, 1, 3, 4))


def fft_block(G9, G18, V9, V18, p, b, Q, n9, timing):
    """The b steps' terms of the states in rows p - Q b .. p - 1 (the b steps read up to row p - 1 + s;
    the states of rows >= p are the block's own, not in these terms)."""
    F = V9.shape[0]
    outh = np.empty((F, 2 * b, n9 + G18.shape[-1]), np.complex128)
    for V, Gh, c, j0 in ((V9, G9, 9, 0), (V18, G18, 18, n9)):
        X = np.zeros((F, Q, 2 * b, c), np.complex128)
        for q in range(1, Q + 1):
            X[:, q - 1, :b] = V[:, p - q * b:p - q * b + b]
        Xh = np.ascontiguousarray(fft(X, axis=2).transpose(0, 2, 1, 3))
        t0 = time.perf_counter()
        _tf_products(Xh, Gh, outh, j0)
        timing[0] += time.perf_counter() - t0
    return ifft(outh, axis=1)[:, b - 1:2 * b - 1]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--slab", type=int, default=3780, help="frequencies of this rank's slab")
    ap.add_argument("--lags", type=int, default=54, help="D, the exact lags")
    ap.add_argument("--block", type=int, default=8, help="b, steps a block")
    ap.add_argument("--repeat", type=int, default=5)
    a = ap.parse_args()
    try:
        from mpi4py import MPI
        comm = MPI.COMM_WORLD
    except ImportError:
        comm = None
    rank = comm.Get_rank() if comm else 0
    F, D, b = a.slab, a.lags, a.block
    n9, n18 = 8, 4                      # the H pattern: K9 (9D x 8), K18 (18D x 4)
    Q = (D + b - 1) // b                # state blocks back whose lags reach d <= D: q b - (b - 1) <= D
    rng = np.random.default_rng(1 + rank)
    W = Q * b + 2 * b
    V9 = rng.standard_normal((F, W, 9)) + 1j * rng.standard_normal((F, W, 9))
    V18 = rng.standard_normal((F, W, 18)) + 1j * rng.standard_normal((F, W, 18))
    K9 = rng.standard_normal((F, 9 * D, n9)) + 1j * rng.standard_normal((F, 9 * D, n9))
    K18 = rng.standard_normal((F, 18 * D, n18)) + 1j * rng.standard_normal((F, 18 * D, n18))
    G9, G18 = segment_spectra(K9, 9, D, b, Q), segment_spectra(K18, 18, D, b, Q)
    p = Q * b + 1                       # row of the block's first own state (n0 + 1)
    V9[:, p:] = 0.0                     # (the block's own states: not in the block products)
    V18[:, p:] = 0.0
    ref = history_products(K9, K18, V9, V18, p - D, b, D)
    tm = [0.0]
    got = fft_block(G9, G18, V9, V18, p, b, Q, n9, tm)
    err = float(np.abs(got - ref).max() / np.abs(ref).max())

    def best(fn):
        ts = []
        for _ in range(a.repeat):
            if comm:
                comm.Barrier()          # (the ranks time at once: they share the memory bus as in a run)
            t0 = time.perf_counter()
            fn()
            ts.append(time.perf_counter() - t0)
        return 1e3 * min(ts)
    t_direct = best(lambda: history_products(K9, K18, V9, V18, p - D, b, D))
    tm[0] = 0.0
    t_fft = best(lambda: fft_block(G9, G18, V9, V18, p, b, Q, n9, tm))
    t_prod = 1e3 * tm[0] / a.repeat
    row = (rank, (K9.nbytes + K18.nbytes) / 1e6, (G9.nbytes + G18.nbytes) / 1e6, t_direct, t_fft, t_prod, err)
    rows = comm.gather(row, root=0) if comm else [row]
    if rank == 0:
        print(f"# H side, slab {F} frequencies, D = {D} exact lags, b = {b} steps a block, {Q} state blocks back; "
              f"{len(rows)} process(es) at once")
        print("| rank | direct kernels [MB] | FFT-in-time kernels [MB] | direct [ms/block] | FFT in time [ms/block] "
              "| of it the compiled products [ms] | largest difference / largest term |")
        print("|---|---|---|---|---|---|---|")
        for r in rows:
            print("| %d | %.0f | %.0f | %.1f | %.1f | %.1f | %.1e |" % r)


if __name__ == "__main__":
    main()
