"""Singular integration over nine-node elements: analytic values, convergence."""
import numpy as np
import pytest

from petsc_ssi.bem.quadrature import singular_static, integrate_pair
from petsc_ssi.bem.packs import wave
from petsc_ssi.mesh import quad9
from petsc_ssi.mesh.surface import grid

pytestmark = pytest.mark.run

NU, MU = 0.25, 1.0


def _static(X, c, order):
    g, w = np.polynomial.legendre.leggauss(order)
    Us = np.zeros((9, 3, 3)); Ps = np.zeros((9, 3, 3))
    singular_static(X, c, order, order, g, w, g, w, NU, MU, Us, Ps, 1.0)     # (h_ref given, as the assembly does)
    return Us, Ps


def test_weakly_singular_corner_analytic():
    """Sum over shape functions of int U_static over a flat 2x2 square from a
    corner: int 1/r = 2 s ln(1+sqrt2), int xy/r^3 = 2 s (1 - 1/sqrt2). 1e-12."""
    X = grid(2.0, 2.0, 2.0).cell_coords()[0]
    s = 2.0
    I1 = 2 * s * np.log(1 + np.sqrt(2)); Ixy = 2 * s * (1 - 1 / np.sqrt(2))
    c = 1 / (16 * np.pi * MU * (1 - NU))
    d = c * ((3 - 4 * NU) * I1 + I1 / 2)
    ref = np.array([[d, c * Ixy, 0], [c * Ixy, d, 0], [0, 0, c * (3 - 4 * NU) * I1]])
    Us, _ = _static(X, 0, 12)
    assert np.abs(Us.sum(0) - ref).max() <= 1e-12 * np.abs(ref).max()


def _brute_cpv(X, c, n=300):
    """CPV of the flat-surface static traction kernel times N_a, as
    int K(g) (N_a(x) - N_a(xi)) / r^2 (regular) + N_a(xi) * 0 (odd kernel
    over a domain symmetric about the centre node)."""
    g, w = np.polynomial.legendre.leggauss(6)
    hs = 2.0 / n
    cs = -1 + hs * (np.arange(n) + 0.5)
    XI, ET = np.meshgrid(cs, cs, indexing="ij")
    GX, GY = np.meshgrid(g, g, indexing="ij")
    xi = (XI[..., None, None] + hs / 2 * GX).ravel(); et = (ET[..., None, None] + hs / 2 * GY).ravel()
    ww = np.broadcast_to(np.outer(w, w) * (hs / 2) ** 2, (n, n, 6, 6)).ravel()
    N = quad9.shape(xi, et); x = N @ X
    Nc = quad9.shape(*quad9.NODE_XI[c])
    rv = x - X[c]; r = np.linalg.norm(rv, axis=1); gv = rv / r[:, None]
    k = (1 - 2 * NU) / (8 * np.pi * (1 - NU) * r ** 2)
    out = np.zeros((9, 3, 3))
    for a in range(9):
        f = (N[:, a] - Nc[a]) * ww * k
        out[a, 0, 2] = (f * gv[:, 0]).sum(); out[a, 2, 0] = -out[a, 0, 2]
        out[a, 1, 2] = (f * gv[:, 1]).sum(); out[a, 2, 1] = -out[a, 1, 2]
    return out


def test_strongly_singular_cpv_centre_node():
    """Guiggiani CPV at the centre node against a brute-force regularised
    integral (accurate to ~1e-4 relative); the polar rule converges: orders
    12 and 24 agree to 1e-10."""
    X = grid(2.0, 2.0, 2.0).cell_coords()[0]
    _, P12 = _static(X, 8, 12)
    _, P24 = _static(X, 8, 24)
    assert np.abs(P12 - P24).max() <= 1e-10 * np.abs(P24).max()
    ref = _brute_cpv(X, 8)
    assert np.abs(P24 - ref).max() <= 1e-4 * np.abs(ref).max()


@pytest.mark.parametrize("c", [0, 4, 8])
def test_polar_rule_converges_on_curved_element(c):
    """On a curved element (z = 0.1 (x^2 - y^2)) the singular integrals
    converge geometrically with the polar order: |I_16 - I_32| < 1e-7 |I|."""
    X = grid(2.0, 2.0, 2.0).cell_coords()[0].copy()
    X[:, 2] = 0.1 * (X[:, 0] ** 2 - X[:, 1] ** 2)
    U16, P16 = _static(X, c, 16)
    U32, P32 = _static(X, c, 32)
    assert np.abs(U16 - U32).max() <= 1e-9 * np.abs(U32).max()
    assert np.abs(P16 - P32).max() <= 1e-7 * np.abs(P32).max()


def test_element_lag_sum_is_static_integral():
    """Sum over all lags of the element integrals of U^l equals the static
    Kelvin integral with the same quadrature (the kernel identity survives
    space integration, to 1e-10), for a far and an adjacent element."""
    dt, cp, cs, rho = 7.5e-4, 548.0, 316.0, 2000.0
    nu = (cp ** 2 - 2 * cs ** 2) / (2 * (cp ** 2 - cs ** 2))
    gq, gw = np.polynomial.legendre.leggauss(2)
    for shift in (6.0, 1.5):
        X = grid(1.0, 1.0, 1.0).cell_coords()[0] + np.array([shift, 0.3, 0.0])
        L = int((shift + 1.5) / (cs * dt)) + 4
        Ub = np.zeros((L, 9, 3, 3)); Pb = np.zeros((L, 9, 3, 3))
        integrate_pair(np.zeros(3), X, -1, 4, 1, L, wave(dt, cp, cs, rho, nu), gq, gw, Ub, Pb, True)
        # static reference with the same points: one "lag" of width infinity
        U0 = np.zeros((1, 9, 3, 3)); P0 = np.zeros((1, 9, 3, 3))
        integrate_pair(np.zeros(3), X, -1, 4, 1, 1, wave(1e3, cp, cs, rho, nu), gq, gw, U0, P0, True)
        assert np.abs(Ub.sum(0) - U0[0]).max() <= 1e-10 * np.abs(U0).max()


def test_traction_lag_sum_is_static_integral():
    """The same identity for the traction kernel P (1e-10)."""
    dt, cp, cs, rho = 7.5e-4, 548.0, 316.0, 2000.0
    nu = (cp ** 2 - 2 * cs ** 2) / (2 * (cp ** 2 - cs ** 2))
    gq, gw = np.polynomial.legendre.leggauss(2)
    X = grid(1.0, 1.0, 1.0).cell_coords()[0].copy() + np.array([2.0, 0.3, 0.0])
    X[:, 2] = 0.05 * X[:, 0] ** 2          # curved: gamma.n != 0, all terms active
    L = int(3.0 / (cs * dt)) + 4
    Ub = np.zeros((L, 9, 3, 3)); Pb = np.zeros((L, 9, 3, 3))
    integrate_pair(np.zeros(3), X, -1, 4, 1, L, wave(dt, cp, cs, rho, nu), gq, gw, Ub, Pb, False)
    U0 = np.zeros((1, 9, 3, 3)); P0 = np.zeros((1, 9, 3, 3))
    integrate_pair(np.zeros(3), X, -1, 4, 1, 1, wave(1e3, cp, cs, rho, nu), gq, gw, U0, P0, False)
    assert np.abs(Pb.sum(0) - P0[0]).max() <= 1e-10 * np.abs(P0).max()


def test_static_row_sum_equals_analytic_cpv_on_nonuniform_mesh():
    """Row sums of the static H (one lag of dt = 1e3 s) at interior nodes of a
    non-uniform flat mesh equal I/2 + the analytic CPV over the rectangle,
    K int (x - x_i)/r^3 dA with K = (1-2nu)/(8 pi (1-nu)) (1e-6): checks the
    log term of the Guiggiani CPV at corner, edge and centre nodes."""
    from helpers import petsc
    PETSc = petsc()
    from petsc_ssi.bem.lagset import Material, Regions, LagSet
    mesh = grid(6.0, 5.0, 0.7, patch=(1.1, 0.8))
    mat = Material(548.0, 316.0, 2000.0)
    reg = Regions(mesh)
    opts = {"gauss": 2, "singular_order": 16, "subdivisions": 4, "near_factor": 2.0,
            "max_subdivisions": 32, "cache": False}
    x = mesh.nodes
    interior = np.where((np.abs(x[:, 0]) < 2.5) & (np.abs(x[:, 1]) < 2.0))[0][::7]
    ls = LagSet(PETSc.COMM_SELF, mesh, mat, 1e3, 1, reg, [], opts)
    ls.rows = np.ascontiguousarray(interior)     # (contiguous, as a run's rows: a strided view compiled the
    #                                                     assembly kernel for a layout of its own in every fresh CI)
    ls.assemble()
    r, c, v = ls.H.peek(1)
    K = (1 - 2 * mat.nu) / (8 * np.pi * (1 - mat.nu))

    def cpv(xi, yi, x0, x1, y0, y1):
        f = lambda y, a: np.arcsinh((y - yi) / abs(a - xi))
        return (f(y1, x0) - f(y0, x0)) - (f(y1, x1) - f(y0, x1))
    for i in interior:
        S = v[r == i].sum(0)
        Ix = K * cpv(x[i, 0], x[i, 1], -3, 3, -2.5, 2.5)
        Iy = K * cpv(x[i, 1], x[i, 0], -2.5, 2.5, -3, 3)
        ref = 0.5 * np.eye(3)
        ref[0, 2], ref[2, 0], ref[1, 2], ref[2, 1] = Ix, -Ix, Iy, -Iy
        assert np.abs(S - ref).max() <= 1e-6, (i, S, ref)
