"""An independent static reference for the rigid disk's horizontal-rocking coupling (issue 46, the
rocking terms): a welded (bonded) rigid disk of radius R on an elastic half-space, solved with the
half-space's own surface Green's function (Boussinesq-Cerruti), so only the disk is meshed.

Model: the disk's contact area is cut into N_r rings (radii R sin(pi i / (2 N_r)), finer toward the
edge where the tractions are singular) and N_t sectors; each cell carries a uniform traction vector,
collocated at its centroid (3 N_r N_t unknowns). The surface displacement of a surface point force
F in z-down axes (z into the soil), with d = x - y, r = |d| (Johnson, Contact Mechanics, 3.2):

    u_x = [ (2 (1 - nu) / r + 2 nu d_x^2 / r^3) F_x + 2 nu d_x d_y / r^3 F_y - (1 - 2 nu) d_x / r^2 F_z ] / (4 pi G)
    u_y = the same with x and y exchanged
    u_z = [ (1 - 2 nu) (d_x F_x + d_y F_y) / r^2 + 2 (1 - nu) / r F_z ] / (4 pi G)

turned to z up (the project's axes) by D = diag(1, 1, -1): G_up = D G_down D. Off the diagonal the
cell integrals are Gauss rules in (rho, phi) (more points for near cells); the diagonal cell's weakly
singular integrals are taken in polar coordinates about the collocation point, int g(theta)
R(theta) d theta with R(theta) the distance to the cell's boundary (every kernel here is g(theta)/r).

The rigid motions u_x = 1, u_z = 1, theta_y = 1 (z up, right-handed: u_z = -theta_y x) give the
stiffness matrix of (F_x, F_z, M_y) with M_y = sum over cells of -x t_z A about the disk's centre on
the surface: the project's convention (petsc-ssi impedance: K_hr = M_y per u_x, K_rh = F_x per
theta_y). The collocation here is the same kind as the BEM's, so its K_hr and K_rh differ slightly;
both are given, with their mean, against the number of rings (three levels, Richardson's
extrapolation at the observed order). Checks of the solver: K_z against the bonded punch's closed
form 4 G R ln(3 - 4 nu) / (1 - 2 nu) (k_z_bonded) and K_r against the frictionless
punch's 8 G R^3 / (3 (1 - nu)) (the bonded value is slightly larger).

The same kernel, rules and collocation on an n x n grid of rectangles graded toward the edges
give the welded rigid square (``square_stiffness``), and the torsion theta_z ((u_x, u_y) =
theta (-y, x), M_z) is the fourth motion of both. Checks of the machinery against exact values
(tests/analytic/test_disk_static.py): the frictionless disk (``frictionless_disk``: vertical and
rocking), the disk's torsion 16 G R^3 / 3 (welded = frictionless there), the bonded disk's vertical
closed form, and nu = 1/2, where the coupling vanishes.

Used by runs/impedance/disk_coupling_static.py, runs/impedance/graded_static.py (the study) and tests/analytic/test_disk_static.py.
"""
import math

import numpy as np

__all__ = ["stiffness", "square_stiffness", "frictionless_disk", "k_z_bonded", "cells", "green_up"]


def cells(nr, nt, R=1.0):
    """(rho0, rho1, phi0, phi1) of the cells, (n, 4)."""
    rho = R * np.sin(0.5 * np.pi * np.arange(nr + 1) / nr)
    phi = 2 * np.pi * np.arange(nt + 1) / nt
    out = [(rho[i], rho[i + 1], phi[j], phi[j + 1]) for i in range(nr) for j in range(nt)]
    return np.array(out)


def green_up(dx, dy, G, nu):
    """(..., 3, 3) surface displacement at d = (dx, dy) per unit surface force, z up."""
    r2 = dx * dx + dy * dy
    r = np.sqrt(r2)
    r3 = r2 * r
    c = 1.0 / (4 * np.pi * G)
    g = np.zeros(dx.shape + (3, 3))
    g[..., 0, 0] = c * (2 * (1 - nu) / r + 2 * nu * dx * dx / r3)
    g[..., 0, 1] = g[..., 1, 0] = c * 2 * nu * dx * dy / r3
    g[..., 1, 1] = c * (2 * (1 - nu) / r + 2 * nu * dy * dy / r3)
    g[..., 0, 2] = -c * (1 - 2 * nu) * dx / r2
    g[..., 1, 2] = -c * (1 - 2 * nu) * dy / r2
    g[..., 2, 0] = c * (1 - 2 * nu) * dx / r2
    g[..., 2, 1] = c * (1 - 2 * nu) * dy / r2
    g[..., 2, 2] = c * 2 * (1 - nu) / r
    D = np.array([1.0, 1.0, -1.0])
    return g * D[:, None] * D[None, :]


def centroids(C):
    r0, r1, p0, p1 = C.T
    area = 0.5 * (r1 ** 2 - r0 ** 2) * (p1 - p0)
    rc = (2.0 / 3.0) * (r1 ** 3 - r0 ** 3) / (r1 ** 2 - r0 ** 2)
    pc = 0.5 * (p0 + p1)
    # centroid of an annular sector: rc sin(dp/2)/(dp/2) along the bisector
    dp = p1 - p0
    s = np.sin(0.5 * dp) / (0.5 * dp)
    return np.column_stack([rc * s * np.cos(pc), rc * s * np.sin(pc)]), area


def gauss_cell(C, m):
    """Points (n, m*m, 2) and weights (n, m*m) of an m x m Gauss rule on each cell (area element
    rho d rho d phi)."""
    s, w = np.polynomial.legendre.leggauss(m)
    s, w = 0.5 * (s + 1), 0.5 * w
    r0, r1, p0, p1 = (C[:, k][:, None, None] for k in range(4))
    rho = r0 + (r1 - r0) * s[None, :, None]
    phi = p0 + (p1 - p0) * s[None, None, :]
    W = (r1 - r0) * (p1 - p0) * w[None, :, None] * w[None, None, :] * rho
    pts = np.stack([rho * np.cos(phi), rho * np.sin(phi)], axis=-1)
    return pts.reshape(len(C), m * m, 2), W.reshape(len(C), m * m)


def self_integral(c, x, G, nu, nth=4096):
    """int over cell c of green_up(x - y) dA_y, x inside c: polar about x, int g(theta) R(theta)."""
    r0, r1, p0, p1 = c
    th = 2 * np.pi * (np.arange(nth) + 0.5) / nth
    e = np.column_stack([np.cos(th), np.sin(th)])
    best = np.full(nth, np.inf)
    # arcs rho = r0, r1: |x + t e| = a  ->  t^2 + 2 t (x.e) + |x|^2 - a^2 = 0
    xe = e @ x
    for a in (r0, r1):
        if a <= 0:
            continue
        disc = xe ** 2 - (x @ x - a * a)
        ok = disc >= 0
        for sgn in (-1.0, 1.0):
            t = np.where(ok, -xe + sgn * np.sqrt(np.where(ok, disc, 0.0)), np.inf)
            good = t > 1e-14
            best = np.where(good & (t < best), t, best)
    # radial lines phi = p0, p1: points s (cos p, sin p), s >= 0
    for p in (p0, p1):
        n = np.array([-math.sin(p), math.cos(p)])     # normal of the line through 0
        den = e @ n
        with np.errstate(divide="ignore", invalid="ignore"):
            t = -(x @ n) / den
        q = x[None, :] + t[:, None] * e
        along = q @ np.array([math.cos(p), math.sin(p)])
        good = (t > 1e-14) & (along >= -1e-12) & np.isfinite(t)
        best = np.where(good & (t < best), t, best)
    # the kernel is g(theta)/r: evaluate at unit distance (r = 1) in direction -e (d = x - y = -t e)
    g = green_up(-e[:, 0], -e[:, 1], G, nu)
    return (g * best[:, None, None]).sum(0) * (2 * np.pi / nth)


def _ray_to_rectangle(c, x, e):
    """Distance from x (inside the rectangle c = (x0, x1, y0, y1)) to its boundary along the unit
    directions e (m, 2)."""
    x0, x1, y0, y1 = c
    with np.errstate(divide="ignore"):
        tx = np.where(e[:, 0] > 0, (x1 - x[0]) / e[:, 0], np.where(e[:, 0] < 0, (x0 - x[0]) / e[:, 0], np.inf))
        ty = np.where(e[:, 1] > 0, (y1 - x[1]) / e[:, 1], np.where(e[:, 1] < 0, (y0 - x[1]) / e[:, 1], np.inf))
    return np.minimum(tx, ty)


def _self_rectangle(c, x, G, nu, nth=4096):
    th = 2 * np.pi * (np.arange(nth) + 0.5) / nth
    e = np.column_stack([np.cos(th), np.sin(th)])
    g = green_up(-e[:, 0], -e[:, 1], G, nu)
    return (g * _ray_to_rectangle(c, x, e)[:, None, None]).sum(0) * (2 * np.pi / nth)


def _gauss_rectangle(C, m):
    s, w = np.polynomial.legendre.leggauss(m)
    s, w = 0.5 * (s + 1), 0.5 * w
    x0, x1, y0, y1 = (C[:, k][:, None, None] for k in range(4))
    X = x0 + (x1 - x0) * s[None, :, None]
    Y = y0 + (y1 - y0) * s[None, None, :]
    W = (x1 - x0) * (y1 - y0) * w[None, :, None] * w[None, None, :]
    X, Y, W = np.broadcast_arrays(X, Y, W)
    return np.stack([X, Y], axis=-1).reshape(len(C), m * m, 2), W.reshape(len(C), m * m)


def _assemble(X, A, far, near, self_term, G, nu):
    n = len(A)
    M = np.zeros((n, 3, n, 3))
    size = np.sqrt(A)
    for i in range(n):
        d = np.linalg.norm(X[None, i] - X, axis=1)
        is_near = d < 3 * np.maximum(size, size[i])
        for sel, (P, W) in ((~is_near, far), (is_near, near)):
            idx = np.nonzero(sel)[0]
            idx = idx[idx != i]
            if not len(idx):
                continue
            dd = X[i][None, None, :] - P[idx]
            g = green_up(dd[..., 0], dd[..., 1], G, nu)
            M[i, :, idx, :] = np.einsum("kq,kqab->kab", W[idx], g)
        M[i, :, i, :] = self_term(i)
    return M.reshape(3 * n, 3 * n)


def assemble(nr, nt, G, nu):
    C = cells(nr, nt)
    X, A = centroids(C)
    M = _assemble(X, A, gauss_cell(C, 3), gauss_cell(C, 10), lambda i: self_integral(C[i], X[i], G, nu), G, nu)
    return M, X, A


def _solve_rigid(M, X, A):
    """K (4 x 4) of (F_x, F_z, M_y, M_z) against (u_x, u_z, theta_y, theta_z), moments about the
    origin on the surface (z up, right-handed: theta_y gives u_z = -theta x, theta_z gives
    (u_x, u_y) = theta (-y, x))."""
    n = len(A)
    U = np.zeros((3 * n, 4))
    U[0::3, 0] = 1.0                 # u_x
    U[2::3, 1] = 1.0                 # u_z
    U[2::3, 2] = -X[:, 0]            # theta_y
    U[0::3, 3] = -X[:, 1]            # theta_z
    U[1::3, 3] = X[:, 0]
    T = np.linalg.solve(M, U).reshape(n, 3, 4)       # tractions [Pa] of each motion
    F = np.einsum("n,nam->am", A, T)                  # forces (3, motions)
    My = -np.einsum("n,n,nm->m", A, X[:, 0], T[:, 2, :])
    Mz = np.einsum("n,n,nm->m", A, X[:, 0], T[:, 1, :]) - np.einsum("n,n,nm->m", A, X[:, 1], T[:, 0, :])
    return np.array([F[0], F[2], My, Mz])


def stiffness(nr, nt, G, nu):
    """K of (F_x, F_z, M_y, M_z) against (u_x, u_z, theta_y, theta_z) [N/m, N, N m] of the disk
    (R = 1; _solve_rigid)."""
    M, X, A = assemble(nr, nt, G, nu)
    return _solve_rigid(M, X, A)


def frictionless_disk(nr, nt, G, nu):
    """(K_z, K_r) [N/m, N m] of the rigid disk (R = 1) in frictionless contact: only the normal
    tractions, the u_z-t_z block of the kernel; the exact values are 4 G R / (1 - nu) and
    8 G R^3 / (3 (1 - nu)) (Boussinesq; the checks of this module's rules and lever arms)."""
    M, X, A = assemble(nr, nt, G, nu)
    Mzz = M[2::3, 2::3]
    tz = np.linalg.solve(Mzz, np.column_stack([np.ones(len(A)), -X[:, 0]]))
    return float(A @ tz[:, 0]), float(-(A * X[:, 0]) @ tz[:, 1])


def square_stiffness(n, G, nu, B=1.0):
    """The same 4 x 4 K of a welded rigid square [-B, B]^2: n x n rectangular cells on lines
    -B cos(pi k / n) (finer toward the edges), the same kernel, rules and collocation."""
    xs = -B * np.cos(np.pi * np.arange(n + 1) / n)
    C = np.array([(xs[i], xs[i + 1], xs[j], xs[j + 1]) for i in range(n) for j in range(n)])
    X = np.column_stack([0.5 * (C[:, 0] + C[:, 1]), 0.5 * (C[:, 2] + C[:, 3])])
    A = (C[:, 1] - C[:, 0]) * (C[:, 3] - C[:, 2])
    M = _assemble(X, A, _gauss_rectangle(C, 3), _gauss_rectangle(C, 10),
                  lambda i: _self_rectangle(C[i], X[i], G, nu), G, nu)
    return _solve_rigid(M, X, A)


def k_z_bonded(G, nu, R=1.0):
    """The bonded rigid punch's vertical stiffness (Mossakovskii 1954; Spence 1968):
    4 G R ln(3 - 4 nu) / (1 - 2 nu) [N/m]; it equals the frictionless 4 G R / (1 - nu) at nu = 1/2
    and exceeds it by 2.2 % at nu = 1/3, 9.9 % at nu = 0."""
    return 4 * G * R * math.log(3 - 4 * nu) / (1 - 2 * nu)
