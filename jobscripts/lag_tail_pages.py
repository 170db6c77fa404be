#!/usr/bin/env python3
"""How many bytes the lag arrays' last huge pages hold beyond the blocks stored (issue 29): assembles
an options file's lags (default runs/pekeris/paper.opts) on each rank and counts, for every H and G
lag array of 4 MB and more (numpy's huge-page threshold), the bytes from its last stored block to
the end of the 2 MB page holding it (or the array's end): what a huge page faults in for nothing
when the whole array is backed by huge pages. Also the stored and allocated bytes. (Since issue 29's
small tail pages, sysmem.small_pages_from, these bytes are small pages: the count is what the
advice saves, not what the run now holds.)

    mpirun -n 2 python jobscripts/lag_tail_pages.py [-options_file F]"""
import sys

sys.argv = [sys.argv[0]] + (["-options_file", "runs/pekeris/paper.opts"] if "-options_file" not in sys.argv else []) + sys.argv[1:]
from petsc_ssi.petsc import init  # noqa: E402
PETSc = init(sys.argv)
from petsc_ssi import options  # noqa: E402
import petsc_ssi.app.kinds  # noqa: E402,F401  (every option declared)
from petsc_ssi.bem.halfspace import HalfSpace  # noqa: E402
from petsc_ssi.bem.assemble import get_lag  # noqa: E402

HP = 2 << 20
cfg = options.resolve(("common", "bem"))
prob = HalfSpace(cfg, PETSc.COMM_WORLD, log=lambda m: None)
ls = prob.lagset(prob.interp_plan())
H, G = ls.assemble()
tail = used = cap = 0
for B in (H, G):
    for lag in range(1, ls.L + 1):
        c, v, v32 = get_lag(B._c, B._v, B._v32, lag)
        n = int(B.n[lag])
        for a in (c, v, v32):
            if a.nbytes < (4 << 20) or not a.shape[0]:
                continue
            u = n * (a.nbytes // a.shape[0])
            end = a.ctypes.data + u
            page_end = min((end + HP - 1) // HP * HP, a.ctypes.data + a.nbytes)
            tail += max(0, page_end - end) if u else 0
            used += u
            cap += a.nbytes
print(f"rank {PETSc.COMM_WORLD.rank}: stored {used / 1e9:.2f} GB in {cap / 1e9:.2f} GB of arrays; "
      f"last huge pages beyond the stored blocks {tail / 1e9:.3f} GB", flush=True)
