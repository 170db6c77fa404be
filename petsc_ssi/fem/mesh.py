"""Hex8 meshes of the structure: gmsh reader, structured generator, groups.

A ``HexMesh`` is replicated on every rank (structures here have at most
~1e5 nodes); the PETSc matrices built from it are distributed by node
ownership ranges (see ``assembly.Layout``). Node order of a hex8 cell is
gmsh's (= VTK's): 0-3 the face zeta = -1 counter-clockwise seen from +z,
4-7 the face zeta = +1 above them.

Groups (gmsh physical groups, or the generator's names):
  ``faces[name]``  (F, 4) boundary quads, node order giving the outward normal
                   of the brick that owns the face (re-oriented here, whatever
                   order the file had);
  ``nodes[name]``  node ids of any physical group (points, curves, surfaces,
                   volumes); a face group's nodes are also a node group.
"""
from dataclasses import dataclass, field

import numpy as np

from ..petsc import SSIError, collective_error
from ..points import parse_triple

# Local faces of a hex8, each ordered so that (x1-x0) x (x3-x0) points outward.
HEX_FACES = np.array([[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4],
                      [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]])
# The 12 edges of a hex8 (local node pairs).
HEX_EDGES = np.array([[0, 1], [1, 2], [2, 3], [3, 0], [4, 5], [5, 6], [6, 7], [7, 4],
                      [0, 4], [1, 5], [2, 6], [3, 7]])
GMSH_HEX8, GMSH_QUAD4, GMSH_QUAD9 = 5, 3, 10


@dataclass
class HexMesh:
    coords: np.ndarray                          # (N, 3) float
    cells: np.ndarray                           # (E, 8) int64
    faces: dict = field(default_factory=dict)   # name -> (F, 4) outward quads
    nodes: dict = field(default_factory=dict)   # name -> (k,) node ids
    source: str = ""

    @property
    def n_nodes(self):
        return self.coords.shape[0]

    @property
    def n_cells(self):
        return self.cells.shape[0]

    def group_names(self):
        return sorted(set(self.faces) | set(self.nodes))

    def group_nodes(self, name):
        """Node ids of a face or node group (KeyError if absent)."""
        if name in self.nodes:
            return self.nodes[name]
        return np.unique(self.faces[name])


def one_line(exc):
    """'Type: first line of the message' of an unexpected exception."""
    lines = str(exc).strip().splitlines()
    return f"{type(exc).__name__}: {lines[0]}" if lines else type(exc).__name__


# ------------------------------------------------------------------ generator
def structured_box(cells=(10, 10, 4), size=(1.0, 1.0, 0.5), origin=(-0.5, -0.5, 0.0)):
    """Structured brick mesh of a box, with the face groups of meshes/foundation.geo.

    Face groups: xmin, xmax, ymin, ymax, base (z = z0), top (z = z0 + lz),
    top_left / top_right (top faces whose centre has x below / above the box
    centre) and the node group "all".
    """
    nx, ny, nz = (int(c) for c in cells)
    if min(nx, ny, nz) < 1:
        raise SSIError(f"box cells {cells}: need at least one brick per direction")
    x = [origin[d] + np.linspace(0.0, size[d], n + 1) for d, n in enumerate((nx, ny, nz))]
    X, Y, Z = np.meshgrid(*x, indexing="ij")
    coords = np.column_stack([X.ravel("F"), Y.ravel("F"), Z.ravel("F")])

    def nid(i, j, k):
        return i + (nx + 1) * (j + (ny + 1) * k)

    i, j, k = (a.ravel("F") for a in np.meshgrid(np.arange(nx), np.arange(ny), np.arange(nz), indexing="ij"))
    cells_ = np.column_stack([nid(i, j, k), nid(i + 1, j, k), nid(i + 1, j + 1, k), nid(i, j + 1, k),
                              nid(i, j, k + 1), nid(i + 1, j, k + 1), nid(i + 1, j + 1, k + 1),
                              nid(i, j + 1, k + 1)]).astype(np.int64)
    mesh = HexMesh(coords, cells_, source=f"box:{nx},{ny},{nz}")
    lo, hi = np.asarray(origin, float), np.asarray(origin, float) + np.asarray(size, float)
    bfaces = boundary_faces(cells_)
    centre = coords[bfaces].mean(axis=1)
    tol = 1e-9 * max(size)
    for name, d, val in (("xmin", 0, lo[0]), ("xmax", 0, hi[0]), ("ymin", 1, lo[1]), ("ymax", 1, hi[1]),
                         ("base", 2, lo[2]), ("top", 2, hi[2])):
        mesh.faces[name] = bfaces[np.abs(centre[:, d] - val) < tol]
    top_c = coords[mesh.faces["top"]].mean(axis=1)
    xmid = 0.5 * (lo[0] + hi[0])
    mesh.faces["top_left"] = mesh.faces["top"][top_c[:, 0] < xmid - tol]
    mesh.faces["top_right"] = mesh.faces["top"][top_c[:, 0] > xmid + tol]
    mesh.nodes["all"] = np.arange(coords.shape[0])
    return mesh


# ------------------------------------------------------------------ faces
def _face_keys(quads):
    return np.sort(quads, axis=1)


def all_cell_faces(cells):
    """(6E, 4) outward-ordered faces of every brick, cell-major."""
    return cells[:, HEX_FACES].reshape(-1, 4)


def boundary_faces(cells):
    """Faces that belong to exactly one brick, outward-ordered."""
    faces = all_cell_faces(cells)
    _, inv, cnt = np.unique(_face_keys(faces), axis=0, return_inverse=True, return_counts=True)
    return faces[cnt[inv.ravel()] == 1]


def orient_faces(cells, quads, name="?"):
    """Replace each group quad by the boundary face of the brick that owns it.

    The node order then gives the outward normal. Raises SSIError if a quad
    is not a boundary face of the hex mesh.
    """
    if len(quads) == 0:
        return np.zeros((0, 4), np.int64)
    bnd = boundary_faces(cells)
    keys = np.concatenate([_face_keys(bnd), _face_keys(quads)])
    _, inv = np.unique(keys, axis=0, return_inverse=True)
    inv = inv.ravel()
    pos = np.full(inv.max() + 1, -1)
    pos[inv[:len(bnd)]] = np.arange(len(bnd))
    match = pos[inv[len(bnd):]]
    if np.any(match < 0):
        raise SSIError(f"face group '{name}': {int(np.sum(match < 0))} quad(s) are not boundary faces of the "
                       "hex8 mesh")
    return bnd[match]


# ------------------------------------------------------------------ gmsh
def read_gmsh(path):
    """Serial: read a .msh, or mesh a .geo in 3D, with gmsh; return a HexMesh.

    Only nodes used by hex8 cells are kept (renumbered 0..N-1). Raises
    SSIError on a mesh without hex8 cells or with other 3D cell types.
    """
    import gmsh
    gmsh.initialize(readConfigFiles=False, interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        try:
            gmsh.open(path)
            if not path.endswith(".msh"):
                gmsh.model.mesh.generate(3)
        except Exception as exc:
            raise SSIError(f"gmsh could not read/mesh '{path}': {exc}") from None
        return _gmsh_model_to_mesh(gmsh, path)
    finally:
        gmsh.finalize()


def _gmsh_model_to_mesh(gmsh, path):
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    types, _, enodes = gmsh.model.mesh.getElements(3)
    found = {int(t): len(n) // gmsh.model.mesh.getElementProperties(t)[3] for t, n in zip(types, enodes)}
    if GMSH_HEX8 not in found:
        desc = ", ".join(f"{gmsh.model.mesh.getElementProperties(t)[0]} x{c}" for t, c in found.items())
        raise SSIError(f"mesh '{path}' has no hex8 (8-node brick) cells (3D cells found: {desc or 'none'}); "
                       "use Transfinite/Recombine or extrusion with Layers/Recombine in the .geo")
    others = {t: c for t, c in found.items() if t != GMSH_HEX8}
    if others:
        desc = ", ".join(f"{gmsh.model.mesh.getElementProperties(t)[0]} x{c}" for t, c in others.items())
        raise SSIError(f"mesh '{path}' mixes hex8 with other 3D cells ({desc}); only hex8 is supported")
    tag2idx = np.full(int(tags.max()) + 1, -1, dtype=np.int64)
    tag2idx[tags.astype(np.int64)] = np.arange(len(tags))
    coords_all = xyz.reshape(-1, 3)
    hex_tags = np.asarray(enodes[list(types).index(GMSH_HEX8)], dtype=np.int64).reshape(-1, 8)
    used = np.unique(hex_tags)
    new = np.full(tag2idx.shape[0], -1, dtype=np.int64)
    new[used] = np.arange(len(used))
    cells = new[hex_tags]
    coords = coords_all[tag2idx[used]]
    mesh = HexMesh(coords, cells, source=path)
    for dim, ptag in gmsh.model.getPhysicalGroups():
        name = gmsh.model.getPhysicalName(dim, ptag) or f"{dim}:{ptag}"
        ntags, _ = gmsh.model.mesh.getNodesForPhysicalGroup(dim, ptag)
        ids = new[np.asarray(ntags, dtype=np.int64)]
        mesh.nodes[name] = np.unique(ids[ids >= 0])
        if dim == 2:
            quads = _gmsh_group_quads(gmsh, dim, ptag, name)
            mesh.faces[name] = orient_faces(cells, new[quads], name)
    return mesh


def _gmsh_group_quads(gmsh, dim, ptag, name):
    out = []
    for ent in gmsh.model.getEntitiesForPhysicalGroup(dim, ptag):
        types, _, enodes = gmsh.model.mesh.getElements(dim, ent)
        for t, n in zip(types, enodes):
            nper = gmsh.model.mesh.getElementProperties(t)[3]
            if t not in (GMSH_QUAD4, GMSH_QUAD9):
                raise SSIError(f"face group '{name}' has {gmsh.model.mesh.getElementProperties(t)[0]} "
                               "elements; hex8 faces must be quads")
            out.append(np.asarray(n, dtype=np.int64).reshape(-1, nper)[:, :4])
    return np.concatenate(out) if out else np.zeros((0, 4), np.int64)


# ------------------------------------------------------------------ ordering
def renumber_rcm(mesh):
    """Reverse Cuthill-McKee renumbering: compact, banded rank partitions."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import reverse_cuthill_mckee
    n = mesh.n_nodes
    i = np.repeat(mesh.cells, 8, axis=1).ravel()
    j = np.tile(mesh.cells, (1, 8)).ravel()
    graph = coo_matrix((np.ones(i.size, np.int8), (i, j)), shape=(n, n)).tocsr()
    perm = reverse_cuthill_mckee(graph, symmetric_mode=True)   # new -> old
    old2new = np.empty(n, dtype=np.int64)
    old2new[perm] = np.arange(n)
    return HexMesh(mesh.coords[perm], old2new[mesh.cells],
                   {k: old2new[v] for k, v in mesh.faces.items()},
                   {k: old2new[v] for k, v in mesh.nodes.items()}, mesh.source)


def build_mesh(cfg):
    """Serial: the mesh the options describe (no renumbering)."""
    if cfg.fem_mesh == "box":
        return structured_box(parse_triple(cfg.fem_box_cells, int, "-ssi_fem_box_cells"),
                              parse_triple(cfg.fem_box_size, float, "-ssi_fem_box_size"),
                              parse_triple(cfg.fem_box_origin, float, "-ssi_fem_box_origin"))
    return read_gmsh(cfg.fem_mesh)


def load_mesh(cfg, comm):
    """Collective: build or read the mesh on rank 0, renumber, broadcast.

    gmsh runs on rank 0 only; any error there (SSIError or not) is raised on
    every rank as a one-line SSIError, so the other ranks never wait in bcast.
    """
    mpi = comm.tompi4py()
    mesh, err = None, None
    if mpi.rank == 0:
        try:
            mesh = build_mesh(cfg)
            if cfg.fem_renumber:
                mesh = renumber_rcm(mesh)
        except SSIError as exc:
            err = str(exc)
        except Exception as exc:  # noqa: BLE001 -- any failure must reach the other ranks
            err = f"reading the mesh '{cfg.fem_mesh}' failed: {one_line(exc)}"
    collective_error(err, comm)
    return mpi.bcast(mesh, root=0)


# ------------------------------------------------------------------ queries
def largest_element_size(mesh):
    """The longest edge of any brick: the mesh's largest element size h_max."""
    if mesh.n_cells == 0:
        return 0.0
    X = mesh.coords[mesh.cells]
    a, b = HEX_EDGES.T
    return float(np.linalg.norm(X[:, a] - X[:, b], axis=2).max())


def snap_points(mesh, points, what="-ssi_receivers"):
    """Nearest FE node of each point: (node ids, distances).

    SSIError (one line, naming ``what``) if a point is farther from its
    nearest node than the largest element size: it lies outside the
    structure (any point inside a brick is within half the brick's diagonal
    of a node).
    """
    from scipy.spatial import cKDTree
    pts = np.atleast_2d(np.asarray(points, dtype=float))
    if pts.size == 0:
        return np.zeros(0, np.int64), np.zeros(0)
    dist, idx = cKDTree(mesh.coords).query(pts)
    h = largest_element_size(mesh)
    far = np.nonzero(dist > h)[0]
    if far.size:
        p, d = pts[far[0]], dist[far[0]]
        raise SSIError(f"{what}: point ({p[0]:g}, {p[1]:g}, {p[2]:g}) is {d:.3g} m from the nearest FE node, "
                       f"more than the largest element size {h:.3g} m: it lies outside the structure")
    return idx.astype(np.int64), dist
