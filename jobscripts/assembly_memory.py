"""Resident memory of each rank through the BEM assembly (issue 29): before it, right after the shared
element cache's integration (before the assembly gives freed memory back), after a malloc_trim there,
every 20 chunks of rows, and at the end; with the cache pools' sizes. What sysmem.release_freed
rests on: the freed temporaries of the cache's integration stay resident without it.

  mpirun -n 2 python jobscripts/assembly_memory.py [-options_file F] [-sf L]   (default runs/pekeris/paper.opts, L = 3)
"""
import sys

sys.argv = [sys.argv[0]] + (["-options_file", "runs/pekeris/paper.opts"] if "-options_file" not in sys.argv else []) \
    + sys.argv[1:]
from petsc_ssi.petsc import init  # noqa: E402
PETSc = init(sys.argv)
from petsc_ssi import options  # noqa: E402
import petsc_ssi.app.kinds  # noqa: E402,F401  (every option declared)
from petsc_ssi.bem.halfspace import HalfSpace  # noqa: E402
from petsc_ssi.bem import lagset as model, assemble as kern  # noqa: E402
from petsc_ssi.sysmem import process_rss, release_freed  # noqa: E402

r = PETSc.COMM_WORLD.rank
cfg = options.resolve(("common", "bem"))
prob = HalfSpace(cfg, PETSc.COMM_WORLD, log=lambda m: None)
ls = prob.lagset(prob.interp_plan())
print(f"rank {r}: before the assembly {process_rss() / 1e9:.2f} GB", flush=True)
share = model.LagSet._share_cache


def shared(self, *a, **k):
    out = share(self, *a, **k)
    before = process_rss()
    release_freed()
    print(f"rank {r}: after the shared cache's integration {before / 1e9:.2f} GB, after malloc_trim "
          f"{process_rss() / 1e9:.2f} GB (cache pools {(out[2].nbytes + out[3].nbytes) / 1e9:.2f} GB)", flush=True)
    return out


model.LagSet._share_cache = shared
rows = kern.assemble_rows         # (LagSet.assemble imports it from bem/assemble.py at each call)
calls = [0]


def counted(*a, **k):
    out = rows(*a, **k)
    calls[0] += 1
    if calls[0] % 20 == 0:
        print(f"rank {r}: {calls[0]} chunks of rows {process_rss() / 1e9:.2f} GB", flush=True)
    return out


kern.assemble_rows = counted
ls.assemble(single_from=int(PETSc.Options().getInt("sf", 3)))
print(f"rank {r}: after the assembly {process_rss() / 1e9:.2f} GB", flush=True)
