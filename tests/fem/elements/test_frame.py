"""Tests of the 2-node 3D Timoshenko frame element (petsc_ssi/fem/elements/frame.py).

Solved with the small independent scipy assembler np_assembly (no PETSc).
"""
import dataclasses
import os
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import np_assembly as npa  # noqa: E402

from petsc_ssi.fem.elements import Props, REGISTRY  # noqa: E402
from petsc_ssi.fem.elements.frame import FRAME, Frame, rect_section  # noqa: E402
from petsc_ssi.petsc import SSIError  # noqa: E402

pytestmark = pytest.mark.unit

# Euler-Bernoulli cantilever eigenvalues beta_n L (Blevins, "Formulas for natural frequency and mode shape")
BETA_L = np.array([1.87510407, 4.69409113, 7.85475744])


def section_props(b=0.3, h=0.5, **kw):
    """Concrete-like rectangle b (along y') x h (along z', the orientation)."""
    base = dict(E=30e9, nu=0.2, rho=2500.0, shear_factor=5.0 / 6.0, **rect_section(b, h))
    base.update(kw)
    return Props(**base)


def random_rotation(rng):
    Q, R = np.linalg.qr(rng.standard_normal((3, 3)))
    Q = Q * np.sign(np.diag(R))
    if np.linalg.det(Q) < 0:
        Q[:, 0] = -Q[:, 0]
    return Q


def local_axes(d, v):
    """Expected local axes of a member along d with orientation v (the contract's words)."""
    ex = d / np.linalg.norm(d)
    ez = v - (v @ ex) * ex
    ez /= np.linalg.norm(ez)
    return ex, np.cross(ez, ex), ez


def random_members(rng, n):
    X = rng.uniform(-5, 5, (n, 2, 3))
    V = rng.standard_normal((n, 3))
    return X, V


def rigid_body_modes(X):
    """(12, 6) element vectors: 3 translations, 3 rotations about an arbitrary point."""
    x0 = np.array([0.7, -1.3, 2.1])
    R = np.zeros((12, 6))
    for k in range(3):
        e = np.eye(3)[k]
        for a in range(2):
            R[6 * a:6 * a + 3, k] = e
            R[6 * a:6 * a + 3, 3 + k] = np.cross(e, X[a] - x0)
            R[6 * a + 3:6 * a + 6, 3 + k] = e
    return R


# ---------------------------------------------------------------------- contract
def test_registered_and_declared():
    assert REGISTRY["frame"] is FRAME and isinstance(FRAME, Frame)
    assert FRAME.name == "frame" and FRAME.dim == 1 and FRAME.nodes_per_cell == 2
    assert FRAME.dof_names == ("ux", "uy", "uz", "rx", "ry", "rz")
    assert FRAME.gmsh_type == 1 and FRAME.xdmf_type == "Polyline" and FRAME.ndof == 12
    assert FRAME.required == ("E", "nu", "rho", "area", "Iy", "Iz", "J")
    assert FRAME.optional == {"shear_factor": 5 / 6, "orientation": (0, 0, 1), "added_mass": 0.0}
    for k in FRAME.required + tuple(FRAME.optional):
        assert hasattr(Props(), k)


# ------------------------------------------------------------ fast == reference
@pytest.mark.parametrize("shear_factor", [5.0 / 6.0, 0.0])
@pytest.mark.parametrize("per_cell_orientation", [False, True])
def test_fast_kernel_matches_reference(shear_factor, per_cell_orientation):
    rng = np.random.default_rng(1)
    X, V = random_members(rng, 40)
    if per_cell_orientation:
        props = section_props(0.2, 0.6, shear_factor=shear_factor, orientation=V)
        K, Kr = FRAME.stiffness(X, props), FRAME.stiffness_reference(X, props)
    else:        # one orientation per part: compare cell by cell with its own vector
        K, Kr = [], []
        for e in range(X.shape[0]):
            p = section_props(0.2, 0.6, shear_factor=shear_factor, orientation=V[e])
            K.append(FRAME.stiffness(X[e:e + 1], p)[0])
            Kr.append(FRAME.stiffness_reference(X[e:e + 1], p)[0])
        K, Kr = np.array(K), np.array(Kr)
    rel = np.abs(K - Kr).max(axis=(1, 2)) / np.abs(Kr).max(axis=(1, 2))
    assert rel.max() <= 1e-12, rel.max()


def test_local_axes_follow_the_orientation():
    """Depth direction z' is the orientation's normal part: for a member along x with the
    orientation along +z, local ty is -d w/dx (global ry) and the z'-deflection stiffness
    12 E Iy / L^3 sits on uz."""
    p = section_props(0.2, 0.6, shear_factor=0.0, orientation=np.array([0.3, 0.0, 2.0]))
    L = 2.0
    K = FRAME.stiffness(np.array([[[0, 0, 0], [L, 0, 0]]], float), p)[0]
    EIy, EIz = p.E * p.Iy, p.E * p.Iz
    assert np.isclose(K[2, 2], 12 * EIy / L ** 3, rtol=1e-14)   # uz: Iy = b h^3 / 12
    assert np.isclose(K[1, 1], 12 * EIz / L ** 3, rtol=1e-14)   # uy: Iz = h b^3 / 12
    assert np.isclose(K[2, 4], -6 * EIy / L ** 2, rtol=1e-14)   # uz-ry coupling
    assert np.isclose(K[1, 5], 6 * EIz / L ** 2, rtol=1e-14)    # uy-rz coupling
    assert np.isclose(K[3, 3], p.G() * p.J / L, rtol=1e-14)


# --------------------------------------------------------- symmetry, null space
@pytest.mark.parametrize("shear_factor", [5.0 / 6.0, 0.0])
def test_symmetric_and_rigid_body_null_space(shear_factor):
    rng = np.random.default_rng(2)
    X = rng.uniform(-1, 1, (20, 2, 3))
    X[:, 1] = X[:, 0] + rng.uniform(0.5, 2.0, (20, 1)) * rng.standard_normal((20, 3)) / np.sqrt(3)
    V = rng.standard_normal((20, 3))
    p = section_props(0.1, 0.25, shear_factor=shear_factor, orientation=V)
    K = FRAME.stiffness(X, p)
    assert np.array_equal(K, K.transpose(0, 2, 1))
    worst_null, worst_gap = 0.0, np.inf
    for e in range(X.shape[0]):
        R = rigid_body_modes(X[e])
        assert np.linalg.matrix_rank(R) == 6
        worst_null = max(worst_null, np.abs(K[e] @ R).max() / (np.abs(K[e]).max() * np.abs(R).max()))
        s = np.linalg.svd(K[e], compute_uv=False)
        assert np.linalg.matrix_rank(K[e]) == 6
        worst_gap = min(worst_gap, s[5] / s[0])            # smallest nonzero singular value
        assert s[6] / s[0] < 1e-14
    assert worst_null < 1e-13, worst_null
    assert worst_gap > 1e-6, worst_gap


def test_assembled_space_frame_has_six_rigid_modes():
    coords, blocks = space_frame(np.eye(3))
    K, _ = npa.assemble(coords.shape[0], blocks)
    K = K.toarray()
    n = K.shape[0]
    assert np.linalg.matrix_rank(K) == n - 6
    x0 = np.array([1.0, 2.0, 3.0])
    for k in range(3):
        e = np.eye(3)[k]
        r = np.zeros((coords.shape[0], 6))
        r[:, 3:] = e
        r[:, :3] = np.cross(e, coords - x0)
        assert np.abs(K @ r.ravel()).max() <= 1e-12 * np.abs(K).max() * np.abs(r).max()


# -------------------------------------------------------------------- lumped mass
def test_lumped_mass_totals_and_rotations():
    rng = np.random.default_rng(3)
    X, V = random_members(rng, 30)
    p = section_props(0.2, 0.6, added_mass=150.0, orientation=V)
    m = FRAME.lumped_mass(X, p)
    assert m.shape == (30, 12) and np.all(m > 0)
    L = np.linalg.norm(X[:, 1] - X[:, 0], axis=1)
    total = np.sum((p.rho * p.area + p.added_mass) * L)
    for i in range(3):
        got = m[:, i].sum() + m[:, 6 + i].sum()
        assert abs(got - total) <= 1e-13 * total, (i, got, total)
    # rotations: diag(Lam^T diag(local) Lam), built here from the expected axes
    m_lin = p.rho * p.area + p.added_mass
    rho_r = p.rho + p.added_mass / p.area
    for e in range(30):
        ex, ey, ez = local_axes(X[e, 1] - X[e, 0], V[e])
        Lam = np.array([ex, ey, ez])
        d = np.array([rho_r * (p.Iy + p.Iz) * L[e] / 2,
                      m_lin * L[e] ** 3 / 78 + rho_r * p.Iy * L[e] / 2,
                      m_lin * L[e] ** 3 / 78 + rho_r * p.Iz * L[e] / 2])
        full = Lam.T @ np.diag(d) @ Lam
        for a in range(2):
            assert np.allclose(m[e, 6 * a + 3:6 * a + 6], np.diag(full), rtol=1e-12, atol=0)
            assert np.isclose(m[e, 6 * a + 3:6 * a + 6].sum(), d.sum(), rtol=1e-13)   # trace kept
            assert np.allclose(m[e, 6 * a:6 * a + 3], m_lin * L[e] / 2, rtol=1e-14)


def test_lumped_mass_axis_aligned_is_exact_and_positive_without_rho():
    L = 3.0
    X = np.array([[[0, 0, 0], [0, L, 0]]], float)                 # along y, depth along x
    p = section_props(0.2, 0.6, orientation=np.array([1.0, 0, 0]))
    m = FRAME.lumped_mass(X, p)[0]
    mb = p.rho * p.area * L ** 3 / 78
    # x' = y, z' = x, y' = z' x x' = x cross y = z: global rx is local tz (bending with Iz),
    # ry is the torsion, rz is local ty (bending with Iy)
    assert np.allclose(m[3:6], [mb + p.rho * p.Iz * L / 2, p.rho * (p.Iy + p.Iz) * L / 2,
                                mb + p.rho * p.Iy * L / 2], rtol=1e-14)
    assert np.array_equal(m[3:6], m[9:12])
    q = dataclasses.replace(p, rho=0.0, added_mass=80.0)
    mq = FRAME.lumped_mass(X, q)
    assert np.all(mq > 0)
    assert np.isclose(mq[0, 0], 80.0 * L / 2, rtol=1e-14)


# ------------------------------------------------------------------ cantilevers
def cantilever(d, v, L, n, props, graded):
    """n elements along the unit direction d from x0; returns coords, K (csr), fixed dofs."""
    x0 = np.array([0.3, -0.2, 1.1])
    s = np.linspace(0.0, 1.0, n + 1)
    if graded:
        s = s ** 1.7
    coords = x0 + L * s[:, None] * d
    cells = np.stack([np.arange(n), np.arange(1, n + 1)], axis=1)
    p = dataclasses.replace(props, orientation=v)
    K, m = npa.assemble(n + 1, [(FRAME, cells, coords, p)])
    return coords, K, m, np.arange(6)


CANT_CASES = [(1, False, 5.0 / 6.0), (5, True, 5.0 / 6.0), (1, False, 0.0), (5, True, 0.0)]


@pytest.mark.parametrize("n,graded,kappa", CANT_CASES)
def test_cantilever_closed_forms(n, graded, kappa):
    """Tip force, tip moment, axial force, torque in both bending planes; a (thick, L/h = 4)
    skew cantilever, exact for any n because the Timoshenko element is exact for nodal loads."""
    d = np.array([1.0, 2.0, -0.5])
    d /= np.linalg.norm(d)
    v = np.array([0.2, -0.4, 1.0])                              # not normal to d: tests the projection
    L = 2.0
    p = section_props(0.3, 0.5, shear_factor=kappa)
    coords, K, _, fixed = cantilever(d, v, L, n, p, graded)
    ex, ey, ez = local_axes(d, v)
    E, G, A, Iy, Iz, J = p.E, p.G(), p.area, p.Iy, p.Iz, p.J
    shear = L / (G * kappa * A) if kappa > 0 else 0.0
    P, M = 1.0e5, 3.0e4
    cases = {                                       # load (force, moment) -> (tip u, tip theta)
        "P along y'": ((P * ey, 0 * ey), (P * (L ** 3 / (3 * E * Iz) + shear) * ey, P * L ** 2 / (2 * E * Iz) * ez)),
        "P along z'": ((P * ez, 0 * ez), (P * (L ** 3 / (3 * E * Iy) + shear) * ez, -P * L ** 2 / (2 * E * Iy) * ey)),
        "M about z'": ((0 * ez, M * ez), (M * L ** 2 / (2 * E * Iz) * ey, M * L / (E * Iz) * ez)),
        "M about y'": ((0 * ey, M * ey), (-M * L ** 2 / (2 * E * Iy) * ez, M * L / (E * Iy) * ey)),
        "axial": ((P * ex, 0 * ex), (P * L / (E * A) * ex, 0 * ex)),
        "torque": ((0 * ex, M * ex), (0 * ex, M * L / (G * J) * ex)),
    }
    N = coords.shape[0]
    for name, ((F, Mo), (u_ex, t_ex)) in cases.items():
        f = np.zeros(6 * N)
        f[6 * (N - 1):6 * (N - 1) + 3] = F
        f[6 * (N - 1) + 3:6 * N] = Mo
        u = npa.solve_static(K, f, fixed).reshape(N, 6)
        scale = max(np.abs(u_ex).max(), np.abs(t_ex).max() * L)
        err_u = np.abs(u[-1, :3] - u_ex).max() / scale
        err_t = np.abs(u[-1, 3:] - t_ex).max() * L / scale
        assert err_u < 1e-9 and err_t < 1e-9, (name, err_u, err_t)
    # interior nodes of the tip-force case follow the exact Timoshenko deflection line
    f = np.zeros(6 * N)
    f[6 * (N - 1):6 * (N - 1) + 3] = P * ez
    u = npa.solve_static(K, f, fixed).reshape(N, 6)
    x = (coords - coords[0]) @ d
    w = P / (E * Iy) * (L * x ** 2 / 2 - x ** 3 / 6) + P * x * (shear / L)
    assert np.abs(u[:, :3] @ ez - w).max() < 1e-9 * np.abs(w).max()


def test_cantilever_shear_vanishes_as_shear_area_grows():
    """Tip deflection -> Euler-Bernoulli P L^3 / (3 E I) as shear_factor grows; shear_factor = 0 is EB."""
    d = np.array([0.0, 0.6, 0.8])
    v = np.array([1.0, 0.0, 0.0])
    L, P = 1.5, 1.0e5
    ex, ey, ez = local_axes(d, v)
    errs = []
    for kappa in (5.0 / 6.0, 50.0, 5000.0, 0.0):
        p = section_props(0.3, 0.5, shear_factor=kappa)
        coords, K, _, fixed = cantilever(d, v, L, 3, p, False)
        N = coords.shape[0]
        f = np.zeros(6 * N)
        f[6 * (N - 1):6 * (N - 1) + 3] = P * ez
        w = npa.solve_static(K, f, fixed).reshape(N, 6)[-1, :3] @ ez
        errs.append(w / (P * L ** 3 / (3 * p.E * p.Iy)) - 1.0)
    assert errs[0] > 0.05                                  # thick beam: shear matters (L/h = 3)
    assert errs[0] > errs[1] > errs[2] > 0
    assert errs[2] < 1e-3 and abs(errs[3]) < 1e-12, errs


# ---------------------------------------------------------- rotation invariance
def space_frame(Q):
    """A 3D frame (4 columns, 4 top beams, a brace, a cantilever arm, 2 elements per member),
    rigidly rotated by Q. Returns coords (N, 3) and np_assembly blocks (3 parts)."""
    corners = np.array([[0, 0, 0], [4, 0, 0], [4, 5, 0], [0, 5, 0]], float)
    pts = list(corners) + list(corners + [0, 0, 3]) + [np.array([6.0, 5.5, 3.2])]
    pts = np.array(pts)
    members = {"columns": [(0, 4), (1, 5), (2, 6), (3, 7)],
               "beams": [(4, 5), (5, 6), (6, 7), (7, 4), (6, 8)],
               "brace": [(0, 5)]}
    orient = {"columns": np.array([1.0, 0, 0]), "beams": np.array([0, 0, 1.0]),
              "brace": np.array([0, 1.0, 0.3])}
    sec = {"columns": section_props(0.4, 0.4), "beams": section_props(0.3, 0.6),
           "brace": section_props(0.15, 0.2, shear_factor=0.0)}
    coords = list(pts)
    blocks = []
    for part, mm in members.items():
        cells = []
        for a, b in mm:                                       # split every member in two
            coords.append(0.5 * (pts[a] + pts[b]))
            c = len(coords) - 1
            cells += [(a, c), (c, b)]
        blocks.append([part, np.array(cells)])
    coords = np.array(coords) @ Q.T
    out = [(FRAME, cells, coords, dataclasses.replace(sec[part], orientation=Q @ orient[part]))
           for part, cells in blocks]
    return coords, out


def test_rotated_frame_gives_rotated_answer():
    rng = np.random.default_rng(4)
    Q = random_rotation(rng)
    coords0, blocks0 = space_frame(np.eye(3))
    coords1, blocks1 = space_frame(Q)
    N = coords0.shape[0]
    fixed = np.arange(24)                                      # nodes 0-3: column bases
    F = rng.standard_normal((N, 3)) * 1e5
    Mo = rng.standard_normal((N, 3)) * 1e5
    K0, _ = npa.assemble(N, blocks0)
    K1, _ = npa.assemble(N, blocks1)
    u0 = npa.solve_static(K0, np.hstack([F, Mo]).ravel(), fixed).reshape(N, 6)
    u1 = npa.solve_static(K1, np.hstack([F @ Q.T, Mo @ Q.T]).ravel(), fixed).reshape(N, 6)
    err_u = np.abs(u1[:, :3] - u0[:, :3] @ Q.T).max() / np.abs(u0[:, :3]).max()
    err_t = np.abs(u1[:, 3:] - u0[:, 3:] @ Q.T).max() / np.abs(u0[:, 3:]).max()
    assert err_u < 1e-10 and err_t < 1e-10, (err_u, err_t)
    assert np.abs(u0[4:, :3]).max() > 1e-6                    # a real, non-trivial response


# ------------------------------------------------------------------ frequencies
def eb_frequencies(p, I, L):
    return BETA_L ** 2 / (2 * np.pi * L ** 2) * np.sqrt(p.E * I / (p.rho * p.area))


SLENDER = dict(b=0.2, h=0.1, L=10.0)                          # L / h = 100, L / b = 50
MESHES = (8, 16, 32)


def frequency_errors(meshes, plane):
    """Relative errors of the 3 lowest bending frequencies of an axis-aligned cantilever
    (along x, depth along z) in one plane: the out-of-plane dofs are fixed."""
    b, h, L = SLENDER["b"], SLENDER["h"], SLENDER["L"]
    p = section_props(b, h, shear_factor=0.0)
    I, keep = (p.Iy, (0, 2, 4)) if plane == "xz" else (p.Iz, (0, 1, 5))
    errs = []
    for n in meshes:
        _, K, m, fixed = cantilever(np.array([1.0, 0, 0]), np.array([0, 0, 1.0]), L, n, p, False)
        out = [6 * a + k for a in range(n + 1) for k in range(6) if k not in keep]
        f = npa.lowest_frequencies(K, m, np.union1d(fixed, out), k=3)
        errs.append(np.abs(f / eb_frequencies(p, I, L) - 1.0))
    return np.array(errs)


@pytest.mark.parametrize("plane", ["xz", "xy"])
def test_cantilever_frequencies_converge_to_euler_bernoulli(plane):
    errs = frequency_errors(MESHES, plane)
    assert np.all(errs[1:] < errs[:-1]), errs                 # every mode, every refinement
    assert errs[-1].max() < 0.01, errs[-1]


def test_skew_cantilever_frequencies():
    """Full 3D skew cantilever (diagonal of the rotational mass in global dofs): the 5 lowest
    frequencies are the bending modes z1 y1 z2 y2 z3 (z: Iy, from the depth h along the
    orientation; y: Iz = 4 Iy); the 6th would be z4 (beta L = 10.9955), just below y3."""
    b, h, L = SLENDER["b"], SLENDER["h"], SLENDER["L"]
    p = section_props(b, h, shear_factor=0.0)
    d = np.array([1.0, -2.0, 2.0]) / 3.0
    v = np.array([0.5, 1.0, 0.2])
    fz, fy = eb_frequencies(p, p.Iy, L), eb_frequencies(p, p.Iz, L)
    expected = np.array([fz[0], fy[0], fz[1], fy[1], fz[2]])
    assert np.all(np.diff(expected) > 0)
    errs = []
    for n in MESHES:
        _, K, m, fixed = cantilever(d, v, L, n, p, False)
        f = npa.lowest_frequencies(K, m, fixed, k=5)
        errs.append(np.abs(f / expected - 1.0))
    errs = np.array(errs)
    assert np.all(errs[1:] < errs[:-1]), errs
    assert errs[-1].max() < 0.01, errs[-1]


# ------------------------------------------------------------------------ check
def test_check_reports_bad_cells_and_props():
    p = section_props()
    good = np.array([[[0, 0, 0], [1, 0, 0]], [[1, 0, 0], [1, 2, 0]]], float)
    assert FRAME.check(good, p) is None
    zero = good.copy()
    zero[1, 1] = zero[1, 0]
    msg = FRAME.check(zero, p)
    assert msg and "cell 1" in msg and "zero length" in msg and "\n" not in msg
    assert "[1.0, 0.0, 0.0]" in msg
    with pytest.raises(SSIError, match="zero length"):
        FRAME.stiffness(zero, p)
    with pytest.raises(SSIError, match="zero length"):
        FRAME.lumped_mass(zero, p)
    par = good.copy()
    par[1, 1] = [1, 0, 5]                                     # cell 1 along z, orientation z
    msg = FRAME.check(par, p)
    assert msg and "cell 1" in msg and "parallel" in msg and "\n" not in msg
    with pytest.raises(SSIError, match="parallel"):
        FRAME.stiffness(par, p)
    assert FRAME.check(good, dataclasses.replace(p, orientation=np.array([1.0, 0, 0]))).startswith(
        "frame cell 0")                                      # cell 0 along x
    nearly = dataclasses.replace(p, orientation=np.array([1.0, 0, 1e-4]))
    assert FRAME.check(good[:1], nearly) is None             # 1e-4 off the axis: accepted
    assert "orientation" in FRAME.check(good, dataclasses.replace(p, orientation=np.zeros(3)))
    for key in ("area", "Iy", "Iz", "J"):
        for val in (0.0, -1.0):
            msg = FRAME.check(good, dataclasses.replace(p, **{key: val}))
            assert msg and key in msg, (key, msg)
    assert FRAME.check(good, dataclasses.replace(p, rho=0.0, added_mass=0.0))


def test_rect_section_torsion_constant():
    """J / (a c^3) against the St-Venant table of Timoshenko and Goodier (3 decimals)."""
    table = {1: 0.141, 1.5: 0.196, 2: 0.229, 3: 0.263, 5: 0.291, 10: 0.312}
    for r, beta in table.items():
        s = rect_section(1.0, r)
        assert abs(s["J"] / (r * 1.0) - beta) < 6e-4, (r, s["J"] / r)
        assert rect_section(r, 1.0)["J"] == pytest.approx(s["J"], rel=1e-15)
    s = rect_section(0.2, 0.6)
    assert s["Iy"] == pytest.approx(0.2 * 0.6 ** 3 / 12) and s["Iz"] == pytest.approx(0.6 * 0.2 ** 3 / 12)
    assert rect_section(1, 1000)["J"] == pytest.approx(1000 / 3 * (1 - 0.630 / 1000), rel=1e-4)
