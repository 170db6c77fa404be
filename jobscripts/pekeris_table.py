#!/usr/bin/env python3
"""Turn the Pekeris benchmark logs into a CSV and a Markdown table.

  python jobscripts/pekeris_table.py OUTDIR README.md CSV

Reads OUTDIR/pekeris-<case>-n<ranks>.log (-log_view, -memory_view and the
run's own summary lines) and the HDF5 outputs beside them (errors against
Pekeris via petsc_ssi.verify). Rewrites README.md between the markers
<!-- bench:begin --> and <!-- bench:end -->.
"""
import csv
import glob
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from logview import parse  # noqa: E402

BEGIN, END = "<!-- bench:begin -->", "<!-- bench:end -->"


def run_row(log):
    text = open(log).read()
    lv = parse(text)
    m = re.search(r"pekeris-([\w-]+?)-n(\d+)\.log", log)
    case, ranks = m.group(1), int(m.group(2))
    row = {"case": case, "ranks": ranks}
    m = re.search(r"BEM: (\d+) nine-node elements \((\d+) with", text)
    row["elements"] = int(m.group(2)) if m else ""
    m = re.search(r"(\d+) DOFs", text)
    row["dofs"] = int(m.group(1)) if m else ""
    m = re.search(r"dt \S+ s, (\d+) steps", text)
    row["steps"] = int(m.group(1)) if m else ""
    m = re.search(r"lags stored (\d+)", text)
    row["lags"] = int(m.group(1)) if m else ""
    m = re.search(r"stored (\S+) GB", text)
    row["lag_GB"] = float(m.group(1)) if m else ""
    m = re.search(r"mean block fill (\S+)%", text)
    row["fill_pct"] = float(m.group(1)) if m else ""
    st, ev = lv["stages"], lv["events"]
    row["assembly_s"] = round(st.get("SSI BEM assembly", float("nan")), 2)
    row["factor_s"] = round(ev.get("SSI_BEM_Factor", (0, float("nan")))[1], 2)
    row["history_s"] = round(ev.get("SSI_BEM_History", (0, float("nan")))[1], 2)
    row["solve_s"] = round(ev.get("SSI_BEM_Solve", (0, float("nan")))[1], 2)
    row["time_loop_s"] = round(st.get("SSI BEM time loop", float("nan")), 2)
    row["total_s"] = round(lv["total_s"] or float("nan"), 2)
    row["peak_mem_GB"] = round((lv["peak_rss_bytes"] or float("nan")) / 1e9, 2)
    h5 = log[:-4] + ".h5"
    try:
        from petsc_ssi.verify import lamb_errors
        for k, (r, ev_, eh) in enumerate(lamb_errors(h5)):
            row[f"r{k + 1}_m"] = r
            row[f"err_vert_r{k + 1}_pct"] = round(100 * ev_, 2)
            row[f"err_rad_r{k + 1}_pct"] = round(100 * eh, 2)
    except Exception as exc:  # a run that did not finish
        row["note"] = f"no result ({type(exc).__name__})"
    # an interpolated case against the exact run of the same case and ranks
    if case.endswith("-interp"):
        ref = h5.replace(f"pekeris-{case}-", f"pekeris-{case[:-len('-interp')]}-")
        try:
            import h5py
            import numpy as np
            with h5py.File(h5, "r") as a, h5py.File(ref, "r") as b:
                ua, ub = a["receivers/u"][:], b["receivers/u"][:]
            for k in range(ua.shape[1]):
                for c, name in ((2, "vert"), (0, "rad")):
                    row[f"vs_exact_{name}_r{k + 1}_pct"] = round(
                        100 * np.linalg.norm(ua[:, k, c] - ub[:, k, c]) / np.linalg.norm(ub[:, k, c]), 3)
        except OSError:
            pass
    return row


def markdown(rows, cols):
    out = ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    for r in rows:
        out.append("| " + " | ".join(str(r.get(c, "")) for c in cols) + " |")
    return "\n".join(out)


def main(outdir, readme, csvpath):
    order = {"small": 0, "medium": 1, "paper": 2, "paper-interp": 3}
    logs = sorted(glob.glob(os.path.join(outdir, "pekeris-*-n*.log")),
                  key=lambda p: (order.get(re.search(r"pekeris-([\w-]+?)-n\d", p).group(1), 9), p))
    rows = [run_row(l) for l in logs]
    cols = ["case", "ranks", "elements", "dofs", "steps", "lags", "fill_pct", "lag_GB", "assembly_s",
            "factor_s", "history_s", "solve_s", "time_loop_s", "total_s", "peak_mem_GB",
            "r1_m", "err_vert_r1_pct", "err_rad_r1_pct", "r2_m", "err_vert_r2_pct", "err_rad_r2_pct",
            "vs_exact_vert_r1_pct", "vs_exact_rad_r1_pct", "vs_exact_vert_r2_pct", "vs_exact_rad_r2_pct"]
    with open(csvpath, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=cols + ["note"], extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    table = markdown(rows, cols)
    text = open(readme).read()
    i, j = text.index(BEGIN) + len(BEGIN), text.index(END)
    open(readme, "w").write(text[:i] + "\n" + table + "\n" + text[j:])
    print(table)


if __name__ == "__main__":
    main(*sys.argv[1:4])
