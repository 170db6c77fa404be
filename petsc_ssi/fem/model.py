"""The structure a set of options describes: mesh, K, lumped M, loads, fixed dofs.

``build_model`` is collective and checks every input (groups, receivers,
point loads) on the replicated mesh before the matrices are assembled, so a
bad input costs no assembly and raises the same SSIError on every rank.
Receivers and point loads snap to the nearest FE node; one farther away than
the largest element size is refused (it lies outside the structure).
"""
from dataclasses import dataclass

import numpy as np

from ..petsc import init, SSIError, collective_error, printf
from .assembly import Layout, Material, assemble
from .loads import fixed_dofs, nodal_load, restrains_rigid_motion
from .mesh import load_mesh, snap_points
from ..points import parse_points


@dataclass
class Model:
    mesh: object
    layout: object
    material: object
    fixed: np.ndarray            # replicated sorted global dofs
    F: np.ndarray                # replicated (N, 3) spatial load [N]
    receivers: np.ndarray        # (R, 3) requested points
    receiver_nodes: np.ndarray   # (R,) nearest nodes
    receiver_dist: np.ndarray    # (R,) snapping distances
    K: object = None             # PETSc Mat
    m: object = None             # PETSc Vec (lumped mass per dof)

    def coords_vec(self):
        return self.layout.nodal_vec(self.mesh.coords)

    def load_vec(self):
        return self.layout.nodal_vec(self.F)

    def constrained(self):
        return restrains_rigid_motion(self.mesh.coords, self.fixed)


def _inputs(mesh, cfg):
    fixed = fixed_dofs(mesh, cfg.fem_fixed)
    F, pdist = nodal_load(mesh, cfg)
    pts = parse_points(cfg.receivers, 3, "-ssi_receivers")
    nodes, dist = snap_points(mesh, pts, "-ssi_receivers")
    return fixed, F, pts, nodes, dist, pdist


def build_model(cfg, comm, assemble_matrices=True, log=printf):
    """Collective: read the mesh, check the inputs, then assemble K and M."""
    init()
    mesh = load_mesh(cfg, comm)
    err = None
    try:
        fixed, F, pts, nodes, dist, pdist = _inputs(mesh, cfg)
    except SSIError as exc:
        err = str(exc)
    collective_error(err, comm)
    log(f"[fem] mesh {mesh.source}: {mesh.n_nodes} nodes, {mesh.n_cells} hex8, {3 * mesh.n_nodes} dofs, "
        f"{len(fixed)} fixed, groups: {', '.join(mesh.group_names())}")
    for p, n, d in zip(pts, nodes, dist):
        log(f"[fem] receiver ({p[0]:g}, {p[1]:g}, {p[2]:g}) -> node {n} at "
            f"({mesh.coords[n, 0]:g}, {mesh.coords[n, 1]:g}, {mesh.coords[n, 2]:g}), snapping distance {d:.3g} m")
    for d in pdist:
        log(f"[fem] point load snapped to the nearest node at distance {d:.3g} m")
    mat = Material(cfg.fem_E, cfg.fem_nu, cfg.fem_rho)
    model = Model(mesh, Layout(mesh.n_nodes, comm), mat, fixed, F, pts, nodes, dist)
    if assemble_matrices:
        model.K, model.m = assemble(mesh, mat, model.layout)
    return model
