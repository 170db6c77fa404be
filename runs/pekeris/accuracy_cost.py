#!/usr/bin/env python3
"""Accuracy against cost on the Lamb/Pekeris case (issue 3): sweep element
size, time step, interpolation method, tau_L and k; plot the error against the
analytic solution versus wall time and versus memory, mark the Pareto front
and the paper's configuration (1 m elements, dt = 7.5e-4 s, Chebyshev from
tau_L = 1.5 with one exact matrix every 5 steps, i.e. -ssi_interp auto).

Base case: small.opts (16 m x 16 m quarter model, receivers at 3 m and 5 m,
t_end = 0.04 s). Error: the largest of the relative L2 errors of u~ over tau
in [0, 2.5] (vertical and radial, both receivers) against the Pekeris solution
for the same loaded square (petsc_ssi.verify). Cost: -log_view total time and
-memory_view peak memory, 1 rank, this machine.

Usage: python runs/pekeris/accuracy_cost.py [--out DIR] [--quick]
Writes accuracy_cost.csv, accuracy_cost_time.png, accuracy_cost_memory.png
here. Runs whose log exists are not repeated.
"""
import argparse
import csv
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "jobscripts"))
sys.path.insert(0, ROOT)
from logview import parse  # noqa: E402

from petsc_ssi.launch import child_env  # noqa: E402

R_FAR, CS = 5.0, 316.0


def configs(quick=False):
    out = []
    grids = [(1.0, 7.5e-4), (1.0, 5e-4), (1.0, 1e-3), (0.5, 3.75e-4), (0.5, 5e-4)]
    if quick:
        grids = grids[:2]
    for h, dt in grids:
        base = {"mesh_h": h, "dt": dt}
        out.append((f"h{h}-dt{dt}-none", base, "none"))
        out.append((f"h{h}-dt{dt}-auto", {**base, "interp": "auto"}, "auto (paper rule)"))
    for meth in ("chebyshev", "linear"):
        for tl in (0.5, 1.0, 1.5):
            for k in ((3, 5) if quick else (3, 5, 8)):
                out.append((f"h1.0-dt0.00075-{meth}-tau{tl}-k{k}",
                            {"mesh_h": 1.0, "dt": 7.5e-4, "interp": meth, "interp_tl": tl * R_FAR / CS,
                             "interp_k": k}, meth))
    return out


def run_one(name, opts, out):
    log = os.path.join(out, name + ".log")
    h5 = os.path.join(out, name + ".h5")
    if not (os.path.exists(log) and "done in" in open(log).read()):
        args = []
        for k, v in opts.items():
            args += [f"-ssi_{k}", str(v)]
        cmd = [sys.executable, "-m", "petsc_ssi", "-options_file", os.path.join(HERE, "small.opts"),
               "-ssi_output", h5, "-ssi_output_overwrite", "-ssi_output_stride", "0", "-ssi_warn_beta", "0", "-log_view",
               "-memory_view"] + args
        print("[sweep]", name, flush=True)
        with open(log, "w") as fh:
            subprocess.run(cmd, stdout=fh, stderr=subprocess.STDOUT, cwd=ROOT, check=True, env=child_env())
    lv = parse(open(log).read())
    from petsc_ssi.verify import lamb_errors
    errs = lamb_errors(h5)
    return {"name": name, "time_s": lv["total_s"], "peak_GB": lv["peak_rss_bytes"] / 1e9,
            "error_pct": 100 * max(max(e[1], e[2]) for e in errs),
            "err_vert_r3": 100 * errs[0][1], "err_rad_r3": 100 * errs[0][2],
            "err_vert_r5": 100 * errs[1][1], "err_rad_r5": 100 * errs[1][2]}


def pareto(rows, key):
    pts = sorted(rows, key=lambda r: (r[key], r["error_pct"]))
    front, best = [], float("inf")
    for r in pts:
        if r["error_pct"] < best:
            front.append(r)
            best = r["error_pct"]
    return front


def smooth_levels():
    """The smooth-pulse convergence study's levels (convergence_smooth.csv, runs/pekeris/convergence_smooth.py):
    [(h [m], r [m], the larger of the radial and vertical relative L2 errors [%], wall [s], peak [GB])]."""
    path = os.path.join(HERE, "convergence_smooth.csv")
    if not os.path.exists(path):
        return []
    best = {}
    with open(path) as fh:
        for r in csv.DictReader(fh):
            if r["kind"] != "error" or not r["wall time [s]"]:
                continue
            key = (float(r["h [m]"]), float(r["r [m]"]))
            err = float(r["relative L2 error [%]"])
            cost = (float(r["wall time [s]"]), float(r["peak memory, all ranks [GB]"]))
            if key not in best or err > best[key][0]:
                best[key] = (err, *cost)
    return [(h, rr, *v) for (h, rr), v in sorted(best.items())]


def plot(rows, key, label, png):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    smooth = smooth_levels()
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(13, 5), gridspec_kw={"width_ratios": [1.5, 1]})
    _smooth_panel(ax2, smooth, key, label)
    styles = {"none": ("k", "o"), "auto (paper rule)": ("tab:red", "*"), "chebyshev": ("tab:blue", "s"),
              "linear": ("tab:green", "^")}
    for kind, (c, m) in styles.items():
        sel = [r for r in rows if r["kind"] == kind]
        if sel:
            ax.scatter([r[key] for r in sel], [r["error_pct"] for r in sel], c=c, marker=m, s=40 if m != "*" else 120,
                       label=kind, alpha=0.85, edgecolors="none")
    fr = pareto(rows, key)
    ax.plot([r[key] for r in fr], [r["error_pct"] for r in fr], "k--", lw=1, label="Pareto front")
    paper = [r for r in rows if r["name"] == "h1.0-dt0.00075-auto"]
    if paper:
        ax.annotate("paper's configuration", (paper[0][key], paper[0]["error_pct"]), xytext=(15, 25),
                    textcoords="offset points", arrowprops=dict(arrowstyle="->"))
    for r in rows:
        if r["kind"] == "none":
            ax.annotate(r["name"].replace("-none", ""), (r[key], r["error_pct"]), fontsize=7,
                        xytext=(4, -10), textcoords="offset points")
    ax.set_xscale("log"); ax.set_yscale("log")
    ax.set_xlabel(label); ax.set_ylabel("max relative L2 error vs Pekeris (%)")
    ax.set_title("Heaviside load (the paper's), 16 m x 16 m quarter model, 1 rank", fontsize=10)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(png, dpi=120)
    plt.close(fig)


def _smooth_panel(ax, smooth, key, label):
    """The smooth pulse's levels (error at r = 5 m and 15 m against the level's cost), beside the sweep."""
    col = 3 if key == "time_s" else 4
    # the h = 3 m level's wall held the first run's numba compilation (386 s against 53 s at h = 1.5 m):
    # no time point for it, its memory stands
    for rr, c in ((5.0, "tab:blue"), (15.0, "tab:orange")):
        sel = [v for v in smooth if v[1] == rr and not (key == "time_s" and v[0] == 3.0)]
        if not sel:
            continue
        ax.plot([v[col] for v in sel], [v[2] for v in sel], "-o", c=c, label=f"smooth pulse, r = {rr:g} m")
        for v in sel:
            ax.annotate(f"h = {v[0]:g} m", (v[col], v[2]), fontsize=7, xytext=(4, 4), textcoords="offset points")
    for y in (1.0, 5.0):
        ax.axhline(y, color="0.6", lw=0.8, ls=":")
    ax.set_xscale("log"); ax.set_yscale("log")
    ax.set_xlabel(label.replace("1 rank", "2 ranks") + (" (h = 3 m left out: its wall held numba's compilation)"
                                                         if key == "time_s" else ""))
    ax.set_ylabel("max relative L2 error vs convolved Pekeris (%)")
    ax.set_title("smooth pulse sin^4 (T = 0.03 s), 48 m quarter model, 2 ranks\n(convergence_smooth.py; "
                 "dotted: 1 % and 5 %)", fontsize=10)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "sweep"))
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--replot", action="store_true", help="redraw the PNGs from accuracy_cost.csv and "
                    "convergence_smooth.csv without running")
    a = ap.parse_args()
    if a.replot:
        with open(os.path.join(HERE, "accuracy_cost.csv")) as fh:
            rows = [{k: (v if k in ("name", "kind") else float(v)) for k, v in r.items()} for r in csv.DictReader(fh)]
        plot(rows, "time_s", "wall time, 1 rank (s)", os.path.join(HERE, "accuracy_cost_time.png"))
        plot(rows, "peak_GB", "peak memory (GB)", os.path.join(HERE, "accuracy_cost_memory.png"))
        return
    os.makedirs(a.out, exist_ok=True)
    rows = []
    for name, opts, kind in configs(a.quick):
        r = run_one(name, opts, a.out)
        r["kind"] = kind
        rows.append(r)
    with open(os.path.join(HERE, "accuracy_cost.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    plot(rows, "time_s", "wall time, 1 rank (s)", os.path.join(HERE, "accuracy_cost_time.png"))
    plot(rows, "peak_GB", "peak memory (GB)", os.path.join(HERE, "accuracy_cost_memory.png"))
    for r in sorted(rows, key=lambda r: r["error_pct"]):
        print(f"{r['name']:45s} err {r['error_pct']:6.2f}%  {r['time_s']:7.1f} s  {r['peak_GB']:.2f} GB")


if __name__ == "__main__":
    main()
