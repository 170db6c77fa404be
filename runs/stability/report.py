"""Figures and README tables of runs/stability from the CSVs (no numbers typed by hand).

Called by stability_map.py at the end of a sweep and by --plot-only.
"""
import csv
import os
import re

SYMBOL = {"stable": "S", "slowly growing": "G", "unstable": "U"}
COLOUR = {"stable": "tab:green", "slowly growing": "tab:orange", "unstable": "tab:red"}
TAU_R = 1.0877


def read(path):
    if not os.path.exists(path):
        return []
    with open(path) as fh:
        rows = list(csv.DictReader(fh))
    for r in rows:
        for k in ("h", "beta", "rate", "dt", "beta_p_min", "norm_late", "norm_plateau", "wall_s"):
            r[k] = float(r[k]) if r.get(k) not in (None, "") else float("nan")
        for k in ("steps_run", "steps_planned", "lags", "cut"):
            r[k] = int(r[k])
    return rows


def _cell(r):
    if r["cut"]:
        return f"U (blow-up, step {r['steps_run']})"
    return f"{SYMBOL[r['class']]} ({_rate(r['rate'])})"


def _rate(x):
    return "~0" if abs(x) < 1e-6 else f"{x:.1e}"


# ---------------------------------------------------------------- map
def map_table(rows, scheme):
    sel = [r for r in rows if r["scheme"] == scheme]
    if not sel:
        return []
    betas = sorted({r["beta"] for r in sel})
    hs = sorted({r["h"] for r in sel})
    out = [f"**{scheme}** (rows: element size h [m]; columns: beta = c_s dt / l, l = h/2)", "",
           "| h \\ beta | " + " | ".join(f"{b:g}" for b in betas) + " |",
           "|---|" + "---|" * len(betas)]
    for h in hs:
        cells = []
        for b in betas:
            m = [r for r in sel if r["h"] == h and r["beta"] == b]
            cells.append(_cell(m[0]) if m else "not run")
        out.append(f"| {h:g} | " + " | ".join(cells) + " |")
    return out


def summary(rows):
    """Per scheme and h: the largest beta that is not stable, and the beta from
    which every larger beta of the grid is stable."""
    out = ["| scheme | h [m] | largest beta not stable (class) | stable for every beta >= | runs | wall time (s) |",
           "|---|---|---|---|---|---|"]
    for scheme in ("plain", "stabilized"):
        for h in sorted({r["h"] for r in rows}):
            sel = sorted([r for r in rows if r["scheme"] == scheme and r["h"] == h], key=lambda r: r["beta"])
            if not sel:
                continue
            bad = [r for r in sel if r["class"] != "stable"]
            worst = f"{bad[-1]['beta']:g} ({bad[-1]['class']})" if bad else "none"
            above = None
            for r in reversed(sel):
                if r["class"] != "stable":
                    break
                above = r["beta"]
            out.append(f"| {scheme} | {h:g} | {worst} | {'-' if above is None else f'{above:g}'} | {len(sel)} | "
                       f"{sum(r['wall_s'] for r in sel):.0f} |")
    return out


def guard_summary(rows):
    """Where the default guard (factor 100) stops, per class."""
    out = ["| class | runs | stopped by the default guard (factor 100) | guard step / onset step (median, max) |",
           "|---|---|---|---|"]
    for cls in ("stable", "slowly growing", "unstable"):
        sel = [r for r in rows if r["class"] == cls]
        if not sel:
            continue
        hit = [r for r in sel if r["guard100_step"] not in ("", None)]
        ratios = sorted(float(r["guard100_step"]) / float(r["onset_step"]) for r in hit if r["onset_step"])
        rs = f"{ratios[len(ratios) // 2]:.2f}, {ratios[-1]:.2f}" if ratios else "-"
        out.append(f"| {cls} | {len(sel)} | {len(hit)} | {rs} |")
    return out


def map_plot(rows, scheme, png):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    sel = [r for r in rows if r["scheme"] == scheme]
    if not sel:
        return
    fig, ax = plt.subplots(figsize=(9, 3.8))
    ax.axvspan(0.3, 0.8, color="tab:blue", alpha=0.12, label="paper's range 0.3 < beta < 0.8")
    for cls, col in COLOUR.items():
        s = [r for r in sel if r["class"] == cls]
        ax.scatter([r["beta"] for r in s], [r["h"] for r in s], s=260, marker="s", c=col, label=cls,
                   edgecolors="k", linewidths=0.5)
    for r in sel:
        txt = f"x@{r['steps_run']}" if r["cut"] else ("~0" if abs(r["rate"]) < 1e-6 else f"{r['rate']:.0e}")
        ax.annotate(txt, (r["beta"], r["h"]), xytext=(0, 11), textcoords="offset points", ha="center", fontsize=6.5)
    ax.set_xscale("log")
    bet = sorted({r["beta"] for r in sel})
    ax.set_xticks(bet)
    ax.set_xticklabels([f"{b:g}" for b in bet])
    ax.minorticks_off()
    hs = sorted({r["h"] for r in sel})
    ax.set_yticks(hs)
    ax.set_ylim(min(hs) - 0.35, max(hs) + 0.45)
    ax.set_xlabel("beta = c_s dt / l   (l = h/2, node spacing)")
    ax.set_ylabel("element size h (m)")
    ax.set_title(f"{scheme} scheme: Lamb problem, 6 m x 6 m quarter model, max(1000, 3L) steps "
                 "(label: late growth rate per step; x@n: blow-up at step n)", fontsize=8)
    ax.legend(fontsize=7, loc="lower right", ncol=4)
    fig.tight_layout()
    fig.savefig(png, dpi=120)
    plt.close(fig)


# ---------------------------------------------------------------- interpolation
def interp_table(rows, method):
    sel = [r for r in rows if r["interp"] == method]
    taus = sorted({float(r["tau_L"]) for r in sel})
    ks = sorted({int(r["k"]) for r in sel})
    out = [f"**{method}** (rows: tau_L = c_s T_L / r, r = 3 m; columns: k; cell: class, deviation of u_z at r from "
           "the exact-lag run)", "", "| tau_L \\ k | " + " | ".join(str(k) for k in ks) + " |",
           "|---|" + "---|" * len(ks)]
    for t in taus:
        cells = []
        for k in ks:
            m = [r for r in sel if float(r["tau_L"]) == t and int(r["k"]) == k]
            if not m:
                cells.append("not run")
                continue
            r = m[0]
            dev = f", {float(r['dev_pct']):.3g}%" if r["dev_pct"] not in ("", None) else ""
            cells.append(f"{SYMBOL[r['class']]}{dev}" if not r["cut"] else f"U (blow-up, step {r['steps_run']})")
        out.append(f"| {t:g}{' (< tau_R)' if t < TAU_R else ''} | " + " | ".join(cells) + " |")
    return out


def interp_plot(rows, png):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axs = plt.subplots(1, 2, figsize=(10, 4), sharey=True)
    for ax, meth in zip(axs, ("chebyshev", "linear")):
        sel = [r for r in rows if r["interp"] == meth]
        for cls, col in COLOUR.items():
            s = [r for r in sel if r["class"] == cls]
            ax.scatter([int(r["k"]) for r in s], [float(r["tau_L"]) for r in s], s=300, marker="s", c=col,
                       label=cls, edgecolors="k", linewidths=0.5)
        for r in sel:
            if r["dev_pct"] not in ("", None):
                ax.annotate(f"{float(r['dev_pct']):.2g}%", (int(r["k"]), float(r["tau_L"])), xytext=(0, 12),
                            textcoords="offset points", ha="center", fontsize=7)
        ax.axhline(TAU_R, color="k", ls="--", lw=1, label="Rayleigh arrival tau_R = 1.0877")
        ax.set_xlabel("interpolating matrices k")
        ax.set_title(f"{meth}", fontsize=9)
        ax.set_xticks(sorted({int(r["k"]) for r in sel}) or [0])
    axs[0].set_ylabel("tau_L = c_s T_L / r  (r = 3 m)")
    axs[1].legend(fontsize=7, loc="upper right")
    fig.suptitle("Lag interpolation, stabilised scheme, dt = 7.5e-4 s, 1 m elements (beta = 0.47), 12 m x 12 m "
                 "quarter model, 1000 steps (label: max deviation of u_z at r = 3 m from exact lags)", fontsize=8)
    fig.tight_layout()
    fig.savefig(png, dpi=120)
    plt.close(fig)


def history_plot(rows, outdir, png):
    """|u^n| of the h = 1 m runs of both schemes (from the saved .npy histories)."""
    import numpy as np
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axs = plt.subplots(1, 2, figsize=(10, 3.8), sharey=True)
    found = False
    for ax, scheme in zip(axs, ("plain", "stabilized")):
        sel = sorted([r for r in rows if r["scheme"] == scheme and r["h"] == 1.0], key=lambda r: r["beta"])
        for r in sel:
            f = os.path.join(outdir, r["case"] + ".npy")
            if not os.path.exists(f):
                continue
            un = np.load(f)
            found = True
            ax.semilogy(np.arange(1, len(un) + 1) / r["lags"], un, lw=0.9, label=f"beta {r['beta']:g}")
        ax.set_title(f"{scheme}, h = 1 m", fontsize=9)
        ax.set_xlabel("step / causal lag count L")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=6, ncol=2)
    axs[0].set_ylabel("|u^n| (m)")
    axs[0].set_ylim(1e-7, 1e2)
    axs[0].set_xlim(0, 4)
    fig.tight_layout()
    if found:
        fig.savefig(png, dpi=120)
    plt.close(fig)


def precision_table(prec, mp):
    """Per scheme: h x beta cells 'double class -> single class' of the map's runs and their single-precision
    repeats (-ssi_lag_single_from), and the single run's final norm relative to the double one's."""
    out = []
    for scheme in ("plain", "stabilized"):
        sel = [r for r in prec if r["scheme"] == scheme]
        if not sel:
            continue
        betas = sorted({r["beta"] for r in sel})
        out += [f"**{scheme}**: class double -> single (final |u| single / double - 1, where both ran to the end)", "",
                "| h \\ beta | " + " | ".join(f"{b:g}" for b in betas) + " |", "|---|" + "---|" * len(betas)]
        for h in sorted({r["h"] for r in sel}):
            cells = []
            for b in betas:
                s1 = [r for r in sel if r["h"] == h and r["beta"] == b]
                d1 = [r for r in mp if r["scheme"] == scheme and r["h"] == h and r["beta"] == b]
                if not s1 or not d1:
                    cells.append("not run")
                    continue
                s1, d1 = s1[0], d1[0]
                c = f"{SYMBOL[d1['class']]} -> {SYMBOL[s1['class']]}"
                if not s1["cut"] and not d1["cut"] and d1["norm_late"] > 0:
                    c += f" ({s1['norm_late'] / d1['norm_late'] - 1:.1e})"
                elif s1["cut"] or d1["cut"]:
                    c += f" (blow-up step {d1['steps_run'] if d1['cut'] else '-'} / {s1['steps_run'] if s1['cut'] else '-'})"
                cells.append(c)
            out.append(f"| {h:g} | " + " | ".join(cells) + " |")
        out.append("")
    same = sum(1 for r in prec for d in mp if d["scheme"] == r["scheme"] and d["h"] == r["h"]
               and d["beta"] == r["beta"] and d["class"] == r["class"])
    out.append(f"Same class in {same} of {len(prec)} cases.")
    return out


def replace_block(text, name, lines):
    b, e = f"<!-- BEGIN {name} -->", f"<!-- END {name} -->"
    block = b + "\n" + "\n".join(lines) + "\n" + e
    if b in text:
        return re.sub(re.escape(b) + ".*?" + re.escape(e), lambda m: block, text, flags=re.S)
    return text + "\n" + block + "\n"


def report(here, outdir):
    mp = read(os.path.join(here, "stability_map.csv"))
    ip = read(os.path.join(here, "stability_interp.csv"))
    readme = os.path.join(here, "README.md")
    text = open(readme).read() if os.path.exists(readme) else "# Stability maps\n"
    if mp:
        for scheme in ("plain", "stabilized"):
            map_plot(mp, scheme, os.path.join(here, f"stability_map_{scheme}.png"))
        history_plot(mp, outdir, os.path.join(here, "stability_histories.png"))
        tab = []
        for scheme in ("plain", "stabilized"):
            tab += map_table(mp, scheme) + [""]
        text = replace_block(text, "map-table", tab)
        text = replace_block(text, "map-summary", summary(mp))
        text = replace_block(text, "guard-summary", guard_summary(mp + ip))
    pp = read(os.path.join(here, "stability_precision.csv"))
    if pp and mp:
        text = replace_block(text, "precision-table", precision_table(pp, mp))
    if ip:
        ipi = [r for r in ip if r["interp"] != "none"]
        interp_plot(ipi, os.path.join(here, "stability_interp.png"))
        ex = [r for r in ip if r["interp"] == "none"]
        tab = []
        if ex:
            tab += [f"Exact lags (reference): {_cell(ex[0])}, {ex[0]['lags']} lags, "
                    f"{ex[0]['wall_s']:.0f} s.", ""]
        for meth in ("chebyshev", "linear"):
            tab += interp_table(ipi, meth) + [""]
        text = replace_block(text, "interp-table", tab)
    with open(readme, "w") as fh:
        fh.write(text)
    print(f"[stability] wrote {readme} and the figures")
