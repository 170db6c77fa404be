"""Loads and constraints of the structure: f(t) = h(t) F, fixed dofs.

Spatial part F: a pressure p0 on named face groups, converted to consistent
nodal forces over the bilinear face quads,
    F_a = -p0 int_face N_a n dA = -p0 int N_a (x_s x x_t) ds dt   (2x2 Gauss, exact
for flat or warped bilinear quads), with n the outward normal (p0 > 0 pushes
into the body: the paper's top load p(t) = -p0 (H(t) - H(t - 0.025 s)) is
p0 = 1000 N/m^2 on "top" with the box history; 'name:factor' scales p0 on a
group, e.g. 'top_left,top_right:-1' for the antisymmetric case); plus point loads at the
nearest FE nodes (refused farther away than the largest element size).

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

from ..petsc import SSIError
from ..histories import History  # noqa: F401  (the FEM's load histories)
from ..points import parse_points
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


def nodal_load(mesh, cfg):
    """Replicated (N, 3) spatial load F [N] and the point-load snap distances."""
    F = np.zeros((mesh.n_nodes, 3))
    if cfg.fem_load_p0 != 0:
        for name, scale in load_groups(cfg.fem_load_group):
            quads = group_faces(mesh, name, "-ssi_fem_load_group")
            fq = quad_pressure_forces(mesh.coords[quads], scale * cfg.fem_load_p0)
            for i in range(3):
                F[:, i] += np.bincount(quads.ravel(), weights=fq[:, :, i].ravel(), minlength=mesh.n_nodes)
    dist = np.zeros(0)
    if cfg.fem_point_load.strip():
        pl = parse_points(cfg.fem_point_load, 6, "-ssi_fem_point_load", "x,y,z,fx,fy,fz")
        nodes, dist = snap_points(mesh, pl[:, :3], "-ssi_fem_point_load")
        np.add.at(F, nodes, pl[:, 3:])
    return F, dist


def fixed_dofs(mesh, spec):
    """Sorted global dofs fixed by 'name[:xyz],...' (all components by default)."""
    dofs = []
    for item in [s.strip() for s in str(spec).split(",") if s.strip()]:
        name, _, comps = item.partition(":")
        comps = comps.strip().lower() or "xyz"
        if set(comps) - set("xyz"):
            raise SSIError(f"-ssi_fem_fixed '{item}': components must be letters of xyz")
        if name not in mesh.nodes and name not in mesh.faces:
            raise SSIError(f"-ssi_fem_fixed: no group '{name}' in mesh {mesh.source} "
                           f"(groups: {', '.join(mesh.group_names()) or 'none'})")
        nodes = mesh.group_nodes(name)
        for c in sorted(set(comps)):
            dofs.append(3 * nodes + "xyz".index(c))
    return np.unique(np.concatenate(dofs)) if dofs else np.zeros(0, np.int64)


def rigid_body_modes(coords):
    """(3N, 6) rigid-body displacement fields: 3 translations, 3 rotations."""
    n = coords.shape[0]
    R = np.zeros((n, 3, 6))
    R[:, [0, 1, 2], [0, 1, 2]] = 1.0
    x, y, z = coords.T
    R[:, 1, 3], R[:, 2, 3] = -z, y        # about x
    R[:, 0, 4], R[:, 2, 4] = z, -x        # about y
    R[:, 0, 5], R[:, 1, 5] = -y, x        # about z
    return R.reshape(3 * n, 6)


def restrains_rigid_motion(coords, fixed):
    """Whether the fixed dofs remove all six rigid-body modes (K nonsingular)."""
    if len(fixed) == 0:
        return False
    c = coords - coords.mean(axis=0)
    R = rigid_body_modes(c / max(np.abs(c).max(), 1e-300))[fixed]
    s = np.linalg.svd(R, compute_uv=False)
    return s.size == 6 and s[-1] > 1e-8 * s[0]
