"""Figs. 15 and 16 of the paper for the building on the half-space, the peak table, the
comparisons (half vs full, bonded vs unilateral, 1 vs 2 ranks) and the benchmark table.

  .venv/bin/python runs/building/ssi_figures.py            (from the repository root)

Reads the runs of runs/building/ssi-*.opts written as out/building/<case>-n<ranks>.h5 (+
_structure.h5, .json) and their logs out/building/logs/<case>-n<ranks>.log (-log_view
-memory_view), see runs/building/README.md "On the half-space" for the commands. Writes into
runs/building/:
  ssi_fig15.png        u~ = pi mu |u| r / p0 of soil and structure at t = 0.35 s (3-D view of the
                       deformed soil surface and building, and the section y = 0)
  ssi_fig16.png        x1 and vertical accelerations at A (roof centre) and B (foundation centre):
                       time histories and spectra (FFT, zero-padded to 2^15 points, peaks marked)
  ssi_accelerations.csv, ssi_spectra.csv, ssi_peaks.csv, ssi_compare.csv, ssi_bench.csv
and the tables between the markers <!-- ssi-halfspace-*:begin/end --> of README.md.
"""
import csv
import glob
import json
import os
import re
import sys

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
OUT = os.path.join(ROOT, "out", "building")
README = os.path.join(HERE, "README.md")

CS, RHO, P0 = 100.0, 1800.0, 1000.0
MU = RHO * CS ** 2
XL = 14.5                                   # load centre (x, 0)
T_SNAP = 0.35
NFFT = 2 ** 15
PAPER = [("f1", 3.09, "x1 1st"), ("f4", 10.48, "x1 2nd"), ("f7", 17.70, "x1 3rd"),
         ("f9", 19.76, "?"), ("f11", 28.01, "slab bending"), ("f12", 29.73, "slab bending")]
# fixed-base modes of the paper's building (runs/building/README.md, Fig. 14 table)
FIXED = [(1, 3.8779, "x2 1st"), (2, 3.9151, "x1 1st"), (3, 4.2316, "torsion 1st"),
         (4, 12.3357, "x2 2nd"), (5, 12.4149, "x1 2nd"), (6, 13.4733, "torsion 2nd"),
         (7, 21.0527, "x2 3rd"), (8, 21.0967, "x1 3rd"), (9, 23.1085, "torsion 3rd"),
         (10, 29.0215, "slab bending, sym"), (11, 30.2531, "slab bending, anti x"),
         (12, 31.1304, "slab bending, anti y")]
CASES = ["ssi-full-bonded", "ssi-full-unilateral", "ssi-half-bonded", "ssi-half-unilateral",
         "ssi-full-bonded-ny4", "ssi-full-bonded-released"]
RELEASED = "ssi-full-bonded-released"
# fixed-base modes of the building with released slabs: runs/building/modes_release.csv (modes_figure.py)
RELEASE_CSV = os.path.join(HERE, "modes_release.csv")


def fixed_released():
    """[(mode, f, kind)] of the released-slab building on a fixed base, or None."""
    if not os.path.exists(RELEASE_CSV):
        return None
    with open(RELEASE_CSV) as fh:
        rows = list(csv.DictReader(fh))
    return [(int(r["mode_released"]), float(r["f_released_hz"]), r["kind_released"].replace(" (", " ").replace(")", ""))
            for r in rows]
PRIMARY = "ssi-full-bonded"

sys.path.insert(0, HERE)


def find(case):
    """The run of a case: 2 ranks preferred, else 1 rank; None if not run."""
    for n in (2, 1):
        p = os.path.join(OUT, f"{case}-n{n}.h5")
        if os.path.exists(p):
            return p
    return None


def structure(path):
    s = path[:-3] + "_structure.h5"
    with h5py.File(s, "r") as f:
        r = f["receivers"]
        return dict(t=r["t"][:], u=r["u"][:], a=r["acceleration"][:], v=r["velocity"][:],
                    points=r["points"][:])


def mixed_topology(topo):
    quads, lines, i = [], [], 0
    while i < topo.size:                     # XDMF mixed: 5 = quad, 2 = polyline (2, n)
        t = int(topo[i])
        if t == 5:
            quads.append(topo[i + 1:i + 5]); i += 5
        elif t == 2:
            n = int(topo[i + 1]); lines.append(topo[i + 2:i + 2 + n]); i += 2 + n
        else:
            raise ValueError(f"unexpected XDMF cell type {t}")
    return np.array(quads, np.int64).reshape(-1, 4), np.array(lines, np.int64).reshape(-1, 2)


def snapshot(path, t_snap=T_SNAP):
    """Soil and structure fields at the snapshot closest to t_snap, mirrored about y = 0 for a
    half model (ymin = 0)."""
    with h5py.File(path, "r") as f:
        ts = f["time"][:]
        k = int(np.argmin(np.abs(ts - t_snap)))
        soil = dict(X=f["coordinates"][:], u=f[f"displacement_{k:06d}"][:], cells=f["topology"][:], t=ts[k])
    with h5py.File(path[:-3] + "_structure.h5", "r") as f:
        ts2 = f["time"][:]
        k2 = int(np.argmin(np.abs(ts2 - t_snap)))
        q, l = mixed_topology(f["topology"][:])
        st = dict(X=f["coordinates"][:], u=f[f"displacement_{k2:06d}"][:], quads=q, lines=l, t=ts2[k2])
    if soil["X"][:, 1].min() > -1e-9:        # half model: mirror
        for d, cq in ((soil, "cells"), (st, "quads")):
            n = len(d["X"])
            Xm = d["X"] * [1, -1, 1]
            um = d["u"] * [1, -1, 1]
            d["X"] = np.vstack([d["X"], Xm]); d["u"] = np.vstack([d["u"], um])
            d[cq] = np.vstack([d[cq], d[cq] + n])
            if cq == "quads":
                d["lines"] = np.vstack([d["lines"], d["lines"] + n])
    return soil, st


def utilde(X, u):
    r = np.hypot(X[:, 0] - XL, X[:, 1])
    return np.pi * MU * np.linalg.norm(u, axis=1) * r / P0


def fig15(path, png):
    import matplotlib
    matplotlib.use("Agg")
    from modes_figure import _venv_mpl_toolkits
    _venv_mpl_toolkits(matplotlib)
    import matplotlib.pyplot as plt
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection, Line3DCollection
    soil, st = snapshot(path)
    us, ub = utilde(soil["X"], soil["u"]), utilde(st["X"], st["u"])
    vmax = float(np.percentile(np.concatenate([us, ub]), 99.5))
    umax = max(np.abs(soil["u"]).max(), np.abs(st["u"]).max())
    umax_b = np.abs(st["u"]).max()
    scale = 1.0 / umax_b                     # the building's largest displacement drawn as 1 m
    cmap = matplotlib.colormaps["viridis"]
    norm = matplotlib.colors.Normalize(0, vmax)
    fig = plt.figure(figsize=(13, 5.6))
    ax = fig.add_subplot(1, 2, 1, projection="3d", computed_zorder=False)
    c9 = soil["cells"]
    sub = np.concatenate([c9[:, [0, 4, 8, 7]], c9[:, [4, 1, 5, 8]], c9[:, [8, 5, 2, 6]], c9[:, [7, 8, 6, 3]]])
    Y = soil["X"] + scale * soil["u"]
    Y[:, 2] = np.clip(Y[:, 2], -3, 3)         # the wave front far from the building: clipped at 3 m
    pc = Poly3DCollection(Y[sub], facecolors=cmap(norm(us[sub].mean(axis=1))), edgecolors="none", zorder=1)
    ax.add_collection3d(pc)
    Ys = st["X"] + scale * st["u"]
    if len(st["quads"]):
        ax.add_collection3d(Poly3DCollection(Ys[st["quads"]], facecolors=cmap(norm(ub[st["quads"]].mean(axis=1))),
                                             edgecolors=(0, 0, 0, 0.15), linewidths=0.2, zorder=2))
    if len(st["lines"]):
        ax.add_collection3d(Line3DCollection(Ys[st["lines"]], colors=cmap(norm(ub[st["lines"]].mean(axis=1))),
                                             linewidths=0.8, zorder=3))
    ax.set_xlim(-18, 18); ax.set_ylim(-18, 18); ax.set_zlim(-6, 12)
    ax.set_box_aspect((36, 36, 18))
    ax.view_init(elev=28, azim=-60)
    ax.set_xlabel("x1 [m]"); ax.set_ylabel("x2 [m]"); ax.set_zlabel("z [m]")
    ax.set_title(f"u~ = pi mu |u| r / p0 at t = {soil['t']:.3g} s (displacements x {scale:.3g}; soil clipped at +-3 m)", fontsize=9)
    fig.colorbar(matplotlib.cm.ScalarMappable(norm=norm, cmap=cmap), ax=ax, shrink=0.6, label="u~")
    # section y = 0: soil surface nodes (free field) and the foundation slab's nodes (interface)
    ax2 = fig.add_subplot(1, 2, 2)
    on = np.abs(soil["X"][:, 1]) < 1e-6
    o = np.argsort(soil["X"][on, 0])
    xs, U = soil["X"][on, 0][o], soil["u"][on][o]
    r = np.abs(xs - XL)
    for c, name, sty in ((2, "u~_z", "-"), (0, "u~_x", "--")):
        ax2.plot(xs, np.pi * MU * U[:, c] * r / P0, "k" + sty, lw=1, label=f"soil {name}")
    fo = (np.abs(st["X"][:, 1]) < 1e-6) & (np.abs(st["X"][:, 2]) < 1e-6)
    o = np.argsort(st["X"][fo, 0])
    xf, Uf = st["X"][fo, 0][o], st["u"][fo][o]
    rf = np.abs(xf - XL)
    ax2.plot(xf, np.pi * MU * Uf[:, 2] * rf / P0, "o", ms=3, mfc="none", color="tab:red", label="foundation u~_z")
    ax2.plot(xf, np.pi * MU * Uf[:, 0] * rf / P0, "s", ms=3, mfc="none", color="tab:blue", label="foundation u~_x")
    ro = (np.abs(st["X"][:, 1]) < 1e-6) & (np.abs(st["X"][:, 2] - st["X"][:, 2].max()) < 1e-6)
    o = np.argsort(st["X"][ro, 0])
    ax2.plot(st["X"][ro, 0][o], np.pi * MU * st["u"][ro][o][:, 0] * np.abs(st["X"][ro, 0][o] - XL) / P0, ":",
             color="tab:blue", label="roof u~_x")
    ax2.axvspan(-7.2, 7.2, color="0.9", zorder=0)
    ax2.axvline(XL, color="0.5", lw=0.8)
    ax2.set_xlabel("x1 [m] (y = 0; grey: building, line: load)")
    ax2.set_ylabel("u~ = pi mu u r / p0")
    ax2.set_title(f"section y = 0, t = {soil['t']:.3g} s ({os.path.basename(path)})", fontsize=9)
    ax2.legend(fontsize=7)
    ax2.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(png, dpi=130)
    plt.close(fig)
    return dict(max_soil=float(us.max()), max_structure=float(ub.max()), t=float(soil["t"]))


def spectrum(t, a):
    dt = t[1] - t[0]
    F = np.abs(np.fft.rfft(a, NFFT)) * dt
    f = np.fft.rfftfreq(NFFT, dt)
    return f, F


def peaks(f, F, fmax=40.0, rel=0.04):
    from scipy.signal import find_peaks
    m = (f > 0.5) & (f < fmax)
    i0 = np.nonzero(m)[0][0]
    idx, _ = find_peaks(F[m], prominence=rel * F[m].max())
    idx = idx + i0
    return [(float(f[i]), float(F[i])) for i in idx]


def fig16(path, png, csv_acc, csv_spec):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    s = structure(path)
    t, a = s["t"], s["a"]
    fig, axs = plt.subplots(2, 2, figsize=(12, 7))
    found = {}
    spec_cols = {}
    for col, (c, name) in enumerate(((0, "x1 (in-plane)"), (2, "vertical"))):
        for rcv, lab, color in ((0, "A (roof centre)", "0.6"), (1, "B (foundation centre)", "k")):
            axs[0, col].plot(t, a[:, rcv, c], color=color, lw=1, label=lab)
            f, F = spectrum(t, a[:, rcv, c])
            axs[1, col].plot(f, F, color=color, lw=1, label=lab)
            pk = peaks(f, F)
            found[(rcv, c)] = pk
            spec_cols[f"{'AB'[rcv]}_{'xyz'[c]}"] = F
            top = sorted(pk, key=lambda p: -p[1])[:8]
            for fp, Fp in top:
                axs[1, col].plot(fp, Fp, "v", color="tab:red" if rcv == 0 else "tab:blue", ms=5)
                axs[1, col].annotate(f"{fp:.2f}", (fp, Fp), textcoords="offset points", xytext=(2, 4), fontsize=7,
                                     color="tab:red" if rcv == 0 else "tab:blue")
        axs[0, col].set_title(f"{name} acceleration", fontsize=10)
        axs[0, col].set_xlabel("t [s]"); axs[0, col].set_ylabel("a [m/s^2]")
        axs[1, col].set_xlabel("f [Hz]"); axs[1, col].set_ylabel("|A(f)| [m/s]")
        axs[1, col].set_xlim(0, 40)
        for ff in [p[1] for p in PAPER]:
            axs[1, col].axvline(ff, color="tab:green", lw=0.6, ls=":")
        for a_ in axs[:, col]:
            a_.legend(fontsize=8); a_.grid(alpha=0.3)
    fig.suptitle(f"Fig. 16: accelerations at A and B ({os.path.basename(path)}); dotted green: the paper's peaks",
                 fontsize=10)
    fig.tight_layout()
    fig.savefig(png, dpi=130)
    plt.close(fig)
    with open(csv_acc, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["t_s", "aA_x", "aA_z", "aB_x", "aB_z", "uA_x", "uA_z", "uB_x", "uB_z"])
        for k in range(len(t)):
            w.writerow([f"{t[k]:.6g}"] + [f"{v:.6e}" for v in (a[k, 0, 0], a[k, 0, 2], a[k, 1, 0], a[k, 1, 2],
                                                               s["u"][k, 0, 0], s["u"][k, 0, 2], s["u"][k, 1, 0],
                                                               s["u"][k, 1, 2])])
    f, _ = spectrum(t, a[:, 0, 0])
    keep = f <= 50
    with open(csv_spec, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["f_hz"] + list(spec_cols))
        for k in np.nonzero(keep)[0]:
            w.writerow([f"{f[k]:.5f}"] + [f"{spec_cols[c][k]:.6e}" for c in spec_cols])
    return found


def peak_table(found, fixed=FIXED):
    """Match the paper's peaks with the peaks found (A and B, x and z spectra) and the fixed-base modes."""
    allp = []
    for (rcv, c), pk in found.items():
        top = max(F for _, F in pk) if pk else 1.0
        for f, F in pk:
            allp.append((f, F / top, f"{'AB'[rcv]} {'x1' if c == 0 else 'z'}"))
    rows = []
    for name, fp, kind in PAPER:
        near = [p for p in allp if abs(p[0] - fp) <= 0.2 * fp]
        if near:
            # the most prominent nearby peak (relative height in its own spectrum)
            best = max(near, key=lambda p: p[1] - abs(p[0] - fp) / fp)
            f, rel, where = best
        else:
            f, rel, where = float("nan"), float("nan"), "-"
        # only the modes symmetric about y = 0 (x1 sway, slab bending) can be excited by this load
        sym = [m for m in fixed if m[0] in (2, 5, 8, 10, 11)]
        fb = min(sym, key=lambda m: abs(m[1] - (f if np.isfinite(f) else fp)))
        rows.append(dict(paper=name, paper_hz=fp, paper_kind=kind, ssi_hz=f, rel_height=rel, spectrum=where,
                         diff_pct=100 * (f - fp) / fp if np.isfinite(f) else float("nan"),
                         fixed_mode=fb[0], fixed_hz=fb[1], fixed_kind=fb[2],
                         shift_pct=100 * (f - fb[1]) / fb[1] if np.isfinite(f) else float("nan")))
    return rows, sorted(allp)


def rel_diff(a, b):
    n = min(len(a), len(b))
    return float(np.abs(a[:n] - b[:n]).max() / max(np.abs(b[:n]).max(), 1e-300))


def compare():
    rows = []
    pairs = [("ssi-half-bonded", "ssi-full-bonded-ny4", "half vs full (4 y-bays), bonded"),
             ("ssi-half-unilateral", "ssi-half-bonded", "unilateral vs bonded, half"),
             ("ssi-full-unilateral", "ssi-full-bonded", "unilateral vs bonded, full"),
             ("ssi-full-bonded-ny4", "ssi-full-bonded", "4 y-bays vs 3 y-bays (paper), full bonded"),
             ("ssi-full-bonded-released", "ssi-full-bonded", "slabs released vs monolithic, full bonded")]
    for a, b, what in pairs:
        pa, pb = find(a), find(b)
        if not (pa and pb):
            continue
        sa, sb = structure(pa), structure(pb)
        r = dict(what=what, a=os.path.basename(pa), b=os.path.basename(pb))
        for rcv in (0, 1):
            for c in (0, 2):
                r[f"acc_{'AB'[rcv]}{'xyz'[c].replace('y', '')}"] = rel_diff(sa["a"][:, rcv, c], sb["a"][:, rcv, c])
                r[f"u_{'AB'[rcv]}{'xyz'[c].replace('y', '')}"] = rel_diff(sa["u"][:, rcv, c], sb["u"][:, rcv, c])
        rows.append(r)
    for case in CASES:                      # ranks
        p1, p2 = os.path.join(OUT, f"{case}-n1.h5"), os.path.join(OUT, f"{case}-n2.h5")
        if os.path.exists(p1) and os.path.exists(p2):
            sa, sb = structure(p2), structure(p1)
            r = dict(what=f"2 ranks vs 1 rank, {case}", a=os.path.basename(p2), b=os.path.basename(p1))
            for rcv in (0, 1):
                for c in (0, 2):
                    r[f"acc_{'AB'[rcv]}{'xyz'[c].replace('y', '')}"] = rel_diff(sa["a"][:, rcv, c], sb["a"][:, rcv, c])
                    r[f"u_{'AB'[rcv]}{'xyz'[c].replace('y', '')}"] = rel_diff(sa["u"][:, rcv, c], sb["u"][:, rcv, c])
            rows.append(r)
    return rows


def contact_summary(path):
    with h5py.File(path, "r") as f:
        it = f["interface"]
        nopen = it["n_open"][:]
        pN = it["pN"][:]
        return dict(max_open=int(nopen.max()), changes=int(it["changes"][:].sum()),
                    max_tension=float(pN.max()), min_pN=float(pN.min()),
                    eq=float(np.abs(it["force_fe"][:] + it["force_be"][:]).max() /
                             max(np.abs(it["force_be"][:]).max(), 1e-300)))


STAGES = {"SSI setup": "setup", "SSI FEM assembly": "fem_assembly", "SSI BEM assembly": "bem_assembly",
          "SSI time loop": "time_loop"}


def parse_log(path):
    out = {}
    txt = open(path, errors="replace").read()
    m = re.search(r"Summary of Stages:.*?\n(.*?)\n\n", txt, re.S)
    if m:
        for line in m.group(1).splitlines():
            mm = re.match(r"\s*\d+:\s+(.+?):\s+([0-9.eE+-]+)", line)
            if mm and mm.group(1).strip() in STAGES:
                out[STAGES[mm.group(1).strip()]] = float(mm.group(2))
    mm = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): (\S+)", txt)
    if mm:
        parts = [float(x) for x in mm.group(1).split(":")]
        out["wall_process"] = sum(p * 60 ** (len(parts) - 1 - i) for i, p in enumerate(parts))
    mm = re.search(r"Maximum \(over computational time\) process memory:\s+total\s+([0-9.eE+-]+)\s+max\s+([0-9.eE+-]+)",
                   txt)
    if mm:
        out["mem_total_petsc"], out["mem_max_rank_petsc"] = float(mm.group(1)), float(mm.group(2))
    return out


def bench():
    rows = []
    for case in CASES:
        for n in (1, 2):
            h5 = os.path.join(OUT, f"{case}-n{n}.h5")
            js = h5[:-3] + ".json"
            if not os.path.exists(js):
                continue
            st = json.load(open(js))["stats"]
            r = dict(case=case, ranks=n, wall=st["wall_s"], bem_lag_assembly=st["assembly_s"],
                     interface_setup=st["capacitance_setup_s"], lags_GB=st["lag_bytes"] / 1e9,
                     peak_rank_GB=st["peak_rss_max_rank_bytes"] / 1e9, peak_sum_GB=st["peak_rss_sum_bytes"] / 1e9)
            lg = os.path.join(OUT, "logs", f"{case}-n{n}.log")
            if os.path.exists(lg):
                r.update(parse_log(lg))
            rows.append(r)
    return rows


def write_csv(path, rows):
    if not rows:
        return
    keys = list(rows[0])
    for r in rows[1:]:
        keys += [k for k in r if k not in keys]
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, keys)
        w.writeheader()
        for r in rows:
            w.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in r.items()})


def fmt(v, d=3):
    if isinstance(v, float):
        return "-" if not np.isfinite(v) else f"{v:.{d}g}"
    return str(v)


def md_table(rows, cols, heads):
    s = "| " + " | ".join(heads) + " |\n|" + "---|" * len(heads) + "\n"
    for r in rows:
        s += "| " + " | ".join(fmt(r.get(c, "-")) for c in cols) + " |\n"
    return s


def replace_block(text, name, body):
    b, e = f"<!-- ssi-halfspace-{name}:begin -->", f"<!-- ssi-halfspace-{name}:end -->"
    if b in text and e in text:
        i, j = text.index(b), text.index(e)
        return text[:i + len(b)] + "\n" + body + text[j:]
    return text


def main():
    prim = find(PRIMARY) or find("ssi-half-bonded")
    if prim is None:
        sys.exit("no run found in out/building (see runs/building/README.md)")
    f15 = fig15(prim, os.path.join(HERE, "ssi_fig15.png"))
    print(f"Fig. 15 from {prim}: t = {f15['t']:.3g} s, max u~ soil {f15['max_soil']:.3g}, "
          f"structure {f15['max_structure']:.3g}")
    found = fig16(prim, os.path.join(HERE, "ssi_fig16.png"), os.path.join(HERE, "ssi_accelerations.csv"),
                  os.path.join(HERE, "ssi_spectra.csv"))
    rows, allp = peak_table(found)
    write_csv(os.path.join(HERE, "ssi_peaks.csv"), rows)
    for r in rows:
        print(f"  {r['paper']} {r['paper_hz']:6.2f} Hz -> {fmt(r['ssi_hz'], 4)} Hz ({r['spectrum']}, "
              f"{fmt(r['diff_pct'])} %), fixed-base mode {r['fixed_mode']} {r['fixed_hz']} Hz ({r['fixed_kind']})")
    print("  all peaks (f, height relative to the spectrum's largest, spectrum):",
          ", ".join(f"{f:.2f} ({h:.2f} {w})" for f, h, w in allp))
    rel_rows = None
    prel = find(RELEASED)
    if prel is not None and fixed_released() is not None:
        import tempfile
        with tempfile.TemporaryDirectory() as tmp:
            found_rel = fig16(prel, os.path.join(HERE, "ssi_fig16_released.png"), os.path.join(tmp, "a.csv"),
                              os.path.join(tmp, "s.csv"))
        rel_rows, _ = peak_table(found_rel, fixed_released())
        write_csv(os.path.join(HERE, "ssi_peaks_released.csv"), rel_rows)
        for r in rel_rows:
            print(f"  released: {r['paper']} {r['paper_hz']:6.2f} Hz -> {fmt(r['ssi_hz'], 4)} Hz ({r['spectrum']}, "
                  f"{fmt(r['diff_pct'])} %), fixed-base mode {r['fixed_mode']} {r['fixed_hz']} Hz ({r['fixed_kind']})")
    cmp_rows = compare()
    write_csv(os.path.join(HERE, "ssi_compare.csv"), cmp_rows)
    for r in cmp_rows:
        print("  " + r["what"] + ": " + ", ".join(f"{k} {v:.2e}" for k, v in r.items() if isinstance(v, float)))
    cont = []
    for case in CASES:
        p = find(case)
        if p:
            c = contact_summary(p)
            c["case"] = os.path.basename(p)
            cont.append(c)
            print(f"  {c['case']}: max open {c['max_open']}, changes {c['changes']}, max interface tension "
                  f"{c['max_tension']:.4g} N/m^2, equilibrium {c['eq']:.2e}")
    b = bench()
    write_csv(os.path.join(HERE, "ssi_bench.csv"), b)
    for r in b:
        print("  bench " + ", ".join(f"{k} {fmt(v)}" for k, v in r.items()))
    text = open(README).read()
    text = replace_block(text, "peaks", md_table(
        rows, ["paper", "paper_hz", "paper_kind", "ssi_hz", "diff_pct", "spectrum", "rel_height", "fixed_mode",
               "fixed_hz", "fixed_kind", "shift_pct"],
        ["paper", "paper [Hz]", "paper's kind", "here (SSI) [Hz]", "here vs paper [%]", "spectrum", "rel. height",
         "fixed-base mode", "fixed-base [Hz]", "kind", "SSI shift [%]"]))
    if rel_rows is not None:
        text = replace_block(text, "peaks-released", md_table(
            rel_rows, ["paper", "paper_hz", "paper_kind", "ssi_hz", "diff_pct", "spectrum", "rel_height",
                       "fixed_mode", "fixed_hz", "fixed_kind", "shift_pct"],
            ["paper", "paper [Hz]", "paper's kind", "here, slabs released (SSI) [Hz]", "here vs paper [%]",
             "spectrum", "rel. height", "fixed-base mode (released)", "fixed-base [Hz]", "kind", "SSI shift [%]"]))
    text = replace_block(text, "compare", md_table(
        cmp_rows, ["what", "acc_Ax", "acc_Az", "acc_Bx", "acc_Bz", "u_Ax", "u_Az", "u_Bx", "u_Bz"],
        ["comparison", "a_x A", "a_z A", "a_x B", "a_z B", "u_x A", "u_z A", "u_x B", "u_z B"]))
    text = replace_block(text, "contact", md_table(
        cont, ["case", "max_tension", "min_pN", "max_open", "changes", "eq"],
        ["run", "max interface tension p_N [N/m^2]", "min p_N [N/m^2]", "max open nodes", "status changes",
         "max |f_fe + f_be| / max |f_be|"]))
    text = replace_block(text, "bench", md_table(
        b, ["case", "ranks", "wall", "wall_process", "setup", "fem_assembly", "bem_assembly", "time_loop",
            "lags_GB", "peak_rank_GB", "peak_sum_GB", "mem_max_rank_petsc"],
        ["case", "ranks", "run [s] (json)", "process [s]", "set-up [s]", "FEM assembly [s]",
         "BEM assembly [s]", "time loop [s]", "lags [GB]", "peak RSS per rank [GB]", "peak RSS all ranks [GB]",
         "PETSc max process memory [B]"]))
    open(README, "w").write(text)


if __name__ == "__main__":
    main()
