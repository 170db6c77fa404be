"""The coupled model before assembly: the soil (``bem.halfspace.HalfSpace``), the structure's
model (``fem.model.build_model``, not assembled) and the interface that joins them, every input
checked (``build_coupled``); and the bytes of the coupling's dense interface matrices for the
memory check (``interface_bytes``). Collective."""
import numpy as np

from ..petsc import SSIError, collective, printf
from ..bem.halfspace import HalfSpace, read_soil_surface
from ..bem import symmetry
from ..fem.model import build_model
from .interface import build_interface, fem_symmetry_dofs, fe_interface_faces, ground_tol, interface_offsets
from .step import STRATEGIES


def check_on_surface(mesh, groups, soil=None):
    """SSIError when the structure's interface faces (-ssi_fem_interface) do not lie on the soil's
    surface z = 0 (a structure placed above or below the soil), naming their heights. On a ``soil``
    surface with an excavation the faces below the ground are the interface (walls and bottom: the
    matching names any that miss the soil's nodes); a structure wholly above the ground is refused."""
    excavated = soil is not None and not soil.flat
    z = mesh.coords[np.unique(fe_interface_faces(mesh, groups, excavated)), 2]
    if excavated:
        return
    if np.abs(z).max() > ground_tol(mesh):
        where = "above" if z.min() > 0 else "below" if z.max() < 0 else "off"
        raise SSIError(f"-ssi_fem_interface {groups}: the structure's interface faces lie at z = {z.min():.6g} .. "
                       f"{z.max():.6g} m, {where} the soil's surface z = 0 (they must rest on it: move the "
                       "structure, e.g. -ssi_fem_box_origin, or its mesh)")


def build_coupled(cfg, comm):
    """Collective: the soil problem, the structure's model (not assembled) and the
    interface, all checked. Returns (prob, model, iface, integrator): the last, the structure's time
    integrator that the coupling strategy takes (``step.STRATEGIES``)."""
    from .options import ignored_contact_options
    from ..petsc import warn
    ignored = ignored_contact_options(cfg)
    if ignored:
        warn(f"{' '.join(ignored)} act{'s' if len(ignored) == 1 else ''} only with -ssi_contact unilateral; "
             f"ignored (the interface is {cfg.contact})", comm)
    planes = symmetry.parse(cfg.symmetry)
    mesh = read_soil_surface(cfg, comm, planes)
    if not mesh.flat and cfg.contact == "unilateral" and cfg.contact_separation == "free":
        warn("-ssi_contact unilateral on a surface with an excavation with -ssi_contact_separation free: the active "
             "set is known not to settle there (a wall node in tension whose released shear pushes it into the "
             "soil has no consistent status; a stiff block in a 2 x 2 x 1 m pit under a horizontal pulse cycled at "
             "48 of 56 steps); -ssi_contact_separation auto keeps such a node's tangential bond and settles", comm)
    model = build_model(cfg, comm, assemble_matrices=False, receivers=cfg.structure_receivers,
                        receivers_what="-ssi_structure_receivers",
                        check_mesh=lambda fe: check_on_surface(fe, cfg.fem_interface, mesh))
    iface = sym = None
    with collective(comm, "matching the interface"):
        iface = build_interface(mesh, model.mesh, cfg.interface, cfg.fem_interface, cfg.interface_tol,
                                planes, float(mesh.element_sizes().max()))
        sym = fem_symmetry_dofs(model.mesh, planes, dofmap=model.dofmap)
        if cfg.interface_offset and not np.abs(interface_offsets(model.mesh, iface, cfg.fem_interface)).any():
            raise SSIError(f"-ssi_interface_offset: the interface (-ssi_fem_interface {cfg.fem_interface}) has no "
                           "shell slab nodes; the offset applies to a shell foundation slab only and does nothing "
                           "here: drop it")
    # the soil with its interface: the structure's tractions, the seismic control point, points of interest
    prob = HalfSpace(cfg, comm, log=printf, mesh=mesh, interface=iface,
                     record_scheme=STRATEGIES[cfg.coupling].record_scheme)
    model.fixed = np.union1d(model.fixed, sym).astype(np.int64)
    model.dofmap.set_fixed(model.fixed)
    return prob, model, iface, STRATEGIES[cfg.coupling].integrator


def interface_bytes(cfg, prob, model, iface, ranks):
    """Estimated bytes of the coupling's dense interface matrices over all ranks: the local rows
    of Z = A^-1 H_s E_I (soil dofs x 3 n_I; the region's, ``columns.estimated_region_nodes``, and then the
    region's LU factors, fill_bytes n ln n of its n DOFs, toeplitz.RATES) and, implicit, of D^-1 T^T (structure dofs x 3 n_I);
    on every rank Z_II, M3, C (3 n_I)^2 each and the interface LUs (one bonded; a cache of at
    most 512 MB with unilateral contact)."""
    from .columns import estimated_region_nodes
    n = 3 * iface.n
    nz = estimated_region_nodes(cfg, prob, iface.be_nodes)
    b = 8.0 * 3 * nz * n + 3 * 8.0 * n * n * ranks
    if nz < prob.mesh.n_nodes:          # the region's own LU beside the step matrix's, during the set-up
        import math
        from ..bem.toeplitz import RATES
        b += RATES["fill_bytes"] * 3 * nz * math.log(max(3 * nz, 2))
    if cfg.coupling == "implicit":
        b += 8.0 * model.dofmap.size * n + 8.0 * n * n * ranks
    lu = 8.0 * n * n
    b += ranks * (max(lu, 512e6) if cfg.contact == "unilateral" else lu)
    return b
