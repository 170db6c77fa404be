#!/usr/bin/env python3
"""The building's soil alone against the exact half-space (jobscripts/building_soil_exact.sh): each run's
soil receivers (y = 0; u_x, u_z) against the exact surface displacement of its own load, a uniform pressure
p0 (H(t) - H(t - T0)) on a square patch (``petsc_ssi.analytic.pekeris.patch_displacement``: the point-load
solution integrated over the patch, for the soil's nu; the box as the difference of two steps).

Errors per receiver and component, over its first 0.5 s (the direct waves: the Rayleigh pulse from the load
has passed every receiver, x = -10 m included, by 0.3 s) and after (the late response, where the exact one is
the static offset of the pulse, zero: what remains is the mesh's edges and the interpolated far lags):
  peak    (max|u| - max|u_ref|) / max|u_ref|, t <= 0.5 s
  history max|u - u_ref| / max|u_ref|, t <= 0.5 s and t > 0.5 s (max|u_ref| over the whole run)
Each run's log is checked for the load it should carry (its traction nodes and p0).

    python jobscripts/building_soil_exact.py OUTDIR [--print]

Writes runs/building/building_soil_exact.csv (every receiver of every run), building_soil_exact.png (u_z
at two receivers, every run and the exact solution) and the table between
<!-- building-soil-exact:begin/end --> of runs/building/README.md; --print: the table on stdout only.
"""
import csv
import os
import re
import sys

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, ROOT)
sys.path.insert(0, HERE)
from building_uniform_table import fmt, md, put  # noqa: E402

CP, CS, RHO, T0 = 208.0, 100.0, 1800.0, 0.025       # ssi-common.opts: the soil and the box's duration
P15 = 1000.0 / 1.44
# run: (soil mesh, load centre x [m], half-width [m], p0 [N/m^2], what its log must show: the traction nodes of
# its loaded cells, or an area load's line)
AREA = "-ssi_load_area 14,15,-0.5,0.5: its lag vectors"
EXACT = " (every lag exact)"
RUNS = {"today": ("graded 36 x 36 m (building_soil.geo)", 14.5, 0.5, 1000.0, 9),
        "today-exact": ("graded 36 x 36 m (building_soil.geo)" + EXACT, 14.5, 0.5, 1000.0, 9),
        "uniform-36-1m": ("uniform 36 x 37 m, 1 m cells", 14.5, 0.5, 1000.0, 9),
        "uniform-72-1m": ("uniform 72 x 73 m, 1 m cells", 14.5, 0.5, 1000.0, 9),
        "uniform-72-area": ("uniform 72 x 73.2 m, 1.2 m cells, the load as an area", 14.5, 0.5, 1000.0, AREA),
        "uniform-72-area-exact": ("uniform 72 x 73.2 m, 1.2 m cells, the load as an area" + EXACT, 14.5, 0.5, 1000.0,
                                  AREA),
        "today-load15": ("graded 36 x 36 m (building_soil.geo)", 15.0, 0.6, P15, 9),
        "uniform-36": ("uniform 36 x 37.2 m, 1.2 m cells", 15.0, 0.6, P15, 9),
        "uniform-72": ("uniform 72 x 73.2 m, 1.2 m cells", 15.0, 0.6, P15, 9),
        "uniform-72-exact": ("uniform 72 x 73.2 m, 1.2 m cells" + EXACT, 15.0, 0.6, P15, 9),
        "uniform-36-h06": ("uniform 36 x 37.2 m, 0.6 m cells, dt 2.5 ms", 15.0, 0.6, P15, 25),
        # the smooth load (a 0.1 s Hann pulse), every lag exact
        "today-smooth": ("graded 36 x 36 m (building_soil.geo)" + EXACT, 14.5, 0.5, 1000.0, 9, "hann"),
        "today-fine-smooth": ("graded 36 x 36 m refined (cells <= 1.5 m)" + EXACT, 14.5, 0.5, 1000.0, 9, "hann"),
        "uniform-36-area-smooth": ("uniform 36 x 37.2 m, 1.2 m cells, the load as an area" + EXACT, 14.5, 0.5, 1000.0,
                                   AREA, "hann"),
        "uniform-72-area-smooth": ("uniform 72 x 73.2 m, 1.2 m cells, the load as an area" + EXACT, 14.5, 0.5, 1000.0,
                                   AREA, "hann")}
HANN_T, HANN_DT, FINE = 0.1, 1e-3, 1e-4     # s: the pulse, its table's rows (building_soil_exact.sh), the ramps' grid
EARLY = 0.5     # s: the direct waves (t <= EARLY) and the late response (t > EARLY)


def exact(x, y, t, xl, a, p0, history="box"):
    """(u_x, u_z) [m] of the load at the surface point (x, y) at times t: the box as two steps, or the tabulated
    Hann pulse (``exact_table``)."""
    from petsc_ssi.analytic.pekeris import patch_displacement
    if history == "hann":
        return exact_table(x, y, t, xl, a, p0)
    step = lambda tt: np.array(patch_displacement(x - xl, y, np.maximum(tt, 0.0), a, a, p0, CS, CP, RHO))
    u = step(t) - np.where(t > T0, 1.0, 0.0) * step(t - T0)
    return u[0], u[2]


def exact_table(x, y, t, xl, a, p0):
    """(u_x, u_z) [m] under p0 p(t), p the run's table (sin^2(pi t / HANN_T) at rows HANN_DT apart, linear
    between them): sum over the rows' segments of slope_k (R(t - t_k) - R(t - t_k+1)), R the ramp response,
    the step response (``patch_displacement``) integrated in time on a FINE grid (trapezoids; the patch's
    response is continuous, so the error is O(FINE^2))."""
    from petsc_ssi.analytic.pekeris import patch_displacement
    tf = np.arange(0.0, float(t.max()) + 1.5 * FINE, FINE)
    U = np.array(patch_displacement(x - xl, y, tf, a, a, p0, CS, CP, RHO))
    R = np.concatenate([np.zeros((3, 1)), np.cumsum(0.5 * FINE * (U[:, 1:] + U[:, :-1]), axis=1)], axis=1)
    rows = np.arange(0.0, HANN_T + 0.5 * HANN_DT, HANN_DT)
    v = np.sin(np.pi * rows / HANN_T) ** 2
    out = np.zeros_like(R)
    step = int(round(HANN_DT / FINE))
    for k, s in enumerate(np.diff(v) / HANN_DT):
        for sh, sign in ((k * step, 1.0), ((k + 1) * step, -1.0)):
            out[:, sh:] += sign * s * R[:, :R.shape[1] - sh]
    return np.interp(t, tf, out[0]), np.interp(t, tf, out[2])


def check_log(outdir, name):
    """The run's DOFs, steps and wall [s]; SystemExit when its log shows another load than RUNS says."""
    text = open(os.path.join(outdir, name + ".log"), errors="replace").read()
    m = re.search(r"(\d+) DOFs;(?: (\d+) traction nodes;)? dt (\S+) s, (\d+) steps", text)
    want = RUNS[name][4]
    if len(RUNS[name]) > 5 and "-ssi_load_history table" not in text:
        sys.exit(f"{name}: its log does not show the tabulated load history")
    if not m or (want not in text if isinstance(want, str) else int(m.group(2) or 0) != want):
        sys.exit(f"{name}: its log does not show its load ({want!r})")
    if "(every lag exact)" in RUNS[name][0] and "lag interpolation: none" not in text:
        sys.exit(f"{name}: its log does not say that every lag is exact")
    wall = re.search(r"done in (?:(\d+)m)?([\d.]+)s", text)
    peak = re.search(r"sampled peak RSS over the ranks: ([\d.]+) GB", text)
    return (int(m.group(1)), int(m.group(4)), 60 * float(wall.group(1) or 0) + float(wall.group(2)) if wall else float("nan"),
            float(peak.group(1)) if peak else float("nan"))


_EXACT = {}


def errors(outdir, name):
    """Rows per receiver and component, and the series for the plot."""
    _, xl, a, p0, _ = RUNS[name][:5]
    history = RUNS[name][5] if len(RUNS[name]) > 5 else "box"
    with h5py.File(os.path.join(outdir, name + ".h5"), "r") as f:
        if abs(float(f.attrs["load_p0"]) - p0) > 1e-9 * p0:
            sys.exit(f"{name}: load_p0 {f.attrs['load_p0']} in its output, not {p0}")
        t, u, pts = f["receivers/t"][:], f["receivers/u"][:], f["receivers/points"][:]
    rows, series = [], {}
    for i, p in enumerate(pts):
        key = (float(p[0]), float(p[1]), xl, a, p0, history, len(t), float(t[-1]))
        if key not in _EXACT:          # (the smooth runs share their receivers: their reference made once)
            _EXACT[key] = exact(p[0], p[1], t, xl, a, p0, history)
        ux, uz = _EXACT[key]
        for c, ref in ((0, ux), (2, uz)):
            q = f"x = {p[0]:g} m u_{'xz'[c // 2]}"
            series[q] = (t, u[:, i, c], ref)
            row = {"run": name, "receiver": q}
            pr = float(np.abs(ref).max()) or float("nan")            # (no wave yet: a short check's window)
            e, late = t <= EARLY + 1e-12, t > EARLY + 1e-12
            row[f"peak error, t <= {EARLY:g} s [%]"] = 100 * (float(np.abs(u[e, i, c]).max()) - pr) / pr
            row[f"history error, t <= {EARLY:g} s [%]"] = 100 * float(np.abs(u[e, i, c] - ref[e]).max()) / pr
            row[f"history error, t > {EARLY:g} s [%]"] = (100 * float(np.abs(u[late, i, c] - ref[late]).max()) / pr
                                                          if late.any() else float("nan"))
            rows.append(row)
    return rows, series


def summary(outdir, name, rows):
    dofs, steps, wall, peak = check_log(outdir, name)
    mesh, xl, a, p0, _ = RUNS[name][:5]
    hist = "0.1 s Hann pulse" if len(RUNS[name]) > 5 else "25 ms box"
    out = {"run": name, "soil mesh": mesh, "load": f"{2 * a:g} m square at x = {xl:g} m, p0 = {p0:.4g} N/m^2, {hist}",
           "soil DOFs": dofs, "steps": steps, "wall [s]": wall, "peak RSS [GB]": peak}
    for key in (f"peak error, t <= {EARLY:g} s [%]", f"history error, t <= {EARLY:g} s [%]",
                f"history error, t > {EARLY:g} s [%]"):
        v = np.array([r[key] for r in rows])
        ok = np.isfinite(v).any()
        out["largest " + key.replace(" error", " error (abs.)")] = float(np.nanmax(np.abs(v))) if ok else float("nan")
        out["median " + key.replace(" error", " error (abs.)")] = float(np.nanmedian(np.abs(v))) if ok else float("nan")
    return out


def plot(all_series, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    qs = ["x = 10 m u_z", "x = -10 m u_z"]
    fig, axs = plt.subplots(len(qs), 2, figsize=(12, 7), sharex=True)
    for row, q in enumerate(qs):
        for col, group in enumerate((("today", "today-exact", "uniform-72-area", "uniform-72-area-exact"),
                                     ("today-load15", "uniform-72", "uniform-72-exact", "uniform-36-h06"))):
            ax = axs[row, col]
            ref = None
            for name in group:
                if name in all_series and q in all_series[name]:
                    t, u, ref_n = all_series[name][q]
                    ax.plot(t, 1e6 * u, lw=1, label=name)
                    ref = (t, ref_n) if ref is None else ref
            if ref is not None:
                ax.plot(ref[0], 1e6 * ref[1], "k--", lw=1, label="exact (half-space)")
            ax.set_title(f"{q}, load {'1 m at x = 14.5 m' if col == 0 else '1.2 m at x = 15 m'}", fontsize=9)
            ax.set_ylabel("displacement u_z [um] (+z up)")
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7)
    for ax in axs[-1]:
        ax.set_xlabel("time t [s]")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main(outdir, *flags):
    names = [n for n in RUNS if os.path.exists(os.path.join(outdir, n + ".h5"))]
    per, summ, series = [], [], {}
    for n in names:
        rows, s = errors(outdir, n)
        per += rows
        series[n] = s
        summ.append(summary(outdir, n, rows))
    cols = list(summ[0]) if summ else []
    lines = md(summ, cols)
    if "--print" in flags:
        print("\n".join(lines))
        print("\n".join(md(per, list(per[0]))))
        return
    put(os.path.join(ROOT, "runs/building/README.md"), "building-soil-exact", [""] + lines + [""])
    with open(os.path.join(ROOT, "runs/building/building_soil_exact.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(per[0]))
        w.writeheader()
        w.writerows({k: (fmt(v) if isinstance(v, float) else v) for k, v in r.items()} for r in per)
    plot(series, os.path.join(ROOT, "runs/building/building_soil_exact.png"))
    print("\n".join(lines))


if __name__ == "__main__":
    main(*sys.argv[1:])
