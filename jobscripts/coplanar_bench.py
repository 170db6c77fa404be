"""The split lags of an excavated surface against the general pattern (issue 42, item 1; runs/basement/README.md,
"The coplanar pairs' flat pattern"): runs/basement's basement soil (-ssi_mesh pit a=3.6,b=3.6,d=3 on 16.8 m x
16.8 m, h 1.2 m, the paper's soil, dt 5 ms) assembled on one process for lags 1..L (-ssi_lag_pattern auto:
H split, bsr.SplitBSR; full: every block 9 values), then the history sum's products over those lags timed
the same way for both, alternately: panel products of b states (march's time-blocked sum) and
matrix-vector products (its per-step terms), the best of R repetitions.

    .venv/bin/python jobscripts/coplanar_bench.py [L=20] [b=16] [R=5]

Prints per pattern the stored bytes of the L lags [GB], the assembly time [s] and the products' times
[s]; and the largest difference of the products relative to their largest value."""
import sys
import time

import numpy as np


def lags(pattern, L):
    from petsc_ssi.petsc import init
    from petsc_ssi.mesh.surface import pit
    from petsc_ssi.bem.lagset import Material, Regions, LagSet
    from petsc_ssi.bem import lagmats
    PETSc = init()
    m = pit(16.8, 16.8, 1.2, 3.6, 3.6, 3.0)
    opts = {"gauss": 2, "singular_order": 12, "subdivisions": 4, "near_factor": 2.0, "max_subdivisions": 32,
            "cache": True, "block_pattern": pattern}
    ls = LagSet(PETSc.COMM_SELF, m, Material(208.0, 100.0, 1800.0), 0.005, L, Regions(m), [], opts)
    t0 = time.perf_counter()
    H, _ = ls.assemble()
    N = m.n_nodes
    mats, _ = lagmats.build(ls.comm, H, L, ls.node_range, N, N, N, "sparse")
    return [M for M in mats if M is not None], time.perf_counter() - t0, N


def timed(ctxs, f, R):
    best = np.inf
    for _ in range(R):
        t0 = time.perf_counter()
        for c in ctxs:
            f(c)
        best = min(best, time.perf_counter() - t0)
    return best


def main(L=20, b=16, R=5):
    from petsc_ssi.bem import bsr, lagmats
    from petsc_ssi.bem.lagset import load_kernels
    load_kernels()                            # (the compiled kernels loaded before either assembly is timed)
    res = {}
    for pattern in ("auto", "full"):
        mats, t_asm, N = lags(pattern, L)
        res[pattern] = (mats, t_asm, sum(lagmats.mat_bytes(M) for M in mats) / 1e9)
    rng = np.random.default_rng(1)
    XT = rng.standard_normal((3 * N, b))
    x = rng.standard_normal(3 * N)
    out = {k: [bsr.context(M) for M in v[0]] for k, v in res.items()}
    times = {k: [0.0, 0.0] for k in out}
    for _ in range(2):                        # alternately, so that both see the same load
        for k, ctxs in out.items():
            RT, y = np.zeros((3 * N, b)), np.empty(3 * N)
            times[k][0] = times[k][0] + timed(ctxs, lambda c: c.panel(XT, RT, 1.0), R) / 2
            times[k][1] = times[k][1] + timed(ctxs, lambda c: c.matvec(x, y), R) / 2
    ra, rf = np.zeros((3 * N, b)), np.zeros((3 * N, b))
    for a, f in zip(out["auto"], out["full"]):
        a.panel(XT, ra, 1.0)
        f.panel(XT, rf, 1.0)
    for k in ("full", "auto"):
        print(f"{k:5s}: {L} lags, stored {res[k][2]:.3f} GB, assembly and Mats {res[k][1]:.1f} s, "
              f"panel products (b = {b}) {times[k][0]:.3f} s, matrix-vector products {times[k][1]:.3f} s")
    print(f"panel results: largest difference {np.abs(ra - rf).max() / np.abs(rf).max():.2e} of the largest value")


if __name__ == "__main__":
    main(*[int(a) for a in sys.argv[1:]])
