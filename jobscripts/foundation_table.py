#!/usr/bin/env python3
"""Table of the foundation benchmark from its logs (-log_view: stages, events)
and the runs' JSON records (contact statistics; peak RSS from getrusage, which
unlike -memory_view's samples also catches the transient peak of the BEM
assembly): writes the CSV and the table
between <!-- ssi-bench:begin/end --> in the README.

    python jobscripts/foundation_table.py OUT README CSV
"""
import csv
import glob
import json
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from logview import parse  # noqa: E402

COLS = ["case", "ranks", "wall [s]", "BEM assembly [s]", "BEM factor [s]", "interface set-up [s]",
        "time loop [s]", "per step [ms]", "peak RSS, all ranks [GB]", "peak RSS per rank [GB]", "lags stored [GB]", "status changes",
        "steps with changes", "interface LUs", "cost per change [ms]", "max open nodes"]


def row(log):
    m = re.search(r"foundation-(.+)-n(\d+)\.log$", log)
    case, n = m.group(1), int(m.group(2))
    text = open(log).read()
    lv = parse(text)
    rec = json.load(open(log[:-4] + ".json"))
    st = rec.get("stats", {})
    import h5py
    with h5py.File(log[:-4] + ".h5", "r") as f:
        g = f["interface"]
        changes = g["changes"][:]
        nopen = g["n_open"][:]
        steps = len(g["t"][:])
    ev = lv["events"]
    loop = lv["stages"].get("SSI time loop", float("nan"))
    nch = int(changes.sum())
    per = (ev.get("SSI_Contact", (0, 0.0))[1] / nch * 1e3) if nch else float("nan")
    return {"case": case, "ranks": n, "wall [s]": lv["total_s"],
            "BEM assembly [s]": st.get("assembly_s"), "BEM factor [s]": st.get("bem_factor_s"),
            "interface set-up [s]": st.get("capacitance_setup_s"), "time loop [s]": loop,
            "per step [ms]": 1e3 * loop / steps, "peak RSS, all ranks [GB]": st.get("peak_rss_sum_bytes", float("nan")) / 1e9,
            "peak RSS per rank [GB]": st.get("peak_rss_max_rank_bytes", float("nan")) / 1e9,
            "lags stored [GB]": st.get("lag_bytes", 0) / 1e9, "status changes": nch,
            "steps with changes": int((changes > 0).sum()), "interface LUs": st.get("capacitance_factorisations"),
            "cost per change [ms]": per, "max open nodes": int(nopen.max())}


def fmt(v):
    if isinstance(v, float):
        return "-" if v != v else f"{v:.3g}"
    return str(v)


def main(out, readme, csvpath):
    logs = sorted(glob.glob(os.path.join(out, "foundation-*-n*.log")))
    rows = [row(l) for l in logs]
    order = ["sym-bonded", "sym-unilateral", "anti-bonded", "anti-unilateral", "anti-unilateral-cohesive",
             "sym-bonded-staggered"]
    rows.sort(key=lambda r: (order.index(r["case"]) if r["case"] in order else 9, r["ranks"]))
    with open(csvpath, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=COLS)
        w.writeheader()
        w.writerows(rows)
    lines = ["| " + " | ".join(COLS) + " |", "|" + "---|" * len(COLS)]
    lines += ["| " + " | ".join(fmt(r[c]) for c in COLS) + " |" for r in rows]
    try:
        la = open("/proc/loadavg").read().split()[:3]
        lines += ["", f"Load average (1, 5, 15 min) after the runs: {', '.join(la)}; machine: {os.cpu_count()} cores."]
    except OSError:
        pass
    text = open(readme).read()
    a, b = "<!-- ssi-bench:begin -->", "<!-- ssi-bench:end -->"
    new = a + "\n" + "\n".join(lines) + "\n" + b
    text = re.sub(re.escape(a) + ".*?" + re.escape(b), new, text, flags=re.S) if a in text else text + "\n" + new + "\n"
    open(readme, "w").write(text)
    print("\n".join(lines))


if __name__ == "__main__":
    main(*sys.argv[1:4])
