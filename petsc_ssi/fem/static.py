"""Static solution K u = f with fixed dofs; ``petsc-ssi static`` (any mix of elements).

The command solves K u = F for the spatial load of the options (pressure, point
forces and moments at h = 1) and writes it like a dynamic run with one snapshot
(time = load factor 1): the structure's fields (displacement, rotation), the
receivers (displacement, rotation) and the JSON record.
"""
import numpy as np

from ..petsc import collective_error, warn, init, printf
from ..monitor import event
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


def main():
    """Collective: the ``petsc-ssi static`` command (PETSc already initialised)."""
    PETSc = init()
    comm = PETSc.COMM_WORLD
    from .. import options as ssi_options
    from ..io.output import Output, provenance
    from .model import build_model
    from .run import ReceiverSeries, FieldWriter, receiver_record, near_null_args
    cfg = ssi_options.resolve(("common", "fem"))
    from ..io.output import check_output, command_output
    cfg.set("output", command_output(cfg.output, "static"))       # never the transient run's file
    if cfg.output:
        check_output(cfg.output, comm, cfg.output_overwrite)
    model = build_model(cfg, comm)
    _, near = near_null_args(cfg.fem_solver, model)
    coords = model.coords_vec() if (cfg.fem_solver == "iterative" and near is None) else None
    with event("FEM_static"):
        f = model.load_vec()
        u = static_solve(model.K, f, model.fixed, model.mesh.coords, solver=cfg.fem_solver,
                         dofmap=model.layout, near_null=near if coords is None else
                         PETSc.NullSpace().createRigidBody(coords))
    rec = ReceiverSeries(model.layout, model.receiver_nodes, comm)
    rec.record(1.0, u)
    umax = u.norm(PETSc.NormType.INFINITY)
    printf(f"[static] solved K u = F ({model.layout.size} dofs): max |u_i| = {umax:.6e}")
    if comm.getRank() == 0:
        arr = rec.all_arrays()
        for k, p in enumerate(model.receivers):
            printf(f"[static] receiver ({p[0]:g}, {p[1]:g}, {p[2]:g}): u = ({arr['u'][0, k, 0]:.6e}, "
                   f"{arr['u'][0, k, 1]:.6e}, {arr['u'][0, k, 2]:.6e}) m, rotation = ({arr['rotation'][0, k, 0]:.6e}, "
                   f"{arr['rotation'][0, k, 1]:.6e}, {arr['rotation'][0, k, 2]:.6e}) rad")
    if cfg.output:
        out = Output(cfg.output, comm)
        fw = FieldWriter(out, model, comm)
        fw.write(1.0, u)
        receivers = receiver_record(model, rec.all_arrays()) if comm.getRank() == 0 else None
        out.close(receivers=receivers, attrs={"problem": "static", "time_is": "load factor"},
                  record=provenance(cfg, comm, {"static": {"n_dofs": model.layout.size,
                                                           "max_abs_u": float(umax)}}))
        printf(f"[static] wrote {cfg.output} (+ .xmf, .json)")
    return u, model
