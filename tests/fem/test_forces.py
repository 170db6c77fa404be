"""Member forces (issue 28 item 2): frame end forces and shell stress resultants from the element
kernels (``Frame.end_forces``, ``shell.resultants``) against closed forms, and the output of a run
with -ssi_structure_forces (``fem.forces.ForceRecorder``: per-snapshot datasets, envelopes, the
XDMF cell fields) against the kernels applied to the run's own displacement snapshots.

The static solves use the test's own scipy assembly (elements/np_assembly.py); the frame element
is exact for nodal loads, and the shell patch fields are reproduced exactly, so the closed forms
hold to round-off (tolerances 1e-9 relative unless said).
"""
import os
import sys
import xml.etree.ElementTree as ET

import h5py
import numpy as np
import pytest

from fem_helpers import run_cli

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "elements"))
from np_assembly import assemble, solve_static  # noqa: E402

from petsc_ssi.fem.elements import Props  # noqa: E402
from petsc_ssi.fem.elements.frame import FRAME, rect_section, _geometry  # noqa: E402
from petsc_ssi.fem.elements.shell import SHELL, resultants, local_frame  # noqa: E402
from petsc_ssi.fem import obstacle as ob  # noqa: E402

pytestmark = pytest.mark.mpi


def element_dofs(cells):
    return (6 * np.asarray(cells)[:, :, None] + np.arange(6)).reshape(len(cells), -1)


# ------------------------------------------------------------------ frames
def test_cantilever_end_forces_closed_form():
    """A skew cantilever (4 Timoshenko elements) under a tip force (Px, Py, Pz) in its local axes
    and a tip torque T: every element's end forces are the statics of the tip load, f[6:12] =
    (Px, Py, Pz, T, -Pz a, Py a) at the node a from the tip and f[0:6] the opposite at the other
    end: shear P and moment P L at the root, no moment at the tip."""
    n, L = 4, 3.0
    d = np.array([1.0, 0.4, 0.3])
    d /= np.linalg.norm(d)
    X = np.outer(np.linspace(0, L, n + 1), d) + np.array([0.5, -0.2, 1.0])
    cells = np.column_stack([np.arange(n), np.arange(1, n + 1)])
    props = Props(E=30e9, nu=0.25, rho=2500.0, **rect_section(0.2, 0.4), orientation=(0.0, 0.0, 1.0))
    _, Lam = _geometry(X[cells[:1]], props)
    ex, ey, ez = Lam[0]
    Px, Py, Pz, T = 3e3, -2e3, 1e4, 2e3
    K, _ = assemble(n + 1, [(FRAME, cells, X, props)])
    f = np.zeros(6 * (n + 1))
    f[6 * n:6 * n + 3] = Px * ex + Py * ey + Pz * ez
    f[6 * n + 3:6 * n + 6] = T * ex
    u = solve_static(K, f, np.arange(6))
    fe = FRAME.end_forces(X[cells], props, u[element_dofs(cells)])
    a = L - np.linspace(0, L, n + 1)                   # distance of each node from the tip
    want = np.zeros((n, 12))
    for e in range(n):
        for k, s in ((0, -1.0), (1, 1.0)):
            want[e, 6 * k:6 * k + 6] = s * np.array([Px, Py, Pz, T, -Pz * a[e + k], Py * a[e + k]])
    scale = np.hypot(Py, Pz) * L
    assert np.abs(fe - want).max() < 1e-9 * scale
    assert abs(fe[0, 4] - Pz * L) < 1e-9 * scale and abs(fe[-1, 10]) < 1e-9 * scale   # root P L, tip 0
    # the stress resultants (-f at node 0): My at the root -Pz L (the +z' fibre in compression)
    assert abs(-fe[0, 4] + Pz * L) < 1e-9 * scale


@pytest.mark.parametrize("k", [0.25, 1.0, 1e6])
def test_portal_frame_column_moments_closed_form(k):
    """Fixed-base portal (columns h, beam span L in the x-z plane, Euler-Bernoulli, axial
    deformation negligible: A 1e6 times the section's) under a horizontal force H at the beam:
    the classical sway solution with k = I_b h / (I_c L): column shear H/2, moments
    M_base = H h/2 (3k+1)/(6k+1), M_top = H h/2 3k/(6k+1), beam end moments M_top, beam shear
    and column axial force 2 M_top / L, no moment at mid-span (the beam is two elements). k = 1e6
    is the infinitely stiff beam (M_base = M_top = H h/4)."""
    h, L, H = 3.0, 5.0, 1e4
    Ic = 1e-3
    Ib = k * Ic * L / h
    X = np.array([[0, 0, 0], [0, 0, h], [L / 2, 0, h], [L, 0, h], [L, 0, 0.0]])
    col = Props(E=30e9, nu=0.2, rho=2500.0, area=1e3, Iy=Ic, Iz=Ic, J=Ic, shear_factor=0.0,
                orientation=(1.0, 0.0, 0.0))
    beam = Props(E=30e9, nu=0.2, rho=2500.0, area=1e3, Iy=Ib, Iz=Ic, J=Ic, shear_factor=0.0,
                 orientation=(0.0, 0.0, 1.0))
    cc, cb = np.array([[0, 1], [4, 3]]), np.array([[1, 2], [2, 3]])
    K, _ = assemble(5, [(FRAME, cc, X, col), (FRAME, cb, X, beam)])
    f = np.zeros(30)
    f[6] = H
    u = solve_static(K, f, np.r_[np.arange(6), 24 + np.arange(6)])
    fc = FRAME.end_forces(X[cc], col, u[element_dofs(cc)])
    fb = FRAME.end_forces(X[cb], beam, u[element_dofs(cb)])
    Mb, Mt = H * h / 2 * (3 * k + 1) / (6 * k + 1), H * h / 2 * 3 * k / (6 * k + 1)
    tol = 1e-6 * H * h
    assert np.allclose(np.abs(fc[:, [4, 10]]), [[Mb, Mt], [Mb, Mt]], rtol=0, atol=tol)   # about y' (in plane)
    assert np.allclose(np.abs(fc[:, [2, 8]]), H / 2, rtol=0, atol=1e-6 * H)              # shear along z' = x
    assert np.allclose(np.abs(fc[:, [0, 6]]), 2 * Mt / L, rtol=0, atol=1e-6 * H)         # axial
    assert np.allclose(np.abs(fb[:, [2, 8]]), 2 * Mt / L, rtol=0, atol=1e-6 * H)         # beam shear
    assert abs(abs(fb[0, 4]) - Mt) < tol and abs(abs(fb[1, 10]) - Mt) < tol
    assert abs(fb[0, 10]) < tol and abs(fb[1, 4]) < tol                                  # mid-span: 0
    assert np.abs(np.r_[fc[:, [1, 3, 5, 7, 9, 11]].ravel(), fb[:, [1, 3, 5, 7, 9, 11]].ravel()]).max() < tol
    # the two columns' base moments and shears balance the load: sum of base reactions = H
    assert abs(fc[0, 2] + fc[1, 2] + H) < 1e-6 * H or abs(fc[0, 2] + fc[1, 2] - H) < 1e-6 * H


# ------------------------------------------------------------------ shells
PROPS = Props(E=30e9, nu=0.2, rho=2500.0, thickness=0.3)


def _rotation(seed=6):
    Q, _ = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    return Q * np.sign(np.linalg.det(Q))


def _in_element_frames(T2, R, X):
    """A plane symmetric tensor T2 (2x2, in the patch's axes R[:2]) in each cell's local frame."""
    T3 = R[:2].T @ T2 @ R[:2]
    Re, _, _, _ = local_frame(X)
    return np.einsum("eai,ij,ebj->eab", Re[:, :2], T3, Re[:, :2])


def _patch_solve(U, coords, cells, bnd, props):
    import scipy.sparse.linalg as spla
    K, _ = assemble(8, [(SHELL, cells, coords, props)])
    pres = ob.fix(bnd, range(6))
    u = np.zeros(48)
    u[pres] = U[bnd].ravel()
    free = np.setdiff1d(np.arange(48), pres)
    u[free] = spla.spsolve(K[free][:, free].tocsc(), -(K[free][:, pres] @ u[pres]))
    return u


@pytest.mark.parametrize("rotated", [False, True], ids=["xy-plane", "rotated"])
def test_membrane_patch_resultants(rotated):
    """Uniform in-plane strain (and a rigid rotation, drilling dofs = the exact rotation) on the
    boundary of the distorted 5-element patch: every element's N = E t/(1 - nu^2) [[1, nu, 0],
    [nu, 1, 0], [0, 0, (1-nu)/2]] eps in its own local frame; M, Q = 0."""
    R = _rotation() if rotated else np.eye(3)
    coords, cells, xy, R, bnd, inner = ob.distorted_patch(R, origin=(3.0, -2.0, 1.0))
    B = np.array([[1.0e-3, 0.4e-3], [0.4e-3, -0.6e-3]]) + np.array([[0, -2e-3], [2e-3, 0]])
    uv = np.array([1e-4, -2e-4]) + xy @ B.T
    U = np.zeros((8, 6))
    U[:, :3] = np.c_[uv, np.zeros(8)] @ R
    U[:, 3:] = np.array([0.0, 0.0, 0.5 * (B[1, 0] - B[0, 1])]) @ R
    u = _patch_solve(U, coords, cells, bnd, PROPS)
    s = resultants(coords[cells], PROPS, u[element_dofs(cells)])[:, 0]
    E, nu, t = PROPS.E, PROPS.nu, PROPS.thickness
    eps = 0.5 * (B + B.T)
    sig = E / (1 - nu ** 2) * ((1 - nu) * eps + nu * np.trace(eps) * np.eye(2))
    want = _in_element_frames(t * sig, R, coords[cells])
    scale = np.abs(t * sig).max()
    assert np.abs(s[:, [0, 1, 2]] - want[:, [0, 1, 0], [0, 1, 1]]).max() < 1e-9 * scale
    assert np.abs(s[:, 3:]).max() < 1e-9 * scale * t


@pytest.mark.parametrize("rotated", [False, True], ids=["xy-plane", "rotated"])
def test_bending_patch_resultants(rotated):
    """Constant curvature (quadratic w, Kirchhoff rotations) on the boundary of the distorted
    patch: every element's M = E t^3/(12 (1 - nu^2)) [[1, nu, 0], [nu, 1, 0], [0, 0, (1-nu)/2]]
    kappa with kappa = -grad grad w (M11 > 0 stretches the +e3 fibre) in its local frame, Q = 0
    and N = 0 (to 1e-9 of M / t)."""
    R = _rotation(3) if rotated else np.eye(3)
    coords, cells, xy, R, bnd, inner = ob.distorted_patch(R, origin=(-1.0, 0.5, 2.0))
    c0, c1, c2, a, b, c = 1e-4, 2e-3, -1e-3, 0.02, -0.013, 0.031
    x, y = xy.T
    w = c0 + c1 * x + c2 * y + 0.5 * a * x * x + b * x * y + 0.5 * c * y * y
    U = np.zeros((8, 6))
    U[:, :3] = np.c_[0 * w, 0 * w, w] @ R
    U[:, 3:] = np.c_[c2 + b * x + c * y, -(c1 + a * x + b * y), 0 * w] @ R
    u = _patch_solve(U, coords, cells, bnd, PROPS)
    s = resultants(coords[cells], PROPS, u[element_dofs(cells)])[:, 0]
    E, nu, t = PROPS.E, PROPS.nu, PROPS.thickness
    kap = -np.array([[a, b], [b, c]])
    Mt = E * t ** 3 / (12 * (1 - nu ** 2)) * ((1 - nu) * kap + nu * np.trace(kap) * np.eye(2))
    want = _in_element_frames(Mt, R, coords[cells])
    # the local frames' e3 equals the patch normal R[2] (the cells are counter-clockwise in (x, y))
    assert np.allclose(local_frame(coords[cells])[0][:, 2], R[2])
    scale = np.abs(Mt).max()
    assert np.abs(s[:, [3, 4, 5]] - want[:, [0, 1, 0], [0, 1, 1]]).max() < 1e-9 * scale
    assert np.abs(s[:, 6:]).max() < 1e-9 * scale and np.abs(s[:, :3]).max() < 1e-9 * scale / t


def test_transverse_shear_resultant():
    """A uniform shear strain (w linear, no rotation) on warped, distorted cells: the MITC4
    assumed shear is exact for it, Q = k G t grad w in each cell's local frame; M = N = 0."""
    rng = np.random.default_rng(4)
    X = np.array([[[0, 0, 0], [1.1, 0.1, 0], [1.0, 0.9, 0], [-0.1, 1.2, 0.0]],
                  [[0, 0, 0], [0.8, -0.2, 0], [1.2, 1.0, 0], [0.1, 0.7, 0.0]]])
    g = np.array([2e-3, -1e-3])
    ue = np.zeros((2, 4, 6))
    ue[:, :, 2] = X[..., :2] @ g
    Q = _rotation(9)
    Xr = X @ Q.T + rng.normal(size=3)
    uer = np.concatenate([ue[..., :3] @ Q.T, ue[..., 3:] @ Q.T], axis=2).reshape(2, 24)
    s = resultants(Xr, PROPS, uer)[:, 0]
    Re, _, _, _ = local_frame(Xr)
    ks = 5.0 / 6.0 * PROPS.E / (2 * (1 + PROPS.nu)) * PROPS.thickness
    # local normal e3 = +-Q z: gamma_a3 = dw'/dx_a with w' = u . e3
    sgn = np.sign(Re[:, 2] @ (Q @ [0, 0, 1.0]))
    want = ks * sgn[:, None] * np.einsum("eai,i->ea", Re[:, :2], Q @ np.r_[g, 0.0])
    assert np.abs(s[:, 6:] - want).max() < 1e-9 * np.abs(want).max()
    assert np.abs(s[:, :6]).max() < 1e-9 * np.abs(want).max()


def test_cantilever_plate_strip_under_end_moment():
    """A clamped 2 m x 0.5 m strip (8 x 2 elements, nu = 0) under an end moment m per unit width
    about +y (consistent nodal moments): M11 = m in every element, M22 = M12 = 0, Q = 0, N = 0."""
    props = Props(E=30e9, nu=0.0, rho=2500.0, thickness=0.2)
    nx, ny, Lx, Ly, m = 8, 2, 2.0, 0.5, 3e3
    x, y = np.meshgrid(np.linspace(0, Lx, nx + 1), np.linspace(0, Ly, ny + 1), indexing="ij")
    coords = np.c_[x.ravel(), y.ravel(), np.zeros(x.size)]
    nid = lambda i, j: i * (ny + 1) + j                      # noqa: E731
    cells = np.array([[nid(i, j), nid(i + 1, j), nid(i + 1, j + 1), nid(i, j + 1)]
                      for i in range(nx) for j in range(ny)])
    K, _ = assemble(coords.shape[0], [(SHELL, cells, coords, props)])
    f = np.zeros(6 * coords.shape[0])
    tip = [nid(nx, j) for j in range(ny + 1)]
    share = np.full(ny + 1, Ly / ny)
    share[[0, -1]] *= 0.5
    f[6 * np.array(tip) + 4] = m * share
    u = solve_static(K, f, ob.fix([nid(0, j) for j in range(ny + 1)], range(6)))
    s = resultants(coords[cells], props, u[element_dofs(cells)])[:, 0]
    assert np.abs(s[:, 3] - m).max() < 1e-9 * m
    assert np.abs(s[:, [4, 5, 6, 7]]).max() < 1e-9 * m and np.abs(s[:, :3]).max() < 1e-9 * m / 0.2


# ------------------------------------------------------------------ the output of a run
SLAB = os.path.join("runs", "structures", "slab-on-columns.opts")


def _run(path, nranks, stride, extra=()):
    r = run_cli(["-options_file", SLAB, "-ssi_t_end", "0.02", "-ssi_output", path, "-ssi_output_stride",
                 str(stride), "-ssi_structure_forces", "all", "-ssi_output_overwrite"] + list(extra), n=nranks)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]


def _read(path):
    with h5py.File(path, "r") as f:
        out = {k: f["forces"][k][()] for k in f["forces"]}
        out["attrs"] = {k: dict(f["forces"][k].attrs) for k in ("columns", "slab", "columns_envelope")}
        out["u"] = [f[f"displacement_{k:06d}"][()] for k in out["snapshots"]]
        out["r"] = [f[f"rotation_{k:06d}"][()] for k in out["snapshots"]]
        out["coords"] = f["coordinates"][()]
        out["time"] = f["time"][()]
        out["cell"] = {k[len("cell_peak_"):]: f[k][()] for k in f if k.startswith("cell_peak_")}
        out["cell_units"] = {k[len("cell_peak_"):]: f[k].attrs["unit"] for k in f if k.startswith("cell_peak_")}
        out["topology"] = f["topology"][()]
    return out


def _mixed_cells(flat):
    """The node lists of an XDMF Mixed topology (type id, [node count of a Polyline], nodes)."""
    cells, i, size = [], 0, {5: 4, 9: 8}
    while i < flat.size:
        if flat[i] == 2:
            n, i = int(flat[i + 1]), i + 2
        else:
            n, i = size[int(flat[i])], i + 1
        cells.append(flat[i:i + n].tolist())
        i += n
    return cells


def test_forces_output_of_a_run(tmp_path):
    """The slab on columns (24 frames, 48 shells, 10 steps) with -ssi_structure_forces all, on 1 rank
    writing every step (A) and on 2 ranks writing every 5th (B):
      * the datasets forces/<part> (K, E, 12 | 8) carry units and component names;
      * A's forces at every snapshot equal the element kernels (Frame.end_forces, shell
        resultants) applied to A's own displacement and rotation snapshots (1e-9 of the peak);
      * B's snapshots equal A's at the same times, and B's envelope (2 ranks, written every 5th
        step) equals the max over ALL of A's steps of |value| (1e-9): the envelope sees every
        step; it is >= every written |value|;
      * the cell fields cell_peak_* are the envelopes on the parts' cells (frames: max over both
        ends) and NaN elsewhere; the XDMF parses and has them as Center="Cell" attributes with the
        topology's cell count."""
    a, b = str(tmp_path / "a.h5"), str(tmp_path / "b.h5")
    _run(a, 1, 1)
    _run(b, 2, 5)
    A, B = _read(a), _read(b)
    assert A["columns"].shape == (11, 24, 12) and A["slab"].shape == (11, 48, 8)
    assert B["columns"].shape == (3, 24, 12) and list(B["snapshots"]) == [0, 1, 2]
    assert A["attrs"]["columns"]["unit"].split(",")[4] == "N m" and A["attrs"]["slab"]["unit"].split(",")[3] == "N m/m"
    assert A["attrs"]["columns"]["components"].split(",")[:6] == ["N_i", "V2_i", "V3_i", "T_i", "M2_i", "M3_i"]
    assert A["attrs"]["slab"]["components"] == "N11,N22,N12,M11,M22,M12,Q1,Q2"
    assert np.allclose(A["time"][A["snapshots"]], A["time"]) and np.allclose(B["time"], A["time"][::5])
    # the kernels on A's own snapshots (columns: vertical members, default orientation x)
    col = Props(E=30e9, nu=0.2, rho=2500.0, **rect_section(0.3, 0.3), orientation=(1.0, 0.0, 0.0))
    slab = Props(E=30e9, nu=0.2, rho=2500.0, thickness=0.2, added_mass=100.0)
    X = A["coords"]
    for k in range(len(A["snapshots"])):
        U = np.c_[A["u"][k], A["r"][k]]
        fc = FRAME.end_forces(X[A["columns_nodes"]], col, U[A["columns_nodes"]].reshape(-1, 12))
        fs = resultants(X[A["slab_nodes"]], slab, U[A["slab_nodes"]].reshape(-1, 24))[:, 0]
        assert np.abs(A["columns"][k] - fc).max() <= 1e-9 * np.abs(A["columns"]).max()
        assert np.abs(A["slab"][k] - fs).max() <= 1e-9 * np.abs(A["slab"]).max()
    for part in ("columns", "slab"):
        peak = np.abs(A[part]).max()
        assert np.abs(B[part] - A[part][::5]).max() < 1e-9 * peak
        assert np.abs(B[part + "_envelope"] - np.abs(A[part]).max(axis=0)).max() < 1e-9 * peak
        assert np.all(B[part + "_envelope"] >= np.abs(B[part]).max(axis=0))
        assert np.array_equal(A[part + "_cells"], B[part + "_cells"])
    # B's envelope exceeds its written values somewhere: the steps between the snapshots count
    assert np.any(B["columns_envelope"] > np.abs(B["columns"]).max(axis=0) * (1 + 1e-6))
    topo = _mixed_cells(B["topology"])                             # the XDMF's cell order
    assert len(topo) == 72
    for part in ("columns", "slab"):
        assert [topo[c] for c in B[part + "_cells"]] == B[part + "_nodes"].tolist()
    env = B["columns_envelope"]
    assert np.array_equal(B["cell"]["M3"][B["columns_cells"]], np.maximum(env[:, 5], env[:, 11]))
    assert np.isnan(B["cell"]["M3"][B["slab_cells"]]).all() and np.isnan(B["cell"]["M11"][B["columns_cells"]]).all()
    assert np.array_equal(B["cell"]["Q2"][B["slab_cells"]], B["slab_envelope"][:, 7])
    assert B["cell_units"]["M3"] == "N m" and B["cell_units"]["M11"] == "N m/m"
    root = ET.parse(b.replace(".h5", ".xmf")).getroot()
    grids = root.findall(".//Grid[@GridType='Uniform']")
    assert len(grids) == 3
    for g in grids:
        ne = int(g.find("Topology").get("NumberOfElements"))
        cells = {a.get("Name"): a for a in g.findall("Attribute") if a.get("Center") == "Cell"}
        assert {"peak_M3", "peak_M2", "peak_N", "peak_M11", "peak_Q1"} <= set(cells)
        assert all(int(a.find("DataItem").get("Dimensions")) == ne for a in cells.values())
        assert cells["peak_M3"].find("DataItem").text.endswith(":/cell_peak_M3")


@pytest.mark.parametrize("value, message", [
    ("slabb", "no part 'slabb' (parts: slab, columns); did you mean slab?"),
    ("slab,slab", "a part is named twice"),
])
def test_forces_option_bad_input(value, message, tmp_path):
    """A misspelt or repeated part: one line, before any mesh is read."""
    r = run_cli(["-options_file", SLAB, "-ssi_output", str(tmp_path / "x.h5"), "-ssi_structure_forces", value])
    assert r.returncode != 0 and message in (r.stdout + r.stderr), r.stdout + r.stderr
    assert "[fem] mesh" not in r.stdout


def test_forces_option_refuses_brick_parts():
    from petsc_ssi.fem.parts import PartSpec
    from petsc_ssi.fem.forces import parse_force_parts
    from petsc_ssi.petsc import SSIError
    specs = [PartSpec("block", "hex8", None), PartSpec("beam", "frame", None)]
    assert parse_force_parts("all", specs) == ["beam"] and parse_force_parts("none", specs) == []
    with pytest.raises(SSIError, match="part 'block' is a hex8 part"):
        parse_force_parts("beam,block", specs)
    with pytest.raises(SSIError, match="no frame or shell part"):
        parse_force_parts("all", specs[:1])


def test_forces_xdmf_opens_in_paraview(tmp_path):
    """ParaView reads the cell fields (skipped without pvpython)."""
    from helpers import pv_or_skip, pvpython
    pv_or_skip()
    s = str(tmp_path / "s.h5")
    _run(s, 1, 5)
    got = pvpython("r.UpdatePipeline()\nd = dsa.WrapDataObject(sm.Fetch(r))\n"
                   "m = np.asarray(d.CellData['peak_M3'])\n"
                   "print(json.dumps({'cells': int(d.GetNumberOfCells()), "
                   "'m': [None if v != v else v for v in m.tolist()]}))\n", s.replace(".h5", ".xmf"), tmp_path)
    with h5py.File(s) as f:
        want = f["cell_peak_M3"][()]
    assert got["cells"] == want.size
    assert np.array_equal(np.array([np.nan if v is None else v for v in got["m"]]), want, equal_nan=True)


def test_forces_restart_and_flushes(tmp_path):
    """A run with flushes at every step (-ssi_output_flush 1e-9: the envelopes and the 'forces'
    group rewritten in place) and checkpoints every 4 steps, restarted after step 4 on 2 ranks
    (the envelopes come back from the checkpoint's Vecs): every dataset of the restarted file,
    forces and envelopes included, equals the uninterrupted run's (1e-9 relative: 1 vs 2 ranks)."""
    sys.path.insert(0, os.path.dirname(os.path.dirname(__file__)))
    from test_checkpoint import run_and_restart, datasets
    args = ["-options_file", SLAB, "-ssi_t_end", "0.02", "-ssi_output_stride", "3", "-ssi_structure_forces",
            "columns,slab", "-ssi_output_overwrite", "-ssi_output_flush", "1e-9"]
    for ref, rs in run_and_restart(args, tmp_path, 1, 4, 4, nranks_restart=2):
        A, B = datasets(rs), datasets(ref)
        assert sorted(A) == sorted(B) and A["@run_status"] == "completed"
        for k in A:
            x, y = np.asarray(A[k]), np.asarray(B[k])
            assert x.shape == y.shape, k
            if x.dtype.kind == "f" and x.size:
                assert np.array_equal(np.isnan(x), np.isnan(y)), k            # NaN: cells without the field
                assert np.nanmax(np.abs(x - y)) <= 1e-9 * max(np.nanmax(np.abs(y)), 1e-300), k
            else:
                assert np.array_equal(x, y), k
        assert "forces/columns" in A and "forces_envelope_slab" in A and "cell_peak_M3" in A
        with h5py.File(ref) as f:
            assert f["forces/columns"].shape == (4, 24, 12) and f["forces/columns"].is_virtual


def test_forces_in_a_coupled_run(tmp_path):
    """A coupled run (the one-storey half building of test_building_ci.py on the half-space, 8
    steps, 2 ranks, -ssi_structure_forces all): the structure's file has the forces of its three
    parts at every structure snapshot, equal to the kernels applied to that file's displacement
    and rotation snapshots (1e-9 of the peak), and envelopes >= every written |value|."""
    here = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    sys.path[:0] = [here, os.path.join(here, "coupling")]
    from test_building_ci import building_msh, structure_opts, soil_opts, E, NU, RC
    from helpers import cli
    msh = building_msh(str(tmp_path / "half.msh"), half=True)
    soil = soil_opts(t_end=0.02, sym=True)
    soil[soil.index("-ssi_output_stride") + 1] = "4"
    out = str(tmp_path / "c.h5")
    cli(["-ssi_problem", "ssi", "-ssi_output", out, "-ssi_structure_forces", "all"] + soil + structure_opts(msh),
        nranks=2, timeout=600)
    props = {"foundation": Props(E=E, nu=NU, rho=RC, thickness=0.5), "roof": Props(E=E, nu=NU, rho=RC, thickness=0.2),
             "columns": Props(E=E, nu=NU, rho=RC, **rect_section(0.3, 0.3), orientation=(1.0, 0.0, 0.0))}
    with h5py.File(out.replace(".h5", "_structure.h5"), "r") as f:
        X = f["coordinates"][()]
        snaps = f["forces/snapshots"][()]
        assert len(snaps) == len(f["time"]) == 3 and np.allclose(f["forces/time"][()], f["time"][()])   # t = 0, 4, 8 dt
        for part, p in props.items():
            F, env, nodes = f[f"forces/{part}"][()], f[f"forces/{part}_envelope"][()], f[f"forces/{part}_nodes"][()]
            assert F.shape == (3, nodes.shape[0], 12 if part == "columns" else 8)
            assert not np.any(F[0])                     # at rest at t = 0
            assert f[f"forces/{part}"].attrs["unit"].split(",")[3] == ("N m" if part == "columns" else "N m/m")
            peak = np.abs(F).max()
            assert peak > 0 and np.all(env >= np.abs(F).max(axis=0))
            for i, k in enumerate(snaps):
                U = np.c_[f[f"displacement_{k:06d}"][()], f[f"rotation_{k:06d}"][()]][nodes]
                want = (FRAME.end_forces(X[nodes], p, U.reshape(-1, 12)) if part == "columns" else
                        resultants(X[nodes], p, U.reshape(-1, 24))[:, 0])
                assert np.abs(F[i] - want).max() <= 1e-9 * peak, (part, k)
        assert "cell_peak_M3" in f and "cell_peak_M11" in f


def test_static_cantilever_forces_through_the_cli(tmp_path):
    """`petsc-ssi static` on a skew cantilever (6 frames, 2 ranks) with a tip force P normal to it
    (along the local z') and a tip torque T, -ssi_structure_forces beam: every element's end
    forces are the statics of the tip load (shear P, moment P a at the distance a from the tip:
    P L at the root, 0 at the tip; torque T; no axial force), to 1e-9 of P L."""
    from petsc_ssi.mesh.gmsh import write_msh
    n, L = 6, 3.0
    d = np.array([1.0, 2.0, 2.0]) / 3.0
    X = np.outer(np.linspace(0, L, n + 1), d) + np.array([0.5, -0.2, 1.0])
    msh = str(tmp_path / "cant.msh")
    write_msh(msh, X, {"beam": ("line2", np.column_stack([np.arange(n), np.arange(1, n + 1)])),
                       "root": ("point", [[0]]), "tip": ("point", [[n]])})
    z = np.array([0.0, 0.0, 1.0]) - d[2] * d
    z /= np.linalg.norm(z)
    P, T = 1e4, 2e3
    load = ",".join(repr(v) for v in np.r_[X[-1], P * z, T * d])
    out = str(tmp_path / "cant.h5")
    r = run_cli(["static", "-ssi_problem", "fem", "-ssi_fem_mesh", msh, "-ssi_fem_parts", "beam",
                 "-ssi_fem_part_beam_element", "frame", "-ssi_fem_part_beam_E", "30e9", "-ssi_fem_part_beam_nu", "0.25",
                 "-ssi_fem_part_beam_rho", "2500", "-ssi_fem_part_beam_section", "0.2,0.4",
                 "-ssi_fem_part_beam_orientation", "0,0,1", "-ssi_fem_fixed", "root", "-ssi_fem_point_load", load,
                 "-ssi_output", out, "-ssi_structure_forces", "beam"], n=2)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    with h5py.File(out, "r") as f:
        F, nodes = f["forces/beam"][0], f["forces/beam_nodes"][()]
        env = f["forces/beam_envelope"][()]
        Y = f["coordinates"][()]                                  # the run's node numbering
        assert f["forces/beam"].attrs["components"].split(",")[10] == "M2_j"
    assert np.array_equal(env, np.abs(F))
    a = np.linalg.norm(Y[nodes] - X[-1], axis=2)                  # distance of each end from the tip
    want = np.zeros_like(F)
    want[:, 2], want[:, 3], want[:, 4] = -P, -T, P * a[:, 0]
    want[:, 8], want[:, 9], want[:, 10] = P, T, -P * a[:, 1]
    assert np.abs(F - want).max() < 1e-9 * P * L
    root = int(np.argmax(a[:, 0]))
    tip = int(np.argmin(a[:, 1]))
    assert abs(a[root, 0] - L) < 1e-12 and a[tip, 1] < 1e-12
    assert abs(F[root, 4] - P * L) < 1e-9 * P * L and abs(F[tip, 10]) < 1e-9 * P * L
