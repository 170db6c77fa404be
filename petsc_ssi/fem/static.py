"""Static solution K u = f with fixed dofs (reference for the dynamic runs)."""
import numpy as np

from ..petsc import init, collective_error
from .integrators import make_solver, setup_or_fail, mean_diagonal
from .loads import restrains_rigid_motion


def static_solve(K, f, fixed, coords, prefix="ssi_fem_", solver="direct"):
    """Collective: u with K u = f, u = 0 on ``fixed`` (replicated global dofs).

    ``coords``: replicated (N, 3) node coordinates, used to check that the
    fixed dofs restrain all rigid-body motion (else K is singular).
    """
    PETSc = init()
    comm = K.getComm()
    if not restrains_rigid_motion(coords, np.asarray(fixed)):
        collective_error("K is singular: the fixed dofs (-ssi_fem_fixed) do not restrain all rigid-body "
                         "motion of the structure, so the static problem K u = f has no unique solution", comm)
    r0, r1 = K.getOwnershipRange()
    fx = np.asarray(fixed, dtype=np.int64)
    own = fx[(fx >= r0) & (fx < r1)].astype(PETSc.IntType)
    A = K.copy()
    A.zeroRowsColumns(own, diag=mean_diagonal(A))
    b = f.copy()
    b.getArray()[own - r0] = 0.0
    ksp = make_solver(A, prefix, solver, comm, log=lambda s: None)
    setup_or_fail(ksp, b, "K", comm)
    u = b.duplicate()
    u.zeroEntries()
    ksp.solve(b, u)
    ksp.destroy()
    A.destroy()
    return u
