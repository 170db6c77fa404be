#!/usr/bin/env python3
"""Measured errors of the project's closed-form comparisons (issue 46): each measurement below
repeats what a test asserts, but prints the error instead of comparing it with a bound, so the
verification page (runs/verification/README.md) carries numbers this script obtained.

  kelvin       sum over lags of the time-integrated Stokes kernels U^l, P^l against Kelvin's
               static kernels, 6 random points (tests/bem/test_kernels.py)
  pekeris      Pekeris's closed form (nu = 1/4) against the general-nu Cagniard-de Hoop
               quadrature, tau in [0.3, 4] away from the arrivals (tests/analytic/test_pekeris.py)
  static       lamb_point at tau = 1000 against the Boussinesq limits -(1 - nu)/2 (vertical) and
               -(1 - 2 nu)/4 (radial), nu = 0.1, 0.25, 0.4 (same file)
  boussinesq   the patch step response at c_s t / r = 200 against the closed-form static rectangle
               (same file)
  pulse        the smooth-pulse reference at n = 400 against n = 800 (tests/analytic/test_pulse.py)
  lamb         the BEM under the Heaviside patch load against the Pekeris patch solution
               (tests/bem/test_lamb.py's case: 10 m surface, receivers at 2 m and 3 m, h = 1 and
               0.5 m with dt = 7.5e-4 h / 1 m; relative L2 over tau <= 2.5, petsc_ssi.verify)
  disk         the independent welded-disk solver (petsc_ssi.analytic.disk_static) against the
               bonded punch's vertical closed form, at 8 and 12 rings (tests/analytic/test_disk_static.py);
               the BEM disk's coupling K_hr, K_rh against that solver's at 18 rings
               (runs/impedance/disk_coupling_static.csv, written by disk_coupling_static.py)
  smooth       the smooth-pulse study's rows (runs/pekeris/convergence_smooth.csv, written by
               runs/pekeris/convergence_smooth.py)

Usage: python runs/verification/verify.py [--out DIR] [--only NAME,...]
Writes runs/verification/verify.csv and the table between <!-- verify:begin/end --> in
runs/verification/README.md.
"""
import argparse
import csv
import math
import os
import subprocess
import sys

import numpy as np

from petsc_ssi.launch import child_env

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, ROOT)

CP, CS, RHO = 548.0, 316.0, 2000.0
CMD = "python runs/verification/verify.py --only {}"


def kelvin():
    from petsc_ssi.bem import kernels as K
    mu = RHO * CS ** 2
    nu = (CP ** 2 - 2 * CS ** 2) / (2 * (CP ** 2 - CS ** 2))
    dt = 7.5e-4
    rng = np.random.default_rng(1)
    eu = ep = 0.0
    for _ in range(6):
        x = rng.normal(size=3)
        x *= rng.uniform(0.1, 8.0) / np.linalg.norm(x)
        n = rng.normal(size=3)
        n /= np.linalg.norm(n)
        r = np.linalg.norm(x)
        L = int(r / (CS * dt)) + 4
        su = sum(K.lag_u(x, l * dt, dt, CP, CS, RHO) for l in range(1, L + 1))
        sp = sum(K.lag_p(x, n, l * dt, dt, CP, CS, RHO) for l in range(1, L + 1))
        ku, kp = np.zeros((3, 3)), np.zeros((3, 3))
        K.kelvin_u(x / r, r, nu, mu, ku)
        K.kelvin_p(x / r, n, r, nu, kp)
        eu = max(eu, np.abs(su - ku).max() / np.abs(ku).max())
        ep = max(ep, np.abs(sp - kp).max() / np.abs(kp).max())
    return [("kelvin", "sum of U^l over lags vs Kelvin U (max relative entry difference)", eu, "",
             "tests/bem/test_kernels.py::test_heaviside_sum_equals_kelvin"),
            ("kelvin", "sum of P^l over lags vs Kelvin P (max relative entry difference)", ep, "",
             "tests/bem/test_kernels.py::test_heaviside_sum_equals_kelvin")]


def pekeris():
    from petsc_ssi.analytic import pekeris as pk
    tp, ts, tr = pk.arrivals(0.25)
    tau = np.linspace(0.3, 4.0, 371)
    tau = tau[np.min(np.abs(tau[:, None] - np.array([tp, ts, tr])[None]), axis=1) > 1e-2]
    r1, z1 = pk.pekeris_point(tau, 0.25)
    r2, z2 = pk.lamb_point_general(tau, 0.25)
    return [("pekeris", "Pekeris closed form vs Cagniard-de Hoop quadrature, max |u~_z| difference", float(np.abs(z1 - z2).max()),
             "", "tests/analytic/test_pekeris.py::test_pekeris_vs_general_quadrature"),
            ("pekeris", "the same, max |u~_r| difference", float(np.abs(r1 - r2).max()), "",
             "tests/analytic/test_pekeris.py::test_pekeris_vs_general_quadrature")]


def static():
    from petsc_ssi.analytic import pekeris as pk
    out = []
    for nu in (0.1, 0.25, 0.4):
        ur, uz = pk.lamb_point(np.array([1000.0]), nu)
        out.append(("static", f"nu = {nu}: |u~_z(tau = 1000) + (1 - nu)/2|", abs(uz[0] + (1 - nu) / 2), "",
                    "tests/analytic/test_pekeris.py::test_static_limits_general_nu"))
        out.append(("static", f"nu = {nu}: |u~_r(tau = 1000) + (1 - 2 nu)/4|", abs(ur[0] + (1 - 2 * nu) / 4), "",
                    "tests/analytic/test_pekeris.py::test_static_limits_general_nu"))
    return out


def boussinesq():
    from petsc_ssi.analytic import pekeris as pk
    mu, nu = RHO * CS ** 2, pk.poisson_ratio(CS, CP)
    out = []
    for x, y in ((5.0, 0.0), (3.0, 2.0)):
        t = 200 * math.hypot(x, y) / CS
        ux, uy, uz = pk.patch_displacement(x, y, np.array([t]), 1.0, 1.0, 1000.0, CS, CP, RHO)
        sx, sy, sz = pk.boussinesq_rectangle(x, y, 1.0, 1.0, 1000.0, mu, nu)
        out.append(("boussinesq", f"patch [-1,1]^2 at ({x:g}, {y:g}) m, tau = 200 vs static rectangle: relative "
                    "difference, vertical", abs(uz[0] - sz) / abs(sz), "",
                    "tests/analytic/test_pekeris.py::test_patch_late_time_is_boussinesq"))
        out.append(("boussinesq", "the same, horizontal (|u_h - u_h,static| / |u_h,static|)",
                    math.hypot(ux[0] - sx, uy[0] - sy) / math.hypot(sx, sy), "",
                    "tests/analytic/test_pekeris.py::test_patch_late_time_is_boussinesq"))
    return out


def pulse():
    from petsc_ssi.analytic.pulse import pulse_patch_displacement
    t = np.linspace(0.0, 0.095, 96)
    out = []
    for r in (5.0, 15.0):
        u4 = pulse_patch_displacement(r, 0.0, t, 3.0, 3.0, 1000.0, CS, CP, RHO, 0.03)
        u8 = pulse_patch_displacement(r, 0.0, t, 3.0, 3.0, 1000.0, CS, CP, RHO, 0.03, n=800)
        for c, name in ((2, "vertical"), (0, "radial")):
            out.append(("pulse", f"smooth-pulse reference at r = {r:g} m, {name}: n = 400 vs 800, relative L2",
                        float(np.linalg.norm(u4[c] - u8[c]) / np.linalg.norm(u8[c])), "",
                        "tests/analytic/test_pulse.py"))
    return out


def lamb(out_dir):
    from petsc_ssi.verify import lamb_errors
    levels = (1.0, 0.5)
    errs = {}
    for h in levels:
        h5 = os.path.join(out_dir, f"lamb-h{h:g}.h5")
        opts = dict(problem="bem", cp=CP, cs=CS, rho=RHO, mesh="grid", mesh_size="10,10", mesh_h=h, mesh_patch="1,1",
                    load_group="load", load_p0=1000, load_history="heaviside", symmetry="x=sym,y=sym",
                    receivers="2,0,0;3,0,0", t_end=2.5 * 3 / CS, dt=7.5e-4 * h, scheme="stabilized", output_stride=0,
                    warn_beta=0)
        if not os.path.exists(h5):
            cmd = [sys.executable, "-m", "petsc_ssi", "-ssi_output", h5]
            for k, v in opts.items():
                cmd += [f"-ssi_{k}", str(v)]
            subprocess.run(cmd, cwd=ROOT, check=True, stdout=subprocess.DEVNULL,
                           env=child_env(OPENBLAS_NUM_THREADS="1"))
        errs[h] = lamb_errors(h5)
    out = []
    for k, (r, _, _) in enumerate(errs[levels[0]]):
        for c, name in ((1, "vertical"), (2, "radial")):
            e1, e2 = errs[levels[0]][k][c], errs[levels[1]][k][c]
            out.append(("lamb", f"Heaviside patch, r = {r:g} m, {name}: relative L2, tau <= 2.5, h = 1 m", e1, "",
                        "tests/bem/test_lamb.py"))
            out.append(("lamb", "the same at h = 0.5 m (dt halved)", e2, math.log(e1 / e2) / math.log(2.0),
                        "tests/bem/test_lamb.py"))
    return out


def disk():
    from petsc_ssi.analytic.disk_static import k_z_bonded, stiffness
    nu = 1.0 / 3.0
    out, prev = [], None
    for nr in (8, 12):
        e = abs(stiffness(nr, 4 * nr, 1.0, nu)[1, 1] / k_z_bonded(1.0, nu) - 1)
        order = math.log(prev / e) / math.log(nr / 8) if prev else ""
        out.append(("disk", f"welded disk, nu = 1/3, {nr} rings: K_z vs 4 G R ln(3 - 4 nu) / (1 - 2 nu)", e, order,
                    "tests/analytic/test_disk_static.py"))
        prev = e
    from petsc_ssi.analytic.disk_static import frictionless_disk
    prev = None
    for nr in (8, 12):
        kz, kr = frictionless_disk(nr, 4 * nr, 1.0, nu)
        e = abs(kr / (8 / (3 * (1 - nu))) - 1)
        out.append(("disk", f"frictionless disk, {nr} rings: K_r vs 8 G R^3 / (3 (1 - nu))", e,
                    math.log(prev / e) / math.log(nr / 8) if prev else "", "tests/analytic/test_disk_static.py"))
        prev = e
    rows = list(csv.DictReader(open(os.path.join(ROOT, "runs", "impedance", "disk_coupling_static.csv"))))
    ind = next(r for r in rows if r["rings"] == "18")
    bem = next(r for r in rows if r["rings"].startswith("BEM"))
    for key in ("K_hr / (R K_x) [-]", "K_rh / (R K_x) [-]"):
        out.append(("disk", f"BEM disk (0.25 m elements) coupling {key.split(' [')[0]} vs the welded solver's (18 rings)",
                    abs(float(bem[key]) / float(ind[key]) - 1), "", "runs/impedance/disk_coupling_static.py"))
    return out


def smooth():
    path = os.path.join(ROOT, "runs", "pekeris", "convergence_smooth.csv")
    out = []
    with open(path) as fh:
        for row in csv.DictReader(fh):
            if row["kind"] not in ("error", "error, diffraction-free window t <= min(t_w, t_d)"):
                continue                   # the truncation rows and the larger surfaces' errors
            clean = "diffraction-free" in row["kind"]
            if clean and float(row["r [m]"]) < 10:
                continue                   # at 5 m the two windows are the same
            order = row["observed order vs previous h [-]"]
            out.append(("smooth", f"sin^4 pulse, r = {row['r [m]']} m, {row['component']}, h = {row['h [m]']} m"
                        + (", diffraction-free window" if clean else ""),
                        float(row["relative L2 error [%]"]) / 100, float(order) if order else "",
                        "tests/bem/test_lamb_smooth.py; runs/pekeris/convergence_smooth.py"))
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "verification"))
    ap.add_argument("--only", default="")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    jobs = {"kelvin": kelvin, "pekeris": pekeris, "static": static, "boussinesq": boussinesq, "pulse": pulse,
            "lamb": lambda: lamb(a.out), "disk": disk, "smooth": smooth}
    names = [n for n in jobs if not a.only or n in a.only.split(",")]
    rows = []
    for n in names:
        print("[verify]", n, flush=True)
        rows += jobs[n]()
    with open(os.path.join(HERE, "verify.csv"), "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["measurement", "quantity", "error [relative, or dimensionless u~ where so named]",
                     "observed order [-]", "test"])
        for r in rows:
            w.writerow([r[0], r[1], f"{r[2]:.3g}", f"{r[3]:.2f}" if r[3] != "" else "", r[4]])
    lines = ["| measurement | quantity | error | observed order | test | command |", "|---|---|---|---|---|---|"]
    for r in rows:
        quantity = r[1].replace("|", "\\|")
        order = f"{r[3]:.2f}" if r[3] != "" else ""
        lines.append(f"| {r[0]} | {quantity} | {r[2]:.3g} | {order} | `{r[4]}` | `{CMD.format(r[0])}` |")
    table = "\n".join(lines)
    print(table)
    if not a.only:
        readme = os.path.join(HERE, "README.md")
        text = open(readme).read()
        b, e = "<!-- verify:begin -->", "<!-- verify:end -->"
        i, j = text.index(b) + len(b), text.index(e)
        open(readme, "w").write(text[:i] + "\n" + table + "\n" + text[j:])


if __name__ == "__main__":
    main()
