#!/usr/bin/env python3
"""The step matrix with and without the zeros of the flat pattern (issue 29, item 4): the step
matrix A = 4 H_1 + H_2 (stabilised; and -G of a prescribed region's columns) is built from full
3x3 blocks, zeros included. On a flat surface its off-diagonal blocks hold only the 4 entries of
H's pattern (5 of G's), so A couples the in-plane unknowns of a node with the out-of-plane ones of
its neighbours, and the in-plane ones with each other only through the free term's diagonal. This
script builds A both ways (every entry of the 3x3 blocks; only the non-zero ones), factorises each
with MUMPS (LU) on this run's ranks and times the factorisation and 200 solves, and compares the
solutions: what a step matrix without the zeros would save.

    mpirun -n 2 python jobscripts/step_pattern.py -options_file runs/pekeris/paper.opts"""
import sys
import time

import numpy as np

from petsc_ssi.petsc import init
PETSc = init(sys.argv)
from petsc_ssi import options  # noqa: E402
import petsc_ssi.app.kinds  # noqa: E402,F401  (every option declared)
from petsc_ssi.bem.halfspace import HalfSpace  # noqa: E402
from petsc_ssi.bem import march, symmetry  # noqa: E402

cfg = options.resolve(("common", "bem"))
comm = PETSc.COMM_WORLD
prob = HalfSpace(cfg, comm, log=lambda m: None)
ls = prob.lagset(prob.interp_plan())
ls.assemble(lag_hi=2)
pres = np.zeros(prob.mesh.n_nodes, bool)
pres[prob.regions.disp_nodes] = True
zero = symmetry.zero_dofs(prob.mesh.nodes, prob.planes, prob.h)
out = {}
for name, drop in (("full 3x3 blocks", False), ("flat pattern's entries", True)):
    A = march.step_matrix(comm, ls, cfg.scheme if cfg.scheme.startswith("stabili") else "plain", pres)
    if drop:                                   # the same matrix without its zero entries
        r0, r1 = A.getOwnershipRange()
        ai, aj, av = A.getValuesCSR()
        keep = av != 0.0
        rows = np.repeat(np.arange(r1 - r0), np.diff(ai))[keep]
        ip = np.zeros(r1 - r0 + 1, np.int64)
        np.cumsum(np.bincount(rows, minlength=r1 - r0), out=ip[1:])
        B = PETSc.Mat().createAIJ(size=A.getSizes(), csr=(ip.astype(PETSc.IntType), aj[keep].astype(PETSc.IntType),
                                                          av[keep]), comm=comm)
        B.assemble()
        A.destroy()
        A = B
    r0, r1 = A.getOwnershipRange()
    zd = np.asarray(zero, np.int64)
    A.zeroRowsColumns(zd[(zd >= r0) & (zd < r1)].astype(PETSc.IntType), diag=1.0)
    nnz = comm.tompi4py().allreduce(int(A.getInfo(PETSc.Mat.InfoType.LOCAL)["nz_used"]))
    ksp = PETSc.KSP().create(comm=comm)
    ksp.setOperators(A)
    ksp.setType("preonly")
    ksp.getPC().setType("lu")
    ksp.getPC().setFactorSolverType("mumps")
    t0 = time.perf_counter()
    ksp.setUp()
    t_fac = time.perf_counter() - t0
    b = A.createVecLeft()
    rng = np.random.default_rng(1 + comm.getRank())
    b.getArray()[:] = rng.standard_normal(b.getLocalSize())
    x = b.duplicate()
    t0 = time.perf_counter()
    for _ in range(200):
        ksp.solve(b, x)
    t_sol = (time.perf_counter() - t0) / 200
    out[name] = (nnz, t_fac, t_sol, x.copy())
    for obj in (ksp, A, b, x):                 # collectively, before the next (not at exit's garbage collection)
        obj.destroy()
    if comm.getRank() == 0:
        print(f"{name}: {nnz} entries, factorisation {t_fac * 1e3:.1f} ms, solve {t_sol * 1e3:.2f} ms")
(x1, x2) = (v[3] for v in out.values())
d = x1.copy()
d.axpy(-1.0, x2)
rel = d.norm(PETSc.NormType.INFINITY) / x1.norm(PETSc.NormType.INFINITY)
if comm.getRank() == 0:
    print(f"solutions differ by {rel:.2e} of their largest value")
for v in (d, x1, x2):
    v.destroy()
ls = prob = None
