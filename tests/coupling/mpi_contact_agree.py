"""Run under mpirun -n 2 by test_interface.py: rank 1's interface solve differs from rank 0's by a
traction just over the cohesion limit at node 0 (as ranks whose BLAS differ in the last bit could),
so on its own rank 1 would open node 0 and rank 0 would not. Writes each rank's result to
DIR/rank<r>.json (argument DIR)."""
import json
import sys

import numpy as np
from mpi4py import MPI

from petsc_ssi.coupling.contact import ContactLaw

comm = MPI.COMM_WORLD
nb = np.tile([0.0, 0.0, 1.0], (3, 1))



def solve(closed):
    calls.append(closed.tolist())
    p = np.zeros(9)
    p[2::3] = [1.0 - 1e-6, 0.5, -0.3]           # node 0 just below p_C on rank 0 ...
    if comm.Get_rank() == 1:
        p[2] = 1.0 + 1e-6                        # ... just above it on rank 1
    p[2::3] = np.where(closed, p[2::3], 0.0)
    ub = np.where(np.repeat(closed, 3), 0.0, -1e-3)       # an open node separates: gap > 0
    return np.nonzero(np.repeat(~closed, 3))[0], ub, np.zeros(9), p


out = {"rank": comm.Get_rank()}
for name, c in (("alone", None), ("agreed", comm)):
    calls = []
    law = ContactLaw(nb, np.zeros((3, 3), bool), "unilateral", p_C=1.0, tol=1e-8, comm=c)
    r = law.step(solve, None)
    out[name] = {"closed": r["closed"].tolist(), "iterations": r["iterations"], "calls": calls}
with open(f"{sys.argv[1]}/rank{comm.Get_rank()}.json", "w") as f:     # not stdout: lines interleave
    json.dump(out, f)
