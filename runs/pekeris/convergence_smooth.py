#!/usr/bin/env python3
"""Smooth-pulse Lamb convergence study (issue 46): the BEM's surface displacement at r = 5 m and
15 m under a smooth vertical load pulse, against the Pekeris patch solution convolved with the
pulse, for element sizes h refined with the time step at a fixed beta = c_s dt / h.

The case: the paper's soil (c_p = 548, c_s = 316 m/s, rho = 2000 kg/m^3, nu = 1/4), a uniform
pressure p0 a(t) on the square [-A, A]^2 (A = 3 m: a multiple of every h), a(t) = sin^4(pi t / T)
on [0, T] (C^3, T = 0.03 s; petsc_ssi.analytic.pulse; given to the run as a table of 2000 linear
pieces, within 2e-6 of the pulse), on a 2 D x 2 D surface (quarter model, D = 24 m), stabilised
scheme, far lags in single precision (-ssi_lag_single_from 3: a relative change of the receivers
near 1e-8, runs/pekeris/README.md's precision table). beta = c_s dt / h = 0.237 as in the paper
(h = 1 m, dt = 7.5e-4 s).

Error at a receiver: relative L2 norm over the BEM's samples t_n <= t_w(r) of the difference to
the reference, per component (vertical; radial), with t_w(r) = (r + A) / c_R + T: the Rayleigh
pulse from the farthest loaded point has passed the receiver. Observed order between two levels:
log(e1 / e2) / log(h1 / h2). The shear wavelength of the load is lambda_s = c_s T / 2 (the pulse's
top harmonic, 2 / T = 66.7 Hz: sin^4 x = 3/8 - cos 2x / 2 + cos 4x / 8).

The mesh ends at D = 24 m, so waves diffracted at its edge reach the receivers inside the window
(the earliest, along load -> edge -> receiver at c_p: 0.0547 s at 15 m, 0.073 s at 5 m). Its share
is measured, not assumed: the coarsest levels are run again on a larger surface (D = 48 m at h = 3,
D = 36 m at h = 1.5) and the difference of the two runs, relative to the reference's norm, is
written as the 'truncation' rows.

Usage: python runs/pekeris/convergence_smooth.py [--levels 3,1.5,1] [--out DIR] [--ranks N]
                                                   [--no-truncation]
Writes runs/pekeris/convergence_smooth.csv, convergence_smooth.png and the table between
<!-- smooth:begin/end --> in runs/pekeris/README.md (runs whose log exists in DIR are not
repeated; DIR defaults to out/convergence_smooth).
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
sys.path.insert(0, os.path.join(ROOT, "jobscripts"))
sys.path.insert(0, ROOT)

CP, CS, RHO, P0 = 548.0, 316.0, 2000.0, 1000.0
A = 3.0                     # m, half-width of the loaded square
T = 0.03                    # s, pulse duration
D = 24.0                    # m, half-width of the meshed surface
BETA = CS * 7.5e-4 / 1.0    # c_s dt / h of the paper's mesh (h = 1 m, dt = 7.5e-4 s)
RECEIVERS = (5.0, 15.0)     # m, on the x axis
LEVELS = (3.0, 1.5, 1.0)    # m
TABLE_ROWS = 2000


def rayleigh_speed():
    from petsc_ssi.analytic.pekeris import arrivals, poisson_ratio
    return CS / arrivals(poisson_ratio(CS, CP))[2]


def window(r):
    """t_w(r) [s]: the Rayleigh pulse from the farthest loaded point has passed r."""
    return (r + A) / rayleigh_speed() + T


def diffraction_free(r, half=D):
    """t_d(r) [s]: the earliest wave diffracted at the mesh's edge (load's edge -> mesh edge ->
    receiver at c_p, the run's own warning) reaches r; the window min(t_w, t_d) holds none of it."""
    return (2 * half - A - r) / CP


def t_end():
    return max(window(r) for r in RECEIVERS) + 0.005


def wavelength():
    """lambda_s = c_s T / 2 [m]: the shear wavelength of the pulse's top harmonic."""
    return CS * T / 2.0


def table_file(out):
    from petsc_ssi.analytic.pulse import bump_table
    path = os.path.join(out, f"bump-T{T:g}.txt")
    if not os.path.exists(path):
        np.savetxt(path, bump_table(T, TABLE_ROWS), header="t [s]  a(t) [-]: sin^4(pi t / T)")
    return path


def options(h, half, out):
    dt = BETA * h / CS
    return {"problem": "bem", "cp": CP, "cs": CS, "rho": RHO, "dt": dt, "t_end": t_end(),
            "mesh": "grid", "mesh_size": f"{2 * half:g},{2 * half:g}", "mesh_h": h, "mesh_patch": f"{A:g},{A:g}",
            "symmetry": "x=sym,y=sym", "load_group": "load", "load_p0": P0, "load_history": "table",
            "load_table": table_file(out), "scheme": "stabilized",
            "receivers": ";".join(f"{r:g},0,0" for r in RECEIVERS), "lag_single_from": 3,
            "output_stride": 0, "warn_beta": 0}


def run_level(h, half, out, ranks):
    """Run (or reuse) one level; return (t [s], u [steps, receivers, 3] [m], wall s, peak GB,
    whether the run compiled the kernels)."""
    import h5py
    from logview import parse
    name = f"h{h:g}-D{half:g}"
    log, h5 = os.path.join(out, name + ".log"), os.path.join(out, name + ".h5")
    if not (os.path.exists(log) and "done in" in open(log).read() and os.path.exists(h5)):
        args = []
        for k, v in options(h, half, out).items():
            args += [f"-ssi_{k}", str(v)]
        cmd = [sys.executable, "-m", "petsc_ssi"] + args + ["-ssi_output", h5, "-ssi_output_overwrite",
                                                            "-log_view", "-memory_view"]
        if ranks > 1:
            cmd = ["mpirun", "--allow-run-as-root", "-n", str(ranks)] + cmd
        print("[convergence_smooth]", name, flush=True)
        env = child_env(OPENBLAS_NUM_THREADS="1")
        with open(log, "w") as fh:
            subprocess.run(cmd, stdout=fh, stderr=subprocess.STDOUT, cwd=ROOT, check=True, env=env)
    lv = parse(open(log).read())
    with h5py.File(h5, "r") as f:
        t, u = f["receivers/t"][:], f["receivers/u"][:]
    peak = lv["peak_rss_bytes"] / 1e9 if lv["peak_rss_bytes"] else float("nan")
    return t, u, lv["total_s"], peak, "compiling the BEM kernels" in open(log).read()


def reference(t):
    """{r: (radial, vertical)} [m] at times t [s] (petsc_ssi.analytic.pulse)."""
    from petsc_ssi.analytic.pulse import pulse_patch_displacement
    out = {}
    for r in RECEIVERS:
        ux, _, uz = pulse_patch_displacement(r, 0.0, t, A, A, P0, CS, CP, RHO, T)
        out[r] = (ux, uz)
    return out


def errors(t, u, clean=False):
    """{(r, component): relative L2 error} of one run (module docstring); ``clean``: over
    t <= min(t_w, t_d) instead (no wave diffracted at the mesh's edge in the window)."""
    ref = reference(t)
    out = {}
    for k, r in enumerate(RECEIVERS):
        m = t <= (min(window(r), diffraction_free(r)) if clean else window(r)) + 1e-12
        for c, (comp, rc) in enumerate((("radial", 0), ("vertical", 2))):
            e = u[m, k, rc] - ref[r][c][m]
            out[(r, comp)] = float(np.linalg.norm(e) / np.linalg.norm(ref[r][c][m]))
    return out


def truncation(ta, ua, tb, ub):
    """{(r, component): || u(D) - u(D') || / || u_ref ||} of two runs of one h on two extents."""
    assert np.allclose(ta, tb)
    ref = reference(ta)
    out = {}
    for k, r in enumerate(RECEIVERS):
        m = ta <= window(r) + 1e-12
        for c, (comp, rc) in enumerate((("radial", 0), ("vertical", 2))):
            out[(r, comp)] = float(np.linalg.norm(ua[m, k, rc] - ub[m, k, rc]) / np.linalg.norm(ref[r][c][m]))
    return out


def orders(levels, errs):
    """{(r, component): [order between level i and i + 1]}."""
    out = {}
    for key in errs[levels[0]]:
        out[key] = [math.log(errs[a][key] / errs[b][key]) / math.log(a / b) for a, b in zip(levels, levels[1:])]
    return out


def size_for(levels, errs, key, target):
    """h [m] at which the last two levels' power law reaches the relative error ``target``."""
    a, b = levels[-2], levels[-1]
    p = math.log(errs[a][key] / errs[b][key]) / math.log(a / b)
    return b * (target / errs[b][key]) ** (1.0 / p)


def plot(levels, errs, png):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    lam = wavelength()
    fig, ax = plt.subplots(figsize=(7.5, 5.2))
    hs = np.array(levels)
    marks = {(5.0, "vertical"): ("tab:blue", "o"), (5.0, "radial"): ("tab:blue", "s"),
             (15.0, "vertical"): ("tab:red", "o"), (15.0, "radial"): ("tab:red", "s")}
    for key, (col, mk) in marks.items():
        e = np.array([100 * errs[h][key] for h in levels])
        p = math.log(e[-2] / e[-1]) / math.log(hs[-2] / hs[-1])
        ax.loglog(hs / lam, e, color=col, marker=mk, ls="-" if key[1] == "vertical" else "--",
                  label=f"r = {key[0]:g} m, {key[1]} (last order {p:.2f})")
        for target in (0.01, 0.05):         # the last pair's power law at 1 % and 5 % (x)
            hx = size_for(levels, errs, key, target)
            ax.plot([hx / lam], [100 * target], color=col, marker="x", ms=9, ls="none")
    ref = 100 * errs[levels[-1]][(5.0, "vertical")] * (hs / hs[-1]) ** 2
    ax.loglog(hs / lam, ref, "k:", lw=1, label="slope 2")
    for lvl in (1.0, 5.0):
        ax.axhline(lvl, color="0.5", lw=0.8)
        ax.text(hs.max() / lam, lvl * 1.07, f"{lvl:g} %", fontsize=8, color="0.3", ha="right")
    sec = ax.secondary_xaxis("top", functions=(lambda x: x * lam, lambda x: x / lam))
    sec.set_xlabel("element size h (m)")
    ax.set_xlabel(f"h / lambda_s  (lambda_s = c_s T / 2 = {lam:.2f} m; dt = {BETA:.3f} h / c_s)")
    ax.set_ylabel("relative L2 error vs Pekeris * pulse (%)")
    ax.plot([], [], "kx", ls="none", label="h for 1 % and 5 % (last pair's power law)")
    ax.set_title(f"Lamb's problem, sin^4 pulse T = {T:g} s on [-{A:g}, {A:g}]^2 m, surface {2 * D:g} m")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(png, dpi=120)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--levels", default=",".join(f"{h:g}" for h in LEVELS))
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "convergence_smooth"))
    ap.add_argument("--ranks", type=int, default=2)
    ap.add_argument("--no-truncation", action="store_true")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    levels = [float(v) for v in a.levels.split(",")]
    errs, clean, runs = {}, {}, {}
    for h in levels:
        runs[h] = run_level(h, D, a.out, a.ranks)
        errs[h] = errors(runs[h][0], runs[h][1])
        clean[h] = errors(runs[h][0], runs[h][1], clean=True)
    trunc = {}
    if not a.no_truncation:
        for h, half in ((3.0, 48.0), (1.5, 36.0)):
            if h in runs:
                big = run_level(h, half, a.out, a.ranks)
                trunc[(h, half)] = (truncation(runs[h][0], runs[h][1], big[0], big[1]), errors(big[0], big[1]))
    ords, ords_clean = orders(levels, errs), orders(levels, clean)
    lam = wavelength()
    rows = []
    for h in levels:
        for key, e in errs[h].items():
            i = levels.index(h)
            rows.append({"kind": "error", "h_m": h, "dt_s": BETA * h / CS, "surface_half_width_m": D,
                         "h_per_lambda_s": h / lam, "r_m": key[0], "component": key[1],
                         "window_end_s": window(key[0]), "error_pct": 100 * e,
                         "order_from_previous": ords[key][i - 1] if i else "",
                         "wall_s": runs[h][2], "peak_GB": runs[h][3]})
            rows.append({"kind": "error, diffraction-free window t <= min(t_w, t_d)", "h_m": h, "dt_s": BETA * h / CS,
                         "surface_half_width_m": D, "h_per_lambda_s": h / lam, "r_m": key[0], "component": key[1],
                         "window_end_s": min(window(key[0]), diffraction_free(key[0])),
                         "error_pct": 100 * clean[h][key], "order_from_previous": ords_clean[key][i - 1] if i else "",
                         "wall_s": "", "peak_GB": ""})
    for (h, half), (tr, eb) in trunc.items():
        for key in tr:
            rows.append({"kind": f"truncation: |u(D={D:g} m) - u(D={half:g} m)| / |u_ref|", "h_m": h,
                         "dt_s": BETA * h / CS, "surface_half_width_m": half, "h_per_lambda_s": h / lam,
                         "r_m": key[0], "component": key[1], "window_end_s": window(key[0]),
                         "error_pct": 100 * tr[key], "order_from_previous": "", "wall_s": "", "peak_GB": ""})
            rows.append({"kind": f"error on the larger surface D = {half:g} m", "h_m": h, "dt_s": BETA * h / CS,
                         "surface_half_width_m": half, "h_per_lambda_s": h / lam, "r_m": key[0],
                         "component": key[1], "window_end_s": window(key[0]), "error_pct": 100 * eb[key],
                         "order_from_previous": "", "wall_s": "", "peak_GB": ""})
    names = {"kind": "kind", "h_m": "h [m]", "dt_s": "dt [s]", "surface_half_width_m": "surface half-width D [m]",
             "h_per_lambda_s": "h / lambda_s [-]", "r_m": "r [m]", "component": "component",
             "window_end_s": "window end t_w [s]", "error_pct": "relative L2 error [%]",
             "order_from_previous": "observed order vs previous h [-]", "wall_s": "wall time [s]",
             "peak_GB": "peak memory, all ranks [GB]"}
    with open(os.path.join(HERE, "convergence_smooth.csv"), "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(list(names.values()))
        for r in rows:
            w.writerow([f"{v:.6g}" if isinstance(v, float) else v for v in (r[k] for k in names)])
    plot(levels, errs, os.path.join(HERE, "convergence_smooth.png"))
    lines = [f"lambda_s = c_s T / 2 = {lam:.3f} m, beta = c_s dt / h = {BETA:.4f}, surface half-width D = {D:g} m", "",
             "| r (m) | component | error % at h = " + " / ".join(f"{h:g}" for h in levels) + " m | observed orders | "
             "h for 1 % (h / lambda_s) | h for 5 % (h / lambda_s) |", "|---|---|---|---|---|---|"]
    for key in errs[levels[0]]:
        es = " / ".join(f"{100 * errs[h][key]:.3f}" for h in levels)
        os_ = ", ".join(f"{o:.2f}" for o in ords[key])
        h1, h5 = size_for(levels, errs, key, 0.01), size_for(levels, errs, key, 0.05)
        lines.append(f"| {key[0]:g} | {key[1]} | {es} | {os_} | {h1:.2f} m ({h1 / lam:.3f}) | "
                     f"{h5:.2f} m ({h5 / lam:.3f}) |")
    lines += ["", "The same runs over the diffraction-free window t <= min(t_w, t_d) (t_d: the earliest wave "
              "diffracted at the mesh's edge; at 5 m the window is t_w itself):", "",
              "| r (m) | component | window end (s) | error % at h = " + " / ".join(f"{h:g}" for h in levels) +
              " m | observed orders |", "|---|---|---|---|---|"]
    for key in clean[levels[0]]:
        es = " / ".join(f"{100 * clean[h][key]:.3f}" for h in levels)
        lines.append(f"| {key[0]:g} | {key[1]} | {min(window(key[0]), diffraction_free(key[0])):.4f} | {es} | "
                     + ", ".join(f"{o:.2f}" for o in ords_clean[key]) + " |")
    lines.append("")
    for (h, half), (tr, eb) in trunc.items():
        for key in tr:
            lines.append(f"- truncation at h = {h:g} m, r = {key[0]:g} m, {key[1]}: |u(D = {D:g} m) - u(D = {half:g} m)| "
                         f"/ |u_ref| = {100 * tr[key]:.3f} % (error on D = {half:g} m: {100 * eb[key]:.3f} %, on "
                         f"D = {D:g} m: {100 * errs[h][key]:.3f} %)")
    if (3.0, 48.0) in trunc and (1.5, 36.0) in trunc:
        e3, e15 = trunc[(3.0, 48.0)][1], trunc[(1.5, 36.0)][1]
        lines.append("- the first pair without the mesh edge's diffraction in the window (h = 3 m on D = 48 m, h = 1.5 m "
                     "on D = 36 m): observed orders " + ", ".join(
                         f"r = {k[0]:g} m {k[1]} {math.log(e3[k] / e15[k]) / math.log(2.0):.2f}" for k in e3))
    for h in levels:
        note = ", with the first run's numba compilation" if runs[h][4] else ""
        lines.append(f"- h = {h:g} m, dt = {BETA * h / CS:.4g} s: {runs[h][2]:.0f} s wall{note}, peak {runs[h][3]:.1f} GB "
                     f"(all ranks, {a.ranks} rank(s), a shared machine)")
    text = "\n".join(lines)
    print(text)
    readme = os.path.join(HERE, "README.md")
    body = open(readme).read()
    b, e = "<!-- smooth:begin -->", "<!-- smooth:end -->"
    if b in body:
        i, j = body.index(b) + len(b), body.index(e)
        open(readme, "w").write(body[:i] + "\n" + text + "\n" + body[j:])


if __name__ == "__main__":
    main()
