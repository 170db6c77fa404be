r"""The free term c_lk of the boundary integral equation at every node
(paper eq. 4; Hartmann 1980, 1981), for smooth points, edges and corners.

Shrinking a ball around the collocation point xi, the static traction kernel
on the part of the sphere inside the domain gives

    c_lk = 1/(8 pi (1-nu)) \int_D [ (1-2nu) d_lk + 3 d_l d_k ] dOmega(d),

with D the cone of unit directions d pointing from xi into the domain (for a
smooth surface D is a half-sphere and c = I/2; for the whole space c = I). So
c needs the solid angle |D| and the second moment M = \int_D d d^T dOmega of
the interior cone. The cone is bounded by the surface's tangent sectors at the
node: each element containing the node contributes the sector between its two
edge directions at the node (a half-plane for a mid-side node, nothing for a
centre node), oriented counter-clockwise about its outward normal; chained,
they form a closed loop of great-circle arcs on the unit sphere. D is the
region of the sphere bounded by that loop on the side away from the normals;
it is split into spherical triangles fanned from an interior direction (minus
the mean normal) and integrated exactly in the mapping from the flat triangle
(a, b, c) to the sphere, d = P/|P|, dOmega = det(a, b, c)/|P|^3 du dv,
with Gauss quadrature (the integrand is smooth).

Nodes whose sectors do not close (the truncation edge of an open half-space
mesh) get the smooth value I/2 if the elements there agree on the normal (the
surface is assumed to continue in its tangent plane); otherwise an error.
"""
import numpy as np

from ..petsc import SSIError
from ..mesh import quad9
from ..mesh.surface import segment_sizes

# parameter-plane sector of each local node: (start, end, middle or None)
_SECTORS = {0: ((1, 0), (0, 1), None), 1: ((0, 1), (-1, 0), None), 2: ((-1, 0), (0, -1), None),
            3: ((0, -1), (1, 0), None), 4: ((1, 0), (-1, 0), (0, 1)), 5: ((0, 1), (0, -1), (-1, 0)),
            6: ((-1, 0), (1, 0), (0, -1)), 7: ((0, -1), (0, 1), (1, 0))}


def _tri_rule(n=16):
    """Gauss rule on the unit triangle (collapsed square): points (u, v), weights."""
    g, w = np.polynomial.legendre.leggauss(n)
    x = 0.5 * (g + 1)
    wx = 0.5 * w
    U, V = np.meshgrid(x, x, indexing="ij")
    W = np.outer(wx, wx) * (1 - U)
    return U.ravel(), (V * (1 - U)).ravel(), W.ravel()


_U, _V, _W = _tri_rule(32)


def _refine(loop, parts=4):
    """Split every great-circle arc of the loop into ``parts`` (normalised
    interpolation stays on the arc): smaller fan triangles, better quadrature."""
    out = []
    for b, c in zip(loop, np.roll(loop, -1, axis=0)):
        for t in np.arange(parts) / parts:
            v = (1 - t) * b + t * c
            out.append(v / np.linalg.norm(v))
    return np.array(out)


def cone_moments(loop, apex):
    """|D| and M for the spherical polygon ``loop`` (unit vectors, closed,
    arcs < pi) seen from ``apex``: signed sums over fan triangles."""
    loop = _refine(np.asarray(loop, float))
    area = 0.0
    M = np.zeros((3, 3))
    a = apex / np.linalg.norm(apex)
    for b, c in zip(loop, np.roll(loop, -1, axis=0)):
        det = np.dot(a, np.cross(b, c))
        P = a[None, :] + _U[:, None] * (b - a)[None, :] + _V[:, None] * (c - a)[None, :]
        r = np.linalg.norm(P, axis=1)
        d = P / r[:, None]
        w = _W * det / r ** 3
        area += w.sum()
        M += np.einsum("q,qi,qj->ij", w, d, d)
    return area, M


def free_term_from_cone(area, M, nu):
    return ((1 - 2 * nu) * area * np.eye(3) + 3 * M) / (8 * np.pi * (1 - nu))


# shape-function derivatives at the nine nodes: _D1[a, k] = dN_k/dxi at node a
_D1, _D2 = quad9.shape_grad(quad9.NODE_XI[:, 0], quad9.NODE_XI[:, 1])


def _sectors(X, a):
    """Unit arc directions (start, [mid,] end) of element X's sector at node a,
    and the unit outward normal there."""
    xi, eta = quad9.NODE_XI[a]
    d1, d2 = quad9.shape_grad(np.array(xi), np.array(eta))
    J = np.stack([d1 @ X, d2 @ X], 1)           # (3, 2): dx/dxi, dx/deta
    n = np.cross(J[:, 0], J[:, 1])
    n /= np.linalg.norm(n)
    if a == 8:
        return None, n
    s, e, m = _SECTORS[a]
    pts = [s] + ([m] if m is not None else []) + [e]
    dirs = [J @ np.array(p, float) for p in pts]
    return [v / np.linalg.norm(v) for v in dirs], n


def node_normals(VX):
    """Unit outward normals (n_elem, 9, 3) of every element of ``VX`` (n_elem, 9, 3) at each of its
    nine nodes, vectorised (the normal ``_sectors`` computes for one element and node)."""
    t1 = np.einsum("ak,vkd->vad", _D1, VX)
    t2 = np.einsum("ak,vkd->vad", _D2, VX)
    n = np.cross(t1, t2)
    return n / np.linalg.norm(n, axis=-1, keepdims=True)


def free_terms(VX, VN, n_nodes, nu, tol=1e-8, smooth_deg=1e-6, nodes=None):
    """c (n_nodes, 3, 3) from the virtual elements (mesh + symmetry images),
    for ``nodes`` (default all; the others stay 0).

    A node's elements are those that list it and meet it: an image element lists the node's number
    at the node's mirror image, which is the node itself only on the symmetry plane. The node's place
    is that of the first element listing it (``symmetry.virtual_elements`` puts the mesh's own
    elements first); an element meets it within twice the on-plane tolerance of
    ``symmetry.zero_dofs`` (a node within 1e-9 max(h, 1) of a plane is on it, h the mesh's
    ``element_sizes``), so the free term and the zeroed DOFs see the same nodes on the planes. Nodes
    where their elements' normals agree to ``smooth_deg`` get I/2 exactly (found for all nodes at
    once, vectorised); the others get the cone formula, and must close their fan."""
    c = np.zeros((n_nodes, 3, 3))
    sel = np.arange(n_nodes) if nodes is None else np.asarray(nodes, dtype=np.int64).ravel()
    if sel.size == 0:
        return c
    flat = np.asarray(VN, dtype=np.int64).ravel()
    if flat.size and (flat.min() < 0 or flat.max() >= n_nodes):
        raise ValueError(f"free_terms: element node indices in [{flat.min()}, {flat.max()}], outside [0, {n_nodes})")
    order = np.argsort(flat, kind="stable")          # each node's incidences, in (element, local node) order
    counts = np.bincount(flat, minlength=n_nodes)[:n_nodes]
    start = np.concatenate([[0], np.cumsum(counts)[:-1]])
    lonely = sel[counts[sel] == 0]
    if lonely.size:
        raise SSIError(f"node {int(lonely[0])} belongs to no element: no free term can be defined")
    VX = np.asarray(VX, float)
    first = np.minimum(start, max(len(order) - 1, 0))             # each node's first incidence
    pos = VX.reshape(-1, 3)[order]
    h = float(segment_sizes(VX).max()) if len(VX) else 1.0
    meets = np.linalg.norm(pos - np.repeat(pos[first], counts, axis=0), axis=1) <= 2e-9 * max(h, 1.0)
    nrm = node_normals(VX).reshape(-1, 3)
    dots = np.einsum("id,id->i", nrm[order], np.repeat(nrm[order[first]], counts, axis=0))
    dots[~meets] = np.inf                            # an image element elsewhere: not this node's
    has = counts > 0
    mind = np.full(n_nodes, np.inf)
    mind[has] = np.minimum.reduceat(dots, start[has])
    smooth = mind >= min(np.cos(np.radians(smooth_deg)), 1 - 1e-12)
    c[sel[smooth[sel]]] = 0.5 * np.eye(3)
    for i in sel[~smooth[sel]]:
        inc = order[start[i]:start[i] + counts[i]][meets[start[i]:start[i] + counts[i]]]
        arcs, normals = [], []
        for v, a in zip(inc // 9, inc % 9):
            dirs, n = _sectors(VX[v], a)
            normals.append(n)
            if dirs is not None:
                arcs.append(dirs)
        N = np.array(normals)
        loop = _chain(arcs, tol)
        if loop is None:
            raise SSIError(f"node {i}: the surface is not smooth there and its elements do not close "
                           f"around it (a kink on the mesh boundary): no free term can be defined")
        apex = -N.mean(0)
        area, M = cone_moments(np.array(loop), apex)
        if area < 0:
            area, M = -area, -M
        if not 0 < area < 4 * np.pi:
            raise SSIError(f"node {i}: the interior cone has solid angle {area:.4g} outside (0, 4 pi)")
        c[i] = free_term_from_cone(area, M, nu)
    return c


def _chain(arcs, tol):
    """Chain sector arcs end-to-start into one closed loop of vertices."""
    if not arcs:
        return None
    left = list(range(1, len(arcs)))
    loop = list(arcs[0][:-1])
    end = arcs[0][-1]
    while left:
        for k in left:
            if np.linalg.norm(arcs[k][0] - end) < tol:
                loop += list(arcs[k][:-1])
                end = arcs[k][-1]
                left.remove(k)
                break
        else:
            return None
    if np.linalg.norm(end - loop[0]) > tol:
        return None
    return loop
