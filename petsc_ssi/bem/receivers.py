"""Receivers on the surface mesh: locate, interpolate with the element shape
functions (a sparse PETSc matrix R, y = R u per step: no gather of fields)."""
import numpy as np

from ..petsc import init, SSIError
from ..points import parse_points
from ..mesh import quad9
from . import symmetry


def parse(spec):
    """'x,y,z;...' -> (R, 3) receiver points (the shared parser, petsc_ssi.points)."""
    return parse_points(spec, 3, "-ssi_receivers")


def locate(mesh, p, tol=1e-8):
    """(element, xi, eta) of the surface point nearest to p in plan (x, y) on a plane surface, the
    surface point at p on one that is not (``locate_3d``: a wall, the bottom of an excavation).
    Raises SSIError if p lies off the mesh."""
    if not mesh.flat:
        return locate_3d(mesh, p, tol)
    X = mesh.cell_coords()
    lo = X[:, :, :2].min(1) - 1e-9
    hi = X[:, :, :2].max(1) + 1e-9
    cand = np.where(np.all((p[:2] >= lo) & (p[:2] <= hi), axis=1))[0]
    for e in cand:
        xi = np.zeros(2)
        for _ in range(30):
            N = quad9.shape(xi[0], xi[1])
            d1, d2 = quad9.shape_grad(xi[0], xi[1])
            x = N @ X[e]
            J = np.array([d1 @ X[e][:, :2], d2 @ X[e][:, :2]]).T
            dx = np.linalg.solve(J, p[:2] - x[:2])
            xi += dx
            if np.abs(dx).max() < 1e-13:
                break
        if np.all(np.abs(xi) <= 1 + tol):
            return int(e), float(xi[0]), float(xi[1])
    raise SSIError(f"receiver ({p[0]:g}, {p[1]:g}, {p[2]:g}) lies off the surface mesh")


def locate_3d(mesh, p, tol=1e-8):
    """(element, xi, eta) of the point p on a surface that is not a plane: the first element (in
    element order) whose point nearest to p (Gauss-Newton on |x(xi, eta) - p|) lies inside it and
    within 1e-6 of the mesh's size of p. A point on an edge shared by a wall and the ground is on
    either; its shape functions give the same (continuous) value. SSIError if none holds p."""
    X = mesh.cell_coords()
    h = float(mesh.element_sizes().max())
    near = 1e-6 * max(h, 1.0)
    lo = X.min(1) - near
    hi = X.max(1) + near
    cand = np.where(np.all((p >= lo) & (p <= hi), axis=1))[0]
    for e in cand:
        xi = np.zeros(2)
        for _ in range(50):
            N = quad9.shape(xi[0], xi[1])
            d1, d2 = quad9.shape_grad(xi[0], xi[1])
            J = np.array([d1 @ X[e], d2 @ X[e]]).T            # (3, 2)
            dx = np.linalg.lstsq(J, p - N @ X[e], rcond=None)[0]
            xi = np.clip(xi + dx, -1.5, 1.5)
            if np.abs(dx).max() < 1e-13:
                break
        if np.all(np.abs(xi) <= 1 + tol) and np.linalg.norm(quad9.shape(xi[0], xi[1]) @ X[e] - p) <= near:
            return int(e), float(xi[0]), float(xi[1])
    raise SSIError(f"receiver ({p[0]:g}, {p[1]:g}, {p[2]:g}) lies off the surface mesh (not on the ground, a wall "
                   "or a bottom)")


def operator(comm, mesh, points, planes, ncol_loc):
    """Collective: AIJ matrix (3R x 3N) mapping nodal u to receiver values."""
    PETSc = init()
    R = len(points)
    N = mesh.n_nodes
    rows, cols, vals, where = [], [], [], []
    for k, p in enumerate(points):
        q, s = symmetry.map_point(p, planes)
        e, xi, eta = locate(mesh, q)
        N9 = quad9.shape(xi, eta)
        where.append((e, xi, eta))
        for a in range(9):
            for c in range(3):
                rows.append(3 * k + c); cols.append(3 * mesh.cells[e, a] + c); vals.append(N9[a] * s[c])
    M = PETSc.Mat().createAIJ(size=((PETSc.DECIDE, 3 * R), (ncol_loc, 3 * N)), nnz=(27, 27), comm=comm)
    M.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)
    r0, r1 = M.getOwnershipRange()
    for r, c, v in zip(rows, cols, vals):
        if r0 <= r < r1:
            M.setValue(r, c, v, addv=True)
    M.assemble()
    return M, where


def traction_to_nodes(comm, prob, march):
    """AIJ mapping traction columns to a nodal traction field (for output)."""
    PETSc = init()
    reg = prob.regions
    if not reg.n_t:
        return None
    T = PETSc.Mat().createAIJ(size=((march.u_tmpl.getLocalSize(), 3 * prob.mesh.n_nodes),
                                    (march.p_tmpl.getLocalSize(), 3 * reg.n_t)), nnz=(3, 3), comm=comm)
    T.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)
    r0, r1 = T.getOwnershipRange()
    for k, node in enumerate(reg.tnode):
        for c in range(3):
            if r0 <= 3 * node + c < r1:
                T.setValue(3 * node + c, 3 * k + c, 1.0)
    T.assemble()
    return T
