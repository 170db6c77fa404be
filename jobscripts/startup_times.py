#!/usr/bin/env python3
"""What a petsc-ssi process pays before it works: wall seconds of short processes, each run REPEAT times
(default 5), median and range, one line each, and whether the run imported numba.

    python jobscripts/startup_times.py [REPEAT]

  * python alone; numpy; numba; mpi4py's MPI (an MPI singleton: OpenMPI starts its orted), the same with
    OMPI_MCA_ess_singleton_isolated=1 (no orted); PETSc initialised (petsc4py.init);
  * a one-rank run refused on its options (-ssi_dt -1 on the 4 x 4 m Pekeris patch);
  * a whole structure-only run (the fixed 2 x 2 x 2 box under a load, 3 steps);
  * the 4 x 4 m soil run (3 steps: numba's kernels loaded from the cache);
  * the refused run under `mpirun -n 2` (mpirun's launch, both ranks, the exit's signalling).

Run it on an idle machine (`bash jobscripts/quiet.sh python jobscripts/startup_times.py`); the kernels must be in
numba's cache (`make deps`). Bytecode is written as in the tests (tests/conftest.py: PYTHONDONTWRITEBYTECODE off,
PYTHONPYCACHEPREFIX), so the imports are not compiled again in every process.
"""
import os
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PY = sys.executable
SOIL = ["-ssi_problem", "bem", "-ssi_mesh_size", "4,4", "-ssi_mesh_h", "1", "-ssi_mesh_patch", "1,1",
        "-ssi_load_group", "load", "-ssi_load_p0", "1000", "-ssi_dt", "0.005", "-ssi_t_end", "0.015",
        "-ssi_warn_beta", "0", "-ssi_output_stride", "0", "-ssi_output_overwrite", "1"]
FEM = ["-ssi_problem", "fem", "-ssi_fem_box_cells", "2,2,2", "-ssi_fem_fixed", "base", "-ssi_fem_load_group", "top",
       "-ssi_fem_load_p0", "1000", "-ssi_dt", "0.01", "-ssi_t_end", "0.03", "-ssi_output_overwrite", "1"]
# a run through app/cli.main in this interpreter, printing whether numba was imported (its exit status kept)
RUN = ("import sys\nfrom petsc_ssi.app.cli import main\nrc = main(['petsc-ssi'] + sys.argv[1:])\n"
       "print('numba imported:', 'numba' in sys.modules)\nsys.exit(rc)")


def env(**extra):
    e = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
             OMPI_MCA_odls_base_sigkill_timeout="0",
             PYTHONPYCACHEPREFIX=os.path.join(os.path.expanduser("~"), ".cache", "petsc_ssi", "pycache"),
             PETSC_DIR=os.environ.get("PETSC_DIR", "/usr/lib/petscdir/petsc3.18/x86_64-linux-gnu-real"))
    e.pop("PYTHONDONTWRITEBYTECODE", None)
    e.update(extra)
    return e


def timed(cmd, n, **extra):
    """(median, min, max) wall seconds of ``n`` runs of ``cmd`` (one warm-up run first), and the last run's output."""
    ts, out = [], ""
    for i in range(n + 1):
        t0 = time.perf_counter()
        p = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, env=env(**extra))
        if i:
            ts.append(time.perf_counter() - t0)
        out = p.stdout + p.stderr
    ts.sort()
    return ts[len(ts) // 2], ts[0], ts[-1], out


def main():
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 5
    tmp = tempfile.mkdtemp(prefix="startup-")
    cases = [
        ("python -c pass", [PY, "-c", "pass"], {}),
        ("import numpy", [PY, "-c", "import numpy"], {}),
        ("import numba", [PY, "-c", "import numba"], {}),
        ("MPI singleton (mpi4py)", [PY, "-c", "from mpi4py import MPI"], {}),
        ("MPI singleton, isolated", [PY, "-c", "from mpi4py import MPI"], {"OMPI_MCA_ess_singleton_isolated": "1"}),
        ("PETSc initialised", [PY, "-c", "import petsc4py; petsc4py.init(); from petsc4py import PETSc"], {}),
        ("refused run, 1 rank", [PY, "-c", RUN] + SOIL + ["-ssi_dt", "-1", "-ssi_output", f"{tmp}/r.h5"], {}),
        ("structure-only run, 1 rank", [PY, "-c", RUN] + FEM + ["-ssi_output", f"{tmp}/f.h5"], {}),
        ("soil run, 1 rank", [PY, "-c", RUN] + SOIL + ["-ssi_output", f"{tmp}/s.h5"], {}),
        ("refused run, mpirun -n 2", ["mpirun", "-n", "2", PY, "-c", RUN] + SOIL
         + ["-ssi_dt", "-1", "-ssi_output", f"{tmp}/r2.h5"], {}),
    ]
    print(f"wall seconds of each process, median (min-max) of {n} runs after one warm-up run")
    for name, cmd, extra in cases:
        med, lo, hi, out = timed(cmd, n, **extra)
        numba = [ln.split(": ")[1] for ln in out.splitlines() if ln.startswith("numba imported:")]
        print(f"{name:30s} {med:6.3f} s ({lo:.3f}-{hi:.3f})" + (f"  numba imported: {numba[-1]}" if numba else ""),
              flush=True)


if __name__ == "__main__":
    main()
