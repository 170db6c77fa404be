#!/usr/bin/env python3
"""The flat H lags' panel kernels one row and two rows at a time (bem/bsr.py ``_panel_h4``,
``_panel_h4_pair``, both four states at a time through bem/simd.py) at the panel widths the
time-blocked history sum uses (its blocks and sub-blocks: 8 to 32), on lags 20, 50 and 78 of the
paper's Lamb case (the first 600 rows, one process), best of 5 calls each: ns per stored block and
state. It sets ``bsr.PAIR_FROM``, the width from which the two-row kernel is taken; both give the
same bits (checked here too).

    python jobscripts/panel_widths.py
"""
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
print(f"bsr.PAIR_FROM = {bsr.PAIR_FROM}")
for lag in (20, 50, 78):
    ip, c, v = ls.H.csr(lag)
    out = []
    for b in (8, 12, 16, 24, 32):
        XT = rng.standard_normal((3 * N, b))
        res = {}
        for name, f in (("one", bsr._panel_h4), ("two", bsr._panel_h4_pair)):
            ts = []
            for _ in range(6):
                R = np.zeros((3 * 600, b))
                t = time.perf_counter()
                f(ip, c, v, XT, R, 1.0)
                ts.append(time.perf_counter() - t)
            res[name] = (R, min(ts[1:]) / b / len(c) * 1e9)
        assert np.array_equal(res["one"][0], res["two"][0])
        out.append(f"b {b}: one {res['one'][1]:.3f}, two {res['two'][1]:.3f}")
    print(f"lag {lag}, {len(c)} blocks: " + " | ".join(out), flush=True)
