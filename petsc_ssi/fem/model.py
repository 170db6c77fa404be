"""The structure a set of options describes: parts, mesh, dof map, K, lumped M, loads, fixed dofs.

``build_model`` is collective and checks every input (parts and their
properties, groups, receivers, point loads) on the replicated mesh before the
matrices are assembled, so a bad input costs no assembly and raises the same
SSIError on every rank. Receivers and point loads snap to the nearest FE node;
one farther away than the largest element size is refused (it lies outside the
structure). At start-up it prints each part's element count, total mass and
rotary inertia, and the structure's total mass.
"""
from dataclasses import dataclass

import numpy as np

from ..petsc import init, SSIError, collective, collective_error, printf
from .assembly import Material, assemble, mass_report
from .dofmap import DofMap
from .loads import fixed_dofs, nodal_load, point_masses
from .mesh import load_mesh, snap_points
from .parts import parse_parts, plausibility
from ..points import parse_points


@dataclass
class Model:
    mesh: object
    dofmap: object               # the dof map (fem/dofmap.py)
    material: object             # legacy Material of a hex8 model without parts, else None
    fixed: np.ndarray            # replicated sorted global dofs
    F: np.ndarray                # replicated global dof array: spatial load [N, N m]
    receivers: np.ndarray        # (R, 3) requested points
    receiver_nodes: np.ndarray   # (R,) nearest nodes
    receiver_dist: np.ndarray    # (R,) snapping distances
    K: object = None             # PETSc Mat
    m: object = None             # PETSc Vec (lumped mass per dof)
    specs: list = None           # [parts.PartSpec]
    point_mass: np.ndarray = None  # replicated global dof array of added point masses [kg, kg m^2]

    def assemble(self):
        """Collective: K and the lumped M (point masses added) of the model."""
        self.K, self.m = assemble(self.mesh, self.material, self.dofmap)
        if self.point_mass is not None and np.any(self.point_mass):
            self.m.getArray()[:] += self.point_mass[self.dofmap.r0:self.dofmap.r1]
        return self.K, self.m

    def coords_vec(self):
        """Collective: node coordinates in the dof layout (translation dofs; rotations 0)."""
        return self.dofmap.nodal_vec(self.mesh.coords)

    def load_vec(self):
        return self.dofmap.vec_from_global(self.F)


def structure_receivers(mesh, text, what="-ssi_receivers"):
    """(points (R, 3), nodes (R,), snapping distances (R,)) of 'x,y,z;...' items (nearest node)
    and 'group:NAME' items (every node of a physical group, in node order)."""
    items = [r.strip() for r in str(text or "").replace("\n", ";").split(";") if r.strip()]
    pts, nodes, dist = [], [], []
    for it in items:
        if it.startswith("group:"):
            name = it[len("group:"):].strip()
            g = mesh.group_nodes(name, what)
            pts.append(mesh.coords[g]); nodes.append(g); dist.append(np.zeros(len(g)))
        else:
            p = parse_points(it, 3, what)
            n, d = snap_points(mesh, p, what)
            pts.append(p); nodes.append(n); dist.append(d)
    if not items:
        return np.zeros((0, 3)), np.zeros(0, np.int64), np.zeros(0)
    return np.concatenate(pts), np.concatenate(nodes).astype(np.int64), np.concatenate(dist)


def _inputs(mesh, cfg, dofmap, receivers_what="-ssi_receivers", receivers=None):
    fixed = fixed_dofs(mesh, cfg.fem_fixed, dofmap)
    F, pdist = nodal_load(mesh, cfg, dofmap)
    pm, mdist = point_masses(mesh, cfg.get("fem_point_mass", ""), dofmap)
    pts, nodes, dist = structure_receivers(mesh, cfg.receivers if receivers is None else receivers, receivers_what)
    return fixed, F, pts, nodes, dist, np.r_[pdist, mdist], pm


def describe_parts(mesh, material=None, log=printf):
    """Rank 0: one line per part (element, cells, mass, rotary inertia) and the total mass."""
    parts, total = mass_report(mesh, material)
    for name, r in parts.items():
        rot = "" if r["element"] == "hex8" else \
            " rotary inertia (rx, ry, rz) = ({:.4g}, {:.4g}, {:.4g}) kg m^2".format(*r["rotary"])
        log(f"[fem] part {name}: {r['cells']} {r['element']} cells, mass {r['mass']:.6g} kg{rot}")
    log(f"[fem] structure: total mass {total:.6g} kg")
    return parts, total


def build_model(cfg, comm, assemble_matrices=True, log=printf, receivers_what="-ssi_receivers", check_mesh=None,
                receivers=None):
    """Collective: parse the parts, read the mesh, check the inputs, then assemble K and M.

    ``receivers``: the structure's receivers ('x,y,z;...'; None: ``cfg.receivers``);
    ``receivers_what``: the option that named them (for its errors);
    ``check_mesh(mesh)``: the caller's own check of the mesh (raises SSIError), run before
    the inputs are checked against it (a structure placed wrong is then named as such, not
    as a receiver outside it)."""
    init()
    specs = None
    with collective(comm, "parsing -ssi_fem_parts"):
        specs = parse_parts(cfg)
    mesh = load_mesh(cfg, comm, specs)
    dofmap = DofMap(mesh.has_rotation(), comm, mesh.released_nodes())
    with collective(comm, "checking the structure's inputs"):
        if check_mesh is not None:
            check_mesh(mesh)
        fixed, F, pts, nodes, dist, pdist, pm = _inputs(mesh, cfg, dofmap, receivers_what, receivers)
    dofmap.set_fixed(fixed)
    fixed = dofmap.fixed                  # the section's constraints are the record of the supports
    counts = ", ".join(f"{n} {k}" for k, n in mesh.element_counts().items())
    log(f"[fem] mesh {mesh.source}: {mesh.n_nodes} nodes ({int(mesh.has_rotation().sum())} with rotations), "
        f"{counts}, {dofmap.size} dofs, {len(fixed)} fixed, groups: {', '.join(mesh.group_names())}")
    if dofmap.released.any():
        rel = [s.name for s in specs if s.props.released]
        log(f"[fem] released joints: {int(dofmap.released.sum())} node(s) where part(s) {', '.join(rel)} meet the "
            "other frame/shell parts carry a second rotation triple (translations tied, rotations released)")
    odd = plausibility(specs, float(np.linalg.norm(np.ptp(mesh.coords, axis=0))) if mesh.n_nodes else 0.0)
    if odd:
        from ..petsc import warn
        warn(odd, comm)
    legacy = all(s.legacy for s in specs)
    mat = Material(cfg.fem_E, cfg.fem_nu, cfg.fem_rho) if legacy else None
    if not legacy:
        describe_parts(mesh, None, log)
        hexnodes = np.zeros(mesh.n_nodes, bool)
        hexnodes[mesh.cells.ravel()] = True
        joined = int(np.sum(hexnodes & dofmap.has_rotation))
        if joined:
            from ..petsc import warn
            warn(f"{joined} node(s) join frames or shells to bricks: bricks carry no moments, so these joints are "
                 "pinned (no moment is transferred); embed the member in the brick over several nodes to clamp it",
                 comm)
    if np.any(pm):
        t = dofmap.node_dofs(np.arange(mesh.n_nodes))[:, 0]
        log(f"[fem] point masses: {pm[t].sum():.6g} kg in all")
    for p, n, d in zip(pts, nodes, dist):
        log(f"[fem] receiver ({p[0]:g}, {p[1]:g}, {p[2]:g}) -> node {n} at "
            f"({mesh.coords[n, 0]:g}, {mesh.coords[n, 1]:g}, {mesh.coords[n, 2]:g}), snapping distance {d:.3g} m")
    for d in pdist:
        log(f"[fem] point load/mass snapped to the nearest node at distance {d:.3g} m")
    model = Model(mesh, dofmap, mat, fixed, F, pts, nodes, dist, specs=specs, point_mass=pm)
    if assemble_matrices:
        model.assemble()
    return model
