r"""Space integration of the lag kernels over nine-node elements (paper s.2).

For a collocation point xi and a (virtual) element e, every lag l gets

  U^l_e[a] = int_e U^l(x - xi) N_a dGamma,   P^l_e[a] = int_e P^l(x - xi, n) N_a dGamma.

Regular integration: each element side is divided into ``ns`` equal parts in
natural coordinates, ``ng x ng`` Gauss points per subdivision (paper: 2x2).
Causality: a subdivision is skipped for lags whose wave shell cannot reach
its bounding sphere, and at each Gauss point only the lags with a non-zero
kernel are evaluated. This skip is exact (it drops only exact zeros); unlike
the paper's midpoint rule it does not decide a whole subdivision by its
midpoint, the piecewise kernel is evaluated at every Gauss point.
Near the collocation point the subdivision is refined:
ns = clamp(ceil(near_factor * h / d), ns_base, ns_max), d the distance from
xi to the element's bounding sphere.

Singular case (xi is a node of e): for r < c_s dt, U^1 and P^1 equal the
static Kelvin kernels exactly, and lags >= 2 vanish there (kernels module).
So the lag-1 kernels are split into static + (dynamic - static); the
remainder is regular (zero near xi) and integrated as above, the static part
by polar coordinates around xi in the parameter plane: U_static (weakly
singular, cancelled by the polar Jacobian) by Gauss-Legendre in rho and
theta; P_static (strongly singular) as a Cauchy principal value with
Guiggiani's direct method (Guiggiani & Gigante 1990; Guiggiani 1992):

  CPV = int_theta { int_0^rhohat [F(rho,th) - F_{-1}(th)/rho] drho
                    + F_{-1}(th) ln(rhohat(th) |A(th)| / h_ref) } dth,
  F_{-1}(th) = K(A/|A|, n_c) J_c / |A|^2 (only for the node at xi),

with A(th) = dx/dxi cos th + dx/deta sin th at xi and K the r^-2 coefficient
of Kelvin's traction kernel. Convergence under increasing order is tested.
h_ref (the smallest element size of the mesh) cancels at interior nodes; at a
node on the truncation edge of an open surface the CPV does not exist (the
mesh ends, the half-space does not), and measuring the exclusion radius in
units of h_ref is our convention there: results no longer depend on the
length unit.
The free term c_lk = delta_lk/2 (smooth surface point) is added by the
assembler.
"""
import math

import numpy as np
from numba import njit

from .kernels import ab1, ab2_fast, kelvin_u, kelvin_p
from .packs import DT, CP, CS, RHO, NU, TOFF
from .simd import acc4

# natural coordinates of the nine nodes and 1D Lagrange indices (quad9 module)
_NXI = np.array([-1., 1., 1., -1., 0., 1., 0., -1., 0.])
_NET = np.array([-1., -1., 1., 1., -1., 0., 1., 0., 0.])
_IX = np.array([0, 2, 2, 0, 1, 2, 1, 0, 1])
_IE = np.array([0, 0, 2, 2, 0, 1, 2, 1, 1])


@njit(cache=True)
def shape9(xi, eta, N, d1, d2):
    lx0 = 0.5 * xi * (xi - 1.0); lx1 = 1.0 - xi * xi; lx2 = 0.5 * xi * (xi + 1.0)
    le0 = 0.5 * eta * (eta - 1.0); le1 = 1.0 - eta * eta; le2 = 0.5 * eta * (eta + 1.0)
    dx0 = xi - 0.5; dx1 = -2.0 * xi; dx2 = xi + 0.5
    de0 = eta - 0.5; de1 = -2.0 * eta; de2 = eta + 0.5
    lx = (lx0, lx1, lx2); le = (le0, le1, le2); dx = (dx0, dx1, dx2); de = (de0, de1, de2)
    for a in range(9):
        ix = _IX[a]; ie = _IE[a]
        N[a] = lx[ix] * le[ie]
        d1[a] = dx[ix] * le[ie]
        d2[a] = lx[ix] * de[ie]


@njit(cache=True)
def point_geometry(X, xi, eta, N, d1, d2, x, jn):
    """x = sum N_a X_a, jn = dx/dxi x dx/deta; returns J = |jn|."""
    shape9(xi, eta, N, d1, d2)
    t1 = np.zeros(3); t2 = np.zeros(3)
    for k in range(3):
        s = 0.0; s1 = 0.0; s2 = 0.0
        for a in range(9):
            s += N[a] * X[a, k]; s1 += d1[a] * X[a, k]; s2 += d2[a] * X[a, k]
        x[k] = s; t1[k] = s1; t2[k] = s2
    jn[0] = t1[1] * t2[2] - t1[2] * t2[1]
    jn[1] = t1[2] * t2[0] - t1[0] * t2[2]
    jn[2] = t1[0] * t2[1] - t1[1] * t2[0]
    return math.sqrt(jn[0] ** 2 + jn[1] ** 2 + jn[2] ** 2)


@njit(cache=True)
def _sub_sphere(X, cx, cy, hh, N, d1, d2, xc, jn, pt):
    """Centre (into xc) and radius of a sphere bounding a subdivision."""
    point_geometry(X, cx, cy, N, d1, d2, xc, jn)
    rad = 0.0
    for i in range(-1, 2):
        for j in range(-1, 2):
            if i == 0 and j == 0:
                continue
            point_geometry(X, cx + i * hh, cy + j * hh, N, d1, d2, pt, jn)
            d = math.sqrt((pt[0] - xc[0]) ** 2 + (pt[1] - xc[1]) ** 2 + (pt[2] - xc[2]) ** 2)
            rad = max(rad, d)
    return 1.1 * rad + 1e-12


@njit(cache=True, inline="always")
def _ptensor(g, n, gn, r, A, B, dA, dB, lam, mu, out):
    """Traction tensor of A d_lk + B g_l g_k (kernels.traction_from_ab),
    regrouped as a1 g_l n_k + a2 (n_l g_k + gn d_lk) + a3 gn g_l g_k."""
    br = B / r
    a1 = lam * (dA + dB + 2.0 * br) + 2.0 * mu * br
    a2 = mu * (dA + br)
    a3 = gn * mu * (2.0 * dB - 4.0 * br)
    for l in range(3):
        for k in range(3):
            out[l, k] = a1 * g[l] * n[k] + a2 * n[l] * g[k] + a3 * g[l] * g[k]
        out[l, l] += a2 * gn


@njit(cache=True, inline="always")
def _time_samples(S2, S1, r, ir, plo, phi, phys, want_u, want_p=True):
    """At a point at distance r (ir = 1 / r), rows j - (plo - 2) of S2 = (A, B, dA, dB) of the
    twice-integrated response at the kernel times T = j dt + toff, j = plo - 2 .. phi (zero for T <= 0;
    not formed without ``want_p``), and with ``want_u`` of S1 = (A, B) of the once-integrated one: the
    samples whose differences are the lags plo..phi (``integrate_pair``, ``integrate_plane``). ``phys``:
    the material and the step (``packs.wave``)."""
    dt, toff, alpha, beta = phys[DT], phys[TOFF], phys[CP], phys[CS]
    ia = 1.0 / alpha
    ib = 1.0 / beta
    for j in range(plo - 2, phi + 1):
        jj = j - (plo - 2)
        t = j * dt + toff
        if t <= 0.0:
            S2[jj, 0] = 0.0; S2[jj, 1] = 0.0; S2[jj, 2] = 0.0; S2[jj, 3] = 0.0
            S1[jj, 0] = 0.0; S1[jj, 1] = 0.0
        else:
            if want_p:
                a2, b2, da2, db2 = ab2_fast(r, ir, t, ia, ib)
                S2[jj, 0] = a2; S2[jj, 1] = b2; S2[jj, 2] = da2; S2[jj, 3] = db2
            if want_u:
                a1, b1 = ab1(r, t, alpha, beta)
                S1[jj, 0] = a1; S1[jj, 1] = b1


@njit(cache=True, inline="always")
def _lag_differences(S2, jj, fdt):
    """(A, B, dA, dB) of lag row jj: the second differences of ``_time_samples``' twice-integrated
    samples times fdt (``integrate_pair``, ``integrate_plane``)."""
    A = (S2[jj, 0] - 2.0 * S2[jj - 1, 0] + S2[jj - 2, 0]) * fdt
    B = (S2[jj, 1] - 2.0 * S2[jj - 1, 1] + S2[jj - 2, 1]) * fdt
    dA = (S2[jj, 2] - 2.0 * S2[jj - 1, 2] + S2[jj - 2, 2]) * fdt
    dB = (S2[jj, 3] - 2.0 * S2[jj - 1, 3] + S2[jj - 2, 3]) * fdt
    return A, B, dA, dB


@njit(cache=True, inline="always")
def _sub_lags(cen, rad, xc, lo, hi, ia, ib, toff, dt):
    """The lags lo..hi whose wave shell can reach a subdivision (centre cen, radius rad) from xc:
    (slo, shi), slo > shi for none."""
    dc = math.sqrt((cen[0] - xc[0]) ** 2 + (cen[1] - xc[1]) ** 2 + (cen[2] - xc[2]) ** 2)
    dmin = max(dc - rad, 0.0)
    dmax = dc + rad
    slo = max(lo, int(math.floor((dmin * ia - toff) / dt)) + 1)
    shi = min(hi, int(math.floor((dmax * ib - toff) / dt)) + 2)
    return slo, shi


@njit(cache=True, inline="always")
def _seen_from(X, xc, xi, eta, N, d1, d2, x, jn, g, n):
    """The point (xi, eta) of element X seen from xc: shape functions into N, g = x - xc, the unit
    normal n; returns (the Jacobian J, r = |g|)."""
    J = point_geometry(X, xi, eta, N, d1, d2, x, jn)
    r = 0.0
    for k in range(3):
        g[k] = x[k] - xc[k]
        r += g[k] * g[k]
        n[k] = jn[k] / J
    return J, math.sqrt(r)


@njit(cache=True, inline="always")
def _gauss_point(X, xc, xi, eta, wq, N, d1, d2, x, jn, g, n):
    """The Gauss point (xi, eta) of element X seen from xc: shape functions into N, the unit vector g
    from xc and the unit normal n; returns (weight wq J, distance r, g . n); r < 1e-14: the point is xc
    (g, n and g . n not formed)."""
    J, r = _seen_from(X, xc, xi, eta, N, d1, d2, x, jn, g, n)
    w = wq * J
    if r < 1e-14:
        return w, r, 0.0
    ir = 1.0 / r
    for k in range(3):
        g[k] *= ir
    gn = g[0] * n[0] + g[1] * n[1] + g[2] * n[2]
    return w, r, gn


@njit(cache=True, inline="always")
def _spread(B, li, t, w, N, skip_zero):
    """B[li, c] += t w N_c (c = 0..8), entry by entry; with ``skip_zero`` an entry whose t w is zero adds
    nothing."""
    for a in range(3):
        for b in range(3):
            tw = t[a, b] * w
            if skip_zero and tw == 0.0:
                continue
            for c in range(9):
                B[li, c, a, b] += tw * N[c]


@njit(cache=True, inline="always")
def _add_u(Ub, li, jj, S1, s4, g, w, N, subtract1, ku, ut):
    """Ub[li] += the displacement tensor of lag row jj (the first difference of ``_time_samples``'
    once-integrated samples; minus Kelvin's static ku where ``subtract1``) times w N."""
    A1 = (S1[jj, 0] - S1[jj - 1, 0]) * s4
    B1 = (S1[jj, 1] - S1[jj - 1, 1]) * s4
    for a in range(3):
        for b in range(3):
            ut[a, b] = B1 * g[a] * g[b]
        ut[a, a] += A1
    if subtract1:
        ut -= ku
    _spread(Ub, li, ut, w, N, False)


@njit(cache=True, inline="always")
def _add_lags(Ub, Pb, samples, lags, pt_geo, mat, work, want_u):
    """The lags plo..phi of one Gauss point into Pb (and with ``want_u`` Ub): samples = (S2, S1) of
    ``_time_samples``, lags = (plo, phi, lo, subtract), pt_geo = (g, n, g . n, r, w, N), mat = (lam, mu,
    s4, s4 / dt), work = (ku, kp, pt, ut): Kelvin's static (ku, kp) subtracted from lag 1 where
    ``subtract``, and scratch. Returns the (point, lag) evaluations: phi - plo + 1."""
    S2, S1 = samples
    plo, phi, lo, subtract = lags
    g, n, gn, r, w, N = pt_geo
    lam, mu, s4, fdt = mat
    ku, kp, pt, ut = work
    for l in range(plo, phi + 1):
        jj = l - (plo - 2)
        A, B, dA, dB = _lag_differences(S2, jj, fdt)
        if A == 0.0 and B == 0.0 and dA == 0.0 and dB == 0.0 and not (subtract and l == 1):
            continue
        li = l - lo
        _ptensor(g, n, gn, r, A, B, dA, dB, lam, mu, pt)
        if subtract and l == 1:
            pt -= kp
        _spread(Pb, li, pt, w, N, True)
        if want_u:
            _add_u(Ub, li, jj, S1, s4, g, w, N, subtract and l == 1, ku, ut)
    return phi - plo + 1


@njit(cache=True)
def integrate_pair(xc, X, sing, ns, lo, hi, phys, gq, gw, Ub, Pb, want_u):
    """Regular (subdivided Gauss) integration of lags lo..hi into Ub, Pb.

    ``phys``: the material and the step (``packs.wave``). Lag l is evaluated at the kernel time
    T = l dt + toff (toff in [0, dt): a lag matrix at a non-integer lag time, for the interpolation).
    Ub, Pb: (hi-lo+1, 9, 3, 3), accumulated (caller zeroes). ``sing`` >= 0:
    xi is node ``sing`` of the element; the static kernels are subtracted
    from lag 1 (their singular integral is added by ``singular_static``).
    The traction is linear in (A, B, A', B') at a fixed point, so the second
    time difference is taken on these four scalars and one tensor is formed
    per lag. Returns the number of (point, lag) kernel evaluations.
    """
    dt, alpha, beta, rho, nu, toff = phys[DT], phys[CP], phys[CS], phys[RHO], phys[NU], phys[TOFF]
    mu = rho * beta * beta
    s4 = 1.0 / (4.0 * math.pi * rho)
    mat = (rho * alpha * alpha - 2.0 * mu, mu, s4, s4 / dt)
    ng = gq.shape[0]
    h = 2.0 / ns
    N = np.zeros(9); d1 = np.zeros(9); d2 = np.zeros(9)
    x = np.zeros(3); jn = np.zeros(3); cen = np.zeros(3); tmp = np.zeros(3)
    g = np.zeros(3); n = np.zeros(3)
    S2 = np.zeros((hi - lo + 4, 4))
    S1 = np.zeros((hi - lo + 4, 2))
    work = (np.zeros((3, 3)), np.zeros((3, 3)), np.zeros((3, 3)), np.zeros((3, 3)))    # ku, kp, pt, ut
    ia = 1.0 / alpha
    ib = 1.0 / beta
    subtract = sing >= 0 and lo == 1
    nev = 0
    for si in range(ns):
        for sj in range(ns):
            cx = -1.0 + h * (si + 0.5)
            cy = -1.0 + h * (sj + 0.5)
            rad = _sub_sphere(X, cx, cy, 0.5 * h, N, d1, d2, cen, jn, tmp)
            slo, shi = _sub_lags(cen, rad, xc, lo, hi, ia, ib, toff, dt)
            if sing >= 0:
                slo = lo  # lag 1 carries the static subtraction
            if slo > shi:
                continue
            for p in range(ng):
                for q in range(ng):
                    w, r, gn = _gauss_point(X, xc, cx + 0.5 * h * gq[p], cy + 0.5 * h * gq[q],
                                            gw[p] * gw[q] * 0.25 * h * h, N, d1, d2, x, jn, g, n)
                    if r < 1e-14:
                        continue
                    plo = max(slo, int(math.floor((r * ia - toff) / dt)) + 1)
                    phi = min(shi, int(math.floor((r * ib - toff) / dt)) + 2)
                    if subtract:
                        plo = 1
                    if plo > phi:
                        continue
                    _time_samples(S2, S1, r, 1.0 / r, plo, phi, phys, want_u)
                    if subtract:
                        kelvin_u(g, r, nu, mu, work[0])
                        kelvin_p(g, n, r, nu, work[1])
                    nev += _add_lags(Ub, Pb, (S2, S1), (plo, phi, lo, subtract), (g, n, gn, r, w, N), mat, work,
                                     want_u)
    return nev


@njit(cache=True, inline="always")
def _polar_ray(X, node, ray, rule, elastic, out, scr):
    """One direction of ``singular_static``'s polar rule, ray = (th, its weight wth, rhat: the distance
    from the node to the side along it): the Gauss points in rho (rule = (order_r, gr, gwr)) into
    out = (Us, Ps) and the CPV's -F_{-1}/rho and log terms into Ps[c]; elastic = (nu, mu, h_ref: the
    CPV's length unit). node = (c, its natural coordinates, x, unit normal, Jacobian and tangents
    there); scr: scratch."""
    c, xc0, ec0, xs, nc, Jc, t1, t2 = node
    th, wth, rhat = ray
    nu, mu, h_ref = elastic
    Us, Ps = out
    order_r, gr, gwr = rule
    N, d1, d2, x, jn, g, n, ahat, ku, kp, k0 = scr
    ct = math.cos(th); st = math.sin(th)
    Aabs = 0.0
    for k in range(3):
        ahat[k] = t1[k] * ct + t2[k] * st
        Aabs += ahat[k] ** 2
    Aabs = math.sqrt(Aabs)
    for k in range(3):
        ahat[k] /= Aabs
    kelvin_p(ahat, nc, 1.0, nu, k0)
    fm1 = Jc / (Aabs * Aabs)
    for ir in range(order_r):
        rho_ = 0.5 * rhat * (1.0 + gr[ir])
        wr = 0.5 * rhat * gwr[ir]
        J, r = _seen_from(X, xs, xc0 + rho_ * ct, ec0 + rho_ * st, N, d1, d2, x, jn, g, n)
        for k in range(3):
            g[k] /= r
        kelvin_u(g, r, nu, mu, ku)
        kelvin_p(g, n, r, nu, kp)
        wgt = wth * wr * J * rho_
        for a in range(9):
            for p in range(3):
                for q in range(3):
                    Us[a, p, q] += wgt * ku[p, q] * N[a]
                    Ps[a, p, q] += wgt * kp[p, q] * N[a]
        for p in range(3):
            for q in range(3):
                Ps[c, p, q] -= wth * wr * fm1 * k0[p, q] / rho_
    lg = math.log(rhat * Aabs / h_ref)
    for p in range(3):
        for q in range(3):
            Ps[c, p, q] += wth * fm1 * k0[p, q] * lg


@njit(cache=True)
def singular_static(X, c, order_r, order_t, gr, gwr, gt, gwt, nu, mu, Us, Ps, h_ref):
    """Static Kelvin integrals over an element with xi at its node ``c``.

    Polar coordinates around the node in the parameter square, one triangle
    per square side not containing the node. Us, Ps: (9, 3, 3), accumulated.
    The exclusion radius of the CPV is measured in units of ``h_ref`` (one
    length for the whole mesh): around an interior node the constant cancels
    over the full circle; at a node on the truncation edge of an open surface
    the CPV does not exist and this fixes the result independently of the
    length unit (the convention of the module docstring).
    """
    xc0 = _NXI[c]
    ec0 = _NET[c]
    N = np.zeros(9); d1 = np.zeros(9); d2 = np.zeros(9)
    xs = np.zeros(3); jnc = np.zeros(3)
    scr = (N, d1, d2, np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3), np.zeros((3, 3)),
           np.zeros((3, 3)), np.zeros((3, 3)))
    Jc = point_geometry(X, xc0, ec0, N, d1, d2, xs, jnc)
    nc = jnc / Jc
    t1 = np.zeros(3); t2 = np.zeros(3)
    for k in range(3):
        for a in range(9):
            t1[k] += d1[a] * X[a, k]
            t2[k] += d2[a] * X[a, k]
    node = (c, xc0, ec0, xs, nc, Jc, t1, t2)
    corners = np.array([[-1., -1.], [1., -1.], [1., 1.], [-1., 1.]])
    for e in range(4):
        v1 = corners[e]
        v2 = corners[(e + 1) % 4]
        # distance from the node to the side's line
        ex = v2[0] - v1[0]; ey = v2[1] - v1[1]
        L = math.sqrt(ex * ex + ey * ey)
        nx_ = ey / L; ny_ = -ex / L              # outward normal of the side
        dp = (v1[0] - xc0) * nx_ + (v1[1] - ec0) * ny_
        if dp < 1e-12:
            continue
        th1 = math.atan2(v1[1] - ec0, v1[0] - xc0)
        th2 = math.atan2(v2[1] - ec0, v2[0] - xc0)
        if th2 < th1:
            th2 += 2.0 * math.pi
        thp = math.atan2(ny_, nx_)
        for it in range(order_t):
            th = 0.5 * (th1 + th2) + 0.5 * (th2 - th1) * gt[it]
            _polar_ray(X, node, (th, 0.5 * (th2 - th1) * gwt[it], dp / math.cos(th - thp)), (order_r, gr, gwr),
                       (nu, mu, h_ref), (Us, Ps), scr)


# ---------------------------------------------------------------------------
# Elements in the plane z = 0 (every soil surface petsc_ssi accepts, and its symmetry images): the
# geometry of an element's Gauss points does not depend on the collocation point, and with g_z = 0,
# n = (0, 0, +-1), g . n = 0 the traction kernel keeps four entries and the displacement kernel five
# (bsr.PATTERNS). ``plane_points`` computes the geometry once per element; ``integrate_plane`` is
# ``integrate_pair`` for a regular pair of the plane, the same operations on every kept entry in the
# same order minus the terms that are exact zeros there, so the same bits
# (tests/bem/test_plane_kernel.py).

@njit(cache=True)
def plane_points(X, ns, gq, gw, sub, pts, Ntab):
    """The quadrature of ``integrate_pair`` for an element X in the plane z = 0, point by point as it
    computes it: sub[s] = (centre, radius) of subdivision s = si ns + sj (its bounding sphere),
    pts[k] = (x, y, Gauss weight x subdivision area x Jacobian, n_z) and Ntab[k] the nine shape
    functions at Gauss point k = s ng^2 + p ng + q (the same for every element)."""
    ng = gq.shape[0]
    h = 2.0 / ns
    N = np.zeros(9); d1 = np.zeros(9); d2 = np.zeros(9)
    x = np.zeros(3); jn = np.zeros(3); cen = np.zeros(3); tmp = np.zeros(3)
    k = 0
    for si in range(ns):
        for sj in range(ns):
            cx = -1.0 + h * (si + 0.5)
            cy = -1.0 + h * (sj + 0.5)
            rad = _sub_sphere(X, cx, cy, 0.5 * h, N, d1, d2, cen, jn, tmp)
            s = si * ns + sj
            sub[s, 0] = cen[0]; sub[s, 1] = cen[1]; sub[s, 2] = cen[2]; sub[s, 3] = rad
            for p in range(ng):
                for q in range(ng):
                    xi = cx + 0.5 * h * gq[p]
                    eta = cy + 0.5 * h * gq[q]
                    J = point_geometry(X, xi, eta, N, d1, d2, x, jn)
                    pts[k, 0] = x[0]
                    pts[k, 1] = x[1]
                    pts[k, 2] = gw[p] * gw[q] * 0.25 * h * h * J
                    pts[k, 3] = jn[2] / J
                    for c in range(9):
                        Ntab[k, c] = N[c]
                    k += 1


@njit(cache=True, inline="always")
def _plane_lags(Pf, Uf, S2, S1, plo, phi, lo, pt_geo, mat, Nk, want_u):
    """``_add_lags`` of a point of the plane: lags plo..phi into the flat patterns' P (four entries) and,
    with ``want_u``, U (five), both flat (C order, (lags, 9, 4) and (lags, 9, 5)), four entries at a time
    (``simd.acc4``); pt_geo = (g_x, g_y, n_z, r, w), Nk the shape functions. Returns the evaluations."""
    g0, g1, nz, r, w = pt_geo
    lam, mu, s4, fdt = mat
    for l in range(plo, phi + 1):
        jj = l - (plo - 2)
        A, B, dA, dB = _lag_differences(S2, jj, fdt)
        if A == 0.0 and B == 0.0 and dA == 0.0 and dB == 0.0:
            continue
        li = l - lo
        br = B / r
        a1 = lam * (dA + dB + 2.0 * br) + 2.0 * mu * br
        a2 = mu * (dA + br)
        v0 = a1 * g0 * nz * w
        v1 = a1 * g1 * nz * w
        v2 = a2 * nz * g0 * w
        v3 = a2 * nz * g1 * w
        b = li * 36                     # P[li, c, 0:4] += (v0, v1, v2, v3) N_c, 4-wide (simd.acc4)
        for c in range(9):
            acc4(Pf, b + 4 * c, v0, v1, v2, v3, Nk[c])
        if want_u:
            _plane_u(Uf, li, (S1[jj, 0] - S1[jj - 1, 0]) * s4, (S1[jj, 1] - S1[jj - 1, 1]) * s4, g0, g1, w, Nk)
    return phi - plo + 1


@njit(cache=True, inline="always")
def _plane_u(Uf, li, A1, B1, g0, g1, w, Nk):
    """U[li, c, 0:5] += the flat G pattern's (xx, xy, yx, yy, zz) of the displacement tensor B1 g_a g_b + A1 d_ab
    times w N_c (``_plane_lags``, ``_plane_lags_u``)."""
    u0 = (B1 * g0 * g0 + A1) * w
    u1 = B1 * g0 * g1 * w
    u2 = B1 * g1 * g0 * w
    u3 = (B1 * g1 * g1 + A1) * w
    u4 = A1 * w
    b = li * 45
    for c in range(9):
        Nc = Nk[c]
        acc4(Uf, b + 5 * c, u0, u1, u2, u3, Nc)
        Uf[b + 5 * c + 4] += u4 * Nc


@njit(cache=True, inline="always")
def _plane_lags_u(Uf, S1, plo, phi, lo, pt_geo, s4, Nk):
    """``_plane_lags``' U alone (``integrate_plane`` without ``want_p``: no twice-integrated samples), the same
    values bit for bit. ``_plane_lags`` skips a lag whose twice-integrated differences are all exactly zero;
    inside the wave window plo..phi every lag's three kernel times overlap the time between the P and S
    arrivals, where that response is not linear, so it does not happen (tests/bem/test_plane_kernel.py compares
    the two bit for bit); here a lag with nothing to add is skipped.
    Returns the evaluations."""
    g0, g1, nz, r, w = pt_geo
    for l in range(plo, phi + 1):
        jj = l - (plo - 2)
        A1 = (S1[jj, 0] - S1[jj - 1, 0]) * s4
        B1 = (S1[jj, 1] - S1[jj - 1, 1]) * s4
        if A1 == 0.0 and B1 == 0.0:
            continue
        _plane_u(Uf, l - lo, A1, B1, g0, g1, w, Nk)
    return phi - plo + 1


@njit(cache=True)
def integrate_plane(xc, sub, pts, Ntab, ng2, lo, hi, phys, P, U, want_u, want_p):
    """``integrate_pair`` of a regular pair (``sing`` < 0) whose collocation point xc and element lie in
    the plane z = 0, the element given by ``plane_points`` (sub, pts, Ntab; ng2 Gauss points a
    subdivision), ``phys`` the material and the step (``packs.wave``). Accumulates lags lo..hi into
    P[l - lo, node, j] (the entries of bsr's flat H pattern: (x,z), (y,z), (z,x), (z,y)) and, with
    ``want_u``, U[l - lo, node, j] (flat G: (x,x), (x,y), (y,x), (y,y), (z,z)); without ``want_p`` (and
    with ``want_u``) U alone, P untouched: the H kernels are not formed (``_plane_lags_u``); the caller zeroes them
    (C-contiguous: P (>= nl, 9, 4), U (>= nl, 9, 5), updated four entries at a time by ``simd.acc4``).
    Returns the kernel evaluations.

    With g_z = 0 and n = (0, 0, n_z), integrate_pair's traction tensor a1 g_l n_k + a2 n_l g_k +
    a3 gn g_l g_k (+ a2 gn d_lk) is (a1 g_l) n_z at (l, z), (a2 n_z) g_k at (z, k) and exact zeros
    elsewhere (each kept entry is its first product plus exact zeros), and the displacement tensor
    B1 g_a g_b + A1 d_ab keeps the in-plane block and A1 at (z, z): the same values, bit for bit."""
    dt, alpha, beta, rho, toff = phys[DT], phys[CP], phys[CS], phys[RHO], phys[TOFF]
    mu = rho * beta * beta
    s4 = 1.0 / (4.0 * math.pi * rho)
    mat = (rho * alpha * alpha - 2.0 * mu, mu, s4, s4 / dt)
    S2 = np.zeros((hi - lo + 4, 4))
    S1 = np.zeros((hi - lo + 4, 2))
    ia = 1.0 / alpha
    ib = 1.0 / beta
    nev = 0
    if P.shape[1] != 9 or P.shape[2] != 4 or U.shape[1] != 9 or U.shape[2] != 5:
        raise ValueError("integrate_plane: P must be (lags, 9, 4) and U (lags, 9, 5)")
    Pf = P.reshape(P.size)              # (contiguous: the vector updates address them flat)
    Uf = U.reshape(U.size)
    for s in range(sub.shape[0]):
        slo, shi = _sub_lags(sub[s], sub[s, 3], xc, lo, hi, ia, ib, toff, dt)
        if slo > shi:
            continue
        for k in range(s * ng2, (s + 1) * ng2):
            g0 = pts[k, 0] - xc[0]
            g1 = pts[k, 1] - xc[1]
            r = math.sqrt(g0 * g0 + g1 * g1)
            if r < 1e-14:
                continue
            ir = 1.0 / r
            plo = max(slo, int(math.floor((r * ia - toff) / dt)) + 1)
            phi = min(shi, int(math.floor((r * ib - toff) / dt)) + 2)
            if plo > phi:
                continue
            geo = (g0 * ir, g1 * ir, pts[k, 3], r, pts[k, 2])
            if want_p or not want_u:
                _time_samples(S2, S1, r, ir, plo, phi, phys, want_u)
                nev += _plane_lags(Pf, Uf, S2, S1, plo, phi, lo, geo, mat, Ntab[k], want_u)
            else:
                _time_samples(S2, S1, r, ir, plo, phi, phys, True, False)
                nev += _plane_lags_u(Uf, S1, plo, phi, lo, geo, s4, Ntab[k])
    return nev
