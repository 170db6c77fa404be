#!/usr/bin/env python3
"""Concurrent MPI singletons writing HDF5 files through PETSc's viewer (MPI-IO), with and without OpenMPI's
isolated singletons: ``python jobscripts/singleton_mpiio.py [PROCS] [FILES]`` prints, for each setting, the
seconds, the failed creates and the lines the processes wrote to standard error. Isolated singletons share one
session directory, where MPI-IO's shared file pointers keep a file named after the file opened: the reason
tests/conftest.py does not isolate them (the test workers write outputs of the same part names at once)."""
import os
import subprocess
import sys
import tempfile
import time

CHILD = r"""
import os, sys
from petsc4py import PETSc
d, n = sys.argv[1], int(sys.argv[2])
bad = 0
for i in range(n):
    v = PETSc.Vec().createMPI(300, comm=PETSc.COMM_WORLD)
    v.set(1.0)
    v.setName("x")
    try:
        w = PETSc.Viewer().createHDF5(os.path.join(d, f"p{i % 3:06d}.h5"), mode="w", comm=PETSc.COMM_WORLD)
        v.view(w)
        w.destroy()
    except PETSc.Error:
        bad += 1
    v.destroy()
print(bad)
"""


def trial(procs, files, isolated):
    env = dict(os.environ)
    env.setdefault("PETSC_DIR", "/usr/lib/petscdir/petsc3.18/x86_64-linux-gnu-real")
    env.pop("OMPI_MCA_ess_singleton_isolated", None)
    if isolated:
        env["OMPI_MCA_ess_singleton_isolated"] = "1"
    with tempfile.TemporaryDirectory() as top:
        t0 = time.time()
        ps = []
        for k in range(procs):
            d = os.path.join(top, f"d{k}")
            os.makedirs(d)
            ps.append(subprocess.Popen([sys.executable, "-c", CHILD, d, str(files)], env=env,
                                       stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True))
        outs = [p.communicate() for p in ps]
        dt = time.time() - t0
    bad = sum(int(o.strip().splitlines()[-1]) if o.strip() else files for o, _ in outs)
    lines = [len([ln for ln in e.splitlines() if ln.strip()]) for _, e in outs]
    return dt, bad, lines


if __name__ == "__main__":
    procs = int(sys.argv[1]) if len(sys.argv) > 1 else 6
    files = int(sys.argv[2]) if len(sys.argv) > 2 else 300
    for iso in (True, False):
        dt, bad, lines = trial(procs, files, iso)
        print(f"{'isolated' if iso else 'not isolated':>13s}: {procs} processes x {files} HDF5 files in {dt:.2f} s, "
              f"{bad} creates failed, standard error lines per process {lines}")
