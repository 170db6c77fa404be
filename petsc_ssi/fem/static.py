"""Static solution K u = f with fixed dofs; ``petsc-ssi static`` (any mix of elements).

The command solves K u = F for the spatial load of the options (pressure, point
forces and moments at h = 1) and writes it like a dynamic run with one snapshot
(time = load factor 1): the structure's fields (displacement, rotation), the
receivers (displacement, rotation) and the JSON record.
"""
import numpy as np

from ..petsc import collective_error, warn
from .assembly import owned_dofs, eliminate_dofs
from .integrators import make_solver, setup_or_fail, count_on_fixed, fixed_load_message
from .loads import restrains_rigid_motion


def static_solve(K, f, fixed, coords, prefix="ssi_fem_", solver="direct", dofmap=None, near_null=None):
    """Collective: u with K u = f, u = 0 on ``fixed`` (replicated global dofs).

    ``coords``: replicated (N, 3) node coordinates, used to check that the
    fixed dofs restrain all rigid-body motion (else K is singular; with a dof
    map, its rigid-body modes include the rotation dofs). A force on a fixed dof
    is taken by the support (a warning on rank 0 says so).
    """
    comm = K.getComm()
    ok = dofmap.restrains_rigid_motion(coords, fixed) if dofmap is not None else \
        restrains_rigid_motion(coords, np.asarray(fixed))
    if not ok:
        collective_error("K is singular: the fixed dofs (-ssi_fem_fixed) do not restrain all rigid-body "
                         "motion of the structure, so the static problem K u = f has no unique solution", comm)
    own = owned_dofs(fixed, K)
    count = count_on_fixed([f], own, comm)
    if count:
        warn(fixed_load_message(count, "in the static solve").replace("; warned once", ""), comm)
    A = eliminate_dofs(K.copy(), own)
    b = f.copy()
    b.getArray()[own - K.getOwnershipRange()[0]] = 0.0
    ksp = make_solver(A, prefix, solver, comm, log=lambda s: None, near_null=near_null)
    setup_or_fail(ksp, b, "K", comm)
    u = b.duplicate()
    u.zeroEntries()
    ksp.solve(b, u)
    # a mechanism (e.g. a frame pinned to a brick: bricks carry no moments) leaves K singular even
    # with the six rigid-body modes restrained; a direct factorisation may then return garbage
    # without complaint, so check the residual
    r = b.duplicate()
    A.mult(u, r)
    r.axpy(-1.0, b)
    nb = b.norm()
    rel = r.norm() / nb if nb > 0 else r.norm()
    r.destroy()
    ksp.destroy()
    A.destroy()
    if not np.isfinite(rel) or rel > 1e-6 or not np.isfinite(u.norm()):
        collective_error(f"K is singular (relative residual {rel:.2g} of the static solve): the structure is a "
                         "mechanism (a joint or member free to turn: frames or shells joined to bricks at single "
                         "nodes are pinned there, as bricks carry no moments; or supports that leave a part "
                         "free)", comm)
    return u


