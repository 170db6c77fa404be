#!/usr/bin/env python3
"""The block-sparse panel kernels of a flat surface's H lags (bem/bsr.py, issue 29) on real lags:
``_panel_h4`` (one row at a time) against ``_panel_h4_pair`` (two rows at a time: a column both
rows hold has its rows of the panel read once), at panel widths 16 and 32, on lags 20, 50 and 78
of the paper's Lamb case (the first 600 rows, one process, the lags up to 0.06 s assembled), best of
5 calls each; and whether the two give the same bits. What bsr.PAIR_FROM rests on.

    python jobscripts/panel_kernels.py"""
import sys
import time

import numpy as np

sys.argv = [sys.argv[0], "-options_file", "runs/pekeris/paper.opts", "-ssi_t_end", "0.06"]
from petsc_ssi.petsc import init  # noqa: E402
PETSc = init(sys.argv)
from petsc_ssi import options  # noqa: E402
import petsc_ssi.app.kinds  # noqa: E402,F401  (every option declared)
from petsc_ssi.bem.halfspace import HalfSpace  # noqa: E402
from petsc_ssi.bem import bsr  # noqa: E402

cfg = options.resolve(("common", "bem"))
prob = HalfSpace(cfg, PETSc.COMM_SELF, log=lambda m: None)
ls = prob.lagset(prob.interp_plan())
ls.rows = ls.rows[:600]
ls.node_range = (0, 600)
ls.assemble()
N = prob.mesh.n_nodes
rng = np.random.default_rng(0)
print("| lag | blocks | b | one row [ns/block/state] | two rows [ns/block/state] | same bits |")
print("|---|---|---|---|---|---|")
for lag in (20, 50, 78):
    ip, c, v = ls.H.csr(lag)
    for b in (16, 32):
        XT = rng.standard_normal((3 * N, b))
        res, best = {}, {}
        for name, f in (("one", bsr._panel_h4), ("two", bsr._panel_h4_pair)):
            R = np.zeros((3 * 600, b))
            f(ip, c, v, XT, R, 1.0)
            res[name] = R
            ts = []
            for _ in range(5):
                R = np.zeros((3 * 600, b))
                t = time.perf_counter()
                f(ip, c, v, XT, R, 1.0)
                ts.append(time.perf_counter() - t)
            best[name] = min(ts) / b / len(c) * 1e9
        print(f"| {lag} | {len(c)} | {b} | {best['one']:.2f} | {best['two']:.2f} | "
              f"{np.array_equal(res['one'], res['two'])} |")
