#!/usr/bin/env python3
"""The table of jobscripts/precision_bench.sh: per case, the all-double run and the run with lags from
SINGLE_FROM on in single precision (-ssi_lag_single_from), both at 2 ranks; from each run's -log_view
(stages, -memory_view peak), its log (stored lag GB, the run's own memory estimate), the
`petsc-ssi estimate` of the same options (predicted peak) and its receivers (difference single -
double relative to the double run's maximum, and both runs' error against Pekeris, petsc_ssi.verify).

  python jobscripts/precision_table.py OUT [SINGLE_FROM]

Writes jobscripts/results/precision.csv, jobscripts/results/precision.png (the difference against
time) and the table between <!-- precision:begin --> and <!-- precision:end --> in
jobscripts/README.md and runs/pekeris/README.md."""
import glob
import os
import re
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
sys.path.insert(0, ROOT)
from logview import parse, write_csv, put_block  # noqa: E402


def receivers(h5):
    import h5py
    with h5py.File(h5) as f:
        return f["receivers/t"][...], f["receivers/u"][...]


def row_of(log):
    text = open(log).read()
    prec, case = re.search(r"(double|single)-([\w-]+)\.log$", log).groups()
    lv = parse(text)
    st = lv["stages"]
    stored = re.search(r"\] assembly .*stored ([\d.e+-]+) GB", text)
    run_est = re.search(r"memory estimate: lag matrices ([\d.e+-]+) GB .*peak ([\d.e+-]+) GB", text)
    est = open(log.replace(".log", ".estimate")).read() if os.path.exists(log.replace(".log", ".estimate")) else ""
    pred = None                  # the 2-rank row: "[ssi] ranks nodes | times | total | peak_GB GB/rank_max GB/node | fits"
    for line in est.splitlines():
        parts = line.split("|")
        if len(parts) >= 4 and parts[0].split()[1:2] == ["2"]:
            pred = float(parts[3].split()[0])
    peak = (lv.get("peak_rss_bytes") or np.nan) / 1e9
    r = {"case": case, "precision": prec, "total_s": round(lv["total_s"], 1),
         "assembly_s": round(st.get("SSI BEM assembly", np.nan), 1),
         "time_loop_s": round(st.get("SSI BEM time loop", np.nan), 1),
         "lags_GB": float(stored.group(1)) if stored else np.nan,
         "lags_GB_estimated": float(run_est.group(1)) if run_est else np.nan,
         "peak_GB": round(peak, 2),
         "peak_GB_run_estimate": float(run_est.group(2)) if run_est else np.nan,
         "peak_GB_estimate_cmd": pred if pred is not None else np.nan}
    return r


def main(out, single_from):
    from petsc_ssi.verify import lamb_errors
    rows = [row_of(p) for p in sorted(glob.glob(os.path.join(out, "*.log")))]
    curves = {}
    for r in rows:
        h5 = os.path.join(out, f"{r['precision']}-{r['case']}.h5")
        errs = lamb_errors(h5)
        r["pekeris_err_z"] = " / ".join(f"{e[1]:.4f}" for e in errs)
        if r["precision"] == "single":
            ref = os.path.join(out, f"double-{r['case']}.h5")
            t, a = receivers(h5)
            _, b = receivers(ref)
            d = np.abs(a - b).max(axis=(1, 2)) / np.abs(b).max()
            r["receivers_vs_double"] = f"{d.max():.1e}"
            curves[r["case"]] = (t, d)
    order = {"double": 0, "single": 1}
    rows.sort(key=lambda r: (r["case"], order[r["precision"]]))
    write_csv(os.path.join(HERE, "results", "precision.csv"), rows)
    f = lambda v, u="": "-" if v != v else f"{v:.3g}{u}"
    lines = ["| case | lags | total | assembly | time loop | lags stored (estimated) | peak, all ranks | "
             "run's estimate | `petsc-ssi estimate` | receivers vs double | error vs Pekeris (z; per receiver) |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lab = "double" if r["precision"] == "double" else f"single from lag {single_from}"
        lines.append(f"| {r['case']} | {lab} | {r['total_s']} s | {r['assembly_s']} s | {r['time_loop_s']} s | "
                     f"{f(r['lags_GB'], ' GB')} ({f(r['lags_GB_estimated'], ' GB')}) | {f(r['peak_GB'], ' GB')} | "
                     f"{f(r['peak_GB_run_estimate'], ' GB')} | {f(r['peak_GB_estimate_cmd'], ' GB')} | "
                     f"{r.get('receivers_vs_double', '-')} | {r['pekeris_err_z']} |")
    by = {(r["case"], r["precision"]): r for r in rows}
    notes = []
    for case in sorted({r["case"] for r in rows}):
        d, s = by.get((case, "double")), by.get((case, "single"))
        if d and s:
            notes.append(f"- {case}: lags {d['lags_GB']:.3g} -> {s['lags_GB']:.3g} GB "
                         f"({s['lags_GB'] / d['lags_GB']:.0%}), peak {d['peak_GB']} -> {s['peak_GB']} GB, "
                         f"time loop {d['time_loop_s']} -> {s['time_loop_s']} s, total {d['total_s']} -> "
                         f"{s['total_s']} s; estimated peak / measured: run {s['peak_GB_run_estimate'] / s['peak_GB']:.2f}"
                         f", `petsc-ssi estimate` {s['peak_GB_estimate_cmd'] / s['peak_GB']:.2f} (double: "
                         f"{d['peak_GB_run_estimate'] / d['peak_GB']:.2f}, {d['peak_GB_estimate_cmd'] / d['peak_GB']:.2f})")
    block = "\n".join(lines + [""] + notes) + "\n"
    put_block("precision", block, (os.path.join(HERE, "README.md"), os.path.join(ROOT, "runs", "pekeris", "README.md")))
    if curves:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(7, 4))
        for case, (t, d) in sorted(curves.items()):
            ax.semilogy(t, np.maximum(d, 1e-18), label=case)
        ax.set_xlabel("t (s)")
        ax.set_ylabel("max |u_single - u_double| / max |u_double|")
        ax.set_title(f"receivers, lags from {single_from} in single precision (2 ranks)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
        fig.tight_layout()
        fig.savefig(os.path.join(HERE, "results", "precision.png"), dpi=120)
    print(block)


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "out/bench/precision", sys.argv[2] if len(sys.argv) > 2 else "3")
