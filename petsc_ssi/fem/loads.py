"""Loads and constraints of the structure: f(t) = h(t) F, fixed dofs.

Spatial part F: a pressure p0 on named groups of brick faces or shell cells,
converted to consistent nodal forces over the bilinear quads,
    F_a = -p0 int_face N_a n dA = -p0 int N_a (x_s x x_t) ds dt   (2x2 Gauss, exact
for flat or warped bilinear quads), with n the outward normal (p0 > 0 pushes
into the body: the paper's top load p(t) = -p0 (H(t) - H(t - 0.025 s)) is
p0 = 1000 N/m^2 on "top" with the box history; 'name:factor' scales p0 on a
group, e.g. 'top_left,top_right:-1' for the antisymmetric case; on shells, whose
cells are oriented "up" (fem/mesh.py), p0 > 0 pushes a slab down); plus point
forces and moments at the nearest FE nodes (refused farther away than the largest
element size; a moment needs a node with rotations).

Fixed dofs: 'group[:dofs]' items (``fixed_dofs``), dof names ux uy uz rx ry rz.

Time part h(t): ``petsc_ssi.histories.History``, shared with the BEM:
heaviside H(t) = 1 for t > 0, box 1 on (0, t0], or a table of (t, h) rows
linearly interpolated (0 before the first time, the last value after the
last); h = 0 for t <= 0.

Load samples. The integrators take at step n the mean of the load over the
cell [t_n - dt/2, t_n + dt/2] (for n = 0 the half cell [0, dt/2]),
    f^n = F * (I(b) - I(a)) / (b - a),   I(t) = int_0^t h,
computed exactly (``History.cell_mean``). For smooth loads f^n = f(t_n) +
O(dt^2); at a jump the cell mean is what keeps both integrators second-order
accurate (see integrators.py for why, and tests/fem/test_fem_convergence.py).
"""
import numpy as np

from ..petsc import SSIError, collective
from ..histories import History  # noqa: F401  (the FEM's load histories)
from .mesh import snap_points


def uses_history(cfg):
    """Whether the options load the structure at all (a pressure or point loads)."""
    return cfg.fem_load_p0 != 0 or bool(cfg.fem_point_load.strip())


def history_from(cfg):
    """The load history of the options (SSIError on a bad table); heaviside when nothing is
    loaded (F = 0: the history is never used, its options are not checked)."""
    if not uses_history(cfg):
        return History("heaviside")
    return History(cfg.fem_load_history, cfg.fem_load_t0,
                   cfg.fem_load_table if cfg.fem_load_history == "table" else None)


def quad_pressure_forces(X, p):
    """Consistent nodal forces (F, 4, 3) of a pressure p on quads X (F, 4, 3).

    Nodes of each quad ordered so that the normal points out of the body.
    """
    g = 1.0 / np.sqrt(3.0)
    st = np.array([[-g, -g], [g, -g], [g, g], [-g, g]])
    sn = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], float)
    N = 0.25 * (1 + st[:, None, 0] * sn[None, :, 0]) * (1 + st[:, None, 1] * sn[None, :, 1])   # (G, 4)
    dNs = 0.25 * sn[None, :, 0] * (1 + st[:, None, 1] * sn[None, :, 1])
    dNt = 0.25 * sn[None, :, 1] * (1 + st[:, None, 0] * sn[None, :, 0])
    xs = np.einsum("ga,fai->fgi", dNs, X)
    xt = np.einsum("ga,fai->fgi", dNt, X)
    nda = np.cross(xs, xt)                                    # n dA / (ds dt), weights 1
    return -p * np.einsum("ga,fgi->fai", N, nda)


def group_faces(mesh, names, what):
    """Face quads of the comma-separated groups; SSIError naming what exists."""
    out = []
    for name in [s.strip() for s in names.split(",") if s.strip()]:
        if name not in mesh.faces:
            raise SSIError(f"{what}: no face group '{name}' in mesh {mesh.source} "
                           f"(face groups: {', '.join(sorted(mesh.faces)) or 'none'})")
        out.append(mesh.faces[name])
    return np.concatenate(out) if out else np.zeros((0, 4), np.int64)


def load_groups(spec):
    """[(group, factor)] of 'name[:factor],...': the pressure on a group is factor * p0
    (e.g. 'top_left,top_right:-1' for the paper's antisymmetric load, Fig. 7c)."""
    out = []
    for item in [s.strip() for s in str(spec).split(",") if s.strip()]:
        name, _, fac = item.partition(":")
        try:
            f = float(fac) if fac.strip() else 1.0
        except ValueError:
            raise SSIError(f"-ssi_fem_load_group '{item}': the factor after ':' must be a number") from None
        out.append((name.strip(), f))
    return out


def pressure_groups(mesh, names, what="-ssi_fem_load_group"):
    """Quads of the comma-separated groups: brick faces (outward) or shell cells (oriented up,
    see fem/mesh.py); SSIError naming what exists."""
    out = []
    for name in [s.strip() for s in names.split(",") if s.strip()]:
        if name in mesh.faces:
            out.append(mesh.faces[name])
        elif name in mesh.shells:
            out.append(mesh.shells[name])
        else:
            avail = sorted(set(mesh.faces) | set(mesh.shells))
            raise SSIError(f"{what}: no face group '{name}' in mesh {mesh.source} "
                           f"(face groups: {', '.join(avail) or 'none'}; a pressure acts on brick faces or "
                           "shell cells)")
    return np.concatenate(out) if out else np.zeros((0, 4), np.int64)


def _is_group_row(r):
    head = r.split(",")[0].strip()
    try:
        float(head)
        return False
    except ValueError:
        return True


def parse_point_loads(text, what="-ssi_fem_point_load"):
    """'x,y,z,fx,fy,fz[,mx,my,mz];...' -> (R, 9) (moments 0 where not given); rows that start
    with a group name are left out (see ``group_point_loads``)."""
    rows = [r.strip() for r in str(text or "").replace("\n", ";").split(";") if r.strip()]
    out = []
    for r in rows:
        if _is_group_row(r):
            continue
        try:
            vals = [float(v) for v in r.split(",")]
        except ValueError:
            vals = []
        if len(vals) not in (6, 9) or not np.all(np.isfinite(vals)):
            raise SSIError(f"{what}: '{r}' is not 6 or 9 comma-separated numbers (each point needs x,y,z,fx,fy,fz "
                           "and optionally mx,my,mz)")
        out.append(vals + [0.0] * (9 - len(vals)))
    return np.array(out, float).reshape(-1, 9)


def group_point_loads(mesh, text, what="-ssi_fem_point_load"):
    """[(node ids, (6,) force and moment)] of the rows 'GROUP,fx,fy,fz[,mx,my,mz]' (the force acts
    on every node of the physical group GROUP)."""
    out = []
    for r in [r.strip() for r in str(text or "").replace("\n", ";").split(";") if r.strip()]:
        if not _is_group_row(r):
            continue
        name, *rest = [v.strip() for v in r.split(",")]
        try:
            vals = [float(v) for v in rest]
        except ValueError:
            vals = []
        if len(vals) not in (3, 6) or not np.all(np.isfinite(vals)):
            raise SSIError(f"{what}: '{r}': a group row is GROUP,fx,fy,fz[,mx,my,mz]")
        out.append((mesh.group_nodes(name, what), np.array(vals + [0.0] * (6 - len(vals)))))
    return out


def nodal_load(mesh, cfg, dofmap=None):
    """Replicated spatial load F [N, N m] and the point-load snap distances.

    With ``dofmap``: a global dof array (size dofmap.size), moments on rotation dofs.
    Without (hex8 meshes, the form before the dof map): an (N, 3) array of forces."""
    F = np.zeros((mesh.n_nodes, 3))
    M = np.zeros((mesh.n_nodes, 3))
    if cfg.fem_load_p0 != 0:
        for name, scale in load_groups(cfg.fem_load_group):
            quads = pressure_groups(mesh, name)
            fq = quad_pressure_forces(mesh.coords[quads], scale * cfg.fem_load_p0)
            for i in range(3):
                F[:, i] += np.bincount(quads.ravel(), weights=fq[:, :, i].ravel(), minlength=mesh.n_nodes)
    dist = np.zeros(0)
    rot = mesh.has_rotation() if dofmap is None else dofmap.has_rotation
    for nodes, fm in group_point_loads(mesh, cfg.fem_point_load):
        F[nodes] += fm[:3]
        M[nodes] += fm[3:]
        if np.any(fm[3:] != 0) and not rot[nodes].all():
            raise SSIError("-ssi_fem_point_load: a moment on a group with nodes without rotation dofs (brick "
                           "nodes); load frame or shell nodes")
    if cfg.fem_point_load.strip():
        pl = parse_point_loads(cfg.fem_point_load)
        nodes, dist = snap_points(mesh, pl[:, :3], "-ssi_fem_point_load")
        np.add.at(F, nodes, pl[:, 3:6])
        np.add.at(M, nodes, pl[:, 6:9])
        if np.any(pl[:, 6:9] != 0):
            bad = np.nonzero((np.abs(pl[:, 6:9]).sum(axis=1) > 0) & ~rot[nodes])[0]
            if bad.size:
                p = pl[bad[0]]
                raise SSIError(f"-ssi_fem_point_load: the moment at ({p[0]:g}, {p[1]:g}, {p[2]:g}) acts on a node "
                               "without rotation dofs (a brick node); load a frame or shell node")
    if dofmap is None:
        return F, dist
    return dofmap.nodal_array(F, M), dist


def point_masses(mesh, text, dofmap, what="-ssi_fem_point_mass"):
    """Replicated global dof array of added point masses: rows 'x,y,z,m[,I]' (nearest node) or
    'GROUP,m[,I]' (every node of the group); m on the translations, I on the rotations (nodes
    with rotations only; I > 0 at a brick node is an error). Also the snapping distances."""
    out = np.zeros(dofmap.size)
    dist = []
    for r in [r.strip() for r in str(text or "").replace("\n", ";").split(";") if r.strip()]:
        fields = [v.strip() for v in r.split(",")]
        if _is_group_row(r):
            name, vals = fields[0], fields[1:]
        else:
            name, vals = None, fields[3:]
        try:
            vals = [float(v) for v in vals]
            xyz = None if name else np.array([float(v) for v in fields[:3]])
        except ValueError:
            vals = []
        if len(vals) not in (1, 2) or not np.all(np.isfinite(vals)) or min(vals) < 0:
            raise SSIError(f"{what}: '{r}' is not x,y,z,m[,I] or GROUP,m[,I] with m, I >= 0")
        if name:
            nodes = mesh.group_nodes(name, what)
        else:
            nodes, d = snap_points(mesh, xyz[None], what)
            dist.append(float(d[0]))
        out[dofmap.dofs(nodes, ("ux", "uy", "uz"))] += vals[0]
        if len(vals) == 2 and vals[1] > 0:
            if not dofmap.has_rotation[nodes].all():
                raise SSIError(f"{what}: '{r}': a rotary inertia on a node without rotation dofs (a brick node)")
            out[dofmap.dofs(nodes, ("rx", "ry", "rz"))] += vals[1]
    return out, np.array(dist)


FIXED_LEGACY = set("xyz")


def _fixed_names(item):
    """Dof names of 'group[:spec]': legacy letters (x, xz, xyz: translations), names joined by '+'
    (ux+ry+rz), or all (None) for a bare group."""
    from .dofmap import DOF_NAMES
    name, sep, comps = item.partition(":")
    comps = comps.strip()
    if not sep or not comps:
        return name.strip(), None
    low = comps.lower()
    if set(low) <= FIXED_LEGACY and "+" not in low:
        return name.strip(), tuple("u" + c for c in sorted(set(low)))
    names = tuple(c.strip() for c in comps.split("+") if c.strip())
    for c in names:
        if c not in DOF_NAMES:
            import difflib
            near = difflib.get_close_matches(c, DOF_NAMES, n=1)
            raise SSIError(f"-ssi_fem_fixed '{item}': unknown dof name '{c}' (dof names: {', '.join(DOF_NAMES)}, "
                           "joined by '+'; or letters of xyz)" + (f"; did you mean {near[0]}?" if near else ""))
    return name.strip(), names


def fixed_dofs(mesh, spec, dofmap=None):
    """Sorted global dofs fixed by 'group[:dofs],...': a bare group fixes all its dofs
    (translations, and rotations where its nodes have them); 'group:ux+ry+rz' the named
    ones; 'group:x' (letters of xyz) the translations, as before rotations existed."""
    from .dofmap import DofMap
    dm = dofmap if dofmap is not None else DofMap(mesh.has_rotation())
    dofs = []
    for item in [s.strip() for s in str(spec).split(",") if s.strip()]:
        name, names = _fixed_names(item)
        nodes = mesh.group_nodes(name, "-ssi_fem_fixed")
        if names is None:
            names = ("ux", "uy", "uz", "rx", "ry", "rz")
        elif any(c[0] == "r" for c in names) and not dm.has_rotation[nodes].any():
            raise SSIError(f"-ssi_fem_fixed '{item}': the nodes of group '{name}' have no rotation dofs (bricks only)")
        dofs.append(dm.dofs(nodes, names, all_rotations=True))
    return np.unique(np.concatenate(dofs)) if dofs else np.zeros(0, np.int64)
def rigid_body_modes(coords):
    """(3N, 6) rigid-body displacement fields of a translations-only model: 3 translations,
    3 rotations about the origin (the dof map's modes, ``DofMap.rigid_body_modes``)."""
    from .dofmap import DofMap
    c = np.asarray(coords, float)
    return DofMap(np.zeros(c.shape[0], bool)).rigid_body_modes(c, centre=np.zeros(3))


def restrains_rigid_motion(coords, fixed):
    """Whether the fixed dofs remove all six rigid-body modes (K nonsingular) of a
    translations-only model (``DofMap.restrains_rigid_motion``)."""
    from .dofmap import DofMap
    c = np.asarray(coords, float)
    return DofMap(np.zeros(c.shape[0], bool)).restrains_rigid_motion(c, fixed)


def load_history(cfg, comm):
    """Collective: the load history (the option checks read it once already)."""
    hist = None
    with collective(comm, f"-ssi_fem_load_history {cfg.fem_load_history}", "{what}: {error}"):
        try:
            hist = history_from(cfg)
        except SSIError as exc:
            raise SSIError(f"-ssi_fem_load_history {cfg.fem_load_history}: {exc}") from None
    return hist
