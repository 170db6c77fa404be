"""The toeplitz history sum's products in frequency lanes (``bem/lanes.py``, what the store runs) against
the per-frequency ``matmul`` products they replaced (``toeplitz.history_products``, ``interp_products``), on
one rank's slab of the 72 m building.

Times, best of REPEAT, in milliseconds: a block's exact-lag products (b steps x D lags), a step's products
with its block's last k states (one step, k lags), and a block's interpolating matrices' products (the
weighted states of Chebyshev-like weights over NS states, then the k_i anchors' kernels); for each lane
width of ``--fw`` (the store's is ``lanes.FW``) and the matmul reference, with the largest difference over
the largest term (round-off). Random kernels and states of the store's shapes (H side: 9 D x 8 and 18 D x
4 complex a frequency). Under ``mpirun -n 2`` each rank times its own copy at once (the run's two ranks
share the memory bus) and rank 0 prints every rank's times.
    .venv/bin/python jobscripts/history_lanes.py [--slab 3780 --lags 54 --block 8 --fw 16,32,64 --repeat 5]
    mpirun --allow-run-as-root -n 2 .venv/bin/python jobscripts/history_lanes.py
Defaults: the 72 m building's H side on 2 ranks (FFT grid 120 x 125: 7560 frequencies, 3780 a rank; D = 54
exact lags; k = 20 Chebyshev matrices over the 153 far lags; a step's 3 own states, the mean of a block of 8)."""
import argparse
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from petsc_ssi.bem import lanes  # noqa: E402
from petsc_ssi.bem.toeplitz import history_products, interp_products, _spans, _low_rank  # noqa: E402


def best(f, repeat):
    t = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        f()
        t = min(t, time.perf_counter() - t0)
    return 1e3 * t


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--slab", type=int, default=3780)
    ap.add_argument("--lags", type=int, default=54)
    ap.add_argument("--block", type=int, default=8)
    ap.add_argument("--anchors", type=int, default=20)
    ap.add_argument("--states", type=int, default=153, help="states the interpolating matrices weigh")
    ap.add_argument("--own", type=int, default=3, help="a step's own states in its block")
    ap.add_argument("--fw", default="8,16,64", help="lane widths to time (multiples of lanes.VL)")
    ap.add_argument("--repeat", type=int, default=5)
    a = ap.parse_args(argv)
    slab, D, b, k, ns, kk = a.slab, a.lags, a.block, a.anchors, a.states, a.own
    rng = np.random.default_rng(0)

    def c(*s):
        return rng.standard_normal(s) + 1j * rng.standard_normal(s)
    W = max(D + b, ns) + 8
    K9, K18, V9, V18 = c(slab, 9 * D, 8), c(slab, 18 * D, 4), c(slab, W, 9), c(slab, W, 18)
    A9, A18 = c(slab, 9 * k, 8), c(slab, 18 * k, 4)
    t = np.linspace(-1.0, 1.0, ns)
    C = np.stack([np.stack([np.polynomial.chebyshev.chebval(t + 0.002 * s, np.eye(k)[j]) for j in range(k)])
                  for s in range(b)])
    spans = _spans(C)
    rows = []
    ref_b = history_products(K9, K18, V9, V18, 2, b, D)
    ref_s = history_products(K9[:, 9 * (D - kk):], K18[:, 18 * (D - kk):], V9, V18, 5, 1, kk)
    ref_i = interp_products(A9, A18, V9, V18, C, 1)
    rows.append(("matmul", best(lambda: history_products(K9, K18, V9, V18, 2, b, D), a.repeat),
                 best(lambda: history_products(K9[:, 9 * (D - kk):], K18[:, 18 * (D - kk):], V9, V18, 5, 1, kk),
                      a.repeat),
                 best(lambda: interp_products(A9, A18, V9, V18, C, 1), a.repeat), 0.0))
    for fw in [int(x) for x in a.fw.split(",")]:
        lanes.FW = fw
        L = [lanes.to_lanes(x) for x in (K9, K18, V9, V18, A9, A18)]
        gb = lanes.from_lanes(lanes.history_lanes(L[0], L[1], L[2], L[3], 2, b, D), slab)
        gs = lanes.from_lanes(lanes.history_lanes(L[0], L[1], L[2], L[3], 5, 1, kk, r0=D - kk), slab)
        gi = lanes.from_lanes(lanes.interp_lanes(L[4], L[5], L[2], L[3], C, 1, _low_rank, spans), slab)
        err = max(np.abs(g - r).max() / np.abs(r).max() for g, r in ((gb, ref_b), (gs, ref_s), (gi, ref_i)))
        rows.append((f"lanes FW={fw}",
                     best(lambda: lanes.history_lanes(L[0], L[1], L[2], L[3], 2, b, D), a.repeat),
                     best(lambda: lanes.history_lanes(L[0], L[1], L[2], L[3], 5, 1, kk, r0=D - kk), a.repeat),
                     best(lambda: lanes.interp_lanes(L[4], L[5], L[2], L[3], C, 1, _low_rank, spans), a.repeat),
                     err))
    try:
        from mpi4py import MPI
        comm = MPI.COMM_WORLD
        got = comm.gather(rows, root=0)
        rank = comm.Get_rank()
    except ImportError:
        got, rank = [rows], 0
    if rank == 0:
        print(f"# slab {slab} frequencies, D = {D} lags, b = {b} steps, k = {k} anchors over {ns} states, "
              f"a step's {kk} own states; milliseconds, best of {a.repeat}")
        print("| rank | products | block (b x D) [ms] | a step (1 x k) [ms] | interpolating (b x k) [ms] "
              "| largest difference / largest term |")
        print("|---|---|---|---|---|---|")
        for r, rr in enumerate(got):
            for name, tb, ts, ti, e in rr:
                print(f"| {r} | {name} | {tb:.1f} | {ts:.2f} | {ti:.1f} | {e:.1e} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
