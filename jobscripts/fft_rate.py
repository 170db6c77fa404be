"""The toeplitz store's per-step 2-D real FFTs alone (``petsc_ssi.bem.pfft.SlabFFT``: mpi4py-fft over the ranks),
their rate by the usual count (2.5 N log2 N flops a real plane of N points), for the roofline note of
runs/pekeris/README.md. Per grid: a step's 27 forward planes and 12 inverse ones, repeated; every rank at once.

    mpirun --allow-run-as-root -n 2 .venv/bin/python jobscripts/fft_rate.py [--grids 72x72,120x125] [--repeat 200]

Prints one line a grid: milliseconds a step's forward and inverse transforms on the slowest rank, and GFlop/s
per rank and over the ranks."""
import argparse
import time

import numpy as np
from mpi4py import MPI

from petsc_ssi.bem.pfft import SlabFFT


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--grids", default="72x72,120x125,208x208")
    ap.add_argument("--repeat", type=int, default=200)
    a = ap.parse_args()
    comm = MPI.COMM_WORLD
    if comm.rank == 0:
        print("| grid | ranks | forward, 27 planes [ms] | inverse, 12 planes [ms] | GFlop/s a rank | GFlop/s over the ranks |")
        print("|---|---|---|---|---|---|")
    for g in a.grids.split(","):
        Mx, My = (int(v) for v in g.split("x"))
        f = SlabFFT(comm, Mx, My)
        x = f.inputs(27)
        x[...] = np.random.default_rng(comm.rank).standard_normal(x.shape)
        f.backward_inputs(12)[...] = 1.0
        for _ in range(5):
            f.transform(27)
            f.run_backward(12)
        t = []
        for which in ("fwd", "bwd"):
            comm.Barrier()
            t0 = time.perf_counter()
            for _ in range(a.repeat):
                if which == "fwd":
                    f.transform(27)
                else:
                    f.backward_inputs(12)[...] = 1.0      # (the inverse overwrites its input, as in the run)
                    f.run_backward(12)
            t.append(comm.allreduce((time.perf_counter() - t0) / a.repeat, op=MPI.MAX))
        flops = 39 * 2.5 * Mx * My * np.log2(Mx * My)           # (a step's planes, all ranks together)
        rate = flops / (t[0] + t[1]) / 1e9
        if comm.rank == 0:
            print(f"| {Mx} x {My} | {comm.size} | {1e3 * t[0]:.3f} | {1e3 * t[1]:.3f} | {rate / comm.size:.2f} | "
                  f"{rate:.2f} |", flush=True)
        f.destroy()


if __name__ == "__main__":
    main()
