"""Where one rank's BEM assembly spends its time (issues 13 and 29): runs LagSet.assemble and the
Mat build of an options file (default runs/pekeris/paper.opts) with wrappers timing the integration
of the shared element cache (LagSet._share_cache: the listing of its geometries, enumerate_pairs, their
integration, integrate_batch, the replies, _send_segments, the indexing, cache_index), the kernel that sums the blocks and writes them
where they are kept (assemble_rows) and the Mat constructors, and prints per rank those times, the
kernel (sys) time and minor page faults (getrusage), resident and huge-page memory, and ms per row.
With -prefault 1 the lag arrays are written once (zeros) as they are allocated, timed apart: the
first touch of their pages, which the kernel otherwise pays as it writes.

  mpirun -n 2 python jobscripts/assembly_profile.py [-rows R] [-prefault 1]   (R > 0: R rows from row 1000)
"""
import sys, time
import numpy as np
sys.argv = [sys.argv[0]] + (["-options_file", "runs/pekeris/paper.opts"] if "-options_file" not in sys.argv else []) + sys.argv[1:]
from petsc_ssi.petsc import init
PETSc = init(sys.argv)
from petsc_ssi import options
import petsc_ssi.app.kinds  # noqa: F401  (every option declared)
from petsc_ssi.bem.halfspace import HalfSpace
from petsc_ssi.bem import lagset as model, lagmats, assemble as kern
cfg = options.resolve(("common", "bem"))
prob = HalfSpace(cfg, PETSc.COMM_WORLD, log=lambda m: None)
ls = prob.lagset(prob.interp_plan())
R = int(PETSc.Options().getInt("rows", 64))
PRE = PETSc.Options().getBool("prefault", False)
if R: ls.rows = ls.rows[1000:1000 + R]
if R: ls.node_range = (1000, 1000 + R)
R = len(ls.rows)
T = {}
TS = []
def wrap(mod, name):
    f = getattr(mod, name)
    def g(*a, **k):
        t = time.perf_counter(); r = f(*a, **k); d = time.perf_counter() - t; T[name] = T.get(name, 0) + d
        if name == "assemble_rows": TS.append((d, len(a[0]), a[0][0]))
        if name == "_send_segments": T["received cache, GB"] = 8e-9 * sum(int(n.sum()) for n, _ in a[2])
        return r
    setattr(mod, name, g)
# (LagSet imports the kernels from bem/assemble.py where it calls them, so they are wrapped there)
for n in ("assemble_rows", "enumerate_pairs", "integrate_batch", "cache_index"):
    wrap(kern, n)                           # the last three, with _send_segments: the parts of _share_cache
wrap(model, "_send_segments")
wrap(model.LagSet, "_share_cache")
_init = model.Buckets.__init__
def init_prefault(self, *a, **k):
    _init(self, *a, **k)
    if PRE:
        t = time.perf_counter()
        for l in range(len(self._c)):
            self._c[l].fill(0); self._v[l].fill(0.0); self._v32[l].fill(0.0)
        T["first touch"] = T.get("first touch", 0) + time.perf_counter() - t
model.Buckets.__init__ = init_prefault
for n in ("baij", "dense"):
    wrap(lagmats, n)
t = time.perf_counter(); ls.assemble(); ta = time.perf_counter() - t
print(PETSc.COMM_WORLD.rank, f"assemble {ta:.2f} s:", {k: round(v, 2) for k, v in T.items()})
import resource
ru = resource.getrusage(resource.RUSAGE_SELF); print("rss", open("/proc/self/status").read().split("VmRSS:")[1].split("\n")[0], "AnonHuge", [l for l in open("/proc/self/smaps_rollup") if "AnonHuge" in l])
print(PETSc.COMM_WORLD.rank, "per call (first row, ms/row):", [(int(r), round(1e3*d/max(n,1), 1)) for d, n, r in TS[::7]], "sys", ru.ru_stime, "minflt", ru.ru_minflt, flush=True)
N = prob.mesh.n_nodes
t = time.perf_counter()
H, info = lagmats.build(PETSc.COMM_WORLD, ls.H, ls.L, ls.node_range, N, N, R, "sparse", 0.35)
print(PETSc.COMM_WORLD.rank, f"build {time.perf_counter() - t:.2f}", {k: round(v, 2) for k, v in T.items()},
      "rss", open("/proc/self/status").read().split("VmRSS:")[1].split("\n")[0].strip(),
      "peak", open("/proc/self/status").read().split("VmHWM:")[1].split("\n")[0].strip())
