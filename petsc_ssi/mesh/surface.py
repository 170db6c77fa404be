"""Surface meshes of nine-node quadrilaterals for the half-space BEM.

``SurfaceMesh``: nodes (N, 3), cells (E, 9) in gmsh order, named element
groups. ``grid`` builds a structured mesh (tests, quick runs); ``read_gmsh``
reads a .geo/.msh through the gmsh Python API.
"""
import numpy as np

from ..petsc import SSIError
from . import quad9


def segment_sizes(X):
    """``SurfaceMesh.element_sizes`` of the nine-node elements' coordinates X (E, 9, 3)."""
    X = np.asarray(X, float)
    seg = lambda pairs: np.max([np.linalg.norm(X[:, a] - X[:, b], axis=1) for a, b in pairs], axis=0)  # noqa: E731
    s1 = seg(((0, 4), (4, 1), (3, 6), (6, 2), (7, 8), (8, 5)))
    s2 = seg(((0, 7), (7, 3), (1, 5), (5, 2), (4, 8), (8, 6)))
    return np.stack([s1, s2], 1)


class SurfaceMesh:
    def __init__(self, nodes, cells, groups=None, name=""):
        self.nodes = np.ascontiguousarray(nodes, dtype=float)
        self.cells = np.ascontiguousarray(cells, dtype=np.int64)
        self.groups = {k: np.asarray(v, dtype=np.int64) for k, v in (groups or {}).items()}
        self.name = name

    @property
    def n_nodes(self):
        return self.nodes.shape[0]

    @property
    def n_cells(self):
        return self.cells.shape[0]

    def cell_coords(self):
        return self.nodes[self.cells]          # (E, 9, 3)

    def centres(self):
        return self.nodes[self.cells[:, 8]]

    def select(self, spec):
        """Element ids of a group name or 'box:x0,x1,y0,y1' (centres inside)."""
        if spec.startswith("box:"):
            try:
                x0, x1, y0, y1 = (float(v) for v in spec[4:].split(","))
            except ValueError:
                raise SSIError(f"'{spec}': a box is 'box:x0,x1,y0,y1'") from None
            c = self.centres()
            sel = np.where((c[:, 0] >= x0) & (c[:, 0] <= x1) & (c[:, 1] >= y0) & (c[:, 1] <= y1))[0]
            if sel.size == 0:
                raise SSIError(f"'{spec}': no element centre lies in the box")
            return sel
        if spec not in self.groups:
            raise SSIError(f"element group '{spec}' is not in the mesh (groups: "
                           f"{', '.join(sorted(self.groups)) or 'none'})")
        return self.groups[spec]

    def element_sizes(self):
        """Distance between neighbouring nodes in each element direction (E, 2): the largest of the
        six node-to-node segments along xi (both sides and the midline), and along eta, so that a
        distorted element (an O-grid's) is measured by its longest segment, whatever its node 0."""
        return segment_sizes(self.cell_coords())

    def node_spacing(self):
        """Each node's spacing (N,) [m]: the smallest, over the elements it belongs to, of the element's size in
        its shorter direction (``element_sizes``); the largest element's where a node belongs to none."""
        sizes = self.element_sizes()
        out = np.full(self.n_nodes, float(sizes.max()) if len(sizes) else 1.0)
        if len(sizes):
            np.minimum.at(out, self.cells.ravel(), np.repeat(sizes.min(axis=1), self.cells.shape[1]))
        return out

    # ---------------------------------------------------------------- what the boundary is
    def in_plane(self, rel=1e-9):
        """Whether every node lies on the plane z = 0, within ``rel`` of the mesh's plan extent."""
        ext = float(np.ptp(self.nodes[:, :2], axis=0).max()) if self.n_nodes else 1.0
        return bool(self.n_nodes == 0 or np.abs(self.nodes[:, 2]).max() <= rel * (ext or 1.0))

    def require_plane(self, what, why):
        """SSIError (naming the highest or deepest node) unless every node lies on z = 0 (``in_plane``);
        then put them on it exactly. ``what``: the input named in the error; ``why``: what needs
        the plane. The one place a soil surface is held to z = 0."""
        if not self.in_plane():
            k = int(np.abs(self.nodes[:, 2]).argmax())
            raise SSIError(f"{what}: the surface mesh must lie in the plane z = 0 (the free surface of the "
                           f"half-space z < 0: {why}); node {k} is at z = {self.nodes[k, 2]:.6g} m")
        self.nodes[:, 2] = 0.0

    @property
    def flat(self):
        """Whether the surface is the plane z = 0 exactly (every node's z is 0)."""
        return bool(np.all(self.nodes[:, 2] == 0.0))

    def node_normals(self):
        """Unit normals (N, 3) at the nodes, out of the soil: the mean of the unit normals of the
        elements that share each node (at an edge or a corner a mean direction; ``kinks`` says
        where the surface is not smooth)."""
        X = self.cell_coords()
        xi = quad9.NODE_XI
        _, jn = quad9.geometry(X[:, None, :, :], xi[None, :, 0], xi[None, :, 1])
        n = jn / np.linalg.norm(jn, axis=-1, keepdims=True)          # (E, 9, 3)
        acc = np.zeros((self.n_nodes, 3))
        np.add.at(acc, self.cells.ravel(), n.reshape(-1, 3))
        return acc / np.linalg.norm(acc, axis=1, keepdims=True)

    def edges_and_corners(self, planes=(), max_angle_deg=1.0):
        """(node ids, angles deg) where the surface is not smooth (``kinks``)."""
        return kinks(self, planes, max_angle_deg)

    def check(self):
        """Validate a nine-node surface: conforming ids, positive orientation."""
        if self.cells.ndim != 2 or self.cells.shape[1] != 9:
            raise SSIError("the surface mesh must consist of nine-node quadrilaterals")
        if self.cells.min() < 0 or self.cells.max() >= self.n_nodes:
            raise SSIError("the surface mesh refers to nodes that do not exist")
        X = self.cell_coords()
        _, jn = quad9.geometry(X, np.array([0.0]), np.array([0.0]))
        jn = jn[:, 0, :]
        if np.any(np.linalg.norm(jn, axis=1) <= 0):
            raise SSIError("the surface mesh has degenerate elements")
        used = np.zeros(self.n_nodes, bool)
        used[self.cells.ravel()] = True
        if not used.all():
            raise SSIError(f"the surface mesh has {int((~used).sum())} nodes in no element")


_EDGE_MID = (4, 5, 6, 7)          # mid-side node of element edge k (corner k -> corner k + 1)


def element_edges(cells):
    """{(min(p, q), max(p, q)): [(element, p, q, mid), ...]} of every element edge (corners p -> q in
    the element's own direction, ``mid`` its mid-side node)."""
    owners = {}
    for e, c in enumerate(np.asarray(cells)):
        for k in range(4):
            p, q = int(c[k]), int(c[(k + 1) % 4])
            owners.setdefault((min(p, q), max(p, q)), []).append((e, p, q, int(c[_EDGE_MID[k]])))
    return owners


def _loops(edges):
    """Connected pieces of a set of edges (p, q): the number of boundary loops."""
    parent = {}

    def find(a):
        while parent.setdefault(a, a) != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a
    for p, q in edges:
        parent[find(p)] = find(q)
    return len({find(a) for a in parent})


def check_excavation(mesh, what, planes=()):
    """SSIError in one line unless a surface that is not a plane is one the half-space can take: the
    ground z = 0 with excavations below it (walls and bottoms), a conforming surface (an element edge
    shared by two elements, or by one on the mesh's outer edge), whose free edges form one loop on the
    ground z = 0 (an excavation that does not close on the ground leaves a hole: a second loop; walls
    that meet the mesh's edge leave free edges below z = 0), and whose normals point out of the soil
    (neighbours run their shared edge in opposite directions; the ground faces +z). ``what``: the
    input named in the error. ``read_gmsh`` orients a .geo/.msh surface first (``orient_out_of_soil``);
    a mesh made otherwise must come oriented. ``planes``: symmetry planes ((axis, kind), ...): the part
    modelled is cut there, and its free edges on a plane (below the ground too) are the cut, not a hole."""
    x = mesh.nodes
    ext = float(np.ptp(x, axis=0).max()) if mesh.n_nodes else 1.0
    tol = 1e-9 * max(ext, 1.0)
    k = int(x[:, 2].argmax())
    if x[k, 2] > tol:
        raise SSIError(f"{what}: node {k} at ({x[k, 0]:.6g}, {x[k, 1]:.6g}, {x[k, 2]:.6g}) m lies above the ground "
                       "z = 0 (the soil is z < 0 with excavations below the ground; a hill is not supported)")
    owners = element_edges(mesh.cells)
    for key, own in owners.items():
        if len(own) > 2:
            raise SSIError(f"{what}: an element edge (nodes {key[0]}, {key[1]}) is shared by {len(own)} elements: "
                           "not a surface")
    free = []
    for key, own in owners.items():
        if len(own) == 1:
            free.append(own[0])
            continue
        (e, p, q, _), (f, p2, q2, _) = own
        if p == p2:                    # the same direction: one of the two faces the wrong way
            raise SSIError(f"{what}: the normals of elements {e} and {f} disagree across their shared edge (one "
                           "points into the soil); orient every element out of the soil")
    lo, hi = x[:, :2].min(0), x[:, :2].max(0)
    for e, p, q, m in free:
        for a in (p, m, q):
            if x[a, 2] >= -tol or any(abs(x[a, ax]) <= tol for ax, _ in planes):
                continue
            where = f"({x[a, 0]:.6g}, {x[a, 1]:.6g}, {x[a, 2]:.6g}) m"
            if np.any(np.abs(x[a, :2] - lo) <= tol) or np.any(np.abs(x[a, :2] - hi) <= tol):
                raise SSIError(f"{what}: the excavation meets the mesh's edge: element {e} has a free edge at {where} "
                               "below the ground; keep the walls inside the ground (an excavation closed on every "
                               "side)")
            raise SSIError(f"{what}: the surface does not close: element {e} has a free edge at {where} below the "
                           "ground (a wall or bottom missing)")
    n_loops = _loops([(p, q) for _, p, q, _ in free])
    if n_loops != 1:
        e, p, q, m = free[0]
        raise SSIError(f"{what}: the surface does not close: its free element edges form {n_loops} loops, not the "
                       "one outer edge of the ground (a hole in the ground, or walls and bottom that do not meet it)")
    from . import quad9 as q9
    _, jn = q9.geometry(mesh.cell_coords(), np.array([0.0]), np.array([0.0]))
    n = jn[:, 0] / np.linalg.norm(jn[:, 0], axis=1, keepdims=True)
    ground = np.abs(mesh.cell_coords()[..., 2]).max(1) <= tol
    bad = np.nonzero(ground & (n[:, 2] < 0))[0]
    if len(bad):
        c = mesh.centres()[bad[0]]
        raise SSIError(f"{what}: the normals point into the soil ({len(bad)} ground elements face -z, element "
                       f"{bad[0]} at ({c[0]:.6g}, {c[1]:.6g}, 0) m); the soil's normals point out of it (+z on the "
                       "ground)")
    if not ground.any():
        raise SSIError(f"{what}: no element lies on the ground z = 0")


def kinks(mesh, planes=(), max_angle_deg=1.0):
    """Nodes where the surface is not smooth: the unit normals of the elements
    sharing the node differ by more than ``max_angle_deg`` (an edge or a
    corner), or, on a symmetry plane, the normal is not parallel to the plane
    (the mirrored surface would fold there). Returns (node ids, angles deg)."""
    X = mesh.cell_coords()
    xi = quad9.NODE_XI
    _, jn = quad9.geometry(X[:, None, :, :], xi[None, :, 0], xi[None, :, 1])
    n = jn / np.linalg.norm(jn, axis=-1, keepdims=True)          # (E, 9, 3)
    nodes = mesh.cells.ravel()
    nn = n.reshape(-1, 3)
    order = np.argsort(nodes, kind="stable")
    nodes, nn = nodes[order], nn[order]
    first = np.r_[0, np.nonzero(np.diff(nodes))[0] + 1]
    ref = np.repeat(nn[first], np.diff(np.r_[first, len(nodes)]), axis=0)
    cosang = np.clip(np.einsum("ij,ij->i", nn, ref), -1.0, 1.0)
    worst = np.minimum.reduceat(cosang, first)
    ang = np.degrees(np.arccos(worst))
    x = mesh.nodes[nodes[first]]
    h = float(mesh.element_sizes().max())
    for ax, _ in planes:
        on = np.abs(x[:, ax]) <= 1e-9 * max(h, 1.0)
        tilt = np.degrees(2 * np.arcsin(np.clip(np.abs(nn[first][:, ax]), 0, 1)))
        ang = np.where(on, np.maximum(ang, tilt), ang)
    bad = ang > max_angle_deg
    return nodes[first][bad], ang[bad]


def _graded(s, at_start, at_end, grade):
    """Positions in [0, 1] of the uniform parameters s, clustered toward the ends that are cuts:
    (1 - grade) s + grade phi(s), phi the cosine map that clusters at those ends (phi'(end) = 0)."""
    if at_start and at_end:
        phi = 0.5 * (1.0 - np.cos(np.pi * s))
    elif at_start:
        phi = 1.0 - np.cos(0.5 * np.pi * s)
    elif at_end:
        phi = np.sin(0.5 * np.pi * s)
    else:
        return s
    return (1.0 - grade) * s + grade * phi


def _lines(lo, hi, h, cuts, grade=0.0):
    """Grid lines from lo to hi of spacing about h, passing through cuts; ``grade`` in [0, 1]
    clusters them toward the cuts at the same number of lines (0: uniform, 1: cosine)."""
    inner = {c for c in cuts if lo < c < hi}
    pts = sorted({lo, hi, *inner})
    out = [pts[0]]
    for a, b in zip(pts[:-1], pts[1:]):
        n = max(1, int(round((b - a) / h)))
        s = np.linspace(0.0, 1.0, n + 1)[1:]
        if grade > 0.0:
            s = _graded(s, a in inner, b in inner, grade)
            s[-1] = 1.0
        out += list(a + (b - a) * s)
    return np.array(out)


def grid(Lx, Ly, h, patch=None, xmin=None, ymin=None, grade=0.0):
    """Structured nine-node mesh of [xmin, Lx/2] x [ymin, Ly/2] (z = 0).

    Defaults: centred at the origin. With ``patch=(a, b)`` the grid lines
    pass through x = +-a, y = +-b and the elements inside form group 'load'.
    ``grade`` (0 to 1, -ssi_mesh_grade) clusters the grid lines toward the patch's edges at the
    same number of elements (a rigid footing's tractions are singular there): on each stretch
    between grid ends and patch edges, the lines sit at (1 - grade) s + grade phi(s) of it, s
    uniform and phi the cosine map that clusters at the stretch's ends that are patch edges.
    Outward normal +z (soil below).
    """
    x0 = -Lx / 2 if xmin is None else xmin
    y0 = -Ly / 2 if ymin is None else ymin
    cx = cy = ()
    if patch is not None:
        cx, cy = (-patch[0], patch[0]), (-patch[1], patch[1])
    if grade and patch is None:
        raise ValueError("grid: grading (-ssi_mesh_grade) needs a patch (-ssi_mesh_patch) whose edges it refines")
    xs = _lines(x0, Lx / 2, h, cx, grade)
    ys = _lines(y0, Ly / 2, h, cy, grade)
    nx, ny = len(xs) - 1, len(ys) - 1
    # node lines including mid-points
    xn = np.empty(2 * nx + 1); xn[0::2] = xs; xn[1::2] = 0.5 * (xs[:-1] + xs[1:])
    yn = np.empty(2 * ny + 1); yn[0::2] = ys; yn[1::2] = 0.5 * (ys[:-1] + ys[1:])
    X, Y = np.meshgrid(xn, yn, indexing="ij")
    nodes = np.stack([X.ravel(), Y.ravel(), np.zeros(X.size)], 1)
    idx = lambda i, j: i * (2 * ny + 1) + j
    cells = []
    for i in range(nx):
        for j in range(ny):
            I, J = 2 * i, 2 * j
            cells.append([idx(I, J), idx(I + 2, J), idx(I + 2, J + 2), idx(I, J + 2),
                          idx(I + 1, J), idx(I + 2, J + 1), idx(I + 1, J + 2), idx(I, J + 1),
                          idx(I + 1, J + 1)])
    cells = np.array(cells, dtype=np.int64)
    groups = {"surface": np.arange(len(cells))}
    if patch is not None:
        c = nodes[cells[:, 8]]
        groups["load"] = np.where((np.abs(c[:, 0]) < patch[0]) & (np.abs(c[:, 1]) < patch[1]))[0]
    return SurfaceMesh(nodes, cells, groups, name="grid")


def _quad9(corner, du, dv):
    """The nine nodes (9, 3) of x = corner + (1 + xi)/2 du + (1 + eta)/2 dv (gmsh order; normal du x dv)."""
    c, du, dv = (np.asarray(v, float) for v in (corner, du, dv))
    return c + 0.5 * (1 + quad9.NODE_XI[:, :1]) * du + 0.5 * (1 + quad9.NODE_XI[:, 1:]) * dv


def pit(Lx, Ly, h, a, b, d, xc=0.0, yc=0.0, planes=()):
    """Structured nine-node mesh of the ground [-Lx/2, Lx/2] x [-Ly/2, Ly/2] (z = 0) with a rectangular
    excavation [xc - a, xc + a] x [yc - b, yc + b] of depth d (a basement's pit; a long narrow one, a
    << b, off the centre, is an open trench: runs/trench): its four vertical walls and its bottom
    z = -d. The excavation stays inside the ground (a trench across the whole ground is not this).
    Normals point out of the soil: +z on the ground and the bottom, into the pit on the walls (-x on
    x = xc + a, +x on x = xc - a, -y on y = yc + b, +y on y = yc - b). Grid lines pass through
    x = xc +- a, y = yc +- b; the walls take about d/h elements down. Groups: 'ground', 'walls',
    'bottom', 'pit' (walls and bottom), 'surface'. ``planes``: symmetry planes ((axis, kind), ...) through the
    opening's centre: only the part x >= 0 (y >= 0) is meshed, the grid's lines passing through the plane."""
    if not (0 < a and 0 < b and d > 0 and h > 0 and -Lx / 2 < xc - a and xc + a < Lx / 2
            and -Ly / 2 < yc - b and yc + b < Ly / 2):
        raise SSIError(f"pit: need a, b, d, h > 0 and the opening [x - a, x + a] x [y - b, y + b] inside the ground "
                       f"[-Lx/2, Lx/2] x [-Ly/2, Ly/2] (got Lx {Lx:g}, Ly {Ly:g}, a {a:g}, b {b:g}, d {d:g}, h {h:g}, "
                       f"x {xc:g}, y {yc:g})")
    xa, xb, ya, yb = xc - a, xc + a, yc - b, yc + b
    axes = [ax for ax, _ in planes]
    if (0 in axes and xc != 0.0) or (1 in axes and yc != 0.0):
        raise SSIError(f"pit: a symmetry plane must pass through the opening's centre (x {xc:g}, y {yc:g})")
    xs = _lines(0.0 if 0 in axes else -Lx / 2, Lx / 2, h, (xa, xb))
    ys = _lines(0.0 if 1 in axes else -Ly / 2, Ly / 2, h, (ya, yb))
    zs = _lines(-d, 0.0, h, ())
    X, kind = [], []
    for x0, x1 in zip(xs[:-1], xs[1:]):
        for y0, y1 in zip(ys[:-1], ys[1:]):
            inside = xa < 0.5 * (x0 + x1) < xb and ya < 0.5 * (y0 + y1) < yb
            X.append(_quad9([x0, y0, -d if inside else 0.0], [x1 - x0, 0, 0], [0, y1 - y0, 0]))
            kind.append("bottom" if inside else "ground")
    for z0, z1 in zip(zs[:-1], zs[1:]):
        dz = z1 - z0
        for y0, y1 in zip(ys[:-1], ys[1:]):
            if ya < 0.5 * (y0 + y1) < yb:
                X.append(_quad9([xb, y0, z0], [0, 0, dz], [0, y1 - y0, 0]))      # -x
                kind.append("walls")
                if 0 not in axes:
                    X.append(_quad9([xa, y0, z0], [0, y1 - y0, 0], [0, 0, dz]))     # +x
                    kind.append("walls")
        for x0, x1 in zip(xs[:-1], xs[1:]):
            if xa < 0.5 * (x0 + x1) < xb:
                X.append(_quad9([x0, yb, z0], [x1 - x0, 0, 0], [0, 0, dz]))      # -y
                kind.append("walls")
                if 1 not in axes:
                    X.append(_quad9([x0, ya, z0], [0, 0, dz], [x1 - x0, 0, 0]))     # +y
                    kind.append("walls")
    X = np.array(X)
    scale = max(Lx, Ly, d)
    nodes, inv = np.unique(np.round(X.reshape(-1, 3) / (1e-9 * scale)), axis=0, return_inverse=True)
    coords = nodes * (1e-9 * scale)
    for k, lines in enumerate((xs, ys, zs)):        # exactly on the grid's node lines (mid-points too)
        ln = np.r_[lines, 0.5 * (lines[:-1] + lines[1:])]
        j = np.abs(coords[:, k, None] - ln[None, :]).argmin(1)
        on = np.abs(coords[:, k] - ln[j]) <= 1e-8 * scale
        coords[on, k] = ln[j[on]]
    kind = np.array(kind)
    groups = {k: np.nonzero(kind == k)[0] for k in ("ground", "walls", "bottom")}
    groups["pit"] = np.nonzero(kind != "ground")[0]
    groups["surface"] = np.arange(len(X))
    return SurfaceMesh(coords, inv.reshape(-1, 9), groups, name="pit")


def read_gmsh(path, params=None, user=()):
    """Read nine-node quads (gmsh type 10) from a .msh, or mesh a .geo first
    (order 2), through the one gmsh reader (``mesh/gmsh.py``).

    ``params``: {name: value} set with gmsh.onelab/setNumber before meshing a
    .geo (DefineConstant parameters); ``user``: those the user named (-ssi_mesh_params),
    checked against the .geo's declarations. Physical surface groups become element
    groups. Collective callers should call this on every rank (it is cheap)
    or broadcast the result.
    """
    from . import gmsh as gmsh_reader
    model = gmsh_reader.read(path, dim=2, order=2, params=params, user=user, what="-ssi_mesh_params")
    other2d = dict(gmsh_reader.unknown_of_dim(model, 2))
    if "quad4" in model.blocks:
        other2d["Quadrilateral 4"] = len(model.blocks["quad4"])
    if "quad9" not in model.blocks:
        raise SSIError(f"{path}: the surface mesh has no nine-node quadrilaterals "
                       f"(found: {', '.join(other2d) or 'no 2D elements'})")
    if other2d:
        raise SSIError(f"{path}: the surface mesh mixes element types; use nine-node quadrilaterals only")
    conn = model.blocks["quad9"]
    groups = {name: np.sort(g.cells.get("quad9", np.zeros(0, np.int64)))
              for name, g in model.groups.items() if g.dim == 2}
    coords = model.coords
    used = np.unique(conn)
    remap = -np.ones(len(coords), np.int64)
    remap[used] = np.arange(len(used))
    mesh = SurfaceMesh(coords[used], remap[conn], groups, name=path)
    if not mesh.in_plane():
        return orient_out_of_soil(mesh)
    # gmsh may orient surfaces with normal -z; the half-space needs +z
    X = mesh.cell_coords()
    _, jn = quad9.geometry(X, np.array([0.0]), np.array([0.0]))
    flip = jn[:, 0, 2] < 0
    if flip.any():
        mesh.cells[flip] = mesh.cells[flip][:, FLIP]
    return mesh


FLIP = np.array([0, 3, 2, 1, 7, 6, 5, 4, 8])      # a nine-node element's nodes with its normal reversed


def orient_out_of_soil(mesh):
    """Orient every element of a surface that is not a plane (an excavation's walls and bottom) out
    of the soil: consistently across shared edges (two neighbours run their shared edge in opposite
    directions; breadth-first from each element not yet reached), then each connected piece so that
    its highest elements (the ground) face +z. SSIError for a surface that cannot be oriented (a
    Moebius strip, an edge of three elements). Returns the mesh, its cells reordered in place."""
    cells = mesh.cells
    owners = {}
    for e, c in enumerate(cells):
        for k in range(4):
            p, q = int(c[k]), int(c[(k + 1) % 4])
            owners.setdefault((min(p, q), max(p, q)), []).append(e)
    if any(len(v) > 2 for v in owners.values()):
        raise SSIError(f"{mesh.name}: an element edge is shared by more than two elements: not a surface")

    def runs(e, p, q):           # whether element e runs its edge p -> q
        c = [int(v) for v in cells[e, :4]]
        k = c.index(p)
        return c[(k + 1) % 4] == q

    seen = np.zeros(len(cells), bool)
    z = mesh.centres()[:, 2]
    for start in range(len(cells)):
        if seen[start]:
            continue
        seen[start] = True
        piece, todo = [start], [start]
        while todo:
            e = todo.pop()
            c = cells[e]
            for k in range(4):
                p, q = int(c[k]), int(c[(k + 1) % 4])
                for f in owners[(min(p, q), max(p, q))]:
                    if f == e:
                        continue
                    if not seen[f]:
                        if runs(f, p, q):
                            cells[f] = cells[f][FLIP]
                        seen[f] = True
                        piece.append(f)
                        todo.append(f)
                    elif runs(f, p, q):
                        raise SSIError(f"{mesh.name}: the surface cannot be oriented (elements {e} and {f})")
        piece = np.array(piece)
        _, jn = quad9.geometry(mesh.cell_coords()[piece], np.array([0.0]), np.array([0.0]))
        top = z[piece] >= z[piece].max() - 1e-9 * max(1.0, float(np.abs(z).max()))
        if jn[top, 0, 2].sum() < 0:
            cells[piece] = cells[piece][:, FLIP]
    return mesh
