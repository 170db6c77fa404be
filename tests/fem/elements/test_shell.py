"""The 4-node flat shell (MITC4 bending + Allman/Hughes-Brezzi drilling membrane).

Element checks (fast == reference kernel, symmetry, rigid modes, spurious modes,
mass, patch tests, pressure, input checks) and the obstacle course
(petsc_ssi/fem/obstacle.py): Scordelis-Lo roof, pinched cylinder, twisted beam,
NAFEMS FV16 and a simply supported plate, each on a few meshes with the error
shown to decrease. Larger sweeps: ``python -m petsc_ssi.fem.obstacle``.
"""
import numpy as np
import pytest

from np_assembly import assemble, solve_static, lowest_frequencies, free_dofs
from petsc_ssi.fem import obstacle as ob
from petsc_ssi.fem.elements import Props
from petsc_ssi.fem.elements.shell import SHELL, pressure_forces, local_frame

pytestmark = pytest.mark.unit

PROPS = Props(E=30e9, nu=0.2, rho=2500.0, thickness=0.3)


def rotations(rng, n):
    Q, _ = np.linalg.qr(rng.normal(size=(n, 3, 3)))
    return Q * np.sign(np.linalg.det(Q))[:, None, None]      # proper rotations


def random_quads(rng, n, warp=0.0, distort=0.25):
    """Distorted (convex) unit-ish quads, optionally warped out of plane, in random orientation,
    size and position."""
    base = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.0]])
    X = base[None] + distort * rng.uniform(-1, 1, (n, 4, 3)) * np.array([1, 1, 0])
    X[:, :, 2] += warp * np.array([1, -1, 1, -1]) * rng.uniform(0.5, 1, (n, 1))
    X = X * rng.uniform(0.3, 3.0, (n, 1, 1))
    return np.einsum("eij,eaj->eai", rotations(rng, n), X) + rng.normal(scale=10.0, size=(n, 1, 3))


def rigid_modes(X):
    """(E, 24, 6): 3 translations and 3 rotations w (u = w x (x - c), theta = w) of each cell."""
    d = X - X.mean(axis=1, keepdims=True)
    R = np.zeros((X.shape[0], 4, 6, 6))
    for k in range(3):
        R[:, :, k, k] = 1.0
        w = np.eye(3)[k]
        R[:, :, :3, 3 + k] = np.cross(w, d)
        R[:, :, 3 + k, 3 + k] = 1.0
    return R.reshape(-1, 24, 6)


def block_rotation(Q):
    """24 x 24 block-diagonal of the 3x3 rotation Q."""
    return np.kron(np.eye(8), Q)


# ---------------------------------------------------------------- kernels

@pytest.mark.parametrize("warp", [0.0, 0.05, 0.2])
@pytest.mark.parametrize("props", [PROPS, Props(E=2e11, nu=0.3, rho=7850, thickness=0.02, shear_factor=1.0,
                                                drilling=0.3)])
def test_fast_kernel_equals_reference(warp, props):
    rng = np.random.default_rng(1)
    X = random_quads(rng, 30, warp=warp, distort=0.3)
    assert SHELL.check(X, props) is None
    K = SHELL.stiffness(X, props)
    Kr = SHELL.stiffness_reference(X, props)
    assert K.shape == (30, 24, 24)
    scale = np.abs(Kr).max(axis=(1, 2))[:, None, None]
    assert np.max(np.abs(K - Kr) / scale) < 1e-10


def test_symmetric_objective_and_node_order_invariant():
    rng = np.random.default_rng(2)
    X = random_quads(rng, 20, warp=0.1)
    K = SHELL.stiffness(X, PROPS)
    scale = np.abs(K).max()
    assert np.abs(K - K.transpose(0, 2, 1)).max() < 1e-13 * scale
    # rotating the element rotates K (the local frame is built from the geometry alone)
    Q = rotations(rng, 1)[0]
    T = block_rotation(Q)
    KQ = SHELL.stiffness(X @ Q.T, PROPS)
    assert np.abs(KQ - T @ K @ T.T).max() < 1e-10 * scale
    # a cyclic renumbering of the nodes only permutes the dofs
    perm = np.array([1, 2, 3, 0])
    Kp = SHELL.stiffness(X[:, perm], PROPS)
    idx = (6 * perm[:, None] + np.arange(6)).ravel()
    assert np.abs(Kp - K[:, idx[:, None], idx]).max() < 1e-10 * scale


@pytest.mark.parametrize("warp", [0.0, 0.1, 0.3])
def test_rigid_body_modes_span_null_space(warp):
    """K R = 0 to round-off for the 6 rigid motions, and rank K = 24 - 6 (the rigid-link warping
    correction keeps the rigid modes of warped cells)."""
    rng = np.random.default_rng(3)
    X = random_quads(rng, 20, warp=warp)
    _, _, h, _ = local_frame(X)
    assert (np.abs(h).max() > 0.01) == (warp > 0)
    K = SHELL.stiffness(X, PROPS)
    R = rigid_modes(X)
    KR = np.matmul(K, R)
    nK = np.linalg.norm(K, axis=(1, 2))
    nR = np.linalg.norm(R, axis=1).max(axis=1)
    assert np.max(np.linalg.norm(KR, axis=1).max(axis=1) / (nK * nR)) < 1e-13
    lam = np.linalg.eigvalsh(K)
    rank = np.sum(lam > 1e-10 * lam[:, -1:], axis=1)
    assert np.all(rank == 18)
    assert np.all(np.abs(lam[:, :6]) < 1e-12 * lam[:, -1:])


@pytest.mark.parametrize("shape", ["square", "distorted", "warped", "thin", "elongated"])
def test_exactly_six_zero_eigenvalues(shape):
    """One element: exactly 6 zero-energy modes (no spurious modes, drilling included); with the
    drilling term switched off the Allman membrane has one more (the equal-rotation mode)."""
    X = {"square": [[0, 0, 0], [0.6, 0, 0], [0.6, 0.6, 0], [0, 0.6, 0]],
         "distorted": [[0, 0, 0], [0.7, 0.1, 0], [0.5, 0.6, 0], [-0.1, 0.45, 0]],
         "warped": [[0, 0, 0], [0.6, 0, 0.05], [0.6, 0.6, 0], [0, 0.6, 0.05]],
         "thin": [[0, 0, 0], [0.6, 0, 0], [0.6, 0.6, 0], [0, 0.6, 0]],
         "elongated": [[0, 0, 0], [3.0, 0, 0], [3.0, 0.3, 0], [0, 0.3, 0]]}[shape]
    X = np.array(X, float)[None] @ rotations(np.random.default_rng(4), 1)[0].T
    props = Props(E=30e9, nu=0.2, rho=2500, thickness=0.01 if shape == "thin" else 0.5)
    lam = np.linalg.eigvalsh(SHELL.stiffness(X, props)[0])
    assert np.sum(lam < 1e-9 * lam[-1]) == 6
    assert lam[6] > 1e-9 * lam[-1]
    props.drilling = 0.0
    lam = np.linalg.eigvalsh(SHELL.stiffness(X, props)[0])
    assert np.sum(lam < 1e-11 * lam[-1]) == 7


def test_drilling_stiffness_is_real_in_plane_bending():
    """MacNeal-Harder straight cantilever (6 x 1 rectangles, L = 6, w = 0.2, t = 0.1, E = 1e7,
    nu = 0.3), unit in-plane shear at the tip, reference 0.1081: an element that bends in its
    plane (measured 0.0977, 90 %; the same element with the Allman edge modes removed, i.e. a
    bilinear membrane with the Hughes-Brezzi drilling term, gives 0.0082, 7.6 %). The drilling
    rotation at the tip follows the beam's slope P L^2 / (2 E I) (measured 91 %)."""
    xs = np.linspace(0, 6.0, 7)
    coords = np.r_[np.c_[xs, 0 * xs, 0 * xs], np.c_[xs, 0 * xs + 0.2, 0 * xs]]
    cells = np.array([[i, i + 1, i + 8, i + 7] for i in range(6)])
    K, _ = assemble(14, [(SHELL, cells, coords, Props(E=1e7, nu=0.3, rho=1.0, thickness=0.1))])
    fixed = np.r_[ob.fix([0, 7], range(6)), ob.fix(np.arange(14), [2, 3, 4])]
    f = np.zeros(84)
    f[[6 * 6 + 1, 6 * 13 + 1]] = 0.5
    u = solve_static(K, f, fixed)
    tip = 0.5 * (u[6 * 6 + 1] + u[6 * 13 + 1])
    assert 0.85 < tip / 0.1081 < 1.0
    slope = 1.0 * 6.0 ** 2 / (2 * 1e7 * 0.1 * 0.2 ** 3 / 12)     # P L^2 / (2 E I)
    assert abs(u[6 * 6 + 5] / slope - 1) < 0.15


# ---------------------------------------------------------------- mass

@pytest.mark.parametrize("mpa,added", [(0.0, 0.0), (0.0, 150.0), (900.0, 0.0), (900.0, 250.0)])
def test_lumped_mass(mpa, added):
    rng = np.random.default_rng(5)
    X = random_quads(rng, 25, warp=0.0, distort=0.3)
    props = Props(E=30e9, nu=0.2, rho=2500.0, thickness=0.3, mass_per_area=mpa, added_mass=added)
    m = SHELL.lumped_mass(X, props)
    assert m.shape == (25, 24) and np.all(m > 0)
    area = 0.5 * np.linalg.norm(np.cross(X[:, 2] - X[:, 0], X[:, 3] - X[:, 1]), axis=1)
    ma = mpa if mpa > 0 else 2500.0 * 0.3
    m = m.reshape(25, 4, 6)
    for k in range(3):
        assert np.allclose(m[:, :, k].sum(1), (ma + added) * area, rtol=1e-13, atol=0)
        assert np.allclose(m[:, :, 3 + k].sum(1), (ma + added) * 0.3 ** 2 / 12 * area, rtol=1e-13, atol=0)
    # isotropic per node (same on ux uy uz, same on rx ry rz) -> diagonal in any frame
    assert np.allclose(m[:, :, :3], m[:, :, :1], rtol=1e-15)
    assert np.allclose(m[:, :, 3:], m[:, :, 3:4], rtol=1e-15)
    # nodal shares are int N_a dA: a rectangle gives A/4 to every node
    rect = np.array([[[0, 0, 0], [2, 0, 0], [2, 1, 0], [0, 1, 0.0]]])
    mr = SHELL.lumped_mass(rect, props).reshape(4, 6)
    assert np.allclose(mr[:, 0], (ma + added) * 0.5, rtol=1e-14)


# ---------------------------------------------------------------- patch tests

def solve_prescribed(K, n, pres_dofs, pres_vals):
    """u with K u = 0 on the free dofs, u = pres_vals on pres_dofs."""
    import scipy.sparse.linalg as spla
    u = np.zeros(n)
    u[pres_dofs] = pres_vals
    free = free_dofs(n, pres_dofs)
    rhs = -(K[free][:, pres_dofs] @ u[pres_dofs])
    u[free] = spla.spsolve(K[free][:, free].tocsc(), rhs)
    return u


PATCH_FRAMES = [np.eye(3), rotations(np.random.default_rng(6), 1)[0]]


@pytest.mark.parametrize("R", PATCH_FRAMES, ids=["xy-plane", "rotated"])
@pytest.mark.parametrize("with_rotation", [False, True], ids=["pure-strain", "strain+rotation"])
def test_membrane_patch(R, with_rotation):
    """Linear in-plane field on the boundary of the distorted 5-element patch (drilling rotation
    = its exact rotation (v,x - u,y)/2); the interior nodes reproduce it to round-off."""
    coords, cells, xy, R, bnd, inner = ob.distorted_patch(R, origin=(3.0, -2.0, 1.0))
    B = np.array([[1.0e-3, 0.4e-3], [0.4e-3, -0.6e-3]])
    if with_rotation:
        B += np.array([[0, -2e-3], [2e-3, 0]])
    a = np.array([1e-4, -2e-4])
    uv = a + xy @ B.T
    th = 0.5 * (B[1, 0] - B[0, 1])
    U = np.zeros((8, 6))
    U[:, :3] = np.c_[uv, np.zeros(8)] @ R               # local -> global components
    U[:, 3:] = np.array([0.0, 0.0, th]) @ R
    K, _ = assemble(8, [(SHELL, cells, coords, PROPS)])
    pres = ob.fix(bnd, range(6))
    u = solve_prescribed(K, 48, pres, U[bnd].ravel())
    assert np.abs(u.reshape(8, 6)[inner] - U[inner]).max() < 1e-10 * np.abs(U).max()


@pytest.mark.parametrize("R", PATCH_FRAMES, ids=["xy-plane", "rotated"])
def test_bending_patch(R):
    """Quadratic w with its Kirchhoff rotations (theta_x = w,y, theta_y = -w,x) on the boundary:
    constant curvature, no shear; the interior nodes reproduce it to round-off."""
    coords, cells, xy, R, bnd, inner = ob.distorted_patch(R, origin=(-1.0, 0.5, 2.0))
    c0, c1, c2, a, b, c = 1e-4, 2e-3, -1e-3, 0.02, -0.013, 0.031
    x, y = xy.T
    w = c0 + c1 * x + c2 * y + 0.5 * a * x * x + b * x * y + 0.5 * c * y * y
    thx, thy = c2 + b * x + c * y, -(c1 + a * x + b * y)
    U = np.zeros((8, 6))
    U[:, :3] = np.c_[0 * w, 0 * w, w] @ R
    U[:, 3:] = np.c_[thx, thy, 0 * w] @ R
    for props in (PROPS, Props(E=30e9, nu=0.2, rho=2500, thickness=0.003)):
        K, _ = assemble(8, [(SHELL, cells, coords, props)])
        u = solve_prescribed(K, 48, ob.fix(bnd, range(6)), U[bnd].ravel())
        assert np.abs(u.reshape(8, 6)[inner] - U[inner]).max() < 1e-10 * np.abs(U).max()


# ---------------------------------------------------------------- pressure and checks

def test_pressure_forces():
    rng = np.random.default_rng(7)
    X = random_quads(rng, 10, warp=0.2)
    p = rng.uniform(1, 5, 10)
    f = pressure_forces(X, p)
    # total = -p * vector area, and the vector area of a bilinear quad is (x2 - x0) x (x3 - x1) / 2
    vec_area = 0.5 * np.cross(X[:, 2] - X[:, 0], X[:, 3] - X[:, 1])
    assert np.allclose(f.sum(1), -p[:, None] * vec_area, rtol=1e-12, atol=1e-12 * np.abs(f).max())
    # the moment about the centroid of a flat rectangle vanishes, each node carries a quarter
    rect = np.array([[[0, 0, 0], [2, 0, 0], [2, 1, 0], [0, 1, 0.0]]])
    fr = pressure_forces(rect, 3.0)[0]
    assert np.allclose(fr, [[0, 0, -1.5]] * 4, rtol=1e-14, atol=1e-14)


def test_check_messages():
    good = np.array([[[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.0]]])
    assert SHELL.check(good, PROPS) is None
    zero = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0.0]])
    bowtie = np.array([[0, 0, 0], [1, 0, 0], [0.2, 1, 0], [1, 1.3, 0.0]])
    concave = np.array([[0, 0, 0], [1, 0, 0], [0.2, 0.2, 0], [0, 1, 0.0]])
    for bad, word in ((zero, "zero area"), (bowtie, "Jacobian"), (concave, "Jacobian")):
        X = np.concatenate([good, good, bad[None], bad[None]])
        msg = SHELL.check(X, PROPS)
        assert msg is not None and "cell 2" in msg and word in msg and "\n" not in msg
        assert np.array2string(bad[1], separator=", ").replace(" ", "")[:4] in msg.replace(" ", "")
    msg = SHELL.check(good, Props(E=30e9, nu=0.2, rho=2500, thickness=0.0))
    assert msg is not None and "thickness" in msg


# ---------------------------------------------------------------- obstacle course

def static_value(p):
    K, _ = assemble(p.n_nodes, [(SHELL, p.cells, p.coords, p.props)])
    return p.value(solve_static(K, p.load_vector(), p.fixed))


def frequencies(p):
    K, m = assemble(p.n_nodes, [(SHELL, p.cells, p.coords, p.props)])
    return lowest_frequencies(K, m, p.fixed, k=len(p.reference))


def errors(make, meshes):
    out = []
    for n in meshes:
        p = make(n)
        out.append(abs(static_value(p) / p.reference - 1))
    return np.array(out)


def test_scordelis_lo():
    """Measured: 4x4 -0.3164 (4.7 %), 8x8 -0.3040 (0.53 %), 16x16 -0.3017 (0.23 %); the sweep
    goes on to 32x32 -0.3014 (0.34 %): the element converges to about 0.301."""
    err = errors(ob.scordelis_lo, [4, 8, 16])
    assert err[-1] < 0.02
    assert np.all(np.diff(err) < 0)


def test_pinched_cylinder():
    """Measured: 8x8 1.345e-5 (26.3 %), 16x16 1.694e-5 (7.2 %), 32x32 1.804e-5 (1.15 %)."""
    err = errors(ob.pinched_cylinder, [8, 16, 32])
    assert err[-1] < 0.05
    assert np.all(np.diff(err) < 0)


@pytest.mark.parametrize("load", ["in", "out"])
def test_twisted_beam(load):
    """Meshes 6x1, 12x2 (the standard one), 24x4. Measured errors: in-plane 0.76, 0.37, 0.22 %,
    out-of-plane 0.69, 0.27, 0.16 %."""
    err = errors(lambda n: ob.twisted_beam(n, load), [1, 2, 4])
    assert err[1] < 0.05 and err[2] < 0.05
    assert np.all(np.diff(err) < 0)


def test_fv16():
    """NAFEMS FV16 on 32x32: measured 0.4178, 1.0231, 2.5609, 3.2661, 3.7206, 6.4978 Hz (errors
    -0.75, -0.58, -0.82, -1.21, -0.86, -0.87 %; 16x16 is within 1.91 %). The element converges
    to about 0.6 % below the NAFEMS values (mode 1: 0.41760, 0.41784, 0.41788 Hz at 16, 32, 48
    elements a side), i.e. to omega a^2 sqrt(rho t / D) = 3.471, where Leissa's Ritz value
    (an upper bound) 3.492 gives 0.4204 Hz."""
    p = ob.fv16(32)
    f = frequencies(p)
    assert np.all(np.abs(f / p.reference - 1) < 0.02)


def test_ss_plate():
    """Hard simply supported 1.5 m x 1 m x 2 mm steel plate, 30x20 mesh, against Navier's
    closed form: measured errors -0.06, -0.15, +0.18, -0.03, -0.25, -0.55 %."""
    p = ob.ss_plate(20)
    f = frequencies(p)
    assert np.all(np.abs(f / p.reference - 1) < 0.01)
