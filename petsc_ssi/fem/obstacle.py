"""Standard shell obstacle-course problems for the 4-node shell (elements/shell.py).

The problems of MacNeal & Harder, "A proposed standard set of problems to test
finite element accuracy", Finite Elements in Analysis and Design 1 (1985) 3-20,
and of Belytschko, Stolarski, Liu, Carpenter & Ong, "Stress projection for
membrane and shear locking in shell finite elements", CMAME 51 (1985) 221-258
(the "shell obstacle course"), plus two vibration problems: NAFEMS FV16
(cantilevered thin square plate, "The standard NAFEMS benchmarks", 1990) and a
simply supported rectangular plate against Navier's closed form.

Each generator returns a ``Problem`` on an n-dependent structured mesh:
coords (N, 3), cells (E, 4), props (``Props``), fixed dofs (6 dofs per node,
dof = 6 node + k, k over ux uy uz rx ry rz), loads [(node, dof, value)], the
quantity compared as a linear functional ``probe`` [(node, dof, weight)]
(static problems) or the lowest frequencies (modal problems), and the
reference value(s). ``solve`` computes the quantity with a small scipy
assembler of its own (independent of PETSc); ``convergence_table`` runs a
mesh sweep (for the benchmark scripts; the unit tests use a few meshes).

Sign conventions: the reference values are signed in the probed dof, e.g.
the Scordelis-Lo roof's -0.3024 in uz (downwards).
"""
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .elements.base import Props
from .elements.shell import SHELL, shape, GAUSS


@dataclass
class Problem:
    name: str
    n: int
    coords: np.ndarray
    cells: np.ndarray
    props: Props
    fixed: np.ndarray
    loads: list = field(default_factory=list)        # [(node, dof k, value)]
    probe: list = field(default_factory=list)        # [(node, dof k, weight)]: value = sum w u
    reference: object = None                         # float (static) or array (frequencies [Hz])
    kind: str = "static"                             # 'static' or 'modal'
    note: str = ""

    @property
    def n_nodes(self):
        return self.coords.shape[0]

    def load_vector(self):
        f = np.zeros(6 * self.n_nodes)
        for node, k, v in self.loads:
            f[6 * node + k] += v
        return f

    def value(self, u):
        return float(sum(w * u[6 * node + k] for node, k, w in self.probe))


def grid(n1, n2):
    """Node index (n1 + 1, n2 + 1) and cells (n1 n2, 4), counter-clockwise in (i, j)."""
    idx = np.arange((n1 + 1) * (n2 + 1)).reshape(n1 + 1, n2 + 1)
    c = np.stack([idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]], axis=-1)
    return idx, c.reshape(-1, 4)


def fix(nodes, comps):
    nodes = np.atleast_1d(np.asarray(nodes, np.int64))
    return (6 * nodes[:, None] + np.asarray(comps)[None, :]).ravel()


def area_shares(X):
    """int N_a dA (E, 4) over the bilinear surface of each cell: consistent nodal weights of a
    uniform load per unit area."""
    N, dN = shape(GAUSS)
    g = np.einsum("gak,eai->egki", dN, X)
    dA = np.linalg.norm(np.cross(g[:, :, 0], g[:, :, 1]), axis=-1)
    return np.einsum("ga,eg->ea", N, dA)


def scordelis_lo(n):
    """Scordelis-Lo roof, one quarter, n x n. Axis along y, z up: x = R sin(phi), z = R cos(phi),
    phi in [0, 40 deg] (crown to free edge), y in [0, L/2] (diaphragm end to midspan).
    Self weight 90 per unit area downwards (consistent nodal loads); rigid diaphragm at y = 0:
    ux = uz = 0; symmetry at y = L/2 (uy = rx = rz = 0) and at the crown x = 0 (ux = ry = rz
    = 0). Reference: uz = -0.3024 at the free edge midspan (MacNeal & Harder 1985)."""
    R, L, t = 25.0, 50.0, 0.25
    idx, cells = grid(n, n)
    phi = np.linspace(0, np.radians(40.0), n + 1)[:, None]
    y = np.linspace(0, L / 2, n + 1)[None, :]
    P, Y = np.broadcast_arrays(phi, y)
    coords = np.stack([R * np.sin(P), Y, R * np.cos(P)], -1).reshape(-1, 3)
    fixed = np.concatenate([fix(idx[:, 0], [0, 2]), fix(idx[:, -1], [1, 3, 5]), fix(idx[0, :], [0, 4, 5])])
    w = area_shares(coords[cells])
    share = np.zeros(coords.shape[0])
    np.add.at(share, cells.ravel(), w.ravel())
    loads = [(a, 2, -90.0 * share[a]) for a in range(coords.shape[0])]
    return Problem("scordelis_lo", n, coords, cells, Props(E=4.32e8, nu=0.0, rho=0.0, thickness=t),
                   np.unique(fixed), loads, [(int(idx[-1, -1]), 2, 1.0)], -0.3024,
                   note=f"quarter, {n}x{n}")


def pinched_cylinder(n):
    """Pinched cylinder with rigid end diaphragms, one octant, n x n. Axis along x: y = R sin(phi),
    z = R cos(phi), phi in [0, 90 deg], x in [0, L/2] (midspan to diaphragm). P = 1 pinches at
    (0, 0, +-R): P/4 downwards at the octant's corner node. Symmetry x = 0 (ux = ry = rz = 0),
    y = 0 (uy = rx = rz = 0), z = 0 (uz = rx = ry = 0); diaphragm x = L/2: uy = uz = 0.
    Reference radial displacement under the load 1.8249e-5 (uz = -1.8249e-5)."""
    R, L, t = 300.0, 600.0, 3.0
    idx, cells = grid(n, n)
    x = np.linspace(0, L / 2, n + 1)[:, None]
    phi = np.linspace(0, np.pi / 2, n + 1)[None, :]
    Xx, P = np.broadcast_arrays(x, phi)
    coords = np.stack([Xx, R * np.sin(P), R * np.cos(P)], -1).reshape(-1, 3)
    coords[idx[:, -1], 2] = 0.0                       # exactly on the symmetry plane z = 0
    fixed = np.concatenate([fix(idx[0, :], [0, 4, 5]), fix(idx[:, 0], [1, 3, 5]),
                            fix(idx[:, -1], [2, 3, 4]), fix(idx[-1, :], [1, 2])])
    top = int(idx[0, 0])
    return Problem("pinched_cylinder", n, coords, cells, Props(E=3e6, nu=0.3, rho=0.0, thickness=t),
                   np.unique(fixed), [(top, 2, -0.25)], [(top, 2, 1.0)], -1.8249e-5,
                   note=f"octant, {n}x{n}")


def twisted_beam(n, load="in"):
    """Twisted beam (MacNeal & Harder 1985), thick case: L = 12, width 1.1, t = 0.32, E = 29e6,
    nu = 0.22, 90 deg twist; mesh 6n x n (n = 2: the standard 12 x 2). Axis along x, clamped
    at x = 0 where the width is along y; at x the section is turned by beta = (pi/2) x/L about
    x, so the tip's width is along z. Unit tip load (consistent over the tip nodes):
    load='in' along the tip's width (z), reference 5.424e-3; load='out' along the tip's normal
    (y), reference 1.754e-3. Quantity: mean tip displacement in the load direction."""
    L, w, t = 12.0, 1.1, 0.32
    nl, nw = 6 * n, n
    idx, cells = grid(nl, nw)
    x = np.linspace(0, L, nl + 1)[:, None]
    s = np.linspace(-w / 2, w / 2, nw + 1)[None, :]
    Xx, S = np.broadcast_arrays(x, s)
    beta = 0.5 * np.pi * Xx / L
    coords = np.stack([Xx, S * np.cos(beta), S * np.sin(beta)], -1).reshape(-1, 3)
    fixed = fix(idx[0, :], range(6))
    k = {"in": 2, "out": 1}[load]
    tip = idx[-1, :]
    wts = np.full(nw + 1, 1.0 / nw)
    wts[[0, -1]] *= 0.5
    loads = [(int(a), k, float(c)) for a, c in zip(tip, wts)]
    probe = [(int(a), k, 1.0 / (nw + 1)) for a in tip]
    ref = {"in": 5.424e-3, "out": 1.754e-3}[load]
    return Problem(f"twisted_beam_{load}", n, coords, cells,
                   Props(E=29e6, nu=0.22, rho=0.0, thickness=t), fixed, loads, probe, ref,
                   note=f"{nl}x{nw}")


def fv16(n):
    """NAFEMS FV16 cantilevered thin square plate: 10 m x 10 m, t = 0.05 m, E = 200e9, nu = 0.3,
    rho = 8000, clamped (all six dofs) along x = 0; n x n mesh in the plane z = 0. Reference
    frequencies 0.421, 1.029, 2.582, 3.306, 3.753, 6.555 Hz."""
    a, t = 10.0, 0.05
    idx, cells = grid(n, n)
    x = np.linspace(0, a, n + 1)
    coords = np.stack(np.broadcast_arrays(x[:, None], x[None, :], 0.0), -1).reshape(-1, 3)
    return Problem("fv16", n, coords, cells, Props(E=200e9, nu=0.3, rho=8000.0, thickness=t),
                   fix(idx[0, :], range(6)), reference=np.array([0.421, 1.029, 2.582, 3.306, 3.753, 6.555]),
                   kind="modal", note=f"{n}x{n}")


def ss_plate_frequencies(a, b, t, E, nu, rho, k=6):
    """Lowest k Kirchhoff frequencies [Hz] f_mn = (pi/2) ((m/a)^2 + (n/b)^2) sqrt(D/(rho t))."""
    D = E * t ** 3 / (12 * (1 - nu ** 2))
    m = np.arange(1, 12)
    f = 0.5 * np.pi * ((m[:, None] / a) ** 2 + (m[None, :] / b) ** 2) * np.sqrt(D / (rho * t))
    return np.sort(f.ravel())[:k]


def ss_plate(n, a=1.5, b=1.0, t=0.002):
    """Simply supported thin rectangular steel plate a x b x t (default b/t = 500: shear and
    rotary inertia change the six lowest frequencies by < 1e-4), round(n a/b) x n elements.
    Hard simple support: uz = 0 on the edges and the rotation along each edge
    (rx on x = 0, a; ry on y = 0, b) zero. In-plane dofs (ux, uy, rz) fixed everywhere: the
    flat plate's membrane and bending are uncoupled, this removes the in-plane rigid modes.
    Reference: Navier's closed form (``ss_plate_frequencies``)."""
    E, nu, rho = 200e9, 0.3, 8000.0
    n1 = int(round(n * a / b))
    idx, cells = grid(n1, n)
    x = np.linspace(0, a, n1 + 1)[:, None]
    y = np.linspace(0, b, n + 1)[None, :]
    coords = np.stack(np.broadcast_arrays(x, y, 0.0), -1).reshape(-1, 3)
    fixed = np.concatenate([fix(idx.ravel(), [0, 1, 5]), fix(idx[[0, -1], :].ravel(), [2, 3]),
                            fix(idx[:, [0, -1]].ravel(), [2, 4])])
    return Problem("ss_plate", n, coords, cells, Props(E=E, nu=nu, rho=rho, thickness=t), np.unique(fixed),
                   reference=ss_plate_frequencies(a, b, t, E, nu, rho), kind="modal", note=f"{n1}x{n}")


def distorted_patch(R=None, origin=(0.0, 0.0, 0.0)):
    """MacNeal & Harder's 5-element distorted patch (0.24 x 0.12 rectangle, interior nodes
    (0.04, 0.02), (0.18, 0.03), (0.16, 0.08), (0.08, 0.08)), placed in 3D as
    x = origin + R^T (x2d, y2d, 0) (R: rows = the patch's axes; identity by default).
    Returns (coords (8, 3), cells (5, 4), xy (8, 2) in-plane coordinates, R, boundary nodes
    [0..3], interior nodes [4..7])."""
    xy = np.array([[0, 0], [0.24, 0], [0.24, 0.12], [0, 0.12],
                   [0.04, 0.02], [0.18, 0.03], [0.16, 0.08], [0.08, 0.08]])
    cells = np.array([[0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7], [4, 5, 6, 7]])
    R = np.eye(3) if R is None else np.asarray(R, float)
    coords = np.asarray(origin, float) + np.c_[xy, np.zeros(8)] @ R
    return coords, cells, xy, R, np.arange(4), np.arange(4, 8)


def assemble(problem, element=SHELL):
    """(K csr, lumped m) of a problem, 6 dofs per node."""
    cells = problem.cells
    X = problem.coords[cells]
    Ke = element.stiffness(X, problem.props)
    me = element.lumped_mass(X, problem.props)
    dofs = (6 * cells[:, :, None] + np.arange(6)).reshape(cells.shape[0], -1)
    n = 6 * problem.n_nodes
    rows = np.broadcast_to(dofs[:, :, None], Ke.shape).ravel()
    cols = np.broadcast_to(dofs[:, None, :], Ke.shape).ravel()
    K = sp.csr_matrix((Ke.ravel(), (rows, cols)), shape=(n, n))
    K.sum_duplicates()
    m = np.zeros(n)
    np.add.at(m, dofs.ravel(), me.ravel())
    return K, m


def solve(problem, element=SHELL, k=None):
    """The problem's quantity: the probed displacement (static) or the lowest frequencies [Hz]
    (modal; k of them, default len(reference))."""
    msg = element.check(problem.coords[problem.cells], problem.props)
    if msg:
        raise ValueError(msg)
    K, m = assemble(problem, element)
    free = np.setdiff1d(np.arange(K.shape[0]), problem.fixed)
    Kf = K[free][:, free].tocsc()
    if problem.kind == "static":
        u = np.zeros(K.shape[0])
        u[free] = spla.spsolve(Kf, problem.load_vector()[free])
        return problem.value(u)
    k = len(problem.reference) if k is None else k
    s = sp.diags(1.0 / np.sqrt(m[free]))
    A = (s @ Kf @ s).tocsc()
    if A.shape[0] <= 3000:
        lam = np.linalg.eigvalsh(A.toarray())[:k]
    else:
        lam = np.sort(spla.eigsh(A, k=k, sigma=0.0, which="LM", return_eigenvectors=False))
    return np.sqrt(np.maximum(lam, 0.0)) / (2 * np.pi)


def relative_error(problem, value):
    return (np.asarray(value) - problem.reference) / np.abs(problem.reference)


def convergence_table(make, meshes, **kw):
    """[(n, mesh note, dofs, value(s), relative error(s))] of ``make(n, **kw)`` over ``meshes``,
    e.g. convergence_table(pinched_cylinder, [4, 8, 16, 32])."""
    rows = []
    for n in meshes:
        p = make(n, **kw)
        v = solve(p)
        rows.append((n, p.note, 6 * p.n_nodes - len(p.fixed), v, relative_error(p, v)))
    return rows


PROBLEMS = {"scordelis_lo": scordelis_lo, "pinched_cylinder": pinched_cylinder,
            "twisted_beam_in": lambda n: twisted_beam(n, "in"),
            "twisted_beam_out": lambda n: twisted_beam(n, "out"),
            "fv16": fv16, "ss_plate": ss_plate}


def print_table(name, meshes):
    print(name)
    for n, note, nd, v, err in convergence_table(PROBLEMS[name], meshes):
        vs = np.array2string(np.atleast_1d(v), precision=5)
        es = np.array2string(100 * np.atleast_1d(err), precision=2)
        print(f"  n={n:3d} {note:>12s} dofs={nd:7d} value={vs} error%={es}")


if __name__ == "__main__":
    print_table("scordelis_lo", [4, 8, 16, 32])
    print_table("pinched_cylinder", [4, 8, 16, 32])
    print_table("twisted_beam_in", [1, 2, 4, 8])
    print_table("twisted_beam_out", [1, 2, 4, 8])
    print_table("fv16", [4, 8, 16])
    print_table("ss_plate", [4, 8, 16, 24])


DOF = ("ux", "uy", "uz", "rx", "ry", "rz")


def write_case(problem, directory):
    """Write ``problem`` as a gmsh .msh (part 'shell'; one point group per distinct set of
    fixed dofs, named 'fix_<dofs>') and return (msh path, petsc-ssi options, probe receivers):
    the same problem run through the application (reader, parts, dof map, fixed dof names,
    point forces and moments, ``petsc-ssi static`` / ``modes``) instead of ``solve``'s own
    assembler. The probe's nodes become receivers (in probe order)."""
    import os
    from ..mesh.gmsh import write_msh
    path = os.path.join(directory, f"{problem.name}-{problem.n}.msh")
    groups = {"shell": ("quad4", problem.cells)}
    by_node = {}
    for d in np.asarray(problem.fixed, np.int64):
        by_node.setdefault(int(d // 6), []).append(int(d % 6))
    sets = {}
    for node, ks in by_node.items():
        sets.setdefault(tuple(sorted(ks)), []).append(node)
    spec = []
    for ks, nodes in sorted(sets.items()):
        g = "fix_" + "_".join(DOF[k] for k in ks)
        groups[g] = ("point", np.array(nodes, np.int64)[:, None])
        spec.append(f"{g}:{'+'.join(DOF[k] for k in ks)}")
    write_msh(path, problem.coords, groups)
    p = problem.props
    opts = ["-ssi_fem_mesh", path, "-ssi_fem_parts", "shell", "-ssi_fem_part_shell_element", "shell",
            "-ssi_fem_part_shell_E", repr(p.E), "-ssi_fem_part_shell_nu", repr(p.nu),
            "-ssi_fem_part_shell_rho", repr(p.rho if p.rho > 0 else 1.0),
            "-ssi_fem_part_shell_thickness", repr(p.thickness), "-ssi_fem_fixed", ",".join(spec)]
    if problem.loads:
        F = np.zeros((problem.n_nodes, 6))
        for node, k, v in problem.loads:
            F[node, k] += v
        rows = [",".join(repr(float(v)) for v in np.r_[problem.coords[a], F[a]]) for a in np.nonzero(F.any(1))[0]]
        opts += ["-ssi_fem_point_load", ";".join(rows)]
    if problem.probe:
        opts += ["-ssi_receivers", ";".join(",".join(repr(float(v)) for v in problem.coords[a])
                                            for a, _, _ in problem.probe)]
    return path, opts
