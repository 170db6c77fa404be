#!/usr/bin/env python3
"""Scaling logs -> CSV, plots and the README table.

  python jobscripts/scaling.py [OUT] [--results DIR] [--readme FILE] [--constants JSON]

Reads OUT/strong-<case>-n<p>.log and OUT/weak-<case>-n<p>.log (written by
strong_scaling.sh / weak_scaling.sh: a '# scaling:' header line, then the
run's output with -log_view -memory_view), and writes

  DIR/scaling.csv          one row per run: time per stage, memory per rank,
                           speed-up and parallel efficiency
  DIR/<study>-<case>.png   time per stage against ranks, efficiency, memory per rank
  README                   the table between <!-- scaling:begin --> and <!-- scaling:end -->

Stages (from -log_view): set-up (stage 'SSI BEM setup'), kernel assembly
(event SSI_BEM_Assembly: integration and triplets), matrix build (the rest of
stage 'SSI BEM assembly' without SSI_BEM_Factor: the lag Mats), factorisation
(SSI_BEM_Factor), history sum (SSI_BEM_History), solve (SSI_BEM_Solve), I/O
(SSI_IO). Memory: -memory_view peak per process (largest rank) and summed.

Efficiency: strong, E_p = T_1 / (p T_p). Weak (the problem grows with p, but
its work grows faster than p: N^2 x lags), per unit of work: E_p =
[W_p / (p T_p)] / [W_1 / T_1] with W the cost model's 1-rank time of each
case (petsc_ssi/bem/cost.py, same for every stage), i.e. the time the run
would take at perfect scaling of its own work. Oversubscribed runs (more ranks
than cores) are flagged in the table and drawn with open markers.
"""
import argparse
import csv
import glob
import os
import re
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
sys.path.insert(0, ROOT)
from logview import parse  # noqa: E402

BEGIN, END = "<!-- scaling:begin -->", "<!-- scaling:end -->"
STAGES = [("setup_s", "set-up"), ("kernels_s", "kernel assembly"), ("matbuild_s", "matrix build"),
          ("factor_s", "factorisation"), ("history_s", "history sum"), ("solve_s", "solve"), ("io_s", "I/O")]


def run_row(path):
    text = open(path, errors="replace").read()
    lv = parse(text)
    m = re.search(r"^# scaling: (.*)$", text, re.M)
    meta = dict(kv.split("=", 1) for kv in m.group(1).split()) if m else {}
    st, ev = lv["stages"], lv["events"]
    e = lambda k: ev.get(k, (0, 0.0))[1]
    g = lambda pat, f=int: (f(re.search(pat, text).group(1)) if re.search(pat, text) else "")
    asm = st.get("SSI BEM assembly", float("nan"))
    p = lv["ranks"] or int(meta.get("ranks", 1))
    row = {"study": meta.get("study", ""), "case": meta.get("case", ""), "ranks": p,
           "oversubscribed": int(meta.get("oversubscribed", 0)), "cores_per_node": meta.get("cores_per_node", ""),
           "dofs": g(r"(\d+) DOFs"), "h_m": g(r"-ssi_mesh_h (\S+)", float), "dt_s": g(r"-ssi_dt (\S+)", float),
           "steps": g(r"(\d+) steps"), "lags": g(r"lags stored (\d+)"),
           "lag_GB": g(r"stored (\S+) GB", float),
           "setup_s": st.get("SSI BEM setup", float("nan")), "kernels_s": e("SSI_BEM_Assembly"),
           "matbuild_s": asm - e("SSI_BEM_Assembly") - e("SSI_BEM_Factor"), "factor_s": e("SSI_BEM_Factor"),
           "history_s": e("SSI_BEM_History"), "solve_s": e("SSI_BEM_Solve"), "io_s": e("SSI_IO"),
           "assembly_s": asm, "time_loop_s": st.get("SSI BEM time loop", float("nan")),
           "total_s": lv["total_s"], "mem_rank_max_GB": (lv.get("peak_rss_max_rank_bytes") or float("nan")) / 1e9,
           "mem_total_GB": (lv["peak_rss_bytes"] or float("nan")) / 1e9, "log": os.path.relpath(path, ROOT)}
    row["_text"] = text
    return row


def model_work(row):
    """The cost model's 1-rank times of the case of a log (for weak efficiency)."""
    try:
        from calibrate import log_options, counts
        from petsc_ssi.bem.cost import predict, load_constants
        c, _ = load_constants(os.environ.get("SSI_ESTIMATE_CONSTANTS", ""))
        cnt = counts(log_options(row["_text"]), [1])
        t = predict(cnt, c, 1, 1, 1)
        return {"total_s": t["total"], "assembly_s": t["assembly"], "history_s": t["history"]}
    except Exception as exc:  # no petsc4py here: strong scaling still works
        print(f"[scaling] no model work for {row['log']}: {exc}", file=sys.stderr)
        return None


def efficiencies(rows):
    groups = {}
    for r in rows:
        groups.setdefault((r["study"], r["case"]), []).append(r)
    for (study, case), rs in groups.items():
        rs.sort(key=lambda r: r["ranks"])
        base = rs[0]
        if study == "weak":
            for r in rs:
                r["_work"] = model_work(r)
        for r in rs:
            p = r["ranks"] / base["ranks"]
            for key in ("total_s", "assembly_s", "history_s"):
                name = key.replace("_s", "")
                if study == "weak":
                    if not (r.get("_work") and base.get("_work")):
                        continue
                    ratio = r["_work"][key] / base["_work"][key]
                    r[f"eff_{name}"] = round(ratio * base[key] / (p * r[key]), 3)
                else:
                    r[f"speedup_{name}"] = round(base[key] / r[key], 3)
                    r[f"eff_{name}"] = round(base[key] / (p * r[key]), 3)
            if study == "weak" and r.get("_work"):
                r["model_work_1rank_s"] = round(r["_work"]["total_s"], 2)
    return groups


def plot(groups, results):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    files = []
    for (study, case), rs in sorted(groups.items()):
        P = [r["ranks"] for r in rs]
        over = [r["oversubscribed"] for r in rs]
        fig, ax = plt.subplots(1, 3, figsize=(15, 4.3))
        colors = plt.get_cmap("tab10").colors
        for i, (key, label) in enumerate(STAGES + [("total_s", "total")]):
            y = [r[key] for r in rs]
            if max(y) < 1e-3:
                continue
            ln, = ax[0].plot(P, y, "-", marker="o", lw=2 if key == "total_s" else 1, label=label,
                             color="k" if key == "total_s" else colors[i])
            for x, yy, o in zip(P, y, over):
                if o:
                    ax[0].plot([x], [yy], "o", mfc="white", mec=ln.get_color())
        if study == "strong":
            t1 = rs[0]["total_s"]
            ax[0].plot(P, [t1 * P[0] / p for p in P], color="0.5", ls=":", label="ideal (total)")
        ax[0].set(xscale="log", yscale="log", xlabel="ranks", ylabel="time (s, -log_view)",
                  title=f"{study} scaling, {case}: time per stage")
        ax[0].set_xticks(P)
        ax[0].set_xticklabels([f"{p}*" if o else str(p) for p, o in zip(P, over)])
        ax[0].legend(fontsize=7, ncol=2)
        for key, label in (("eff_total", "total"), ("eff_assembly", "assembly"), ("eff_history", "history sum")):
            y = [r.get(key, float("nan")) for r in rs]
            ax[1].plot(P, y, "-o", label=label)
        ax[1].axhline(1.0, color="k", ls=":")
        ax[1].set(xscale="log", xlabel="ranks", ylabel="parallel efficiency",
                  title="efficiency" + (" (per unit of modelled work)" if study == "weak" else " T1/(p Tp)"),
                  ylim=(0, 1.2))
        ax[1].set_xticks(P)
        ax[1].set_xticklabels([f"{p}*" if o else str(p) for p, o in zip(P, over)])
        ax[1].legend(fontsize=8)
        ax[2].plot(P, [r["mem_rank_max_GB"] for r in rs], "-o", label="largest rank")
        ax[2].plot(P, [r["mem_total_GB"] / r["ranks"] for r in rs], "-s", label="mean over ranks")
        ax[2].plot(P, [r["mem_total_GB"] for r in rs], "-^", label="sum over ranks")
        ax[2].set(xscale="log", xlabel="ranks", ylabel="peak memory (GB, -memory_view)", title="memory")
        ax[2].set_xticks(P)
        ax[2].set_xticklabels([f"{p}*" if o else str(p) for p, o in zip(P, over)])
        ax[2].legend(fontsize=8)
        for a in ax:
            a.minorticks_off()
        cores = rs[0].get("cores_per_node", "")
        fig.suptitle(f"{study} scaling of {case} on a {cores}-core machine (* = oversubscribed, open markers)",
                     fontsize=10)
        fig.tight_layout()
        f = os.path.join(results, f"{study}-{case}.png")
        fig.savefig(f, dpi=90)
        plt.close(fig)
        files.append(f)
    return files


COLS = ["study", "case", "ranks", "oversubscribed", "dofs", "h_m", "dt_s", "steps", "lags", "lag_GB",
        "setup_s", "kernels_s", "matbuild_s", "factor_s", "history_s", "solve_s", "io_s", "total_s",
        "speedup_total", "eff_total", "eff_assembly", "eff_history", "model_work_1rank_s", "mem_rank_max_GB", "mem_total_GB"]


def fmt(v):
    if isinstance(v, float):
        return f"{v:.3g}" if abs(v) < 100 else f"{v:.1f}"
    return str(v)


def markdown(rows):
    out = ["| " + " | ".join(COLS) + " |", "|" + "---|" * len(COLS)]
    for r in rows:
        out.append("| " + " | ".join(fmt(r.get(c, "")) for c in COLS) + " |")
    return "\n".join(out)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out", nargs="?", default=os.path.join(ROOT, "out", "scaling"))
    ap.add_argument("--results", default=os.path.join(HERE, "results"))
    ap.add_argument("--readme", default=os.path.join(HERE, "README.md"))
    a = ap.parse_args(argv)
    logs = sorted(glob.glob(os.path.join(a.out, "strong-*.log")) + glob.glob(os.path.join(a.out, "weak-*.log")))
    rows = [run_row(p) for p in logs]
    rows = [r for r in rows if r["total_s"]]
    if not rows:
        raise SystemExit(f"scaling: no finished logs in {a.out}")
    groups = efficiencies(rows)
    rows = [r for _, rs in sorted(groups.items()) for r in rs]
    os.makedirs(a.results, exist_ok=True)
    csvf = os.path.join(a.results, "scaling.csv")
    keys = COLS + [k for k in ("speedup_assembly", "speedup_history", "assembly_s", "time_loop_s",
                               "model_work_1rank_s", "cores_per_node", "log") if k not in COLS]
    with open(csvf, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=keys, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    files = plot(groups, a.results)
    if a.readme and os.path.exists(a.readme):
        text = open(a.readme).read()
        if BEGIN in text and END in text:
            pre, rest = text.split(BEGIN, 1)
            _, post = rest.split(END, 1)
            imgs = "\n".join(f"![{os.path.basename(f)}]({os.path.relpath(f, os.path.dirname(a.readme))})"
                             for f in files)
            open(a.readme, "w").write(pre + BEGIN + "\n" + markdown(rows) + "\n\n" + imgs + "\n" + END + post)
    print(f"[scaling] {len(rows)} runs -> {csvf}, {len(files)} plots")


if __name__ == "__main__":
    main()
