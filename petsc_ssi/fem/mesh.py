"""The structure's mesh: cell blocks bound to parts, node groups, faces; reader and generator.

A ``StructureMesh`` is replicated on every rank (structures here have at most
~1e5 nodes); the PETSc matrices built from it are distributed by node
ownership (``dofmap.DofMap``). It holds

  coords           (N, 3) node coordinates (only nodes of part cells)
  blocks           [Block(part, element, cells, props)]: the cells of each part
                   (a frame part may be split in two blocks: members along z get
                   the default orientation x, the others z)
  nodes[name]      node ids of any physical group (points, curves, surfaces,
                   volumes) and of the generator's groups
  faces[name]      (F, 4) boundary quads of the bricks, node order giving the
                   outward normal of the brick that owns the face (re-oriented
                   here, whatever order the file had)
  shells[name]     (F, 4) quads of a 2-D group that are shell cells, oriented
                   consistently over each connected surface and "up" (mean normal with
                   n_z > 0; vertical walls n_x > 0, then n_y > 0), or outward when closed
  dims[name]       the dimension of each group

Node order of a hex8 cell is gmsh's (= VTK's): 0-3 the face zeta = -1
counter-clockwise seen from +z, 4-7 the face zeta = +1 above them.

Reading (``build_mesh``, rank 0 only; ``load_mesh`` broadcasts, with one
collective error path): the one gmsh reader (``mesh/gmsh.py``), the part cells
(``parts.py``: each part is a physical group of the element's dimension),
compaction to the nodes of part cells, then the checks: a part on a group of
the wrong dimension or without cells of its type, a cell in two parts,
coincident nodes that should be merged, each element's own geometry check
(zero length or area, inverted cells, a frame orientation parallel to the
member), and a group with nodes in no element (unconnected) when it is used.
"""
from dataclasses import dataclass, field

import numpy as np

from ..petsc import SSIError, collective, warn
from ..points import parse_triple
from .elements import Props

# Local faces of a hex8, each ordered so that (x1-x0) x (x3-x0) points outward.
HEX_FACES = np.array([[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4],
                      [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]])
# The 12 edges of a hex8 (local node pairs).
HEX_EDGES = np.array([[0, 1], [1, 2], [2, 3], [3, 0], [4, 5], [5, 6], [6, 7], [7, 4],
                      [0, 4], [1, 5], [2, 6], [3, 7]])
GMSH_HEX8, GMSH_QUAD4, GMSH_QUAD9 = 5, 3, 10


@dataclass
class Block:
    part: str
    element: object                  # elements.ElementType
    cells: np.ndarray                # (E, nodes_per_cell) node ids
    props: Props = None              # None: the material passed to assembly (legacy hex8 calls)


@dataclass
class StructureMesh:
    coords: np.ndarray
    blocks: list = field(default_factory=list)
    faces: dict = field(default_factory=dict)
    nodes: dict = field(default_factory=dict)
    source: str = ""
    shells: dict = field(default_factory=dict)
    dims: dict = field(default_factory=dict)
    unconnected: dict = field(default_factory=dict)   # group -> nodes of it in no part cell

    @property
    def n_nodes(self):
        return self.coords.shape[0]

    @property
    def n_cells(self):
        return int(sum(b.cells.shape[0] for b in self.blocks))

    @property
    def cells(self):
        """The hex8 cells of every hex8 block (E, 8) (the brick mesh; empty without bricks)."""
        hx = [b.cells for b in self.blocks if b.element.name == "hex8"]
        return np.concatenate(hx) if hx else np.zeros((0, 8), np.int64)

    def element_counts(self):
        out = {}
        for b in self.blocks:
            out[b.element.name] = out.get(b.element.name, 0) + b.cells.shape[0]
        return out

    def has_rotation(self):
        """(N,) bool: nodes touched by an element with rotation dofs."""
        rot = np.zeros(self.n_nodes, bool)
        for b in self.blocks:
            if len(b.element.dof_names) > 3:
                rot[b.cells.ravel()] = True
        return rot

    def released_nodes(self):
        """(N,) bool: nodes where a released part (``-ssi_fem_part_NAME_release rotations``) meets
        a rotational part that is not released: they carry a second rotation triple."""
        rel = np.zeros(self.n_nodes, bool)
        other = np.zeros(self.n_nodes, bool)
        for b in self.blocks:
            if len(b.element.dof_names) > 3:
                (rel if (b.props is not None and b.props.released) else other)[b.cells.ravel()] = True
        return rel & other

    def group_names(self):
        return sorted(set(self.faces) | set(self.nodes) | set(self.shells))

    def group_nodes(self, name, what="group"):
        """Node ids of a group; SSIError (naming ``what``, e.g. the option) if there is no such
        group or some of its nodes belong to no element of any part."""
        if name not in self.nodes and name not in self.faces and name not in self.shells:
            raise SSIError(f"{what}: no group '{name}' in mesh {self.source} "
                           f"(groups: {', '.join(self.group_names()) or 'none'})")
        if self.unconnected.get(name):
            raise SSIError(f"{what} '{name}': {self.unconnected[name]} of its nodes belong to no element of any "
                           "part (unconnected nodes; is the group on the structure?)")
        if name in self.nodes:
            return self.nodes[name]
        if name in self.faces:
            return np.unique(self.faces[name])
        return np.unique(self.shells[name])


def HexMesh(coords, cells, faces=None, nodes=None, source=""):
    """A brick-only StructureMesh (one hex8 block; the material comes with the assembly call)."""
    from .elements import get
    return StructureMesh(np.asarray(coords, float), [Block("structure", get("hex8"), np.asarray(cells, np.int64))],
                         dict(faces or {}), dict(nodes or {}), source)


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
def parse_mesh_params(text, what="-ssi_fem_mesh_params"):
    """{name: float} of 'name=value,...'."""
    out = {}
    for item in [s.strip() for s in str(text or "").split(",") if s.strip()]:
        name, sep, val = item.partition("=")
        name = name.strip()
        if not sep or not name:
            raise SSIError(f"{what}: '{item}' is not name=value")
        try:
            v = float(val)
        except ValueError:
            raise SSIError(f"{what}: '{item}': the value '{val.strip()}' is not a number") from None
        if name in out:
            raise SSIError(f"{what}: '{name}' given twice ({out[name]:g} and {v:g})")
        out[name] = v
    return out


def read_gmsh(path, specs=None, params=None, user=None):
    """Serial: read a .msh, or mesh a .geo in 3D, with gmsh; return a StructureMesh.

    ``specs``: the parts ([parts.PartSpec]); None: one hex8 part of every brick
    (only nodes used by hex8 cells are kept, renumbered 0..N-1, as before parts
    existed). Raises SSIError on any check of the module docstring."""
    from ..mesh import gmsh as reader
    from .parts import parse_parts
    model = reader.read(path, dim=3, params=params, user=tuple(params or ()) if user is None else user)
    if specs is None:
        from types import SimpleNamespace
        specs = parse_parts(SimpleNamespace(get=lambda *a: "", fem_E=1.0, fem_nu=0.0, fem_rho=1.0), raw={})
        specs[0].props = None
    return structure_from_model(model, specs, path)


def _legacy_cells(model, path):
    from ..mesh.gmsh import describe, unknown_of_dim
    other3d = unknown_of_dim(model, 3)
    if "hex8" not in model.blocks:
        raise SSIError(f"mesh '{path}' has no hex8 (8-node brick) cells (3D cells found: "
                       f"{describe(other3d) or 'none'}); use Transfinite/Recombine or extrusion with "
                       "Layers/Recombine in the .geo, or name frame/shell parts with -ssi_fem_parts")
    if other3d:
        raise SSIError(f"mesh '{path}' mixes hex8 with other 3D cells ({describe(other3d)}); only hex8 is supported")
    return model.blocks["hex8"]


def _part_cells(model, spec, path):
    from ..mesh.gmsh import describe
    from .parts import CELL_TYPE, DIM
    grp = model.groups.get(spec.name)
    if grp is None:
        names = sorted(model.groups)
        raise SSIError(f"part '{spec.name}': no physical group '{spec.name}' in mesh {path} "
                       f"(groups: {', '.join(names) or 'none'})")
    want = DIM[spec.element]
    if grp.dim != want:
        raise SSIError(f"part '{spec.name}' is a {spec.element} part ({want}-D cells) but the physical group "
                       f"'{spec.name}' has dimension {grp.dim}")
    ct = CELL_TYPE[spec.element]
    idx = grp.cells.get(ct, np.zeros(0, np.int64))
    if idx.size == 0:
        found = {k: len(v) for k, v in grp.cells.items() if len(v)}
        raise SSIError(f"part '{spec.name}' ({spec.element}): the group has no {ct} cells (found: "
                       f"{describe(found) or 'none'}; shells need quads: Recombine the surfaces)")
    other = [k for k, v in grp.cells.items() if k != ct and len(v) and k != "point"]
    if grp.unknown:
        raise SSIError(f"part '{spec.name}' ({spec.element}): the group also has {describe(grp.unknown)} cells, "
                       f"which a {spec.element} part cannot take (shells need quads only: Recombine with "
                       "Transfinite surfaces or Mesh.RecombinationAlgorithm 2 + Mesh.SubdivisionAlgorithm 1)")
    if other:
        raise SSIError(f"part '{spec.name}' ({spec.element}): the group also has {', '.join(other)} cells; "
                       f"a {spec.element} part takes {ct} cells only")
    return ct, idx


def _up_key(n, scale):
    """The 'up' sign of a normal n: n_z, else n_x, else n_y (each if larger than 1e-8 scale)."""
    tol = 1e-8 * scale
    return n[2] if abs(n[2]) > tol else n[0] if abs(n[0]) > tol else n[1]


def orient_shells(cells, coords, name="?"):
    """Serial: the shell cells reordered so that neighbours agree (a surface keeps one side up) and
    each connected surface faces 'up' (the area-weighted mean normal has n_z > 0; vertical surfaces
    n_x > 0, then n_y > 0) or, for a closed surface or a tube (mean normal ~ 0), outward from its
    centroid. Cells are connected across edges that
    exactly two cells share (T-junctions split a part into separately oriented surfaces). A
    non-orientable surface (a Moebius strip) is an SSIError."""
    from collections import deque
    cells = np.array(cells, np.int64)
    E = cells.shape[0]
    if E == 0:
        return cells
    a = cells.reshape(-1)
    b = np.roll(cells, -1, axis=1).reshape(-1)
    owner = np.repeat(np.arange(E), 4)
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    key = lo * (int(cells.max()) + 1) + hi
    order = np.argsort(key, kind="stable")
    ks = key[order]
    starts = np.r_[0, np.nonzero(np.diff(ks))[0] + 1]
    counts = np.diff(np.r_[starts, ks.size])
    two = starts[counts == 2]
    e1, e2 = order[two], order[two + 1]
    c1, c2 = owner[e1], owner[e2]
    same = a[e1] == a[e2]                     # the shared edge runs the same way in both cells
    adj = [[] for _ in range(E)]
    for i, j, s_ in zip(c1.tolist(), c2.tolist(), same.tolist()):
        adj[i].append((j, s_))
        adj[j].append((i, s_))
    flip = np.zeros(E, bool)
    seen = np.zeros(E, bool)
    X = coords[cells]
    nA = np.cross(X[:, 2] - X[:, 0], X[:, 3] - X[:, 1])        # 2 x area-weighted normals
    closed_edge = np.zeros(E, bool)
    np.logical_or.at(closed_edge, owner[order[starts[counts != 2]]], True)   # cells on a free edge
    for start in range(E):
        if seen[start]:
            continue
        comp = [start]
        seen[start] = True
        queue = deque([start])
        while queue:
            i = queue.popleft()
            for j, s_ in adj[i]:
                want = flip[i] ^ s_
                if seen[j]:
                    if flip[j] != want:
                        raise SSIError(f"shell part '{name}': the surface is not orientable (a Moebius strip?) "
                                       f"near cell {j}")
                    continue
                seen[j] = True
                flip[j] = want
                comp.append(j)
                queue.append(j)
        comp = np.array(comp)
        sgn = np.where(flip[comp], -1.0, 1.0)[:, None]
        n = (sgn * nA[comp]).sum(axis=0)
        scale = np.linalg.norm(nA[comp], axis=1).sum()
        if not closed_edge[comp].any() or np.linalg.norm(n) <= 1e-6 * scale:
            # closed (or a tube, whose mean normal vanishes): outward from the surface's centroid
            cen = X[comp].mean(axis=1)
            cen = cen - cen.mean(axis=0)
            turn = np.sum(sgn[:, 0] * np.einsum("ij,ij->i", cen, nA[comp])) < 0
        else:
            turn = _up_key(n, scale) < 0
        if turn:
            flip[comp] = ~flip[comp]
    out = cells.copy()
    out[flip] = out[flip][:, [0, 3, 2, 1]]
    return out


def _frame_blocks(spec, cells, coords):
    """Blocks of a frame part: with no orientation given, members along z get x, others z."""
    from .elements import get
    from copy import deepcopy
    el = get("frame")
    if spec.orientation_given:
        return [Block(spec.name, el, cells, spec.props)]
    d = coords[cells[:, 1]] - coords[cells[:, 0]]
    L = np.linalg.norm(d, axis=1)
    # "along z" within 1e-3 rad (cos = 1 - 5e-7): a column out of plumb by less keeps the
    # column's default (x), so its strong axis does not turn with the direction of the lean
    vertical = np.abs(d[:, 2]) >= np.cos(1e-3) * np.where(L > 0, L, 1.0)
    out = []
    for sel, o in ((~vertical, (0.0, 0.0, 1.0)), (vertical, (1.0, 0.0, 0.0))):
        if sel.any():
            pr = deepcopy(spec.props)
            pr.orientation = np.array(o)
            out.append(Block(spec.name, el, cells[sel], pr))
    return out


def _layer_blocks(spec, cells, coords):
    """Blocks of a hex8 part layered by depth (``parts.layer_of``: each cell by its centroid's elevation);
    SSIError in one line for cells below the last layer's bottom."""
    from .elements import get
    from .parts import layer_of
    z = coords[cells].mean(axis=1)[:, 2]
    k = layer_of(spec, z)
    if (k < 0).any():
        raise SSIError(f"part '{spec.name}': {int((k < 0).sum())} cell(s) lie below the last layer's bottom "
                       f"(z = {spec.layers[-1][0]:g} m; the lowest centroid at z = {z.min():.6g} m): extend "
                       f"-ssi_fem_part_{spec.name}_layers down to the part's bottom")
    top = float(coords[np.unique(cells)][:, 2].max())
    counts = np.bincount(k, minlength=len(spec.layers))
    for i, (zb, _) in enumerate(spec.layers):
        if counts[i]:
            continue
        if zb >= top - 1e-9 * max(1.0, abs(top)):
            # (a site's profile reused for a part below its first layers is legitimate: said, not refused)
            warn(f"part '{spec.name}': layer {i + 1}'s bottom z = {zb:g} m is at or above the part's top (z = "
                 f"{top:.6g} m): it holds no cell (a sign slip in -ssi_fem_part_{spec.name}_layers?)")
        elif counts[i + 1:].any():
            warn(f"part '{spec.name}': layer {i + 1} (bottom z = {zb:g} m) holds no cell centroid: thinner than the "
                 "part's cells there, its soil is not in the model")
    el = get("hex8")
    return [Block(spec.name, el, cells[k == i], pr) for i, (_, pr) in enumerate(spec.layers) if (k == i).any()]


def structure_from_model(model, specs, path):
    """Serial: the StructureMesh of a gmsh model (``mesh.gmsh.GmshModel``) and the parts."""
    from .elements import get
    chosen = []                                       # (spec, cell type, cells in model node ids)
    seen = {}
    for spec in specs:
        if spec.legacy:
            chosen.append((spec, "hex8", _legacy_cells(model, path)))
            continue
        ct, idx = _part_cells(model, spec, path)
        key = set(zip([ct] * len(idx), idx.tolist()))
        for other, okeys in seen.items():
            both = key & okeys
            if both:
                raise SSIError(f"parts '{other}' and '{spec.name}' share {len(both)} cell(s): a cell belongs to one "
                               "part")
        seen[spec.name] = key
        chosen.append((spec, ct, model.blocks[ct][idx]))
    used = np.unique(np.concatenate([c.ravel() for _, _, c in chosen]))
    new = np.full(model.coords.shape[0], -1, np.int64)
    new[used] = np.arange(used.size)
    coords = model.coords[used]
    blocks = []
    for spec, ct, c in chosen:
        cells = new[c]
        if spec.element == "shell":
            cells = orient_shells(cells, coords, spec.name)
        if spec.element == "frame":
            blocks += _frame_blocks(spec, cells, coords)
        elif spec.layers:
            blocks += _layer_blocks(spec, cells, coords)
        else:
            blocks.append(Block(spec.name, get(spec.element), cells, spec.props))
    mesh = StructureMesh(coords, blocks, source=path)
    legacy = all(s.legacy for s in specs)
    hexcells = mesh.cells
    shell_keys = {}
    for b in blocks:
        if b.element.name == "shell":
            for k, q in zip(map(tuple, np.sort(b.cells, axis=1)), b.cells):
                shell_keys[k] = q
    for name, grp in model.groups.items():
        ids = new[grp.nodes]
        mesh.dims[name] = grp.dim
        mesh.nodes[name] = np.unique(ids[ids >= 0])
        if np.any(ids < 0):
            mesh.unconnected[name] = int(np.sum(ids < 0))
        if grp.dim != 2:
            continue
        quads = [model.blocks[t][grp.cells[t]][:, :4] for t in ("quad4", "quad9") if t in grp.cells]
        if not quads:
            continue
        q = new[np.concatenate(quads)]
        if np.any(q < 0):
            if legacy:
                raise SSIError(f"face group '{name}': some quads are not boundary faces of the hex8 mesh")
            continue
        if hexcells.size:
            try:
                mesh.faces[name] = orient_faces(hexcells, q, name)
                continue
            except SSIError:
                if legacy:
                    raise
        keys = list(map(tuple, np.sort(q, axis=1)))
        if shell_keys and all(k in shell_keys for k in keys):
            mesh.shells[name] = np.array([shell_keys[k] for k in keys], np.int64).reshape(-1, 4)
    check_structure(mesh)
    return mesh


def check_structure(mesh):
    """Serial: coincident nodes and each element's own geometry check (SSIError, one line)."""
    from scipy.spatial import cKDTree
    ext = float(np.ptp(mesh.coords, axis=0).max()) if mesh.n_nodes else 0.0
    pairs = cKDTree(mesh.coords).query_pairs(max(ext, 1e-300) * 1e-9, output_type="ndarray")
    if len(pairs):
        x = mesh.coords[pairs[0, 0]]
        raise SSIError(f"{len(pairs)} pair(s) of coincident nodes (first at ({x[0]:.6g}, {x[1]:.6g}, {x[2]:.6g})): "
                       "duplicate nodes that should be merged (gmsh: Coherence; Coherence Mesh)")
    for b in mesh.blocks:
        msg = b.element.check(mesh.coords[b.cells], b.props if b.props is not None else Props())
        if msg:
            raise SSIError(f"part '{b.part}' ({b.element.name}): {msg}")


# ------------------------------------------------------------------ ordering
def renumber_rcm(mesh):
    """Reverse Cuthill-McKee renumbering over the cells of every block: compact, banded
    rank partitions."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import reverse_cuthill_mckee
    n = mesh.n_nodes
    ii, jj = [], []
    for b in mesh.blocks:
        k = b.cells.shape[1]
        ii.append(np.repeat(b.cells, k, axis=1).ravel())
        jj.append(np.tile(b.cells, (1, k)).ravel())
    i, j = np.concatenate(ii), np.concatenate(jj)
    graph = coo_matrix((np.ones(i.size, np.int8), (i, j)), shape=(n, n)).tocsr()
    perm = reverse_cuthill_mckee(graph, symmetric_mode=True)   # new -> old
    old2new = np.empty(n, dtype=np.int64)
    old2new[perm] = np.arange(n)
    blocks = [Block(b.part, b.element, old2new[b.cells], b.props) for b in mesh.blocks]
    return StructureMesh(mesh.coords[perm], blocks,
                         {k: old2new[v] for k, v in mesh.faces.items()},
                         {k: old2new[v] for k, v in mesh.nodes.items()}, mesh.source,
                         {k: old2new[v] for k, v in mesh.shells.items()}, dict(mesh.dims), dict(mesh.unconnected))


def build_mesh(cfg, specs=None):
    """Serial: the mesh the options describe (no renumbering). ``specs``: the parts."""
    if cfg.fem_mesh == "box":
        if str(cfg.get("fem_mesh_params", "") or "").strip():
            raise SSIError("-ssi_fem_mesh_params: the box generator (-ssi_fem_mesh box) has no parameters; they "
                           "set the DefineConstant parameters of a .geo given as -ssi_fem_mesh")
        if specs is not None and not all(s.legacy for s in specs):
            raise SSIError("-ssi_fem_parts needs a gmsh mesh (-ssi_fem_mesh FILE.geo|.msh); the box generator "
                           "makes one hex8 part")
        cells = parse_triple(cfg.fem_box_cells, int, "-ssi_fem_box_cells")
        size = parse_triple(cfg.fem_box_size, float, "-ssi_fem_box_size")
        if min(cells) < 1:
            raise SSIError(f"-ssi_fem_box_cells {cfg.fem_box_cells}: need at least one brick per direction")
        if not min(size) > 0:
            raise SSIError(f"-ssi_fem_box_size {cfg.fem_box_size}: the box's lengths lx,ly,lz must be > 0 m "
                           "(place the box with -ssi_fem_box_origin, its lowest corner)")
        mesh = structured_box(cells, size, parse_triple(cfg.fem_box_origin, float, "-ssi_fem_box_origin"))
        if specs is not None:
            mesh.blocks[0].props = specs[0].props
        return mesh
    params = parse_mesh_params(cfg.get("fem_mesh_params", ""))
    if params and not cfg.fem_mesh.endswith(".geo"):
        raise SSIError("-ssi_fem_mesh_params needs a .geo mesh (-ssi_fem_mesh)")
    return read_gmsh(cfg.fem_mesh, specs, params)


def load_mesh(cfg, comm, specs=None):
    """Collective: build or read the mesh on rank 0, renumber, broadcast.

    gmsh runs on rank 0 only; any error there (SSIError or not) is raised on
    every rank as a one-line SSIError, so the other ranks never wait in bcast.
    """
    mpi = comm.tompi4py()
    mesh = None
    with collective(comm, f"reading the mesh '{cfg.fem_mesh}'", "{what} failed: {error}"):
        if mpi.rank == 0:
            mesh = build_mesh(cfg, specs)
            if cfg.fem_renumber:
                mesh = renumber_rcm(mesh)
    return mpi.bcast(mesh, root=0)


# ------------------------------------------------------------------ queries
def largest_element_size(mesh):
    """The longest edge of any cell: the mesh's largest element size h_max."""
    h = 0.0
    for blk in mesh.blocks:
        X = mesh.coords[blk.cells]
        k = blk.cells.shape[1]
        edges = HEX_EDGES if k == 8 else np.array([[i, (i + 1) % k] for i in range(k)]) if k > 2 else \
            np.array([[0, 1]])
        a, b = edges.T
        if len(X):
            h = max(h, float(np.linalg.norm(X[:, a] - X[:, b], axis=2).max()))
    return h


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
