"""Static solution K u = f with fixed dofs (reference for the dynamic runs)."""
import numpy as np

from ..petsc import collective_error, warn
from .assembly import owned_dofs, eliminate_dofs
from .integrators import make_solver, setup_or_fail, count_on_fixed, fixed_load_message
from .loads import restrains_rigid_motion


def static_solve(K, f, fixed, coords, prefix="ssi_fem_", solver="direct"):
    """Collective: u with K u = f, u = 0 on ``fixed`` (replicated global dofs).

    ``coords``: replicated (N, 3) node coordinates, used to check that the
    fixed dofs restrain all rigid-body motion (else K is singular). A force
    on a fixed dof is taken by the support (a warning on rank 0 says so).
    """
    comm = K.getComm()
    if not restrains_rigid_motion(coords, np.asarray(fixed)):
        collective_error("K is singular: the fixed dofs (-ssi_fem_fixed) do not restrain all rigid-body "
                         "motion of the structure, so the static problem K u = f has no unique solution", comm)
    own = owned_dofs(fixed, K)
    count = count_on_fixed([f], own, comm)
    if count:
        warn(fixed_load_message(count, "in the static solve").replace("; warned once", ""), comm)
    A = eliminate_dofs(K.copy(), own)
    b = f.copy()
    b.getArray()[own - K.getOwnershipRange()[0]] = 0.0
    ksp = make_solver(A, prefix, solver, comm, log=lambda s: None)
    setup_or_fail(ksp, b, "K", comm)
    u = b.duplicate()
    u.zeroEntries()
    ksp.solve(b, u)
    ksp.destroy()
    A.destroy()
    return u
