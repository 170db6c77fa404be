"""Helpers of the FEM tests: small models, dense references, the CLI."""
import os
import subprocess
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
PY = sys.executable

from petsc_ssi.petsc import init as _init  # noqa: E402
_init([sys.argv[0]])   # before anything else imports PETSc: keep pytest's arguments out


def small_system(mesh, E=1e6, nu=0.25, rho=1e3, comm=None):
    """(K Mat, m Vec, layout) of ``mesh`` on one process."""
    from petsc_ssi.petsc import init
    from petsc_ssi.fem.assembly import Material, assemble
    from petsc_ssi.fem.dofmap import BrickDofMap as Layout
    PETSc = init()
    layout = Layout(mesh.n_nodes, comm or PETSc.COMM_SELF)
    K, m = assemble(mesh, Material(E, nu, rho), layout)
    return K, m, layout


def dense(A):
    """Dense numpy copy of a serial PETSc Mat (A itself is left as it is)."""
    B = A.copy()
    B.convert("dense")
    out = B.getDenseArray().copy()
    B.destroy()
    return out


def vec_from(arr, template):
    v = template.duplicate()
    v.getArray()[:] = arr
    return v


def sdof_mats(k, m):
    """1x1 stiffness Mat and mass Vec (a single-degree-of-freedom system)."""
    return chain_mats(np.array([[k]]), np.array([m]))


def chain_mats(Kd, md):
    from petsc_ssi.petsc import init
    PETSc = init()
    n = len(md)
    K = PETSc.Mat().createAIJ(size=(n, n), nnz=n, comm=PETSc.COMM_SELF)
    r, c = np.nonzero(np.ones((n, n)))
    for i, j in zip(r, c):
        K.setValue(int(i), int(j), float(Kd[i, j]))
    K.assemble()
    m = PETSc.Vec().createSeq(n, comm=PETSc.COMM_SELF)
    m.getArray()[:] = md
    return K, m


def newmark_dense(K, M, C, u0, v0, dt, nsteps, f=None, alpha=0.25, delta=0.5):
    """Textbook Newmark recurrence on dense matrices; f(n) -> load at t_n."""
    f = f or (lambda n: np.zeros(len(u0)))
    a = np.linalg.solve(M, f(0) - C @ v0 - K @ u0)
    Keff = K + M / (alpha * dt ** 2) + delta / (alpha * dt) * C
    u, v, us, vs = u0.copy(), v0.copy(), [u0.copy()], [v0.copy()]
    for n in range(1, nsteps + 1):
        rhs = f(n) + M @ (u / (alpha * dt ** 2) + v / (alpha * dt) + (1 / (2 * alpha) - 1) * a) \
            + C @ (delta / (alpha * dt) * u + (delta / alpha - 1) * v + dt * (delta / (2 * alpha) - 1) * a)
        u1 = np.linalg.solve(Keff, rhs)
        a1 = (u1 - u - dt * v) / (alpha * dt ** 2) - (1 / (2 * alpha) - 1) * a
        v = v + dt * ((1 - delta) * a + delta * a1)
        u, a = u1, a1
        us.append(u.copy())
        vs.append(v.copy())
    return np.array(us), np.array(vs)


def run_cli(args, n=1, cwd=ROOT, timeout=120):
    """Run ``petsc-ssi`` (optionally under mpirun -n n); CompletedProcess."""
    cmd = [PY, "-m", "petsc_ssi"] + list(args)
    if n > 1:
        cmd = ["mpirun", "--allow-run-as-root", "--oversubscribe", "-n", str(n)] + cmd
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OPENBLAS_NUM_THREADS="1")
    return subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)
