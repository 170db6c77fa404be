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

A plane is used only where the footing and the meshed surface are both symmetric about it (checked
on the whole surface before the runs: every node mirrored lands on a node, or the mesh is a half
model ending on the plane with the footing against it); the command says in one line which planes
it uses and why any is not. The rigid motions' reference point x_ref (-ssi_disp_ref) is by default
the footing's centroid, so an off-centre footing rocks and twists about its own centre
(-ssi_impedance_symmetry 0 meshes the whole surface instead). Outputs, from -ssi_output's stem:
<stem>-<mode>.h5 (each run), <stem>-impedance.csv (a0, K, k, c per mode; with the horizontal and rocking
runs also the two coupling terms and their mean, mode coupling-mean), <stem>-impedance.png
(k and c against a0, with each mode's high-frequency dashpot limit: rho c_p A, rho c_s A,
rho c_p I_y, rho c_s J); all of them are checked before the first mode's run, and an existing
one is refused unless -ssi_output_overwrite (``check_outputs``). The trusted band:
a0 >= 4 pi B / (c_s T) (two frequency bins of the record T) and a0 >= 2 pi B c_R / (c_s L) (one
Rayleigh wavelength across the meshed surface, L its smaller extent with the symmetry images:
below it k and c of a 4 m surface around a 2 m square differ from an 8 m surface's by up to 0.13,
above it by under 0.02; runs/impedance/extent_study.py),
a0 <= pi B / (2 h) (four elements per shear wavelength) and omega dt <= 0.3, i.e.
a0 <= 0.3 B / (c_s dt): the time discretisation's error grows with omega dt (on the square footing
of runs/impedance/dt_study.py, k at a0 = 2.5 is 1.23, 0.83, 0.73 with dt = 1.6, 0.8, 0.4 ms, and
converges as dt falls); the command prints the band.
Also: the horizontal-rocking coupling terms (CROSS), the published curves of analytic/impedance_refs.py (k_ref,
c_ref; -ssi_impedance_reference), and rigid_fit for the impedance of a structure coupled to the soil.
"""
import gc
import math
import os
import time

import numpy as np

from ..options import register
from ..petsc import init, SSIError, printf, warn
from ..bem.impedance import step_spectrum, spectrum, rigid_fit

G = "impedance"
register("impedance_modes", "str", "vertical,horizontal,rocking,torsion", "", "petsc-ssi impedance: the modes to "
         "run (vertical, horizontal, rocking, torsion)", G)
register("impedance_rise", "real", 0.0, "s", "petsc-ssi impedance: rise time t0 of the smooth step (0: 4 dt)", G,
         validator=lambda v: None if v >= 0 else "must be >= 0")
register("impedance_B", "real", 0.0, "m", "petsc-ssi impedance: half-width B of the footing for a0 = omega B / c_s "
         "(0: half the region's smaller extent, x or y; a disk's radius)", G, validator=lambda v: None if v >= 0 else "must be >= 0")
register("impedance_a0", "str", "", "", "petsc-ssi impedance: the a0 range 'a0_min,a0_max' wanted (a warning when "
         "it leaves the band the mesh, dt and record length are trusted for)", G)
register("impedance_reference", "enum", "auto", "", "petsc-ssi impedance: published curves plotted and written "
         "(k_ref, c_ref): auto (Pais & Kausel for a rectangle, Veletsos & Verbic for a disk), pais-kausel, "
         "veletsos-verbic, none", G, choices=("auto", "pais-kausel", "veletsos-verbic", "none"))
register("impedance_symmetry", "bool", True, "", "petsc-ssi impedance: use the symmetry planes each mode allows", G)

AMP = 1e-6
MODES = {  # name: (option, motion, symmetry, resultant, component, radiation speed, dashpot area measure)
    "vertical": ("disp_value", "0,0,1", "x=sym,y=sym", "force", 2, "cp", "A"),
    "horizontal": ("disp_value", "1,0,0", "x=anti,y=sym", "force", 0, "cs", "A"),
    "rocking": ("disp_rotation", "0,1,0", "x=anti,y=sym", "moment", 1, "cp", "Iy"),
    "torsion": ("disp_rotation", "0,0,1", "x=anti,y=anti", "moment", 2, "cs", "J"),
}
# the unit of each row's K_re, K_im and K0 (the CSV's K_unit): resultant over motion; the coupling's mean N m/m = N/rad
K_UNIT = {"vertical": "N/m", "horizontal": "N/m", "rocking": "N m/rad", "torsion": "N m/rad",
          "horizontal-rocking": "N m/m", "rocking-horizontal": "N/rad", "coupling-mean": "N"}
# the coupling terms each run also gives: (name, resultant, component)
CROSS = {"horizontal": ("horizontal-rocking", "moment", 1),      # M_y per unit u_x
         "rocking": ("rocking-horizontal", "force", 0)}          # F_x per unit theta_y


def _mirror_equal(pts, ax, tol):
    """Whether the point set (N, 2+) maps onto itself under x_ax -> -x_ax (to ``tol``)."""
    from scipy.spatial import cKDTree
    q = np.array(pts[:, :2], float)
    q[:, ax] *= -1.0
    d, _ = cKDTree(pts[:, :2]).query(q)
    return bool(d.max() <= tol)


def usable_planes(cfg, comm):
    """Collective: which symmetry planes x = 0, y = 0 the footing (-ssi_disp_group) and the surface mesh
    allow, from the whole surface (meshed without planes; cheap, no assembly): (axes, x_ref, one
    line saying which planes are used and why any is not). A plane is usable when the footing's nodes
    and the mesh's nodes both map onto themselves mirrored about it, or when the mesh is a half model
    ending on the plane (its nodes on one side, some on it) with the footing against the plane; and
    x_ref (-ssi_disp_ref, default the footing's centroid) lies on it."""
    from ..bem.halfspace import read_surface_mesh
    from ..bem.lagset import Regions
    from ..bem.input_motion import region_centroid
    from ..bem.resultants import parse_vector
    mesh = read_surface_mesh(cfg, comm, [])
    elems = mesh.select(cfg.disp_group)
    h = float(mesh.element_sizes().max())
    tol = 1e-6 * h
    from ..bem.input_motion import check_soil_around
    check_soil_around(mesh, elems, cfg.disp_group, tol)
    regions = Regions(mesh, (), elems)
    xref = (parse_vector(cfg.disp_ref, "disp_ref") if cfg.user_set("disp_ref")
            else region_centroid(mesh, regions, []))
    X, F = mesh.nodes, mesh.nodes[regions.disp_nodes]
    axes, why = [], []
    for ax, name in ((0, "x"), (1, "y")):
        lo, hi = float(F[:, ax].min()), float(F[:, ax].max())
        half_model = X[:, ax].min() > -tol and np.abs(X[:, ax]).min() < tol
        if half_model:
            ok = abs(lo) < tol
            reason = f"the mesh is a half model on {name} >= 0 but the footing spans {name} in [{lo:.4g}, {hi:.4g}] m, " \
                     "away from the plane"
        elif not _mirror_equal(F, ax, tol):
            ok, reason = False, f"the footing (spanning {name} in [{lo:.4g}, {hi:.4g}] m) is not symmetric about it"
        elif not _mirror_equal(X, ax, tol):
            ok, reason = False, "the meshed surface is not symmetric about it"
        else:
            ok, reason = True, ""
        if ok and abs(xref[ax]) > tol:
            ok, reason = False, f"x_ref (-ssi_disp_ref) is off it ({name} = {xref[ax]:.4g} m)"
        if ok:
            axes.append(ax)
        else:
            why.append(f"{name} = 0 not used: {reason}")
    used = ", ".join(f"{'xy'[a]} = 0" for a in axes) or "none"
    line = (f"[impedance] symmetry planes used: {used}" + (f" ({'; '.join(why)})" if why else "")
            + f"; reference point x_ref = ({', '.join(f'{v:.4g}' for v in xref)}) m")
    return axes, xref, line


def _restrict(sym, axes):
    """A mode's symmetry spec ('x=anti,y=sym') keeping the planes of ``axes`` only ('none' if none)."""
    keep = [p for p in sym.split(",") if "xy".index(p.split("=")[0]) in axes]
    return ",".join(keep) or "none"


def _region_geometry(prob):
    """The prescribed region, whole (the modelled part times its symmetry images: x, x^2 and y^2
    are even under the reflections), by 6 x 6 Gauss points: {'hx', 'hy'} half-extents, 'A' area,
    'Ix' = int y^2, 'Iy' = int x^2, 'J' = Ix + Iy, and 'shape': 'rectangle' (A = 4 hx hy), 'disk'
    (hx = hy, A = pi hx^2, to 1e-3) or 'other'."""
    from ..bem import symmetry
    from ..mesh import quad9
    g, w = np.polynomial.legendre.leggauss(6)
    xi, eta = (v.ravel() for v in np.meshgrid(g, g, indexing="ij"))
    X = prob.mesh.cell_coords()[prob.regions.disp_elems]
    xg, jn = quad9.geometry(X, xi, eta)
    J = np.linalg.norm(jn, axis=-1) * np.outer(w, w).ravel()
    nimg = len(symmetry.images(prob.planes))
    half = []
    for ax in (0, 1):
        v = X[..., ax]
        half.append(float(np.abs(v).max() if any(a == ax for a, _ in prob.planes) else 0.5 * np.ptp(v)))
    c = np.zeros(2)               # the whole region's centroid (0 on each plane)
    for ax in (0, 1):
        if not any(a == ax for a, _ in prob.planes):
            c[ax] = float((J * xg[..., ax]).sum() / J.sum())
    Ix = float((J * (xg[..., 1] - c[1]) ** 2).sum()) * nimg
    Iy = float((J * (xg[..., 0] - c[0]) ** 2).sum()) * nimg
    A = float(J.sum()) * nimg
    hx, hy = half
    shape = "other"
    if abs(A / (4 * hx * hy) - 1) < 1e-3:
        shape = "rectangle"
    elif abs(hx / hy - 1) < 1e-3 and abs(A / (np.pi * hx * hy) - 1) < 1e-3:
        shape = "disk"
    return dict(hx=hx, hy=hy, A=A, Ix=Ix, Iy=Iy, J=Ix + Iy, shape=shape)


def surface_extent(prob):
    """The smaller extent (x or y) of the meshed surface, its symmetry images included."""
    X = np.asarray(prob.mesh.nodes, dtype=float)
    ext = []
    for ax in (0, 1):
        v = X[:, ax]
        mirrored = any(a == ax for a, _ in prob.planes)
        ext.append(float(2 * np.abs(v).max() if mirrored else np.ptp(v)))
    return min(ext)


def extent_limit(prob, B, cs, cp):
    """The lowest a0 the meshed surface is trusted for: one Rayleigh wavelength across it,
    2 pi c_R / omega <= L, i.e. a0 >= 2 pi B c_R / (c_s L) (module docstring)."""
    from ..analytic.pekeris import arrivals, poisson_ratio
    gamma = arrivals(poisson_ratio(cs, cp))[2]          # c_s / c_R
    return 2 * np.pi * B / (gamma * surface_extent(prob))


def _reference(geom, mode, a0, nu, name):
    """(label, k(a0), c(a0)) of the published curve for this footing and mode in our
    normalisation (a0 = omega B / c_s with our B), or None where there is none."""
    shape = geom["shape"]
    if name == "none" or shape == "other":
        return None
    from ..analytic import impedance_refs as refs
    if name in ("auto", "pais-kausel") and shape == "rectangle":
        B, L = min(geom["hx"], geom["hy"]), max(geom["hx"], geom["hy"])
        if geom["hx"] < geom["hy"]:          # the long side along y: our x motions are P&K's y ones
            mode = {"horizontal": "horizontal_y", "rocking": "rocking_x"}.get(mode, mode)
        _, k, c = refs.pais_kausel(mode, a0, LB=L / B, nu=nu)
        return "Pais & Kausel (1988)", k, c
    if name in ("auto", "veletsos-verbic") and shape == "disk" and mode != "torsion":
        try:
            _, k, c = refs.veletsos_verbic(mode, a0, nu=nu)
        except ValueError:                   # not tabulated for this nu (0, 1/3, 0.45, 0.5 only)
            return None
        return f"Veletsos & Verbic (1973), nu = {nu:.3g}", k, c
    return None


def _a0_range(text):
    if not text.strip():
        return None
    try:
        lo, hi = (float(v) for v in text.split(","))
    except ValueError:
        raise SSIError(f"-ssi_impedance_a0 {text}: give 'a0_min,a0_max'") from None
    if not 0 <= lo < hi:
        raise SSIError(f"-ssi_impedance_a0 {text}: needs 0 <= a0_min < a0_max")
    return lo, hi


def check_outputs(stem, modes, comm, overwrite):
    """Collective, before the first mode's run: every file the command writes (each mode's
    ``<stem>-<mode>.h5`` with its sidecars, ``<stem>-impedance.csv`` and ``.png``) may be written
    and replaces nothing unless -ssi_output_overwrite (``io.output.check_output``'s rule); SSIError
    in one line on every rank otherwise."""
    from ..io.output import check_output, replace_error
    from ..petsc import collective_error
    for mode in modes:
        check_output(f"{stem}-{mode}.h5", comm, overwrite)
    err = None
    for f in (stem + "-impedance.csv", stem + "-impedance.png"):
        err = replace_error(f, f"-ssi_output {stem}.h5", "-ssi_output", overwrite)
        if err:
            break
    collective_error(err, comm)


def coupling_report(K0s, cross):
    """The log lines of the static coupling terms: each in units of sqrt(K0_h K0_r), their
    reciprocity and, when both were run, their mean as the symmetric estimate (issue 46: on the disk
    and the square the mean lies within a few per cent of an independent welded-footing solution,
    K_hr alone is the term the collocation misses most; runs/impedance/README.md)."""
    if not ("horizontal" in K0s and "rocking" in K0s):
        return []
    scale = math.sqrt(K0s["horizontal"] * K0s["rocking"])
    out = [f"[impedance] coupling {name}: K0 = {K0:.5g}, {K0 / scale:.3g} of sqrt(K0_h K0_r)"
           for name, K0 in cross.items()]
    if len(cross) == 2:
        a, b = cross["horizontal-rocking"], cross["rocking-horizontal"]
        out.append(f"[impedance] reciprocity of the coupling terms: K_hr / K_rh - 1 = {a / b - 1:.3g} "
                   "(0 for the continuous soil; the BEM's comes from the meshed surface's truncation, falling as "
                   "the surface grows, and from the collocation: runs/impedance/README.md)")
        out.append(f"[impedance] symmetric estimate of the coupling: (K_hr + K_rh) / 2 = {0.5 * (a + b):.5g}, "
                   f"{0.5 * (a + b) / scale:.3g} of sqrt(K0_h K0_r) (the mean is the better estimate: "
                   "runs/impedance/README.md; the CSV's rows 'coupling-mean')")
    return out


def coupling_mean_rows(table):
    """The CSV rows of the symmetric estimate of the coupling, mode 'coupling-mean': at every a0 the
    mean of the horizontal-rocking and rocking-horizontal rows of ``table`` (rows (mode, a0, omega,
    K_re, K_im, k, c, K0, trusted, k_ref, c_ref)), k and c of the mean K over the mean K0, trusted
    where both are; [] unless both terms were run on the same a0 (the same record)."""
    hr = [r for r in table if r[0] == "horizontal-rocking"]
    rh = [r for r in table if r[0] == "rocking-horizontal"]
    if not hr or len(hr) != len(rh) or any(abs(x[1] - y[1]) > 1e-9 * max(1.0, abs(x[1])) for x, y in zip(hr, rh)):
        return []
    K0 = 0.5 * (hr[0][7] + rh[0][7])
    out = []
    for x, y in zip(hr, rh):
        re, im = 0.5 * (x[3] + y[3]), 0.5 * (x[4] + y[4])
        c = im / (x[1] * K0) if x[1] > 0 else np.nan
        out.append(("coupling-mean", x[1], x[2], re, im, re / K0, c, K0, int(x[8] and y[8]), np.nan, np.nan))
    return out


def main():
    """Collective: the ``petsc-ssi impedance`` command (PETSc already initialised)."""
    PETSc = init()
    comm = PETSc.COMM_WORLD
    from .. import options
    from ..bem.problem import BEMTransient
    db = PETSc.Options()
    cfg0 = options.resolve(("common", "bem", G))
    modes = [m.strip() for m in cfg0.impedance_modes.split(",") if m.strip()]
    bad = [m for m in modes if m not in MODES]
    if bad or not modes:
        raise SSIError(f"-ssi_impedance_modes {cfg0.impedance_modes}: modes are {', '.join(MODES)}")
    dup = sorted({m for m in modes if modes.count(m) > 1})
    if dup:                         # each mode writes its own file: the second would stop after the first's run
        raise SSIError(f"-ssi_impedance_modes {cfg0.impedance_modes}: {', '.join(dup)} given twice; name each "
                       "mode once")
    if not cfg0.disp_group:
        raise SSIError("petsc-ssi impedance needs the footing as -ssi_disp_group (a group or 'box:x0,x1,y0,y1')")
    for name in ("disp_value", "disp_rotation", "disp_history", "symmetry", "load_group", "load_area", "disp_rigid"):
        if cfg0.user_set(name):
            raise SSIError(f"petsc-ssi impedance sets -ssi_{name} itself (per mode); drop it")
    want = _a0_range(cfg0.impedance_a0)
    p = None
    if cfg0.impedance_symmetry:
        axes, xref, line = usable_planes(cfg0, comm)
        printf(line)
    else:
        axes, xref, _ = usable_planes(cfg0, comm)
        axes = []
        printf("[impedance] symmetry planes used: none (-ssi_impedance_symmetry 0)")
    if not cfg0.user_set("disp_ref"):
        db.setValue("ssi_disp_ref", ",".join(repr(float(v)) for v in xref))
    stem = os.path.splitext(cfg0.output or "out/impedance.h5")[0]
    check_outputs(stem, modes, comm, bool(cfg0.get("output_overwrite")))
    rise = cfg0.impedance_rise or 4 * cfg0.dt
    nu = ((cfg0.cp / cfg0.cs) ** 2 - 2) / (2 * ((cfg0.cp / cfg0.cs) ** 2 - 1))
    table, curves, K0s, cross = [], {}, {}, {}
    if not cfg0.user_set("warn_edge"):      # (the footing's own reflections from the edge: each mode's a0 band says so)
        db.setValue("ssi_warn_edge", "0")
    for mode in modes:
        opt, motion, sym, what, comp, speed, measure = MODES[mode]
        for k in ("disp_value", "disp_rotation"):
            db.setValue("ssi_" + k, ",".join(f"{AMP * float(v):g}" for v in motion.split(",")) if k == opt else "0,0,0")
        sym = _restrict(sym, axes)
        db.setValue("ssi_symmetry", sym)
        db.setValue("ssi_disp_history", "smoothstep")
        db.setValue("ssi_disp_t0", repr(rise))
        db.setValue("ssi_output", f"{stem}-{mode}.h5")
        cfg = options.resolve(("common", "bem"))
        printf(f"[impedance] mode {mode}: {opt.replace('disp_', '')} {motion} x {AMP:g}, symmetry "
               f"{sym}, smooth step over {rise:.4g} s")
        t_run = time.perf_counter()
        p = res = None                      # (the last mode's lag Mats were freed at the end of its run: run())
        gc.collect()
        p = BEMTransient(cfg, comm)
        res = p.run()
        t_run = time.perf_counter() - t_run
        if comm.getRank() != 0:
            continue
        r = res["resultants"]
        geom = _region_geometry(p.prob)
        B = cfg0.impedance_B or min(geom["hx"], geom["hy"])
        rho, cp, cs = cfg.rho, cfg.cp, cfg.cs
        h_el = p.prob.h                     # the mesh's element size (a gmsh mesh's too)
        n_steps = len(r["h"])
        a0_record = 4 * np.pi * B / (cs * n_steps * cfg.dt)
        a0_extent = extent_limit(p.prob, B, cs, cp)
        band = (max(a0_record, a0_extent), min(np.pi * B / (2 * h_el), 0.3 * B / (cs * cfg.dt)))
        Dh = np.abs(step_spectrum(r["h"], cfg.dt)[1])
        low = np.nonzero(Dh < 1e-3 * Dh[0])[0]   # K is a ratio of spectra: up to where the pulse fades
        keep = slice(0, int(low[0]) if low.size else len(Dh))
        terms = [(mode, what, comp)] + ([CROSS[mode]] if mode in CROSS else [])
        for name, what_, comp_ in terms:
            R = r[what_][:, comp_] / AMP
            om, K = spectrum(R, r["h"], cfg.dt)
            om, K = om[keep], K[keep]
            a0 = om * B / cs
            K0 = float(R[-1] / r["h"][-1])
            with np.errstate(divide="ignore", invalid="ignore"):
                c = np.where(a0 > 0, K.imag / (a0 * K0), np.nan)
            trusted = (a0 >= band[0]) & (a0 <= band[1])
            ref = _reference(geom, name, a0, nu, cfg0.impedance_reference) if name == mode else None
            for i in range(len(a0)):
                table.append((name, a0[i], om[i], K[i].real, K[i].imag, K.real[i] / K0, c[i], K0, int(trusted[i]),
                              ref[1][i] if ref else np.nan, ref[2][i] if ref else np.nan))
            if name != mode:
                cross[name] = K0
                continue
            K0s[mode] = K0
            C_inf = rho * (cp if speed == "cp" else cs) * geom[measure]
            settle = float(np.ptp(R[-max(len(R) // 5, 2):]) / abs(R[-1]))
            curves[mode] = (a0, K.real / K0, c, C_inf * cs / (B * K0), band, ref)
            printf(f"[impedance] {mode}: K0 = {K0:.5g} (the last fifth of the record within {settle:.2g}), "
                   f"trusted a0 in [{band[0]:.3g}, {band[1]:.3g}]; high-frequency dashpot limit c = "
                   f"{C_inf * cs / (B * K0):.4g}; the pulse covers a0 <= {a0[-1]:.3g}; {t_run:.1f} s"
                   + (f"; reference: {ref[0]}" if ref else ""))
            if settle > 1e-2:
                warn(f"impedance {mode}: the response has not settled by t_end (last fifth varies {settle:.2g}): K0 "
                     "and the low frequencies are not converged; raise -ssi_t_end", None)
            if band[0] >= band[1]:
                warn(f"impedance {mode}: this mesh and record trust no a0: the lower limit {band[0]:.3g} (the "
                     f"record, {a0_record:.3g}; one Rayleigh wavelength across the meshed surface, "
                     f"{a0_extent:.3g}) is above the upper {band[1]:.3g} (omega dt <= 0.3, four elements per "
                     "shear wavelength): widen the mesh, refine dt and h or lengthen t_end", None)
            elif want and (want[0] < band[0] or want[1] > band[1]):
                warn(f"impedance {mode}: the requested a0 in [{want[0]:g}, {want[1]:g}] leaves the band this mesh "
                     f"and record trust, [{band[0]:.3g}, {band[1]:.3g}] (lower: the record length t_end, "
                     f"a0 >= {a0_record:.3g}, and one Rayleigh wavelength across the meshed surface, "
                     f"a0 >= {a0_extent:.3g}; upper: omega dt <= 0.3 and four elements per shear wavelength): "
                     "refine dt and h, lengthen t_end or widen the mesh", None)
    if comm.getRank() == 0:
        for line in coupling_report(K0s, cross):
            printf(line)
        table += coupling_mean_rows(table)
        import csv
        with open(stem + "-impedance.csv", "w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(["mode", "a0", "omega_rad_s", "K_re", "K_im", "k", "c", "K0", "trusted", "k_ref", "c_ref",
                        "K_unit"])
            for row in table:
                w.writerow([row[0]] + [f"{v:.8g}" for v in row[1:8]] + [row[8]] + [f"{v:.6g}" for v in row[9:]]
                           + [K_UNIT[row[0]]])
        _plot(stem + "-impedance.png", curves)
        printf(f"[impedance] wrote {stem}-impedance.csv and {stem}-impedance.png")
    comm.tompi4py().Barrier()


def _plot(path, curves):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.5))
    refname = None
    for mode, (a0, k, c, cinf, band, ref) in curves.items():
        m = (a0 > 0) & (a0 <= 1.5 * band[1])
        l1, = ax1.plot(a0[m], k[m], label=mode)
        ax2.plot(a0[m], c[m], color=l1.get_color(), label=mode)
        ax2.axhline(cinf, color=l1.get_color(), ls=":", lw=0.8)
        if ref is not None:
            refname = ref[0]
            ax1.plot(a0[m], ref[1][m], color=l1.get_color(), ls="-.", lw=1.0)
            ax2.plot(a0[m], ref[2][m], color=l1.get_color(), ls="-.", lw=1.0)
        for ax in (ax1, ax2):
            ax.axvline(band[1], color=l1.get_color(), ls="--", lw=0.6)
    ax1.set_xlabel("a0 = omega B / c_s")
    ax1.set_ylabel("k = Re K / K0")
    ax2.set_xlabel("a0 = omega B / c_s")
    ax2.set_ylabel("c = Im K / (a0 K0)")
    ax1.legend()
    ax1.set_title("solid: BEM" + (f"; dash-dot: {refname}" if refname else "") + "; dashed: trusted a0 max",
                  fontsize=8)
    ax2.set_title("dotted: high-frequency dashpot limit", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
