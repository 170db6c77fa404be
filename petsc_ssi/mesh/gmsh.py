"""The one gmsh reader of petsc_ssi: cell blocks and physical groups of every dimension.

Serial (the callers read on rank 0 and broadcast, ``mesh/distribute.py``).
``read(path, dim, order, params)`` opens a .msh, or meshes a .geo up to
dimension ``dim`` (with ``order`` 2 for the soil's nine-node quads), and
returns a ``GmshModel``:

  coords      (N, 3) every node of the model, ordered by gmsh node tag
  blocks      {type: (E, n) node indices} every element of the types petsc_ssi
              knows ('point', 'line2', 'quad4', 'quad9', 'hex8'), all entities
              concatenated in gmsh's order (entity by entity)
  groups      {name: Group} physical groups of every dimension: ``dim``,
              ``cells`` {type: indices into blocks[type]} and ``nodes``
              (sorted node indices of all its elements, points included)
  unknown     {gmsh type name: (dim, count)} elements of other types (the caller
              decides whether that is an error)

Unnamed physical groups are called '<dim>:<tag>'. The soil reader
(``mesh/surface.py``) and the structure reader (``fem/mesh.py``) both use it.
"""
from dataclasses import dataclass, field

import numpy as np

from ..petsc import SSIError

# gmsh element type id -> (petsc_ssi name, nodes per cell)
GMSH_TYPES = {15: ("point", 1), 1: ("line2", 2), 3: ("quad4", 4), 10: ("quad9", 9), 5: ("hex8", 8)}
GMSH_ID = {name: t for t, (name, _) in GMSH_TYPES.items()}


@dataclass
class Group:
    dim: int
    cells: dict = field(default_factory=dict)     # type -> indices into GmshModel.blocks[type]
    nodes: np.ndarray = None                      # sorted node indices
    unknown: dict = field(default_factory=dict)   # gmsh type name -> count of elements of other types


@dataclass
class GmshModel:
    coords: np.ndarray
    blocks: dict
    groups: dict
    unknown: dict
    source: str = ""


def read(path, dim=3, order=1, params=None, user=(), what="-ssi_fem_mesh_params"):
    """Serial: read ``path`` (.msh, or .geo meshed up to ``dim``) with gmsh; see the module docstring.

    ``params``: {name: value} set as ONELAB 'Parameters/<name>' before a .geo is
    opened (DefineConstant parameters). ``user``: the names among them the user gave
    (option ``what``): each must be a parameter the .geo declares, inside the range it
    declares (``Min``, ``Max``; ``Step 1`` with an integer ``Min``: an integer), checked
    before gmsh sees the values, so a parameter that empties a group or breaks
    the .geo is named as the cause. SSIError if gmsh cannot read or mesh it."""
    import gmsh
    own = not gmsh.isInitialized()
    if own:
        gmsh.initialize(["gmsh", "-v", "0"], readConfigFiles=False, interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        try:
            if path.endswith(".geo") and user:
                # the declarations (names, ranges) from the .geo with its defaults, checked before
                # the user's values reach gmsh: a value that breaks the .geo is then named as the
                # cause, and gmsh's parser is spared an error (after one, it fails the next file
                # it opens in this process)
                declared = _declared(gmsh, path)
                if declared is not None:
                    _check_params(declared, path, {k: params[k] for k in user}, what)
            if path.endswith(".geo"):
                for k, v in (params or {}).items():
                    gmsh.onelab.setNumber(f"Parameters/{k}", [float(v)])
            gmsh.open(path)
            if not path.endswith(".msh"):
                gmsh.model.mesh.generate(dim)
                if order > 1:
                    gmsh.model.mesh.setOrder(order)
        except SSIError:
            raise
        except Exception as exc:
            raise SSIError(f"gmsh could not read/mesh '{path}': {str(exc).splitlines()[0] if str(exc) else exc}") \
                from None
        return _model(gmsh, path)
    finally:
        if own:
            gmsh.finalize()


def _declared(gmsh, path):
    """{name: onelab record} of the parameters ``path`` declares (DefineConstant ... Name
    "Parameters/<name>"), read by opening it with its defaults; None if that fails."""
    import json
    import re
    try:
        with open(path, errors="replace") as fh:     # onelab also lists names only set, never declared:
            names = set(re.findall(r'Name\s*"Parameters/(\w+)"', fh.read()))   # the file says which
        gmsh.open(path)
        onelab = {p["name"].split("/", 1)[1]: p for p in json.loads(gmsh.onelab.get())["onelab"]["parameters"]
                  if p.get("type") == "number" and p["name"].startswith("Parameters/")}
    except Exception:
        return None
    finally:
        gmsh.clear()
        gmsh.onelab.clear()
    return {k: onelab.get(k, {}) for k in names}


def _check_params(declared, path, given, what):
    """SSIError naming the first of ``given`` ({name: value}) that ``path`` does not declare or
    that lies outside its declared range (``declared``: ``_declared``'s)."""
    for name, v in given.items():
        p = declared.get(name)
        if p is None:
            raise SSIError(f"{what} {name}={v:g}: '{path}' has no parameter '{name}' (its parameters: "
                           f"{', '.join(sorted(declared)) or 'none'})")
        lo, hi = p.get("min", -1e200), p.get("max", 1e200)
        choices = p.get("choices")
        if choices and not any(v == c for c in choices):
            raise SSIError(f"{what} {name}={v:g}: '{path}' allows {name} in {{{', '.join(f'{c:g}' for c in choices)}}}")
        if not lo <= v <= hi:
            rng = f"[{lo:g}, {hi:g}]" if hi < 1e199 else f">= {lo:g}" if lo > -1e199 else f"<= {hi:g}"
            raise SSIError(f"{what} {name}={v:g}: '{path}' declares {name} {rng}")
        if p.get("step") == 1 and float(lo).is_integer() and not float(v).is_integer():
            raise SSIError(f"{what} {name}={v:g}: '{path}' declares {name} an integer")


def _model(gmsh, path):
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    tags = np.asarray(tags, np.int64)
    order = np.argsort(tags)
    tags = tags[order]
    coords = np.asarray(xyz, float).reshape(-1, 3)[order]
    if tags.size == 0:
        raise SSIError(f"mesh '{path}' has no nodes")
    tag2idx = np.full(int(tags.max()) + 1, -1, np.int64)
    tag2idx[tags] = np.arange(tags.size)
    blocks, etags, unknown = {}, {}, {}
    types, el_tags, el_nodes = gmsh.model.mesh.getElements()
    for t, et, en in zip(types, el_tags, el_nodes):
        t = int(t)
        if t not in GMSH_TYPES:
            prop = gmsh.model.mesh.getElementProperties(t)
            d, c = unknown.get(prop[0], (int(prop[1]), 0))
            unknown[prop[0]] = (d, c + len(et))
            continue
        name, npc = GMSH_TYPES[t]
        blocks[name] = tag2idx[np.asarray(en, np.int64)].reshape(-1, npc)
        etags[name] = np.asarray(et, np.int64)
    sorted_tags = {k: (np.argsort(v, kind="stable"), np.sort(v)) for k, v in etags.items()}
    groups = {}
    for gdim, ptag in gmsh.model.getPhysicalGroups():
        name = gmsh.model.getPhysicalName(gdim, ptag) or f"{gdim}:{ptag}"
        grp = groups.setdefault(name, Group(int(gdim)))
        if grp.dim != gdim:
            raise SSIError(f"mesh '{path}': physical group name '{name}' is used for dimensions {grp.dim} and {gdim}")
        per = {}
        for ent in gmsh.model.getEntitiesForPhysicalGroup(gdim, ptag):
            ts, ets, _ = gmsh.model.mesh.getElements(gdim, ent)
            for t, et in zip(ts, ets):
                if int(t) not in GMSH_TYPES:
                    tn = gmsh.model.mesh.getElementProperties(int(t))[0]
                    grp.unknown[tn] = grp.unknown.get(tn, 0) + len(et)
                    continue
                tname = GMSH_TYPES[int(t)][0]
                perm, st = sorted_tags[tname]
                per.setdefault(tname, []).append(perm[np.searchsorted(st, np.asarray(et, np.int64))])
        for tname, parts in per.items():
            old = grp.cells.get(tname, np.zeros(0, np.int64))
            grp.cells[tname] = np.unique(np.concatenate([old] + parts))
        ntags, _ = gmsh.model.mesh.getNodesForPhysicalGroup(gdim, ptag)
        ids = tag2idx[np.asarray(ntags, np.int64)]
        old = grp.nodes if grp.nodes is not None else np.zeros(0, np.int64)
        grp.nodes = np.unique(np.concatenate([old, ids[ids >= 0]]))
    for grp in groups.values():
        if grp.nodes is None:
            grp.nodes = np.zeros(0, np.int64)
    return GmshModel(coords, blocks, groups, unknown, path)


def describe(counts):
    """'Tetrahedron 4 x12, ...' of {type name: count}."""
    return ", ".join(f"{k} x{v}" for k, v in counts.items())


def unknown_of_dim(model, dim):
    """{gmsh type name: count} of the unknown elements of dimension ``dim``."""
    return {k: c for k, (d, c) in model.unknown.items() if d == dim}


def write_msh(path, coords, groups):
    """Serial: write a gmsh .msh (4.1) of nodes ``coords`` (N, 3) and named groups
    {name: (type, cells)} with type one of 'point', 'line2', 'quad4', 'hex8' and cells
    (E, n) 0-based node indices (points: (E, 1)). Each group becomes one discrete
    entity and a physical group of its dimension, so ``read`` gives the same cells,
    groups and node numbering back. Used for meshes built in Python (the
    obstacle-course problems, benchmarks) to run them through the same reader as
    every user mesh."""
    import gmsh
    dims = {"point": 0, "line2": 1, "quad4": 2, "quad9": 2, "hex8": 3}
    own = not gmsh.isInitialized()
    if own:
        gmsh.initialize(["gmsh", "-v", "0"], readConfigFiles=False, interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("petsc_ssi")
        coords = np.asarray(coords, float)
        n = coords.shape[0]
        node_tags = np.arange(1, n + 1)
        first = True
        etag = 1
        for name, (tname, cells) in groups.items():
            d = dims[tname]
            ent = gmsh.model.addDiscreteEntity(d)
            if first:
                gmsh.model.mesh.addNodes(d, ent, node_tags, coords.ravel())
                first = False
            cells = np.asarray(cells, np.int64).reshape(-1, GMSH_TYPES[GMSH_ID[tname]][1])
            tags = np.arange(etag, etag + cells.shape[0])
            etag += cells.shape[0]
            gmsh.model.mesh.addElementsByType(ent, GMSH_ID[tname], tags, (cells + 1).ravel())
            pg = gmsh.model.addPhysicalGroup(d, [ent])
            gmsh.model.setPhysicalName(d, pg, name)
        gmsh.option.setNumber("Mesh.SaveAll", 0)
        gmsh.write(path)
        gmsh.model.remove()
    finally:
        if own:
            gmsh.finalize()
