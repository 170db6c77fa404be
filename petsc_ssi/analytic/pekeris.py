r"""Lamb's problem: surface response of an elastic half-space to a step point load.

Verification references for the time-domain BEM: the displacement of the free
surface of a homogeneous isotropic elastic half-space under a vertical point
force ``P H(t)`` (Lamb's problem, closed form for Poisson's ratio 1/4 by
Pekeris 1955) and under a uniform pressure ``p0 H(t)`` on a rectangle (the point
solution integrated over the patch).

References
----------
* C. L. Pekeris (1955), "The seismic surface pulse", Proc. Natl. Acad. Sci.
  USA 41, 469-480.  Closed form for nu = 1/4 (vertical formulas (P1) below).
* A. T. de Hoop (1960), "A modification of Cagniard's method for solving
  seismic pulse problems", Appl. Sci. Res. B 8, 349-356; L. R. Johnson (1974),
  "Green's function for Lamb's problem", Geophys. J. R. astr. Soc. 37, 99-131.
  The general-nu representation (C1)-(C2) below is a Cagniard-de Hoop
  inversion in that style, derived for this module from (T1)-(T2).
* H. M. Mooney (1974), "Some numerical solutions for Lamb's problem", Bull.
  Seism. Soc. Am. 64, 473-491, and E. Kausel (2013), "Lamb's problem at its
  simplest", Proc. R. Soc. A 469, 20120462: general-nu closed forms (roots of
  the Rayleigh cubic, real or complex; elliptic integrals for the radial
  component).  The closed forms (G1)-(G2) here are of that kind but were derived
  independently from (C1)-(C2) by partial fractions; they are *not* transcribed
  from those papers.

Conventions
-----------
z points up, the soil is z < 0, the free surface is z = 0.  The force P > 0
pushes DOWN (-z) at the origin with time history P*H(t).  r is the epicentral
distance, c_s, c_p the wave speeds, mu = rho c_s^2, nu Poisson's ratio and

    tau = c_s t / r,     u~ = pi mu r u / P        (dimensionless),
    alpha^2 = c_s^2/c_p^2 = (1 - 2 nu) / (2 (1 - nu)),
    gamma = c_s / c_R  (Rayleigh slowness; gamma^2 is the real root > 1 of P3).

u~_z is positive UP, u~_r positive AWAY from the load.  Arrivals: P at
tau = alpha, S at tau = 1, Rayleigh at tau = gamma.  For nu = 1/4:
alpha = 1/sqrt(3), gamma^2 = (3 + sqrt 3)/4, gamma = 1.087664 (c_R = 0.919402 c_s).
Static limits (Boussinesq): u~_z -> -(1 - nu)/2, u~_r -> -(1 - 2 nu)/4.

Transform-domain solution (T)
-----------------------------
With potentials (Laplace variable s, Hankel wavenumber k, c_s = 1,
nu_p = sqrt(k^2 + alpha^2 s^2), nu_s = sqrt(k^2 + s^2),
R = (2k^2 + s^2)^2 - 4 k^2 nu_p nu_s) the free-surface conditions give the
downward and the outward displacement of the surface

    (T1)  w   = P/(2 pi mu s) int_0^inf  s^2 nu_p / R             J0(kr) k dk
    (T2)  u_r = P/(2 pi mu s) int_0^inf  k (2k^2 + s^2 - 2 nu_p nu_s)/R J1(kr) k dk

Cagniard-de Hoop representation (C), used by `lamb_point_general`
------------------------------------------------------------------
Writing the 2-D Fourier integral with k_x = i s p, k_y = s q, deforming the
p-contour onto the branch cut of the real p axis and substituting
u = p^2 - q^2 (a squared horizontal slowness) gives, with
eta_p = sqrt(alpha^2 - u), eta_s = sqrt(1 - u) taken on the upper lip
(eta = -i sqrt(u - c^2) when u > c^2) and R~ = (1 - 2u)^2 + 4 u eta_p eta_s,

    (C1)  u~_z(tau) = -(1/2pi) PV int_{alpha^2}^{tau^2} Im[eta_p/R~](u) du / sqrt(tau^2 - u)

    (C2)  u~_r(tau) = (tau/4pi) [ 2 int_{alpha^2}^{min(1,tau^2)}
                                      Im[(1 - 2u - 2 eta_p eta_s)/R~](u) du / sqrt(tau^2 - u)
                                  - 2 pi kappa H(tau - gamma) / sqrt(tau^2 - gamma^2) ]

for tau > alpha (both vanish for tau < alpha).  In (C1) the Rayleigh pole at
u = gamma^2 is a principal value (the residues of the two lips cancel); in (C2)
the integrand is real, hence has no imaginary part, for u > 1 and the two lips
add their residues: that gives the Rayleigh term with

    kappa = N(gamma^2) / D'(gamma^2),   N = 1 - 2u + 2E,   D = (1 - 2u)^2 - 4uE,
    E = sqrt((u - alpha^2)(u - 1))       (D = 0 is the Rayleigh equation).

(C2) shows that the radial component is NOT the Rayleigh term alone after the
Rayleigh arrival: the branch-cut integral over alpha^2 < u < 1 persists for all
tau.  The Rayleigh term alone tends to -kappa/2, which equals the static value
-(1 - 2nu)/4 only for nu = 1/4 (kappa = 1/4 there; e.g. kappa/2 = 0.0816 instead
of 0.05 for nu = 0.4).  `lamb_point_general` evaluates (C1)-(C2) by adaptive
quadrature (scipy.integrate.quad; substitution u = tau^2 - v^2; the PV with the
Cauchy weight after dividing out the pole analytically).

Closed forms (G), used by `lamb_point` for any nu
-------------------------------------------------
On alpha^2 < u < 1, |R~|^2 = P3(u) and for u > 1, D(u) (D*)(u) = P3(u) with the
Rayleigh cubic

    P3(u) = (1 - 2u)^4 - 16 u^2 (u - alpha^2)(u - 1)
          = 1 - 8u + (24 - 16 alpha^2) u^2 - 16 (1 - alpha^2) u^3
          = -16 (1 - alpha^2) (u - u_1)(u - u_2)(u - u_3),   u_3 = gamma^2.

Then Im[eta_p/R~] = -[(1-2u)^2 sqrt(u-alpha^2) + H(u-1) 4u(u-alpha^2) sqrt(u-1)]/P3
and Im[...] in (C2) = 2 sqrt((u-alpha^2)(1-u)) (1 - 2u)/P3.  Partial fractions

    (1-2u)^2/P3 = sum c_j/(u-u_j),   4u(u-alpha^2)/P3 = sum d_j/(u-u_j),
    (u-alpha^2)(1-u)(1-2u)/P3 = e_0 + sum e_j/(u-u_j),   e_0 = -1/(8(1-alpha^2)),

and int_a^b sqrt((u-a)/(b-u)) du/(u-c) = pi (1 - S(a,b,c)),
S(a,b,c) = sqrt((c-a)/(c-b)) (principal branch; its real part is 0 for a<c<b,
which is the principal value) give

    (G1) u~_z = 1/2 sum_j c_j [1 - S(alpha^2, tau^2, u_j)]
                + H(tau - 1) 1/2 sum_j d_j [1 - S(1, tau^2, u_j)]          (real part)

    (G2) u~_r = (tau/pi) I(tau) - (kappa/2) H(tau - gamma) tau / sqrt(tau^2 - gamma^2),
         I(tau) = int_{e1}^{e2} [e_0 + sum_j e_j/(u - u_j)] du / sqrt((u-e1)(e2-u)(e3-u))
                = 2/sqrt(e3 - e1) [ e_0 K(m) + sum_j e_j Pi(n_j, m)/(e1 - u_j) ],
         e1 = alpha^2, e2 = min(1, tau^2), e3 = max(1, tau^2),
         m = (e2 - e1)/(e3 - e1),  n_j = (e2 - e1)/(u_j - e1),

with the complete elliptic integrals K(m) = R_F(0, 1-m, 1) and
Pi(n, m) = R_F(0, 1-m, 1) + n/3 R_J(0, 1-m, 1, 1-n) (Carlson; complex n for
complex roots, nu > 0.2631).  At tau = 1 exactly (m = 1) the limit
I(1) = sum_j f_j 2 atan(sqrt(1 - alpha^2)/w_j)/w_j, f_j = (u_j - alpha^2)(1 - 2u_j)/P3'(u_j),
w_j = sqrt(alpha^2 - u_j), is used.  Sum of residues: u~_z = -(1 - nu)/2 exactly
for tau > gamma (for every nu: the vertical reaches its static value right after
the Rayleigh arrival); u~_r = -(1 - 2nu)/4 + O(tau^-2).

Pekeris (1955), nu = 1/4 (`pekeris_point`)
------------------------------------------
Roots u_j = 1/4, (3 - sqrt 3)/4, gamma^2 = (3 + sqrt 3)/4, kappa = 1/4:

    (P1) alpha < tau < 1:
         u~_z = -1/32 [ 6 - sqrt3/sqrt(tau^2 - 1/4) + sqrt(3sqrt3 - 5)/sqrt(tau^2 - (3 - sqrt3)/4)
                        - sqrt(3sqrt3 + 5)/sqrt(gamma^2 - tau^2) ]
         1 < tau < gamma:   u~_z = -1/16 [ 6 - sqrt(3sqrt3 + 5)/sqrt(gamma^2 - tau^2) ]
         tau > gamma:       u~_z = -3/8

    (P2) u~_r = (tau/pi) I(tau) - H(tau - gamma) tau / (8 sqrt(tau^2 - gamma^2)),
         I = 2/sqrt(e3 - 1/3) [ -3/16 K(m) + sum_j e_j Pi(n_j, m)/(1/3 - u_j) ],
         (e_1, e_2, e_3) = (3/64, -(1 - 1/sqrt3)/64, -(1 + 1/sqrt3)/64).

Singularities at the Rayleigh arrival: u~_z -> +inf like
sqrt(3sqrt3+5)/(16 sqrt(gamma^2 - tau^2)) as tau -> gamma- (upward, against the
load) and equals -3/8 for tau > gamma; u~_r is finite (continuous) as
tau -> gamma- and -> -inf like -tau/(8 sqrt(tau^2 - gamma^2)) as tau -> gamma+.
Both are integrable in time.  At tau = gamma itself NaN is returned.

Rectangular patch (`patch_displacement`)
----------------------------------------
With polar coordinates (R, theta) centred at the receiver, the load element
p0 R dR dtheta at distance R contributes p0 u~(c_s t / R)/(pi mu R), so

    u_z = p0/(pi mu) int dR u~_z(c_s t/R) C_0(R),
    (u_x, u_y) = -p0/(pi mu) int dR u~_r(c_s t/R) (C_x(R), C_y(R)),

where C_0, C_x, C_y = int dtheta (1, cos theta, sin theta) over the arcs of the
circle of radius R (centre: receiver) that lie inside the rectangle (the source
point is at receiver + R (cos, sin), the displacement at the receiver points
from source to receiver, hence the minus sign).  The arcs are closed form
(signed sum over the four corner rectangles).  The R integral is split at the
arrival radii c_p t, c_s t, c_s t/gamma and at the geometric kinks (distances
to the side lines and corners); on each piece Gauss-Legendre after
R = lo + (hi - lo)(1 - cos(pi s))/2 removes the 1/sqrt and sqrt endpoint
singularities.  `method='quad'` uses scipy.integrate.quad on each piece instead.

Static rectangle (`boussinesq_rectangle`): u_z = -(1 - nu) p0/(2 pi mu) int dA/rho,
(u_x, u_y) = (1 - 2nu) p0/(4 pi mu) int (xi, eta)/rho^2 dA in closed form.

Verification (tests/analytic/test_pekeris.py): (P) vs (G) vs (C) quadrature,
static limits for several nu, Laplace transforms of (G) against a direct
numerical Hankel inversion of (T1)-(T2), patch -> point and -> Boussinesq.
"""
import functools
import math

import numpy as np
from scipy import integrate, optimize, special

__all__ = [
    "poisson_ratio",
    "arrivals",
    "dimensionless",
    "pekeris_point",
    "lamb_point",
    "lamb_point_general",
    "point_displacement",
    "patch_displacement",
    "boussinesq_rectangle",
]

SQ3 = math.sqrt(3.0)
#: Rayleigh slowness gamma = c_s/c_R for nu = 1/4 (tau of the Rayleigh arrival)
GAMMA2_QUARTER = (3.0 + SQ3) / 4.0
TAU_R_QUARTER = math.sqrt(GAMMA2_QUARTER)


# --------------------------------------------------------------------------
# elementary helpers
# --------------------------------------------------------------------------
def poisson_ratio(cs, cp):
    """Poisson's ratio from the wave speeds (1/4 exactly when cp/cs = sqrt 3)."""
    k2 = (float(cp) / float(cs)) ** 2
    if k2 <= 2.0:
        raise ValueError("need cp/cs > sqrt(2) (0 <= nu < 1/2 supported)")
    nu = (k2 - 2.0) / (2.0 * (k2 - 1.0))
    if abs(nu - 0.25) < 1e-12:
        nu = 0.25
    return nu


def _alpha2(nu):
    return (1.0 - 2.0 * nu) / (2.0 * (1.0 - nu))


def _check_nu(nu):
    nu = float(nu)
    if not (0.0 <= nu < 0.5):
        raise ValueError("Poisson's ratio must satisfy 0 <= nu < 0.5, got %r" % nu)
    return nu


def dimensionless(u, r, P, mu):
    """Dimensionless displacement pi * mu * u * r / P."""
    return np.pi * mu * np.asarray(u) * r / P


class _Consts:
    """Constants of the closed forms (G1)-(G2) for one Poisson's ratio."""

    def __init__(self, nu):
        self.nu = nu
        a2 = _alpha2(nu)
        self.a2 = a2
        coef = np.array([-16.0 * (1.0 - a2), 24.0 - 16.0 * a2, -8.0, 1.0])
        if nu == 0.25:
            roots = np.array([0.25, (3.0 - SQ3) / 4.0, GAMMA2_QUARTER], dtype=complex)
        else:
            roots = np.roots(coef).astype(complex)
            dcoef = np.polyder(coef)
            for _ in range(3):  # Newton polish
                roots = roots - np.polyval(coef, roots) / np.polyval(dcoef, roots)
        real = np.abs(roots.imag) <= 1e-12 * np.abs(roots)
        cand = np.where(real & (roots.real > 1.0), roots.real, -np.inf)
        iR = int(np.argmax(cand))
        if not np.isfinite(cand[iR]):
            raise RuntimeError("Rayleigh root not found for nu=%r" % nu)
        roots[iR] = roots[iR].real
        self.g2 = float(roots[iR].real)
        self.gamma = math.sqrt(self.g2)
        self.alpha = math.sqrt(a2)
        self.roots = roots
        dP = np.polyval(np.polyder(coef), roots)
        self.c = (1.0 - 2.0 * roots) ** 2 / dP
        self.d = 4.0 * roots * (roots - a2) / dP
        self.e = (roots - a2) * (1.0 - roots) * (1.0 - 2.0 * roots) / dP
        self.e0 = -1.0 / (8.0 * (1.0 - a2))
        self.f = (roots - a2) * (1.0 - 2.0 * roots) / dP
        g2 = self.g2
        E = math.sqrt((g2 - a2) * (g2 - 1.0))
        dE = E * (0.5 / (g2 - a2) + 0.5 / (g2 - 1.0))
        self.kappa = (1.0 - 2.0 * g2 + 2.0 * E) / (
            -4.0 * (1.0 - 2.0 * g2) - 4.0 * E - 4.0 * g2 * dE)


@functools.lru_cache(maxsize=64)
def _consts(nu):
    return _Consts(nu)


def arrivals(nu=0.25):
    """Dimensionless arrival times (tau_P, tau_S, tau_R) = (c_s/c_p, 1, c_s/c_R)."""
    k = _consts(_check_nu(nu))
    return k.alpha, 1.0, k.gamma


_ONE_MINUS = float(np.nextafter(1.0, 0.0))


def _PiK(n, m):
    """Complete elliptic integral of the third kind Pi(n, m) (n may be complex).

    1 - m is kept below 1: scipy's elliprj returns NaN for R_J(0, 1, 1, p) with
    complex p (m < 1e-16, i.e. tau > 1e8); the change is O(1e-16).
    """
    y = np.minimum(1.0 - m, _ONE_MINUS)
    return special.elliprf(0.0, y, 1.0) + n / 3.0 * special.elliprj(0.0, y + 0j, 1.0, 1.0 - n)


# --------------------------------------------------------------------------
# closed forms
# --------------------------------------------------------------------------
def _radial_integral(t2, k, e0, e, roots):
    """I(tau) of (G2) for tau^2 = t2 > alpha^2 (1-D array), tau != 1."""
    e1 = k.a2
    e2 = np.minimum(1.0, t2)[:, None]
    e3 = np.maximum(1.0, t2)[:, None]
    m = (e2 - e1) / (e3 - e1)
    n = (e2 - e1) / (roots - e1)
    Kp = special.ellipk(m)
    Pi = _PiK(n, m)
    I = 2.0 / np.sqrt(e3 - e1) * (e0 * Kp + np.sum(e * Pi / (e1 - roots), axis=1, keepdims=True))
    return I[:, 0].real


def _radial_integral_at_one(k):
    """I(1): limit of (G2) at the S arrival (elementary)."""
    w = np.sqrt(k.a2 - k.roots + 0j)
    L = math.sqrt(1.0 - k.a2)
    return float(np.sum(k.f * 2.0 * np.arctan(L / w) / w).real)


def lamb_point(tau, nu=0.25):
    """Closed form (G1)-(G2) of Lamb's problem for any 0 <= nu < 1/2.

    Returns (u~_r, u~_z): dimensionless radial (positive away from the load)
    and vertical (positive up) surface displacement for a downward step point
    load, as functions of tau = c_s t / r.  NaN exactly at the Rayleigh arrival.
    """
    nu = _check_nu(nu)
    k = _consts(nu)
    tau = np.asarray(tau, dtype=float)
    shape = tau.shape
    tau = tau.ravel()
    ur = np.zeros_like(tau)
    uz = np.zeros_like(tau)
    act = tau > k.alpha
    if np.any(act):
        t = tau[act]
        t2 = t * t
        T2 = t2[:, None]
        with np.errstate(divide="ignore", invalid="ignore"):
            Sa = np.sqrt((k.roots - k.a2) / (k.roots - T2) + 0j)
            z = 0.5 * np.sum(k.c * (1.0 - Sa), axis=1)
            S1 = np.sqrt((k.roots - 1.0) / (k.roots - T2) + 0j)
            z = z + np.where(t2 > 1.0, 0.5 * np.sum(k.d * (1.0 - S1), axis=1), 0.0)
            z = z.real
            at_one = np.abs(t2 - 1.0) <= 1e-14
            tt2 = np.where(at_one, 2.0, t2)
            I = _radial_integral(tt2, k, k.e0, k.e, k.roots)
            I = np.where(at_one, _radial_integral_at_one(k), I)
            r = t / np.pi * I
            after = t > k.gamma
            r = r - np.where(after, 0.5 * k.kappa * t / np.sqrt(np.where(after, t2 - k.g2, 1.0)), 0.0)
        sing = np.abs(t2 - k.g2) <= 4e-16 * k.g2
        z[sing] = np.nan
        r[sing] = np.nan
        uz[act] = z
        ur[act] = r
    return ur.reshape(shape), uz.reshape(shape)


def pekeris_point(tau, nu=0.25):
    """Pekeris' closed form for nu = 1/4: (u~_r, u~_z) as functions of tau.

    u~ = pi mu r u / P, tau = c_s t / r; u~_z positive up (-> -3/8), u~_r
    positive away from the load (-> -1/8).  Formulas (P1)-(P2) of the module
    docstring.  For nu != 1/4 this dispatches to the quadrature evaluation
    `lamb_point_general` (slow; `lamb_point` is the fast general closed form).
    NaN exactly at the Rayleigh arrival tau = gamma.
    """
    nu = _check_nu(nu)
    if nu != 0.25:
        return lamb_point_general(tau, nu)
    tau = np.asarray(tau, dtype=float)
    shape = tau.shape
    tau = tau.ravel()
    ur = np.zeros_like(tau)
    uz = np.zeros_like(tau)
    g2 = GAMMA2_QUARTER
    u2 = (3.0 - SQ3) / 4.0
    a2 = 1.0 / 3.0
    A = math.sqrt(3.0 * SQ3 - 5.0)
    B = math.sqrt(3.0 * SQ3 + 5.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        # vertical (P1)
        t2 = tau * tau
        m1 = (t2 > a2) & (t2 < 1.0)
        t = t2[m1]
        uz[m1] = -(6.0 - SQ3 / np.sqrt(t - 0.25) + A / np.sqrt(t - u2) - B / np.sqrt(g2 - t)) / 32.0
        m2 = (t2 >= 1.0) & (t2 < g2)
        uz[m2] = -(6.0 - B / np.sqrt(g2 - t2[m2])) / 16.0
        uz[t2 > g2] = -3.0 / 8.0
        # radial (P2)
        roots = np.array([0.25, u2, g2])
        e = np.array([3.0 / 64.0, -(1.0 - 1.0 / SQ3) / 64.0, -(1.0 + 1.0 / SQ3) / 64.0])
        act = t2 > a2
        if np.any(act):
            ta = tau[act]
            ta2 = ta * ta
            e1 = a2
            e2 = np.minimum(1.0, ta2)[:, None]
            e3 = np.maximum(1.0, ta2)[:, None]
            m = (e2 - e1) / (e3 - e1)
            n = (e2 - e1) / (roots - e1)
            y = np.minimum(1.0 - m, _ONE_MINUS)
            Pi = special.elliprf(0.0, y, 1.0) + n / 3.0 * special.elliprj(0.0, y, 1.0, 1.0 - n)
            I = 2.0 / np.sqrt(e3 - e1) * (-3.0 / 16.0 * special.ellipk(m)
                                          + np.sum(e * Pi / (e1 - roots), axis=1, keepdims=True))
            r = ta / np.pi * I[:, 0]
            at_one = np.abs(ta2 - 1.0) <= 1e-14
            if np.any(at_one):
                r[at_one] = _radial_integral_at_one(_consts(0.25)) / np.pi
            after = ta2 > g2
            r[after] -= ta[after] / (8.0 * np.sqrt(ta2[after] - g2))
            ur[act] = r
    sing = np.abs(tau * tau - g2) <= 4e-16 * g2
    ur[sing] = np.nan
    uz[sing] = np.nan
    return ur.reshape(shape), uz.reshape(shape)


# --------------------------------------------------------------------------
# independent general-nu evaluation by quadrature of (C1)-(C2)
# --------------------------------------------------------------------------
class _QuadConsts:
    def __init__(self, nu):
        a2 = _alpha2(nu)
        self.a2 = a2

        def D(u):
            return (1.0 - 2.0 * u) ** 2 - 4.0 * u * math.sqrt((u - a2) * (u - 1.0))

        # Rayleigh root of D = 0 found directly (no use of the cubic)
        g2 = optimize.brentq(D, 1.0 + 1e-14, 4.0, xtol=1e-16, rtol=1e-15, maxiter=500)
        self.g2 = g2
        E = math.sqrt((g2 - a2) * (g2 - 1.0))
        dE = E * (0.5 / (g2 - a2) + 0.5 / (g2 - 1.0))
        dD = -4.0 * (1.0 - 2.0 * g2) - 4.0 * E - 4.0 * g2 * dE
        self.kappa = (1.0 - 2.0 * g2 + 2.0 * E) / dD
        # D(u) D*(u) = P3(u) = (u - g2) q(u): deflate to remove the pole
        coef = np.array([-16.0 * (1.0 - a2), 24.0 - 16.0 * a2, -8.0, 1.0])
        q, _ = np.polydiv(coef, np.array([1.0, -g2]))
        self.q = q


@functools.lru_cache(maxsize=64)
def _qconsts(nu):
    return _QuadConsts(nu)


def _eta(u, c2):
    """Upper-lip branch of sqrt(c2 - u)."""
    return complex(math.sqrt(c2 - u)) if u < c2 else -1j * math.sqrt(u - c2)


def _im_g(u, a2):
    ep, es = _eta(u, a2), _eta(u, 1.0)
    return (ep / ((1.0 - 2.0 * u) ** 2 + 4.0 * u * ep * es)).imag


def _im_h(u, a2):
    ep, es = _eta(u, a2), _eta(u, 1.0)
    return ((1.0 - 2.0 * u - 2.0 * ep * es) / ((1.0 - 2.0 * u) ** 2 + 4.0 * u * ep * es)).imag


def _lamb_general_scalar(tau, nu, epsabs, epsrel, limit):
    k = _qconsts(nu)
    a2, g2 = k.a2, k.g2
    if tau <= math.sqrt(a2):
        return 0.0, 0.0
    if abs(tau * tau - g2) <= 4e-16 * g2:
        return math.nan, math.nan
    kw = dict(epsabs=epsabs, epsrel=epsrel, limit=limit)
    t2 = tau * tau
    V = math.sqrt(t2 - a2)

    def img_v(v):
        return _im_g(t2 - v * v, a2)

    # ---- vertical (C1), in v = sqrt(tau^2 - u)
    if t2 <= 1.0:
        wz = integrate.quad(img_v, 0.0, V, **kw)[0]
    else:
        V1 = math.sqrt(t2 - 1.0)
        wz = integrate.quad(img_v, V1, V, **kw)[0]
        if t2 < g2:
            wz += integrate.quad(img_v, 0.0, V1, **kw)[0]
        else:
            vR = math.sqrt(t2 - g2)

            def f(v):
                # on u > 1: Im g = -sqrt(u-a2) D*/P3 with P3 = (u-g2) q(u) and
                # u - g2 = -(v - vR)(v + vR), i.e. Im g = f(v)/(v - vR)
                u = t2 - v * v
                Es = math.sqrt((u - a2) * (u - 1.0))
                Dstar = (1.0 - 2.0 * u) ** 2 + 4.0 * u * Es
                return math.sqrt(u - a2) * Dstar / ((v + vR) * np.polyval(k.q, u))

            d = 0.5 * min(vR, V1 - vR)
            lo, hi = vR - d, vR + 0.8 * d
            wz += integrate.quad(f, lo, hi, weight="cauchy", wvar=vR, **kw)[0]
            if lo > 0.0:
                wz += integrate.quad(img_v, 0.0, lo, **kw)[0]
            wz += integrate.quad(img_v, hi, V1, **kw)[0]
    uz = -wz / math.pi
    # ---- radial (C2)
    lo = 0.0 if t2 <= 1.0 else math.sqrt(t2 - 1.0)
    F = 4.0 * integrate.quad(lambda v: _im_h(t2 - v * v, a2), lo, V, **kw)[0]
    if t2 > g2:
        F -= 2.0 * math.pi * k.kappa / math.sqrt(t2 - g2)
    ur = tau / (4.0 * math.pi) * F
    return ur, uz


def lamb_point_general(tau, nu, epsabs=1e-12, epsrel=1e-11, limit=200):
    """Independent evaluation of (u~_r, u~_z) for any nu by quadrature of (C1)-(C2).

    Uses scipy.integrate.quad on the Cagniard-de Hoop integrals (complex
    arithmetic for the integrands, Rayleigh root from D(u) = 0 by brentq, the
    principal value by QAWC after dividing out the pole).  Slow (a few ms per
    tau); meant for cross-checking `pekeris_point` / `lamb_point`.
    """
    nu = _check_nu(nu)
    tau = np.asarray(tau, dtype=float)
    ur = np.zeros(tau.shape)
    uz = np.zeros(tau.shape)
    for idx, tv in np.ndenumerate(tau):
        ur[idx], uz[idx] = _lamb_general_scalar(float(tv), nu, epsabs, epsrel, limit)
    return ur, uz


# --------------------------------------------------------------------------
# dimensional point and patch responses
# --------------------------------------------------------------------------
def _point_dimless(tau, nu):
    if nu == 0.25:
        return pekeris_point(tau, 0.25)
    return lamb_point(tau, nu)


def point_displacement(x, y, t, P, cs, cp, rho):
    """Surface displacement (ux, uy, uz) [m] at (x, y, 0) for a point force P*H(t).

    P > 0 [N] pushes down at the origin; z is up (uz < 0 at late times).
    x, y, t broadcast (t in s; zero for t <= 0).  Any 0 <= nu < 1/2 (closed
    form (G); Pekeris (P) when cp/cs = sqrt 3).  NaN at r = 0 and exactly at the
    Rayleigh arrival.
    """
    nu = poisson_ratio(cs, cp)
    mu = rho * cs * cs
    x, y, t = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float), np.asarray(t, float))
    r = np.hypot(x, y)
    with np.errstate(divide="ignore", invalid="ignore"):
        tau = np.where(r > 0, cs * t / np.where(r > 0, r, 1.0), np.nan)
        tau = np.where(t > 0, tau, 0.0)
        ur, uz = _point_dimless(np.where(np.isfinite(tau), tau, 0.0), nu)
        scale = np.where(r > 0, P / (np.pi * mu * np.where(r > 0, r, 1.0)), np.nan)
        ur = ur * scale
        uz = uz * scale
        ux = np.where(r > 0, ur * x / np.where(r > 0, r, 1.0), np.nan)
        uy = np.where(r > 0, ur * y / np.where(r > 0, r, 1.0), np.nan)
    return ux, uy, uz


def _corners(x, y, a, b):
    X1, X2, Y1, Y2 = -a - x, a - x, -b - y, b - y
    return [(X2, Y2, 1.0), (X1, Y2, -1.0), (X2, Y1, -1.0), (X1, Y1, 1.0)]


def _arc_weights(R, corners):
    """C_0, C_x, C_y of the circle of radius R (centre receiver) inside the rectangle."""
    C0 = np.zeros_like(R)
    Cx = np.zeros_like(R)
    Cy = np.zeros_like(R)
    for X, Y, eps in corners:
        sx, sy = np.sign(X), np.sign(Y)
        if sx == 0.0 or sy == 0.0:
            continue
        cl = np.minimum(1.0, abs(X) / R)   # cos(theta_lo)
        sh = np.minimum(1.0, abs(Y) / R)   # sin(theta_hi)
        th_lo = np.arccos(cl)
        th_hi = np.arcsin(sh)
        L = th_hi - th_lo
        ins = L > 0.0
        w = eps * sx * sy
        C0 += w * np.where(ins, L, 0.0)
        Cx += w * sx * np.where(ins, sh - np.sqrt(1.0 - cl * cl), 0.0)
        Cy += w * sy * np.where(ins, cl - np.sqrt(1.0 - sh * sh), 0.0)
    return C0, Cx, Cy


def patch_displacement(x, y, t, a, b, p0, cs, cp, rho, **quad_opts):
    """Surface displacement (ux, uy, uz) [m] at (x, y, 0) under a step pressure patch.

    A uniform pressure p0*H(t) > 0 (pushing down; total force 4 a b p0) acts on
    the rectangle [-a, a] x [-b, b] of the surface.  The receiver may be inside
    or outside the patch; t is an array of times [s].

    quad_opts:
      method : 'gauss' (default) or 'quad' (scipy.integrate.quad per piece)
      n      : Gauss-Legendre points per piece (default 32)
      epsabs, epsrel, limit : for method='quad' (defaults 1e-13, 1e-10, 200;
               epsabs is relative to p0/(pi mu) * patch size)
    """
    method = quad_opts.pop("method", "gauss")
    n = int(quad_opts.pop("n", 32))
    epsabs = float(quad_opts.pop("epsabs", 1e-13))
    epsrel = float(quad_opts.pop("epsrel", 1e-10))
    limit = int(quad_opts.pop("limit", 200))
    if quad_opts:
        raise TypeError("unknown quad_opts: %s" % sorted(quad_opts))
    if a <= 0 or b <= 0:
        raise ValueError("patch half-widths a, b must be positive")
    nu = poisson_ratio(cs, cp)
    gamma = arrivals(nu)[2]
    mu = rho * cs * cs
    x, y = float(x), float(y)
    tt = np.asarray(t, dtype=float)
    shape = tt.shape
    tt = tt.ravel()
    corners = _corners(x, y, a, b)
    geo = [abs(X) for X, _, _ in corners] + [abs(Y) for _, Y, _ in corners]
    geo += [math.hypot(X, Y) for X, Y, _ in corners]
    Rmin = math.hypot(max(0.0, abs(x) - a), max(0.0, abs(y) - b))
    Rmax = max(math.hypot(X, Y) for X, Y, _ in corners)
    fac = p0 / (np.pi * mu)

    def pieces(tv):
        hi = min(Rmax, cp * tv)
        if hi <= Rmin:
            return []
        bp = [Rmin, hi] + [v for v in geo + [cs * tv / gamma, cs * tv] if Rmin < v < hi]
        bp = np.unique(np.array(bp))
        keep = np.concatenate([[True], np.diff(bp) > 1e-14 * hi])
        bp = bp[keep]
        return list(zip(bp[:-1], bp[1:]))

    out = np.zeros((3, tt.size))
    if method == "gauss":
        s, w = np.polynomial.legendre.leggauss(n)
        s = 0.5 * (s + 1.0)
        w = 0.5 * w
        Rs, Ws, Ts, idx = [], [], [], []
        for i, tv in enumerate(tt):
            if tv <= 0.0:
                continue
            for lo, hi in pieces(tv):
                h = hi - lo
                Rs.append(lo + h * 0.5 * (1.0 - np.cos(np.pi * s)))
                Ws.append(w * h * 0.5 * np.pi * np.sin(np.pi * s))
                Ts.append(np.full(n, tv))
                idx.append(np.full(n, i))
        if Rs:
            R = np.concatenate(Rs)
            W = np.concatenate(Ws)
            T = np.concatenate(Ts)
            I = np.concatenate(idx)
            ur, uz = _point_dimless(cs * T / R, nu)
            C0, Cx, Cy = _arc_weights(R, corners)
            out[0] = -np.bincount(I, W * ur * Cx, minlength=tt.size)
            out[1] = -np.bincount(I, W * ur * Cy, minlength=tt.size)
            out[2] = np.bincount(I, W * uz * C0, minlength=tt.size)
    elif method == "quad":
        size = max(a, b)

        def integrand(R, tv, comp):
            Ra = np.array([R])
            ur, uz = _point_dimless(cs * tv / Ra, nu)
            C0, Cx, Cy = _arc_weights(Ra, corners)
            return float((-ur * Cx, -ur * Cy, uz * C0)[comp][0])

        for i, tv in enumerate(tt):
            if tv <= 0.0:
                continue
            for lo, hi in pieces(tv):
                for comp in range(3):
                    out[comp, i] += integrate.quad(integrand, lo, hi, args=(tv, comp),
                                                   epsabs=epsabs * size, epsrel=epsrel,
                                                   limit=limit)[0]
    else:
        raise ValueError("method must be 'gauss' or 'quad'")
    out *= fac
    return out[0].reshape(shape), out[1].reshape(shape), out[2].reshape(shape)


def boussinesq_rectangle(x, y, a, b, p0, mu, nu):
    """Static surface displacement (ux, uy, uz) under pressure p0 on [-a,a]x[-b,b].

    Boussinesq point solution u_z = -(1-nu) P/(2 pi mu r) (z up),
    u_r = -(1-2nu) P/(4 pi mu r) (towards the load), integrated in closed form:
    u_z = -(1-nu) p0/(2 pi mu) sum_corners eps [X asinh(Y/|X|) + Y asinh(X/|Y|)],
    u_x = (1-2nu) p0/(4 pi mu) sum_corners eps [Y/2 ln(X^2+Y^2) + X atan(Y/X)],
    u_y likewise with X and Y exchanged; (X, Y) = corner - receiver,
    eps = +1 for (a,b), (-a,-b) and -1 for the other two corners.
    """
    x, y = float(x), float(y)

    def asinh_term(X, Y):
        return 0.0 if X == 0.0 else X * math.asinh(Y / abs(X))

    def F(X, Y):
        r2 = X * X + Y * Y
        v = 0.0
        if Y != 0.0:
            v += 0.5 * Y * math.log(r2)
        if X != 0.0:
            v += X * math.atan(Y / X)
        return v

    sz = sx = sy = 0.0
    for X, Y, eps in _corners(x, y, a, b):
        sz += eps * (asinh_term(X, Y) + asinh_term(Y, X))
        sx += eps * F(X, Y)
        sy += eps * F(Y, X)
    uz = -(1.0 - nu) * p0 / (2.0 * math.pi * mu) * sz
    ux = (1.0 - 2.0 * nu) * p0 / (4.0 * math.pi * mu) * sx
    uy = (1.0 - 2.0 * nu) * p0 / (4.0 * math.pi * mu) * sy
    return ux, uy, uz
