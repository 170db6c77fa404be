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


def declared_parameters(path):
    """{name: {'default', 'choices', 'min', 'max', 'step'}} of the ONELAB parameters a .geo declares
    with ``DefineConstant[ name = {default, Name "Parameters/name", Choices {..}, Min a, Max b,
    Step s}, ... ];`` (its own text; files it Includes are not read). Attributes absent: None."""
    import re
    with open(path) as fh:
        text = re.sub(r"//[^\n]*", "", fh.read())
    out = {}
    for block in re.finditer(r"DefineConstant\s*\[", text):
        i, depth, start = block.end(), 1, block.end()
        while i < len(text) and depth:
            depth += {"[": 1, "]": -1}.get(text[i], 0)
            i += 1
        body = text[start:i - 1]
        for m in re.finditer(r"(\w+)\s*=\s*\{", body):
            j, depth = m.end(), 1
            while j < len(body) and depth:
                depth += {"{": 1, "}": -1}.get(body[j], 0)
                j += 1
            entry = body[m.end():j - 1]
            name = re.search(r'Name\s*"Parameters/([^"]+)"', entry)
            info = {"choices": None, "min": None, "max": None, "step": None}
            ch = re.search(r"Choices\s*\{([^}]*)\}", entry)
            if ch:
                try:
                    info["choices"] = [float(v) for v in ch.group(1).split(",") if v.strip()]
                except ValueError:        # named choices ({0="a", 1="b"}): the numbers before '='
                    info["choices"] = [float(v.split("=")[0]) for v in ch.group(1).split(",") if v.strip()]
            for key in ("Min", "Max", "Step"):
                v = re.search(key + r"\s+([-+0-9.eE]+)", entry)
                if v:
                    info[key.lower()] = float(v.group(1))
            out[name.group(1) if name else m.group(1)] = info
    return out


def check_parameters(path, params, what):
    """SSIError unless every parameter of ``params`` ({name: value}, the user's) is one the .geo
    ``path`` declares (DefineConstant) and its value one the declaration allows (Choices, Min, Max,
    Step from Min): gmsh takes an undeclared name or a value out of range without a word."""
    import difflib
    if not params:
        return
    if not str(path).endswith(".geo"):
        raise SSIError(f"{what}: '{path}' is not a .geo: its parameters ({', '.join(params)}) would do nothing")
    decl = declared_parameters(path)
    for name, value in params.items():
        if name not in decl:
            near = difflib.get_close_matches(name, list(decl), n=1)
            raise SSIError(f"{what}: '{name}' is not a parameter of {path}" + (f" (did you mean {near[0]}?)" if near
                           else "") + f"; its parameters: {', '.join(decl) or 'none'}")
        d, v = decl[name], float(value)
        if d["choices"] is not None and v not in d["choices"]:
            raise SSIError(f"{what}: {name}={value:g}: {path} allows {name} in "
                           f"{{{', '.join(f'{c:g}' for c in d['choices'])}}} only")
        if (d["min"] is not None and v < d["min"]) or (d["max"] is not None and v > d["max"]):
            rng = (f">= {d['min']:g}" if d["max"] is None else f"<= {d['max']:g}" if d["min"] is None
                   else f"in [{d['min']:g}, {d['max']:g}]")
            raise SSIError(f"{what}: {name}={value:g}: {path} needs {name} {rng}")
        if d["step"] and abs((v - (d["min"] or 0.0)) / d["step"] - round((v - (d["min"] or 0.0)) / d["step"])) > 1e-9:
            raise SSIError(f"{what}: {name}={value:g}: {path} needs {name} in steps of {d['step']:g}"
                           + (f" from {d['min']:g}" if d["min"] else ""))


def read(path, dim=3, order=1, params=None):
    """Serial: read ``path`` (.msh, or .geo meshed up to ``dim``) with gmsh; see the module docstring.

    ``params``: {name: value} set as ONELAB 'Parameters/<name>' before a .geo is
    opened (DefineConstant parameters). SSIError if gmsh cannot read or mesh it."""
    import gmsh
    own = not gmsh.isInitialized()
    if own:
        gmsh.initialize(["gmsh", "-v", "0"], readConfigFiles=False, interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        try:
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
