"""Checks of the plane-wave free field of a half-space (petsc_ssi.analytic.free_field).

Conventions: soil z < 0, e_z up, u_v positive up, angles in degrees, e^{-i omega t} for complex
coefficients.  Reference values: Aki & Richards (2002), sec. 5.2 (free-surface reflection
coefficients) and Achenbach (1973), ch. 5 (Rayleigh waves), as cited in the module.
The free-surface conditions are re-solved here independently (a 2x2 complex system built from
the stress of one plane-wave term), not through the module's closed forms.
"""
import math

import numpy as np
import pytest
from scipy import optimize, signal

from petsc_ssi.analytic import free_field as ff

pytestmark = pytest.mark.unit

CS, RHO = 200.0, 2000.0
NUS = [0.2, 0.25, 1.0 / 3.0, 0.45]
RNG_SEED = 20240611


def cp_of(nu):
    return CS * math.sqrt(2 * (1 - nu) / (1 - 2 * nu))


def lame(nu):
    mu = RHO * CS ** 2
    return RHO * cp_of(nu) ** 2 - 2 * mu, mu


class Harmonics:
    """Periodic band-limited g = sum a_k cos(w_k t + f_k) with closed-form H, analytic signal."""
    def __init__(self, period, amps, phases):
        self.w = 2 * np.pi * np.arange(1, len(amps) + 1) / period
        self.a, self.f = np.asarray(amps, float), np.asarray(phases, float)

    def _sum(self, t, deriv, fun):
        t = np.asarray(t, float)[..., None]
        return np.sum(self.a * self.w ** deriv * fun(self.w * t + self.f + deriv * np.pi / 2), -1)

    def __call__(self, t, deriv=0):
        return self._sum(t, deriv, np.cos)

    def hilbert(self, t, deriv=0):
        return self._sum(t, deriv, np.sin)

    def analytic(self, t, a=0.0, deriv=0):
        t, a = np.broadcast_arrays(np.asarray(t, float), np.asarray(a, float))
        ph = np.exp(-1j * (self.w * t[..., None] + self.f))
        return np.sum(self.a * (-1j * self.w) ** deriv * ph * np.exp(-self.w * a[..., None]), -1)


# ------------------------------------------------ independent free-surface solve (2-D h, z) ---
def _traction(d, s, lam, mu):
    """sigma e_z per unit g' of one term u = d g(t - s.x): -[lam (d.s) e_z + mu (d s_z + s d_z)]."""
    ez = np.array([0.0, 1.0])
    return -(lam * (d @ s) * ez + mu * (d * s[1] + s * d[1]))


def independent_surface(wave, theta_deg, nu):
    """Reflected amplitudes (R_same, R_converted) and surface (u_h, u_v) from sigma e_z = 0."""
    lam, mu = lame(nu)
    a, b = cp_of(nu), CS
    th = math.radians(theta_deg)
    if wave == "p":
        p = math.sin(th) / a
    else:
        p = math.sin(th) / b
    ci = np.sqrt(complex(1 - (p * a) ** 2))          # +i sqrt(.) beyond the critical angle
    cj = np.sqrt(complex(1 - (p * b) ** 2))
    if wave == "p":                                   # the incident cosine without cancellation
        ci = complex(math.cos(th))
    else:
        cj = complex(math.cos(th))
    si, sj = p * a, p * b
    terms = {"Pin": (np.array([si, ci]), np.array([p, ci / a])),
             "Sin": (np.array([cj, -sj]), np.array([p, cj / b])),
             "Pr": (np.array([si, -ci]), np.array([p, -ci / a])),
             "Sr": (np.array([cj, sj]), np.array([p, -cj / b]))}
    inc, r1, r2 = ("Pin", "Pr", "Sr") if wave == "p" else ("Sin", "Sr", "Pr")
    M = np.column_stack([_traction(*terms[r1], lam, mu), _traction(*terms[r2], lam, mu)])
    R = np.linalg.solve(M, -_traction(*terms[inc], lam, mu))
    u = terms[inc][0] + R[0] * terms[r1][0] + R[1] * terms[r2][0]
    return R, u


def angles_for(nu):
    jc = math.degrees(math.asin(CS / cp_of(nu)))
    return np.unique(np.r_[np.arange(0.0, 90.0, 2.5), 89.9, jc - 1e-3, jc + 1e-3, 45.0])


# ------------------------------------------------------------------------ 1. coefficients ---
@pytest.mark.parametrize("nu", NUS)
@pytest.mark.parametrize("wave", ["p", "sv"])
def test_surface_coefficients_match_independent_solve(wave, nu):
    """Closed forms vs the 2x2 boundary-condition solve, pre- and post-critical: 1e-11 of the
    amplitudes' scale (observed 1.8e-13: SV at 37.8 deg, nu = 0.2, next to the critical angle, where
    the 2x2 solve is ill-conditioned; the former 1e-12 left a margin of 5.6x)."""
    cp = cp_of(nu)
    for th in angles_for(nu):
        pw = ff.PlaneWave(wave, CS, cp, ff.Ricker(5.0), angle=th, control="incident",
                          postcritical=True)
        Ah, Av, At = pw.surface_coefficients()
        R, u = independent_surface(wave, th, nu)
        scale = max(1.0, abs(u[0]), abs(u[1]))
        assert abs(Ah - u[0]) < 1e-11 * scale, (wave, nu, th)
        assert abs(Av - u[1]) < 1e-11 * scale, (wave, nu, th)
        assert At == 0.0
        R_mod = np.array(ff.reflection_coefficients(wave, th, CS, cp))
        np.testing.assert_allclose(R_mod, R, rtol=0, atol=1e-11 * max(1.0, np.abs(R).max()))


TABLE = {  # nu: [(angle, P u_h, P u_v, SV u_h, SV u_v)] (note sec. 2.8), 4 decimals
    0.25: [(0, 0, 2, 2, 0),
           (10, .3998, 1.9635, 1.9515, -.3971),
           (20, .7798, 1.8571, 1.8193, -.7556),
           (30, 1.1211, 1.6901, 1.7321, -1.0),
           (40, 1.4056, 1.4777, .0622 - .7384j, -1.5447 - .1302j),
           (45, 1.5213, 1.3607, 0, -1.4142),
           (60, 1.7321, 1.0, -.1250 + .4841j, -1.0825 - .2795j),
           (75, 1.6126, .6584, -.2997 + .2989j, -.5163 - .5176j)],
    1.0 / 3.0: [(0, 0, 2, 2, 0),
                (10, .3460, 1.9697, 1.9717, -.3417),
                (20, .6733, 1.8812, 1.9268, -.6275),
                (30, .9633, 1.7411, None, None),          # SV: the critical angle, tested apart
                (40, 1.1966, 1.5597, .0306 - .5184j, -1.5503 - .0914j),
                (45, 1.2852, 1.4572, 0, -1.4142),
                (60, 1.3949, 1.1168, -.1053 + .4466j, -1.0939 - .2578j),
                (75, 1.1216, .7075, -.2802 + .2983j, -.5499 - .5166j)],
}


@pytest.mark.parametrize("nu", sorted(TABLE))
def test_note_tables(nu):
    """The note's sec. 2.8 tables (4 decimals): 1e-4."""
    cp = cp_of(nu)
    for th, ph, pv, sh_, sv_ in TABLE[nu]:
        A = ff.surface_amplitudes("p", th, CS, cp)
        assert abs(A[0] - ph) < 1e-4 and abs(A[1] - pv) < 1e-4, (nu, th)
        if sh_ is not None:
            A = ff.surface_amplitudes("sv", th, CS, cp)
            assert abs(A[0] - sh_) < 1e-4 and abs(A[1] - sv_) < 1e-4, (nu, th)


@pytest.mark.parametrize("nu", NUS)
def test_special_values(nu):
    """Vertical = 2, SH = 2 at all angles, SV 45 deg = (0, -sqrt 2): 1e-14."""
    cp, g = cp_of(nu), ff.Ricker(5.0)
    for wave, comp in (("vertical_s", 0), ("vertical_p", 1), ("sv", 0), ("p", 1)):
        A = ff.PlaneWave(wave, CS, cp, g, control="incident").surface_coefficients()
        assert A[comp] == pytest.approx(2.0, abs=1e-14) and abs(A[1 - comp]) < 1e-14
    for th in np.arange(0, 90, 7.5):
        assert ff.surface_amplitudes("sh", th, CS, cp) == (0.0, 0.0, 2.0)
    Ah, Av, _ = ff.surface_amplitudes("sv", 45.0, CS, cp)
    assert abs(Ah) < 1e-14 and Av == pytest.approx(-math.sqrt(2), abs=1e-14)


def test_special_values_nu_quarter_and_critical_limits():
    """nu = 1/4: SV 30 -> (sqrt3, -1), P 60 -> (sqrt3, 1) (1e-14); j -> j_c^-: 4.8990, 3.4641
    (1e-4) with A_v -> 0."""
    cp = cp_of(0.25)
    sq3 = math.sqrt(3)
    np.testing.assert_allclose(ff.surface_amplitudes("sv", 30, CS, cp)[:2], [sq3, -1], atol=1e-14)
    np.testing.assert_allclose(ff.surface_amplitudes("p", 60, CS, cp)[:2], [sq3, 1], atol=1e-14)
    assert abs(ff.reflection_coefficients("sv", 30, CS, cp)[0]) < 1e-14     # complete conversion
    assert abs(ff.reflection_coefficients("p", 60, CS, cp)[0]) < 1e-14
    for nu, lim in ((0.25, 4.8990), (1.0 / 3.0, 3.4641)):
        jc = ff.critical_angle(CS, cp_of(nu))
        Ah, Av, _ = ff.surface_amplitudes("sv", jc * (1 - 1e-13), CS, cp_of(nu))
        assert abs(Ah - lim) < 1e-4 and abs(Av) < 1e-4
    assert ff.critical_angle(CS, cp) == pytest.approx(35.2644, abs=1e-4)
    assert ff.critical_angle(CS, cp_of(1.0 / 3.0)) == pytest.approx(30.0, abs=1e-12)


# ------------------------------------------------------------------------------ 2. energy ---
@pytest.mark.parametrize("nu", NUS)
def test_energy_balance(nu):
    """Reflected flux / incident flux = 1 to 1e-12 (the evanescent P carries none)."""
    cp = cp_of(nu)
    for th in angles_for(nu):
        t = math.radians(th)
        rpp, rps = ff.reflection_coefficients("p", th, CS, cp)
        cj = math.sqrt(1 - (math.sin(t) * CS / cp) ** 2)
        assert abs(abs(rpp) ** 2 + CS * cj / (cp * math.cos(t)) * abs(rps) ** 2 - 1) < 1e-12, th
        rss, rsp = ff.reflection_coefficients("sv", th, CS, cp)
        ci = np.sqrt(complex(1 - (math.sin(t) * cp / CS) ** 2)).real
        assert abs(abs(rss) ** 2 + cp * ci / (CS * math.cos(t)) * abs(rsp) ** 2 - 1) < 1e-12, th


# --------------------------------------------------------------- 3. depth field: traction ---
def _cases(rng, n, nu=0.25):
    """(wave, angle, kwargs) over all wave types; random angles (SV pre and post critical)."""
    jc = math.degrees(math.asin(CS / cp_of(nu)))
    out = [("vertical_s", 0.0, {"polarisation": rng.uniform(0, 360)}), ("vertical_p", 0.0, {}),
           ("rayleigh", 0.0, {"azimuth": rng.uniform(0, 360)})]
    for _ in range(n):
        psi = {"azimuth": rng.uniform(0, 360)}
        out += [("sh", rng.uniform(0, 89), psi), ("p", rng.uniform(0, 89), psi),
                ("sv", rng.uniform(0, 0.95 * jc), psi),
                ("sv", rng.uniform(1.05 * jc, 89), dict(psi, postcritical=True))]
    return out


@pytest.mark.parametrize("nu", NUS)
def test_traction_free_surface_all_waves(nu):
    """sigma.e_z = 0 at z = 0 (random t, x, angles, azimuths): 1e-10 of rho c_p max|g'|; the
    stress at depth is not trivially zero."""
    rng = np.random.default_rng(RNG_SEED)
    g = ff.Ricker(5.0, 0.3)
    scale = RHO * cp_of(nu) * np.abs(g(np.linspace(0, 1, 2001), 1)).max()
    for wave, th, kw in _cases(rng, 3, nu):
        pw = ff.PlaneWave(wave, CS, cp_of(nu), g, angle=th, rho=RHO,
                          x0=rng.uniform(-20, 20, 2), **kw)
        X = np.c_[rng.uniform(-100, 100, (40, 2)), np.zeros(40)]
        t = rng.uniform(-0.2, 1.2, 25)
        sig = pw.stress(X, t)
        assert sig.shape == (25, 40, 3, 3)
        assert np.abs(sig[..., :, 2]).max() < 1e-10 * scale, (wave, th)
        np.testing.assert_allclose(sig, np.swapaxes(sig, -1, -2), atol=1e-12 * scale)
        X[:, 2] = -rng.uniform(2, 30, 40)
        assert np.abs(pw.stress(X, t)).max() > 1e-3 * scale, (wave, th)


@pytest.mark.parametrize("nu", [0.25, 0.45])
def test_navier_equations_at_depth(nu):
    """rho u_tt = div sigma by central differences, h = 5 mm: truncation (k h)^2/6 < 1e-6 for
    k <= 2 pi 15 Hz / c_s; tolerance 1e-5 of max|rho u_tt|."""
    rng = np.random.default_rng(RNG_SEED + 1)
    g, h = ff.Ricker(5.0, 0.3), 5e-3
    for wave, th, kw in _cases(rng, 1, nu):
        pw = ff.PlaneWave(wave, CS, cp_of(nu), g, angle=th, rho=RHO, **kw)
        X = np.c_[rng.uniform(-50, 50, (4, 2)), -rng.uniform(1, 25, 4)]
        t = rng.uniform(0.1, 0.6, 6)
        lhs = RHO * pw.acceleration(X, t)
        div = np.zeros_like(lhs)
        for j in range(3):
            e = np.zeros(3)
            e[j] = h
            div += (pw.stress(X + e, t)[..., :, j] - pw.stress(X - e, t)[..., :, j]) / (2 * h)
        assert np.abs(div - lhs).max() < 1e-5 * np.abs(lhs).max(), (wave, th)


def test_surface_and_depth_forms_agree():
    """The surface shortcut (closed-form A) and the sum of depth terms at z = -1e-6 m agree to
    1e-6 of max|u| (first order in z: |du/dz| <= ~2 k max|u|, k <= 0.5 /m)."""
    rng = np.random.default_rng(RNG_SEED + 2)
    g = ff.Ricker(5.0, 0.3)
    for wave, th, kw in _cases(rng, 2, 0.3):
        pw = ff.PlaneWave(wave, CS, cp_of(0.3), g, angle=th, control="incident", **kw)
        X = np.c_[rng.uniform(-50, 50, (20, 2)), np.zeros(20)]
        t = np.linspace(0, 1, 40)
        u0 = pw.displacement(X, t)
        X[:, 2] = -1e-6
        assert np.abs(pw.displacement(X, t) - u0).max() < 1e-6 * np.abs(u0).max(), (wave, th)


def test_vertical_sh_depth_field_closed_form():
    """SH at any angle: u = e_t [g(tau + d cos/beta) + g(tau - d cos/beta)] (note 2.3): 1e-14 of the
    largest displacement (observed 1.1e-16 absolute; the former absolute 1e-15 left a margin of 9x)."""
    g, th, psi = ff.Ricker(4.0, 0.4), 25.0, 70.0
    pw = ff.PlaneWave("sh", CS, cp_of(0.3), g, angle=th, azimuth=psi, control="incident")
    X = np.array([[10.0, -3.0, -7.0], [0.0, 0.0, -20.0], [-4.0, 8.0, 0.0]])
    t = np.linspace(0, 1, 11)
    eh = np.array([math.cos(math.radians(psi)), math.sin(math.radians(psi)), 0.0])
    et = np.array([-eh[1], eh[0], 0.0])
    tau = t[:, None] - X @ eh * math.sin(math.radians(th)) / CS
    dc = -X[:, 2] * math.cos(math.radians(th)) / CS
    ref = (g(tau + dc) + g(tau - dc))[..., None] * et
    np.testing.assert_allclose(pw.displacement(X, t), ref, rtol=0, atol=1e-14 * np.abs(ref).max())
    assert pw.displacement(X, 0.3).shape == (3, 3)


# ---------------------------------------------------------------------------- 4. Rayleigh ---
RAYLEIGH_TABLE = [  # nu, c_R/beta (6 decimals), H/V (5 decimals), note sec. 2.7
    (0.0, 0.874032, 0.78615), (0.2, 0.910996, 0.70493), (0.25, 0.919402, 0.68125),
    (0.3, 0.927413, 0.65626), (1.0 / 3.0, 0.932526, 0.63890), (0.4, 0.942195, 0.60249),
    (0.45, 0.948960, 0.57372)]


@pytest.mark.parametrize("nu,xi_ref,hv_ref", RAYLEIGH_TABLE)
def test_rayleigh_speed_and_hv_table(nu, xi_ref, hv_ref):
    """c_R/beta to 1e-6 (table has 6 decimals); H/V to 5e-6 (table has 5 decimals); against a
    bracketed root of the secular equation and the null vector of the 2x2 boundary-condition
    matrix built here: 1e-12."""
    cp = cp_of(nu)
    k = cp / CS
    xi = ff.rayleigh_speed(CS, cp) / CS
    hv = ff.rayleigh_hv(CS, cp)
    assert abs(xi - xi_ref) < 1e-6 and abs(hv - hv_ref) < 5e-6
    sec = lambda x: (2 - x * x) ** 2 - 4 * math.sqrt(1 - x * x) * math.sqrt(1 - (x / k) ** 2)
    assert abs(optimize.brentq(sec, 0.5, 1.0, xtol=1e-15) - xi) < 1e-12
    lam, mu = lame(nu)
    p = 1 / (xi * CS)
    qp, qs = -1j * math.sqrt(p * p - 1 / cp ** 2), -1j * math.sqrt(p * p - 1 / CS ** 2)
    dP, sP = np.array([p, qp]) * cp, np.array([p, qp])
    dS, sS = np.array([qs, -p]) * CS, np.array([p, qs])
    M = np.column_stack([_traction(dP, sP, lam, mu), _traction(dS, sS, lam, mu)])
    B = np.linalg.svd(M)[2].conj()[-1]                 # null vector
    u = B[0] * dP + B[1] * dS
    assert abs(np.linalg.svd(M)[1][-1]) < 1e-12 * abs(np.linalg.svd(M)[1][0])
    assert abs(u[0] / u[1] - (-1j * hv)) < 1e-12
    assert ff.surface_amplitudes("rayleigh", 0, CS, cp)[0] == pytest.approx(-1j * hv, abs=1e-15)


def test_rayleigh_exact_quarter():
    """nu = 1/4: c_R = sqrt(2 - 2/sqrt3) c_s to 1e-14."""
    xi = ff.rayleigh_speed(CS, cp_of(0.25)) / CS
    assert xi == pytest.approx(math.sqrt(2 - 2 / math.sqrt(3)), abs=1e-14)


@pytest.mark.parametrize("nu,d_ref", [(0.25, 0.1925), (1.0 / 3.0, 0.1735)])
def test_rayleigh_retrograde_then_prograde(nu, d_ref):
    """Harmonic w = cos(omega t): at the crest the surface particle moves backwards (retrograde);
    the horizontal motion vanishes at the note's depth (4 decimals of lambda_R, tol 1e-4) and
    changes sign below (prograde)."""
    T = 0.2
    g = Harmonics(T, [1.0], [0.0])
    pw = ff.PlaneWave("rayleigh", CS, cp_of(nu), g, azimuth=30.0, control="incident")
    eh = pw.e_h
    lam_R = pw.c_app * T
    X0 = np.zeros((1, 3))
    assert pw.displacement(X0, 0.0)[0, 2] == pytest.approx(1.0, abs=1e-14)    # crest
    assert pw.velocity(X0, 0.0)[0] @ eh < 0                                    # backwards
    # horizontal at t = T/4 (where H[w] = 1) as a function of depth
    uh = lambda d: pw.displacement(np.array([[0, 0, -d * lam_R]]), T / 4)[0] @ eh
    assert uh(0) == pytest.approx(-ff.rayleigh_hv(CS, cp_of(nu)), abs=1e-14)
    d0 = optimize.brentq(uh, 0.05, 0.5, xtol=1e-12)
    assert abs(d0 - d_ref) < 1e-4
    assert uh(0.3) * uh(0.1) < 0


@pytest.mark.parametrize("wave,angle", [("rayleigh", 0.0), ("sv", 52.0)])
def test_hilbert_rule_against_irfft_synthesis(wave, angle):
    """Surface motion Re(A) g + Im(A) H[g] (module) vs irfft of conj(A) G e^{-i w delay} (numpy's
    e^{+i w t}) for a periodic band-limited g: 1e-12 of max|u|."""
    rng = np.random.default_rng(RNG_SEED + 3)
    P, N = 2.0, 256
    g = Harmonics(P, rng.normal(size=12), rng.uniform(0, 2 * np.pi, 12))
    pw = ff.PlaneWave(wave, CS, cp_of(0.25), g, angle=angle, azimuth=40.0, control="incident",
                      postcritical=True)
    A = np.array(pw.surface_coefficients())
    X = np.c_[rng.uniform(-80, 80, (5, 2)), np.zeros(5)]
    t = np.arange(N) * P / N
    u = pw.displacement(X, t)
    G = np.fft.rfft(g(t))
    om = 2 * np.pi * np.fft.rfftfreq(N, P / N)
    for m, x in enumerate(X):
        D = pw.delay(x[None])[0]
        comp = [np.fft.irfft(G * np.conj(Ac) * np.exp(-1j * om * D), N) for Ac in A]
        ref = np.outer(comp[0], pw.e_h) + np.outer(comp[1], [0, 0, 1.0]) + np.outer(comp[2], pw.e_t)
        assert np.abs(u[:, m] - ref).max() < 1e-12 * np.abs(u).max()


def test_postcritical_surface_control_inversion_rule():
    """Note sec. 5.2 item 6: g_inc = (Re A u - Im A H[u])/|A|^2 driven as the incident wave
    reproduces the record u on the controlled component at x0: 1e-13."""
    u = ff.Ricker(5.0, 0.5)
    A = ff.surface_amplitudes("sv", 50.0, CS, cp_of(0.25))[0]
    Ar, Ai, A2 = A.real, A.imag, abs(A) ** 2

    class Inc:
        def __call__(self, t, deriv=0):
            return (Ar * u(t, deriv) - Ai * u.hilbert(t, deriv)) / A2

    class IncH:   # H[g_inc], with H[H[u]] = -u
        def __call__(self, t, deriv=0):
            return (Ar * u.hilbert(t, deriv) + Ai * u(t, deriv)) / A2

    pw = ff.PlaneWave("sv", CS, cp_of(0.25), Inc(), angle=50.0, control="incident",
                      postcritical=True, hilbert=IncH(), x0=(3.0, 4.0))
    t = np.linspace(0, 1.2, 121)
    uh = pw.displacement(np.array([[3.0, 4.0, 0.0]]), t)[:, 0] @ pw.e_h
    assert np.abs(uh - u(t)).max() < 1e-13


def test_ricker_closed_form_hilbert():
    """Ricker's closed-form H (Faddeeva) vs scipy.signal.hilbert on a 400 s periodic grid: 1e-10
    (the periodic transform's wrap-around of the 1/t^3 tail is 2e-11);
    its analytic signal satisfies Cauchy-Riemann dU/da = -i dU/dt (FD, 1e-7 relative)."""
    r = ff.Ricker(5.0, 1.0)
    t = np.linspace(-200, 200, 2 ** 17, endpoint=False)     # wrap-around error ~2e-11
    assert np.abs(signal.hilbert(r(t)).imag - r.hilbert(t)).max() < 1e-10
    tt, a, e = np.linspace(0.5, 1.5, 41), 0.02, 1e-6
    dUda = (r.analytic(tt, a + e) - r.analytic(tt, a - e)) / (2 * e)
    ref = -1j * r.analytic(tt, a, 1)
    assert np.abs(dUda - ref).max() < 1e-7 * np.abs(ref).max()
    assert np.abs(r.analytic(tt, 0.0).real - r(tt)).max() < 1e-14


def test_hilbert_of_against_closed_form():
    """hilbert_of (FFT + cubic Hermite, 100 samples per 1/fc) vs Ricker's closed form for
    deriv 0, 1, 2 and complex times a in {0, 0.01, 0.1} s, inside and beyond the window:
    1e-6 relative (Hermite error ~ (omega dt)^4/384)."""
    r = ff.Ricker(5.0, 1.0)
    H = ff.hilbert_of(r, np.arange(0.0, 2.0, 0.002))
    tq = np.linspace(-15, 20, 4001)
    for d in range(3):
        assert np.abs(H(tq, d) - r.hilbert(tq, d)).max() < 1e-6 * np.abs(r.hilbert(tq, d)).max()
        for a in (0.0, 0.01, 0.1):
            ref = r.analytic(tq, a, d)
            assert np.abs(H.analytic(tq, a, d) - ref).max() < 1e-6 * np.abs(ref).max(), (d, a)


def test_hilbert_taper():
    """Tapered H: unchanged after taper_before, exactly 0 before taper_before - width; tail_level
    = max |H| at t <= taper_before (closed form, 1e-6 relative)."""
    r = ff.Ricker(5.0, 1.0)
    H = ff.hilbert_of(r, np.arange(0.0, 2.0, 0.002), taper_before=0.6, taper_width=0.2)
    assert H.support_start == pytest.approx(0.4)
    t = np.linspace(0.6, 1.9, 500)
    for d in range(3):
        assert np.abs(H(t, d) - r.hilbert(t, d)).max() < 1e-6 * np.abs(r.hilbert(t, d)).max()
        assert np.all(H(np.linspace(-10, 0.399, 300), d) == 0.0)
    tb = np.linspace(-3, 0.6, 20001)
    assert H.tail_level == pytest.approx(np.abs(r.hilbert(tb)).max(), rel=1e-3)


# --------------------------------------------------------------------------- 5. causality ---
def test_causality_with_auto_start():
    """Causal g (sin^4 pulse from t = 0), tapered H for the Hilbert-based fields: with
    t0 = auto_start(points, dt) u, v, a are exactly 0 for t <= 0 at a random surface cloud, for
    every wave type, angle and azimuth; one step less than auto_start - dt breaks it."""
    rng = np.random.default_rng(RNG_SEED + 4)
    dt = 1e-3
    g = ff.Sin4Pulse(0.2)
    H = ff.hilbert_of(g, np.arange(0.0, 0.4, 1e-3), taper_before=0.0, taper_width=0.1)
    t_neg = np.r_[np.linspace(-1.0, 0.0, 401)]
    for wave, th, kw in _cases(rng, 2, 0.3):
        pw = ff.PlaneWave(wave, CS, cp_of(0.3), g, angle=th, hilbert=H, **kw)
        X = np.c_[rng.uniform(-150, 150, (60, 2)), np.zeros(60)]
        pw.t0 = pw.auto_start(X, dt)
        for f in (pw.displacement, pw.velocity, pw.acceleration):
            assert np.all(f(X, t_neg) == 0.0), (wave, th)
        assert np.abs(pw.displacement(X, np.linspace(0, 3, 301))).max() > 0.1
        pw.t0 -= 2 * dt
        assert np.any(pw.displacement(X, t_neg) != 0.0), (wave, th)


def test_delay_and_c_app():
    """delay = (x - x0).e_h / c_app at the surface; earliest (incident) arrival at depth."""
    g = ff.Ricker(5.0)
    pw = ff.PlaneWave("p", CS, cp_of(0.25), g, angle=30.0, azimuth=90.0, x0=(1.0, 2.0))
    assert pw.c_app == pytest.approx(cp_of(0.25) / 0.5, rel=1e-14)
    X = np.array([[5.0, 12.0, 0.0], [1.0, 2.0, -10.0]])
    ref = [10.0 / pw.c_app, -10.0 * math.cos(math.pi / 6) / cp_of(0.25)]
    np.testing.assert_allclose(pw.delay(X), ref, rtol=1e-14)
    assert ff.PlaneWave("vertical_s", CS, cp_of(0.25), g).c_app == math.inf
    c_R = ff.rayleigh_speed(CS, cp_of(0.25))
    assert ff.PlaneWave("rayleigh", CS, cp_of(0.25), g).c_app == pytest.approx(c_R, rel=1e-14)


# ------------------------------------------------------------------ 6. control, refusals ---
CONTROLS = [("vertical_s", 0.0, "horizontal", {}), ("vertical_p", 0.0, "vertical", {}),
            ("sh", 35.0, "transverse", {}), ("sv", 20.0, "horizontal", {}),
            ("sv", 20.0, "vertical", {}),
            ("sv", 55.0, "horizontal", {"postcritical": True}),
            ("sv", 55.0, "vertical", {"postcritical": True}), ("p", 40.0, "vertical", {}),
            ("p", 40.0, "horizontal", {}), ("rayleigh", 0.0, "vertical", {}),
            ("rayleigh", 0.0, "horizontal", {})]


@pytest.mark.parametrize("wave,angle,component,kw", CONTROLS)
def test_surface_control_reproduces_g_at_x0(wave, angle, component, kw):
    """At x0 the controlled component equals g(t - t0) (1e-14 of max|g|), also through "auto"."""
    g = ff.Ricker(5.0, 0.4)
    x0 = (12.0, -7.0)
    pw = ff.PlaneWave(wave, CS, cp_of(0.3), g, angle=angle, azimuth=123.0, x0=x0, t0=0.05,
                      component=component, **kw)
    e = {"horizontal": pw.e_h, "vertical": np.array([0, 0, 1.0]), "transverse": pw.e_t}[component]
    t = np.linspace(0, 1.0, 201)
    for f, d in ((pw.displacement, 0), (pw.velocity, 1), (pw.acceleration, 2)):
        ref = g(t - 0.05, d)
        got = f(np.array([[x0[0], x0[1], 0.0]]), t)[:, 0] @ e
        assert np.abs(got - ref).max() < 1e-14 * np.abs(ref).max()
    if component == ff.AUTO_COMPONENT[wave]:
        auto = ff.PlaneWave(wave, CS, cp_of(0.3), g, angle=angle, azimuth=123.0, x0=x0,
                            t0=0.05, **kw)
        X = np.zeros((1, 3))
        np.testing.assert_array_equal(auto.displacement(X, t), pw.displacement(X, t))


def test_vertical_s_polarisation():
    """vertical_s: u = g(t) (cos phi, sin phi, 0) everywhere on the surface (surface control) and
    2 g with incident control: 1e-15."""
    g, phi = ff.Ricker(5.0, 0.3), 110.0
    ep = np.array([math.cos(math.radians(phi)), math.sin(math.radians(phi)), 0.0])
    X = np.array([[0.0, 0.0, 0.0], [50.0, -20.0, 0.0]])
    t = np.linspace(0, 1, 51)
    for control, fac in (("surface", 1.0), ("incident", 2.0)):
        pw = ff.PlaneWave("vertical_s", CS, cp_of(0.25), g, polarisation=phi, control=control)
        ref = np.broadcast_to(fac * g(t)[:, None, None] * ep, (t.size, 2, 3))
        np.testing.assert_allclose(pw.displacement(X, t), ref, rtol=0, atol=1e-15)


REFUSALS = [
    (dict(wave="sv", angle=45.0, postcritical=True), "no horizontal"),
    (dict(wave="sv", angle=40.0), "35.2644"),
    (dict(wave="p", angle=0.0, component="horizontal"), "no horizontal"),
    (dict(wave="sh", angle=20.0, component="vertical"), "no vertical"),
    (dict(wave="vertical_s", component="transverse"), "no transverse"),
    (dict(wave="p", angle=-1.0), "[0, 90)"),
    (dict(wave="p", angle=90.0), "[0, 90)"),
    (dict(wave="sh", angle=float("nan")), "[0, 90)"),
    (dict(wave="rayleigh", angle=10.0), "not used"),
    (dict(wave="p", angle=10.0, cs=0.0), "cs must be"),
    (dict(wave="p", angle=10.0, cp=-5.0), "cp must be"),
    (dict(wave="p", angle=10.0, cp=1.1 * CS), "Poisson"),
    (dict(wave="p", angle=10.0, cs=float("inf")), "cs must be"),
    (dict(wave="love"), "unknown wave"),
    (dict(wave="p", control="outcrop"), "unknown control"),
    (dict(wave="p", component="radial"), "unknown component"),
    (dict(wave="p", rho=-1.0), "rho"),
    (dict(wave="p", x0=(0.0, 0.0, 1.0)), "x0"),
    (dict(wave="p", azimuth=float("inf")), "azimuth"),
    (dict(wave="sv", angle=50.0, postcritical=True, g=ff.Sin4Pulse(0.2)), "hilbert="),
]


@pytest.mark.parametrize("kw,msg", REFUSALS, ids=[m for _, m in REFUSALS])
def test_refusals(kw, msg):
    """Each invalid input raises FreeFieldError with a one-line message naming the problem."""
    args = dict(cs=CS, cp=cp_of(0.25), g=ff.Ricker(5.0))
    args.update(kw)
    with pytest.raises(ff.FreeFieldError) as ei:
        ff.PlaneWave(args.pop("wave"), args.pop("cs"), args.pop("cp"), args.pop("g"), **args)
    assert msg in str(ei.value) and "\n" not in str(ei.value)


def test_refusals_at_evaluation():
    """stress without rho, points above the surface, bad time grid for hilbert_of."""
    pw = ff.PlaneWave("p", CS, cp_of(0.25), ff.Ricker(5.0), angle=10.0)
    for call, msg in ((lambda: pw.stress(np.zeros((1, 3)), 0.0), "rho"),
                      (lambda: pw.displacement(np.array([[0, 0, 1.0]]), 0.0), "above"),
                      (lambda: pw.displacement(np.zeros((2, 2)), 0.0), "(n, 3)"),
                      (lambda: ff.hilbert_of(ff.Ricker(5.0), np.r_[0:1:0.1, 1.5]), "uniform"),
                      (lambda: ff.reflection_coefficients("rayleigh", 0, CS, 400.0), "wave must")):
        with pytest.raises(ff.FreeFieldError) as ei:
            call()
        assert msg in str(ei.value) and "\n" not in str(ei.value)
