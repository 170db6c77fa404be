"""Checks of the Lamb/Pekeris reference solutions (petsc_ssi.analytic.pekeris).

Conventions: z up, the point force pushes down, tau = c_s t / r,
u~ = pi mu r u / P; u~_z > 0 up, u~_r > 0 away from the load.
"""
import math

import numpy as np
import pytest
from scipy import integrate, special

from petsc_ssi.analytic import pekeris as pk

pytestmark = pytest.mark.unit

SQ3 = math.sqrt(3.0)
TAU_P = 1.0 / SQ3
GAMMA = math.sqrt((3.0 + SQ3) / 4.0)          # c_s / c_R for nu = 1/4
CS, RHO = 200.0, 2000.0
CP = CS * SQ3
MU = RHO * CS * CS


def _grid_away_from_arrivals(nu, lo, hi, n, gap=1e-3):
    tp, ts, tr = pk.arrivals(nu)
    tau = np.linspace(lo, hi, n)
    keep = np.ones(tau.shape, bool)
    for ta in (tp, ts, tr):
        keep &= np.abs(tau - ta) > gap
    return tau[keep]


# ---------------------------------------------------------------- arrivals ---
def test_arrival_times_nu_quarter():
    tp, ts, tr = pk.arrivals(0.25)
    assert tp == pytest.approx(TAU_P, rel=1e-14)       # observed 1 ulp (1.1e-16 of 0.577)
    assert ts == 1.0
    assert tr == pytest.approx(GAMMA, rel=1e-14)
    assert 1.0 / tr == pytest.approx(0.919402, abs=1e-6)   # c_R / c_s
    assert tr == pytest.approx(1.087664, abs=1e-6)


def test_zero_before_p_arrival_nonzero_after():
    tau = np.concatenate([np.linspace(0.0, TAU_P, 50, endpoint=False), [TAU_P * (1 - 1e-13)]])
    for f in (pk.pekeris_point, pk.lamb_point):
        ur, uz = f(tau, 0.25)
        assert np.all(ur == 0.0) and np.all(uz == 0.0)
    ur_g, uz_g = pk.lamb_point_general(tau[::10], 0.25)
    assert np.all(ur_g == 0.0) and np.all(uz_g == 0.0)
    # just after the P arrival both components move (linearly in tau - tau_P)
    d = np.array([1e-6, 1e-4])
    ur, uz = pk.pekeris_point(TAU_P + d)
    assert np.all(np.abs(uz) > 1e-8) and np.all(np.abs(ur) > 1e-8)
    assert uz[1] / uz[0] == pytest.approx(100.0, rel=2e-2)
    assert ur[1] / ur[0] == pytest.approx(100.0, rel=2e-2)
    # dimensional: nothing before t = r / c_p, motion right after it
    r = 10.0
    t = np.array([0.0, 0.5, 0.999999, 1.000001]) * r / CP
    ux, uy, uz = pk.point_displacement(6.0, 8.0, t, 1e6, CS, CP, RHO)
    assert np.all(ux[:3] == 0) and np.all(uy[:3] == 0) and np.all(uz[:3] == 0)
    assert uz[3] != 0.0 and ux[3] != 0.0


# ------------------------------------------------------------ static limits ---
def test_static_limits_closed_form():
    """u~_z is exactly static for tau > tau_R; u~_r -> -1/8 + C/tau^2."""
    taus = np.array([50.0, 200.0])
    ur, uz = pk.pekeris_point(taus)
    np.testing.assert_allclose(uz, -0.375, rtol=0, atol=1e-14)
    err = ur + 0.125
    # convergence rate O(tau^-2): |err| < 0.1/tau^2 and tau^2 err -> constant
    assert np.all(np.abs(err) < 0.1 / taus ** 2)
    c50, c200 = err * taus ** 2
    assert c50 == pytest.approx(c200, rel=2e-3)
    assert c200 == pytest.approx(-0.0781, abs=5e-4)
    # whole late range: vertical constant right after the Rayleigh arrival
    ur, uz = pk.pekeris_point(np.linspace(GAMMA + 1e-6, 30.0, 200))
    np.testing.assert_allclose(uz, -0.375, rtol=0, atol=1e-14)


@pytest.mark.parametrize("nu", [0.15, 0.25, 0.33, 0.4])
def test_static_limits_general_nu(nu):
    """Independent quadrature (C1)-(C2): u~_z -> -(1-nu)/2, u~_r -> -(1-2nu)/4."""
    taus = np.array([50.0, 200.0, 1000.0])
    ur, uz = pk.lamb_point_general(taus, nu)
    np.testing.assert_allclose(uz, -(1 - nu) / 2, rtol=0, atol=1e-9)
    err = ur + (1 - 2 * nu) / 4
    assert np.all(np.abs(err) < 0.15 / taus ** 2)          # O(tau^-2)
    assert abs(err[-1]) < 1e-6
    # the Rayleigh-pole term alone would tend to -kappa/2: right only for nu = 1/4
    kappa = pk._consts(nu).kappa
    if nu == 0.25:
        assert -kappa / 2 == pytest.approx(-0.125, abs=1e-12)
    else:
        assert abs(-kappa / 2 + (1 - 2 * nu) / 4) > 5e-3


# ------------------------------------------------ closed form vs quadrature ---
def test_pekeris_vs_general_quadrature():
    tau = _grid_away_from_arrivals(0.25, 0.5, 4.0, 71)
    tau = np.concatenate([tau, [GAMMA - 1e-3, GAMMA + 1e-3, 1 - 1e-3, 1 + 1e-3, 10.0]])
    pr, pz = pk.pekeris_point(tau)
    gr, gz = pk.lamb_point_general(tau, 0.25)
    assert np.max(np.abs(pr - gr)) < 1e-6
    assert np.max(np.abs(pz - gz)) < 1e-6
    # generic-root closed form (G) reproduces the explicit Pekeris constants
    lr, lz = pk.lamb_point(tau, 0.25)
    assert np.max(np.abs(pr - lr)) < 1e-12 and np.max(np.abs(pz - lz)) < 1e-12


def test_pekeris_explicit_values():
    """Spot values of (P1) typed independently from the docstring formulas."""
    t = 0.8
    uz = -(6 - SQ3 / math.sqrt(t * t - 0.25)
           + math.sqrt(3 * SQ3 - 5) / math.sqrt(t * t - (3 - SQ3) / 4)
           - math.sqrt(3 * SQ3 + 5) / math.sqrt(GAMMA ** 2 - t * t)) / 32
    t2 = 1.05
    uz2 = -(6 - math.sqrt(3 * SQ3 + 5) / math.sqrt(GAMMA ** 2 - t2 * t2)) / 16
    _, z = pk.pekeris_point(np.array([t, t2]))
    # differences of terms up to 11.3 / 16 = 0.7 (observed 8.9e-16 at t2; the former 1e-14 left 11x)
    assert z[0] == pytest.approx(uz, abs=1e-13)
    assert z[1] == pytest.approx(uz2, abs=1e-13)
    # continuity at the S arrival (both components)
    r, z = pk.pekeris_point(np.array([1 - 1e-9, 1.0, 1 + 1e-9]))
    assert np.ptp(z) < 1e-7 and np.ptp(r) < 1e-7


@pytest.mark.parametrize("nu", [0.05, 0.15, 0.33, 0.45])
def test_general_closed_form_vs_quadrature(nu):
    """(G) with real (nu < 0.263) and complex roots against quadrature (C)."""
    tau = _grid_away_from_arrivals(nu, 0.1, 3.0, 41)
    a = pk.lamb_point(tau, nu)
    g = pk.lamb_point_general(tau, nu)
    assert np.max(np.abs(a[0] - g[0])) < 1e-8
    assert np.max(np.abs(a[1] - g[1])) < 1e-8
    # pekeris_point dispatches to the quadrature for nu != 1/4
    d = pk.pekeris_point(tau[::8], nu)
    assert np.array_equal(d[0], g[0][::8]) and np.array_equal(d[1], g[1][::8])
    # finite and static out to huge tau (patch receivers inside the load need it)
    big = np.logspace(1, 16, 61)
    r, z = pk.lamb_point(big, nu)
    assert np.all(np.isfinite(r)) and np.all(np.isfinite(z))
    assert np.all(np.abs(r + (1 - 2 * nu) / 4) < 0.2 / big ** 2 + 1e-14)
    np.testing.assert_allclose(z, -(1 - nu) / 2, rtol=0, atol=1e-14)


def _hankel(sig, comp, a2, pmax=3000.0):
    """(1/2) int_0^inf kernel(p) J_n(sig p) dp of the transform-domain solution."""
    x, w = np.polynomial.legendre.leggauss(20)
    edges = np.linspace(0.0, pmax, int(pmax * sig / np.pi * 2) + 1)
    lo, hi = edges[:-1, None], edges[1:, None]
    p = (0.5 * (hi - lo) * x + 0.5 * (hi + lo)).ravel()
    W = (0.5 * (hi - lo) * w).ravel()
    npp, ns = np.sqrt(p * p + a2), np.sqrt(p * p + 1)
    R = (2 * p * p + 1) ** 2 - 4 * p * p * npp * ns
    if comp == "z":           # downward w, J0
        f, C, J = npp * p / R, 1 / (2 * (1 - a2)), special.j0(sig * p)
    else:                     # outward u_r, J1
        f, C, J = p * p * (2 * p * p + 1 - 2 * npp * ns) / R, -a2 / (2 * (1 - a2)), special.j1(sig * p)
    return 0.5 * (np.sum(W * (f - C) * J) + C / sig)


@pytest.mark.parametrize("sig", [0.5, 2.0])
def test_laplace_transform_against_hankel_inversion(sig):
    """int e^{-sig tau} u~(tau) dtau equals the Laplace-domain solution (T1)-(T2)
    evaluated by direct numerical Hankel transform (no Cagniard inversion):
    checks signs, scaling and the time-domain formulas as a whole."""
    edges = [TAU_P, 1.0, GAMMA, 3.0, 10.0, 80.0 / sig]
    out = {}
    for comp, k in (("r", 0), ("z", 1)):
        f = lambda t: math.exp(-sig * t) * float(pk.pekeris_point(np.array([t]))[k][0])
        out[comp] = sum(integrate.quad(f, lo, hi, epsabs=1e-12, epsrel=1e-10, limit=200)[0]
                        for lo, hi in zip(edges[:-1], edges[1:]))
    assert -out["z"] == pytest.approx(_hankel(sig, "z", 1 / 3), abs=1e-7, rel=1e-6)
    assert out["r"] == pytest.approx(_hankel(sig, "r", 1 / 3), abs=1e-7, rel=1e-6)


# ------------------------------------------------------ Rayleigh singularity ---
def test_rayleigh_singularity():
    d = 10.0 ** -np.arange(2, 10)
    _, uz = pk.pekeris_point(GAMMA - d)
    # |u~_z| grows without bound as tau -> tau_R-, upward, like 1/sqrt(tau_R^2 - tau^2)
    assert np.all(np.diff(uz) > 0) and uz[-1] > 1e3
    # for 1 < tau < tau_R: u~_z = -3/8 + sqrt(3 sqrt3 + 5) / (16 sqrt(tau_R^2 - tau^2))
    coef = (uz + 0.375) * np.sqrt(GAMMA ** 2 - (GAMMA - d) ** 2)
    np.testing.assert_allclose(coef, math.sqrt(3 * SQ3 + 5) / 16, rtol=1e-6)
    # after the arrival the vertical is finite (static); the radial is finite
    # before and -> -inf like -tau/(8 sqrt(tau^2 - tau_R^2)) after
    ur_b, _ = pk.pekeris_point(GAMMA - d)
    assert np.all(np.abs(ur_b) < 0.02)
    ur_a, uz_a = pk.pekeris_point(GAMMA + d)
    np.testing.assert_allclose(uz_a, -0.375, atol=1e-14, rtol=0)
    assert np.all(np.diff(ur_a) < 0) and ur_a[-1] < -1e2
    # u~_r = -tau / (8 sqrt(tau^2 - tau_R^2)) + O(1), the O(1) part ~ -0.012 here
    sq = np.sqrt((GAMMA + d) ** 2 - GAMMA ** 2)
    assert np.all(np.abs(ur_a * sq + (GAMMA + d) / 8) < 0.02 * sq)
    # singular point itself is undefined
    assert np.all(np.isnan(pk.pekeris_point(GAMMA)))
    # the singularity is where the quadrature puts it too (not a typo in (P1))
    _, gz = pk.lamb_point_general(np.array([GAMMA - 1e-6]), 0.25)
    assert gz[0] == pytest.approx(uz[4], rel=1e-6)


# ------------------------------------------------------------- dimensional ---
def test_point_displacement_scaling_and_direction():
    x, y = 3.0, -4.0
    r = 5.0
    tau = np.array([0.7, 0.9, 1.05, 1.5, 3.0])
    P = 2.5e6
    ux, uy, uz = pk.point_displacement(x, y, tau * r / CS, P, CS, CP, RHO)
    ur_ref, uz_ref = pk.pekeris_point(tau)
    np.testing.assert_allclose(pk.dimensionless(uz, r, P, MU), uz_ref, rtol=1e-13)
    np.testing.assert_allclose(pk.dimensionless(ux, r, P, MU), ur_ref * x / r, rtol=1e-13)
    np.testing.assert_allclose(pk.dimensionless(uy, r, P, MU), ur_ref * y / r, rtol=1e-13)


# -------------------------------------------------------------------- patch ---
def test_patch_tends_to_point_far_away():
    """Small patch, far receiver: relative difference ~ (a/r)^2 (two sizes)."""
    x, y, r = 8.0, 6.0, 10.0
    tau = np.array([0.65, 0.7, 0.8, 0.9, 0.95, 1.2, 1.5, 2.0, 3.0, 5.0])
    t = tau * r / CS
    p0 = 1e5
    errs = []
    for a, b in [(0.2, 0.1), (0.1, 0.05)]:
        pt = pk.point_displacement(x, y, t, p0 * 4 * a * b, CS, CP, RHO)
        pa = pk.patch_displacement(x, y, t, a, b, p0, CS, CP, RHO)
        errs.append([np.max(np.abs(pa[i] - pt[i])) / np.max(np.abs(pt[i])) for i in range(3)])
    errs = np.array(errs)
    assert np.all(errs[1] < 1e-3)                 # ~ 8 (a/r)^2 with a/r = 0.01
    ratio = errs[0] / errs[1]                     # halving a, b: factor 4
    assert np.all((ratio > 3.7) & (ratio < 4.4)), ratio


@pytest.mark.parametrize("xy,cp_over_cs", [((0.3, 0.2), SQ3), ((2.0, 1.5), SQ3), ((-1.7, 0.1), SQ3),
                                            ((1.0, 0.5), SQ3), ((0.3, 0.2), 2.0), ((2.0, 1.5), 2.0)])
def test_patch_late_time_is_boussinesq(xy, cp_over_cs):
    x, y = xy
    a, b, p0 = 1.0, 0.5, 1e5
    nu = pk.poisson_ratio(CS, CS * cp_over_cs)      # 1/4 or 1/3 (complex roots)
    bx, by, bz = pk.boussinesq_rectangle(x, y, a, b, p0, MU, nu)
    rmax = max(math.hypot(x + sa * a, y + sb * b) for sa in (-1, 1) for sb in (-1, 1))
    # tau_min = c_s t / rmax: vertical exact once tau_min > tau_R; radial O(tau_min^-2)
    t = np.array([2.0, 200.0, 400.0]) * rmax / CS
    ux, uy, uz = pk.patch_displacement(x, y, t, a, b, p0, CS, CS * cp_over_cs, RHO)
    np.testing.assert_allclose(uz, bz, rtol=1e-4)
    assert abs(uz[0] / bz - 1) < 1e-10
    scale = math.hypot(bx, by)
    assert math.hypot(ux[1] - bx, uy[1] - by) < 1e-4 * scale
    assert math.hypot(ux[2] - bx, uy[2] - by) < 3e-5 * scale


def test_boussinesq_rectangle_against_quadrature():
    x, y, a, b, p0, nu = 2.0, 1.5, 1.0, 0.5, 1e5, 0.25
    bx, by, bz = pk.boussinesq_rectangle(x, y, a, b, p0, MU, nu)
    kw = dict(epsabs=1e-13, epsrel=1e-12)
    iz = integrate.dblquad(lambda Y, X: 1 / math.hypot(X - x, Y - y), -a, a, -b, b, **kw)[0]
    ix = integrate.dblquad(lambda Y, X: (X - x) / ((X - x) ** 2 + (Y - y) ** 2), -a, a, -b, b, **kw)[0]
    iy = integrate.dblquad(lambda Y, X: (Y - y) / ((X - x) ** 2 + (Y - y) ** 2), -a, a, -b, b, **kw)[0]
    assert bz == pytest.approx(-(1 - nu) * p0 / (2 * math.pi * MU) * iz, rel=1e-12)
    assert bx == pytest.approx((1 - 2 * nu) * p0 / (4 * math.pi * MU) * ix, rel=1e-12)
    assert by == pytest.approx((1 - 2 * nu) * p0 / (4 * math.pi * MU) * iy, rel=1e-12)
    # uniform load: symmetric centre has no horizontal motion, vertical = classic value
    cx, cy, cz = pk.boussinesq_rectangle(0.0, 0.0, a, a, p0, MU, nu)
    assert cx == 0.0 and cy == 0.0
    # centre of a square 2a x 2a: u_z = -(1-nu) p0 (2a) * 4 asinh(1) / (2 pi mu)
    assert cz == pytest.approx(-(1 - nu) * p0 * 8 * a * math.asinh(1.0) / (2 * math.pi * MU), rel=1e-14)


@pytest.mark.parametrize("xy", [(0.3, 0.2), (2.0, 1.5), (1.0, 0.2)])
def test_patch_quadrature_converges(xy):
    x, y = xy
    a, b, p0 = 1.0, 0.5, 1e5
    rmax = max(math.hypot(x + sa * a, y + sb * b) for sa in (-1, 1) for sb in (-1, 1))
    t = np.linspace(0.0, 3.0 * rmax / CS, 200)
    u32 = pk.patch_displacement(x, y, t, a, b, p0, CS, CP, RHO)
    u64 = pk.patch_displacement(x, y, t, a, b, p0, CS, CP, RHO, n=64)
    scale = np.max(np.abs(u64[2]))
    for i in range(3):
        assert np.max(np.abs(u32[i] - u64[i])) < 1e-6 * scale
    # independent adaptive quadrature (scipy quad) on a few times
    tq = t[[67, 75, 199]]
    uq = pk.patch_displacement(x, y, tq, a, b, p0, CS, CP, RHO, method="quad", epsrel=1e-9)
    ug = pk.patch_displacement(x, y, tq, a, b, p0, CS, CP, RHO, n=64)
    for i in range(3):
        assert np.max(np.abs(uq[i] - ug[i])) < 1e-6 * scale
