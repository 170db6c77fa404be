"""``petsc-ssi static``: the static solution K u = F of a FE structure (loads at h = 1), written
like a run (``fem.static.static_solve``)."""
from ..petsc import init, printf
from ..monitor import event
from ..fem.static import static_solve


def structure_command(name):
    """Collective: (PETSc, comm, cfg, model) of a command on the structure alone (``name``:
    static, modes): the options of the structure resolved and checked, the output the command's
    own (``io.output.command_output``: never the transient run's file) and checked, the model
    built."""
    PETSc = init()
    comm = PETSc.COMM_WORLD
    from .. import options as ssi_options
    from ..fem import options as _fem_options  # noqa: F401
    from ..fem.model import build_model
    from ..io.output import check_output, command_output
    cfg = ssi_options.resolve(("common", "fem"))
    _needs_structure(cfg, name, ssi_options)
    cfg.set("output", command_output(cfg.output, name))
    if cfg.output:
        check_output(cfg.output, comm, cfg.output_overwrite)
    return PETSc, comm, cfg, build_model(cfg, comm)


def _needs_structure(cfg, name, ssi_options):
    """SSIError unless the options describe a structure: some -ssi_fem_* option (the mesh, the box,
    the parts, a material, a load...) or -ssi_problem fem (whose default is the box). A soil-only
    options set used to mesh the default 1 m box and fail later on a receiver, or solve it."""
    fem = [o.name for o in ssi_options.options().values() if o.group == "fem" and o.name != "modes_n"]
    if cfg.problem == "fem" and cfg.user_set("problem") or any(cfg.user_set(n) for n in fem):
        return
    from ..petsc import SSIError
    raise SSIError(f"petsc-ssi {name} needs a structure, and these options describe none (no -ssi_fem_* option, "
                   f"-ssi_problem {cfg.problem}): give -ssi_fem_mesh FILE with -ssi_fem_parts, or -ssi_fem_box_cells "
                   "(or -ssi_problem fem for the default box)")


def main():
    """Collective: the ``petsc-ssi static`` command (PETSc already initialised)."""
    from ..io.output import Output, provenance
    from ..fem.integrators import near_null_args
    from ..io.structure import ReceiverSeries, FieldWriter, receiver_record
    PETSc, comm, cfg, model = structure_command("static")
    _, near = near_null_args(cfg.fem_solver, model)
    coords = model.coords_vec() if (cfg.fem_solver == "iterative" and near is None) else None
    with event("FEM_static"):
        f = model.load_vec()
        u = static_solve(model.K, f, model.fixed, model.mesh.coords, solver=cfg.fem_solver,
                         dofmap=model.dofmap, near_null=near if coords is None else
                         PETSc.NullSpace().createRigidBody(coords))
    from ..fem.gravity import gravity_case            # -ssi_fem_gravity: the self-weight added to the loads
    grav = gravity_case(cfg, model, comm)
    if grav is not None:
        u.axpy(1.0, grav.u)
        printf("[static] the solution is the options' loads plus the self-weight (-ssi_fem_gravity)")
    rec = ReceiverSeries(model.dofmap, model.receiver_nodes, comm)
    rec.record(1.0, u)
    umax = u.norm(PETSc.NormType.INFINITY)
    printf(f"[static] solved K u = F ({model.dofmap.size} dofs): max |u_i| = {umax:.6e}")
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
        from ..fem.forces import add_force_recorder
        forces = add_force_recorder(cfg, out, model, comm)          # -ssi_structure_forces
        if forces is not None:
            forces.record(1.0, u, write=True)
        receivers = receiver_record(model, rec.all_arrays()) if comm.getRank() == 0 else None
        from ..fem.problem import symmetry_attr
        attrs = {"problem": "static", "time_is": "load factor", "symmetry": symmetry_attr(cfg)}
        if grav is not None:
            attrs["gravity"] = grav.g
        out.close(receivers=receivers, attrs=attrs, groups={"gravity": grav.group()} if grav is not None and
                  comm.getRank() == 0 else None,
                  record=provenance(cfg, comm, {"static": {"n_dofs": model.dofmap.size,
                                                           "max_abs_u": float(umax)}}))
        printf(f"[static] wrote {cfg.output} (+ .xmf, .json)")
    return u, model
