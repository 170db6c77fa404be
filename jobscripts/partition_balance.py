#!/usr/bin/env python3
"""How evenly the soil nodes' work falls on the ranks (-ssi_partition), counted from assembled lags.

For each case (an options file of runs/pekeris), assemble its lag matrices on one process and
count each node's stored 3x3 blocks (memory and assembly) and history products (each block of lag
l once per step that uses it, partition.lag_uses, and the node's dense row of G); then cut the
nodes over p = 2, 4, 8, 16 ranks as PETSc's equal node counts and as -ssi_partition balanced (bem/partition.py, from its estimate)
would, and (mixed) as a cut by an equal mix of the estimated blocks' and products' shares would
(the alternative partition.weights explains), and give the busiest rank's blocks and products
over the mean (1: even). Writes
jobscripts/results/partition_balance.csv and the table between <!-- partition_balance:begin/end -->
in jobscripts/README.md.

    python jobscripts/partition_balance.py [CASES...]      (default: medium paper; the paper case
                                                             assembles 12 GB on one process)"""
import json
import os
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
sys.path.insert(0, ROOT)
from logview import write_csv, put_block  # noqa: E402

from petsc_ssi.launch import child_env  # noqa: E402

RANKS = (2, 4, 8, 16)


def counts(case):
    """Rows of the table for one case: per rank count, the busiest rank over the mean."""
    from petsc_ssi.petsc import init
    PETSc = init([sys.argv[0], "-options_file", os.path.join(ROOT, "runs", "pekeris", case + ".opts")])
    from petsc_ssi import options
    import petsc_ssi.app.kinds  # noqa: F401  (every option declared)
    from petsc_ssi.bem.halfspace import HalfSpace
    from petsc_ssi.bem import partition
    cfg = options.resolve(("common", "bem"))
    prob = HalfSpace(cfg, PETSc.COMM_SELF, log=lambda m: None)
    plan = prob.interp_plan()
    ls = prob.lagset(plan)
    if plan.active:
        raise SystemExit(f"{case}: lag interpolation; this script counts the exact lags only")
    N, Lx = prob.mesh.n_nodes, plan.Lx
    nimg = len(ls.Vc) // prob.mesh.n_cells
    # the weights a run computes (bem/halfspace.py HalfSpace.lagset, bem/partition.py)
    stab = cfg.scheme.startswith("stabili")
    lag_w = partition.lag_weights(Lx, prob.L, stab)                   # (uses of a run of L steps)
    b, q = partition.node_work(prob.mesh.nodes, np.arange(N), ls.Vc, ls.VR, prob.mat, prob.dt, nimg, lag_w, Lx,
                               prob.regions.n_t)
    w = partition.weights(b, q)
    w_mix = b / b.sum() + q / q.sum()       # the alternative partition.weights explains: blocks' + products' shares
    # assembled: each node's blocks of every lag; products: each block once per step that uses its
    # lag, and the node's dense row of G (n_t blocks) in every used matrix
    H, G = ls.assemble(lag_hi=Lx)
    blocks = H.counts[1:Lx + 1, :N].astype(float)
    tb = blocks.sum(0)
    uses = partition.lag_weights(Lx, prob.n_steps, stab)             # this run's own uses
    tq = (blocks * uses[:, None]).sum(0) + prob.regions.n_t * uses.sum()
    rows = []
    for p in RANKS:
        r = {"case": case, "ranks": p}
        for kind, ranges in (("equal", partition.equal_ranges(N, p)), ("balanced", partition.balanced_ranges(w, p)),
                             ("mixed", partition.balanced_ranges(w_mix, p))):
            r[f"blocks_{kind}"] = round(partition.imbalance(tb, ranges), 3)
            r[f"products_{kind}"] = round(partition.imbalance(tq, ranges), 3)
        rows.append(r)
    return rows


def main(cases):
    rows = []
    for case in cases:            # one process per case (PETSc reads its options file once)
        out = subprocess.run([sys.executable, __file__, "--one", case], capture_output=True, text=True, check=True,
                             env=child_env())
        for line in out.stdout.splitlines():
            if line.startswith("{"):
                rows.append(json.loads(line))
                print(line, flush=True)
    write_csv(os.path.join(HERE, "results", "partition_balance.csv"), rows)
    lines = ["| case | ranks | blocks, busiest / mean: equal nodes | balanced | (mixed) | products: equal nodes | "
             "balanced | (mixed) |", "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['case']} | {r['ranks']} | {r['blocks_equal']:.3f} | **{r['blocks_balanced']:.3f}** | "
                     f"({r['blocks_mixed']:.3f}) | {r['products_equal']:.3f} | **{r['products_balanced']:.3f}** | "
                     f"({r['products_mixed']:.3f}) |")
    put_block("partition_balance", "\n".join(lines) + "\n", (os.path.join(HERE, "README.md"),))


if __name__ == "__main__":
    if sys.argv[1:2] == ["--one"]:
        for r in counts(sys.argv[2]):
            print(json.dumps(r))
    else:
        main(sys.argv[1:] or ["medium", "paper"])
