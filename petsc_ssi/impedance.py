"""``petsc-ssi impedance``: dynamic stiffness (impedance) functions of a surface foundation from
one transient BEM run per mode (issue 12, item 2; a first version).

For each mode the foundation region (-ssi_disp_group, a rigid footing) is given a rigid motion
h(t) [u0 + theta0 x (x - x_ref)] with h a smooth step (``smoothstep``: (1 - cos(pi t/t0))/2 up to
t0 = -ssi_impedance_rise, then held), and the run records the region's force or moment
(``bem/resultants.py``). Since h and the resultant R both settle, their first differences are
pulses and

    K(omega) = FFT(dR) / FFT(dh) * exp(i omega dt/2)

(zero-padded to 8x the next power of two; the phase factor moves the traction, a mean over
(t_{n-1}, t_n], to t_n where h is sampled). K0 = R/h at the last step (the static stiffness, once
the response has settled), and K = K0 [k(a0) + i a0 c(a0)], a0 = omega B / c_s with B the
footing's half-width in x (-ssi_impedance_B, default from the region). Modes and the symmetry
planes each allows (a footing symmetric about x = 0 and y = 0, x_ref = the origin):

    vertical    u0 = (0, 0, 1)    x=sym,  y=sym       horizontal  u0 = (1, 0, 0)   x=anti, y=sym
    rocking     theta0 = (0,1,0)  x=anti, y=sym       torsion     theta0 = (0,0,1) x=anti, y=anti

(-ssi_impedance_symmetry 0 meshes the whole surface instead). Outputs, from -ssi_output's stem:
<stem>-<mode>.h5 (each run), <stem>-impedance.csv (a0, K, k, c per mode), <stem>-impedance.png
(k and c against a0, with each mode's high-frequency dashpot limit: rho c_p A, rho c_s A,
rho c_p I_y, rho c_s J). The trusted band: a0 >= 4 pi B / (c_s T) (two frequency bins of the
record T), a0 <= pi B / (2 h) (four elements per shear wavelength) and omega dt <= 0.3, i.e.
a0 <= 0.3 B / (c_s dt): the time discretisation's error grows with omega dt (on the square footing
of runs/impedance/dt_study.py, k at a0 = 2.5 is 1.23, 0.83, 0.73 with dt = 1.6, 0.8, 0.4 ms, and
converges as dt falls); the command prints the band.
Not yet: the published dynamic curves as references, the coupling terms, the hex8 path.
"""
import math
import os

import numpy as np

from .options import register
from .petsc import init, SSIError, printf, warn

G = "impedance"
register("impedance_modes", "str", "vertical,horizontal,rocking,torsion", "", "petsc-ssi impedance: the modes to "
         "run (vertical, horizontal, rocking, torsion)", G)
register("impedance_rise", "real", 0.0, "s", "petsc-ssi impedance: rise time t0 of the smooth step (0: 4 dt)", G,
         validator=lambda v: None if v >= 0 else "must be >= 0")
register("impedance_B", "real", 0.0, "m", "petsc-ssi impedance: half-width B of the footing for a0 = omega B / c_s "
         "(0: half the region's extent in x)", G, validator=lambda v: None if v >= 0 else "must be >= 0")
register("impedance_symmetry", "bool", True, "", "petsc-ssi impedance: use the symmetry planes each mode allows", G)

AMP = 1e-6
MODES = {  # name: (option, motion, symmetry, resultant, component, radiation speed, dashpot area measure)
    "vertical": ("disp_value", "0,0,1", "x=sym,y=sym", "force", 2, "cp", "A"),
    "horizontal": ("disp_value", "1,0,0", "x=anti,y=sym", "force", 0, "cs", "A"),
    "rocking": ("disp_rotation", "0,1,0", "x=anti,y=sym", "moment", 1, "cp", "Iy"),
    "torsion": ("disp_rotation", "0,0,1", "x=anti,y=anti", "moment", 2, "cs", "J"),
}


def step_spectrum(s, dt, traction=False, pad=8):
    """(omega, S(omega)): the FFT of the first differences of a series s_n, n = 1..K, that starts
    from rest and settles (s_0 = 0), zero-padded to ``pad`` times the next power of two. A traction
    resultant (``traction``: the mean over (t_{n-1}, t_n]) is moved by half a step to t_n, where
    displacements are sampled: times exp(i omega dt/2)."""
    s = np.asarray(s, dtype=float)
    n = pad * (1 << int(math.ceil(math.log2(max(len(s), 2)))))
    om = 2 * np.pi * np.fft.rfftfreq(n, dt)
    S = np.fft.rfft(np.diff(np.r_[0.0, s], axis=0), n, axis=0)
    if traction:
        S = S * np.exp(1j * om * dt / 2).reshape((-1,) + (1,) * (S.ndim - 1))
    return om, S


def spectrum(R, h, dt, pad=8):
    """(omega, K(omega)) from the resultant R_n and the motion factor h_n, n = 1..K (module docstring)."""
    om, SR = step_spectrum(R, dt, traction=True, pad=pad)
    return om, SR / step_spectrum(h, dt, pad=pad)[1]


def rigid_fit(x, u, x_ref=(0.0, 0.0, 0.0)):
    """Least-squares rigid motion of nodal displacements: u_i ~ t + theta x (x_i - x_ref).

    x (n, 3) node positions, u (..., n, 3) displacements (any leading axes, e.g. steps). Returns
    (t (..., 3), theta (..., 3), residual): the translation, the small rotation about x_ref and
    max |u - fit| / max |u| (how rigid the motion is). For a foundation that is not rigid (a
    flexible block, a slab) this is the rigid-body part of its interface motion."""
    r = np.asarray(x, dtype=float) - np.asarray(x_ref, dtype=float)
    u = np.asarray(u, dtype=float)
    n = len(r)
    A = np.zeros((n, 3, 6))
    A[:, :, :3] = np.eye(3)
    A[:, 0, 4], A[:, 0, 5] = r[:, 2], -r[:, 1]      # theta x r = (th_y r_z - th_z r_y, ...)
    A[:, 1, 3], A[:, 1, 5] = -r[:, 2], r[:, 0]
    A[:, 2, 3], A[:, 2, 4] = r[:, 1], -r[:, 0]
    A = A.reshape(3 * n, 6)
    lead = u.shape[:-2]
    b = u.reshape(-1, 3 * n).T
    sol, *_ = np.linalg.lstsq(A, b, rcond=None)
    fit = (A @ sol).T.reshape(u.shape)
    scale = np.abs(u).max()
    resid = float(np.abs(u - fit).max() / scale) if scale > 0 else 0.0
    sol = sol.T.reshape(lead + (6,))
    return sol[..., :3], sol[..., 3:], resid


def _region_geometry(prob):
    """(half-width in x, area, I_y, J) of the prescribed region, whole (the modelled part times its
    symmetry images: x, x^2 and y^2 are even under the reflections), by 6 x 6 Gauss points."""
    from .bem import symmetry
    from .mesh import quad9
    g, w = np.polynomial.legendre.leggauss(6)
    xi, eta = (v.ravel() for v in np.meshgrid(g, g, indexing="ij"))
    X = prob.mesh.cell_coords()[prob.regions.disp_elems]
    xg, jn = quad9.geometry(X, xi, eta)
    J = np.linalg.norm(jn, axis=-1) * np.outer(w, w).ravel()
    nimg = len(symmetry.images(prob.planes))
    xs = X[..., 0]
    half = float(xs.max() if any(ax == 0 for ax, _ in prob.planes) else 0.5 * np.ptp(xs))
    Ix = float((J * xg[..., 1] ** 2).sum()) * nimg
    Iy = float((J * xg[..., 0] ** 2).sum()) * nimg
    return half, float(J.sum()) * nimg, Iy, Ix + Iy


def main():
    """Collective: the ``petsc-ssi impedance`` command (PETSc already initialised)."""
    PETSc = init()
    comm = PETSc.COMM_WORLD
    from . import options
    from .bem.problem import BEMTransient
    db = PETSc.Options()
    cfg0 = options.resolve(("common", "bem", G))
    modes = [m.strip() for m in cfg0.impedance_modes.split(",") if m.strip()]
    bad = [m for m in modes if m not in MODES]
    if bad or not modes:
        raise SSIError(f"-ssi_impedance_modes {cfg0.impedance_modes}: modes are {', '.join(MODES)}")
    if not cfg0.disp_group:
        raise SSIError("petsc-ssi impedance needs the footing as -ssi_disp_group (a group or 'box:x0,x1,y0,y1')")
    for name in ("disp_value", "disp_rotation", "disp_history", "symmetry", "load_group"):
        if cfg0.user_set(name):
            raise SSIError(f"petsc-ssi impedance sets -ssi_{name} itself (per mode); drop it")
    stem = os.path.splitext(cfg0.output or "out/impedance.h5")[0]
    rise = cfg0.impedance_rise or 4 * cfg0.dt
    table, curves = [], {}
    for mode in modes:
        opt, motion, sym, what, comp, speed, measure = MODES[mode]
        for k in ("disp_value", "disp_rotation"):
            db.setValue("ssi_" + k, ",".join(f"{AMP * float(v):g}" for v in motion.split(",")) if k == opt else "0,0,0")
        db.setValue("ssi_symmetry", sym if cfg0.impedance_symmetry else "none")
        db.setValue("ssi_disp_history", "smoothstep")
        db.setValue("ssi_disp_t0", repr(rise))
        db.setValue("ssi_output", f"{stem}-{mode}.h5")
        cfg = options.resolve(("common", "bem"))
        printf(f"[impedance] mode {mode}: {opt.replace('disp_', '')} {motion} x {AMP:g}, symmetry "
               f"{sym if cfg0.impedance_symmetry else 'none'}, smooth step over {rise:.4g} s")
        p = BEMTransient(cfg, comm)
        res = p.run()
        if comm.getRank() != 0:
            continue
        r = res["resultants"]
        R = r[what][:, comp] / AMP
        om, K = spectrum(R, r["h"], cfg.dt)
        B, A, Iy, J = _region_geometry(p.prob)
        B = cfg0.impedance_B or B
        K0 = float(R[-1] / r["h"][-1])
        a0 = om * B / cfg.cs
        with np.errstate(divide="ignore", invalid="ignore"):
            c = np.where(a0 > 0, K.imag / (a0 * K0), np.nan)
        rho, cp, cs = cfg.rho, cfg.cp, cfg.cs
        C_inf = rho * (cp if speed == "cp" else cs) * {"A": A, "Iy": Iy, "J": J}[measure]
        settle = float(np.ptp(R[-max(len(R) // 5, 2):]) / abs(R[-1]))
        h_el = p.prob.h                     # the mesh's element size (a gmsh mesh's too)
        band = (4 * np.pi * B / (cs * len(R) * cfg.dt), min(np.pi * B / (2 * h_el), 0.3 * B / (cs * cfg.dt)))
        curves[mode] = (a0, K.real / K0, c, C_inf * cs / (B * K0), band)
        for i in range(len(a0)):
            table.append((mode, a0[i], om[i], K[i].real, K[i].imag, K.real[i] / K0, c[i], K0))
        printf(f"[impedance] {mode}: K0 = {K0:.5g} (the last fifth of the record within {settle:.2g}), "
               f"trusted a0 in [{band[0]:.3g}, {band[1]:.3g}]; high-frequency dashpot limit c = "
               f"{C_inf * cs / (B * K0):.4g}")
        if settle > 1e-2:
            warn(f"impedance {mode}: the response has not settled by t_end (last fifth varies {settle:.2g}): K0 and "
                 "the low frequencies are not converged; raise -ssi_t_end", None)
    if comm.getRank() == 0:
        import csv
        with open(stem + "-impedance.csv", "w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(["mode", "a0", "omega_rad_s", "K_re", "K_im", "k", "c", "K0"])
            for row in table:
                w.writerow([row[0]] + [f"{v:.8g}" for v in row[1:]])
        _plot(stem + "-impedance.png", curves)
        printf(f"[impedance] wrote {stem}-impedance.csv and {stem}-impedance.png")
    comm.tompi4py().Barrier()


def _plot(path, curves):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
    for mode, (a0, k, c, cinf, band) in curves.items():
        m = (a0 > 0) & (a0 <= 1.5 * band[1])
        l1, = ax1.plot(a0[m], k[m], label=mode)
        ax2.plot(a0[m], c[m], color=l1.get_color(), label=mode)
        ax2.axhline(cinf, color=l1.get_color(), ls=":", lw=0.8)
        for ax in (ax1, ax2):
            ax.axvline(band[1], color=l1.get_color(), ls="--", lw=0.6)
    ax1.set_xlabel("a0 = omega B / c_s")
    ax1.set_ylabel("k = Re K / K0")
    ax2.set_xlabel("a0 = omega B / c_s")
    ax2.set_ylabel("c = Im K / (a0 K0)   (dotted: high-frequency dashpot limit)")
    ax1.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
