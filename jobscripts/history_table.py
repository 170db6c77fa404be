#!/usr/bin/env python3
"""The table of jobscripts/history_bench.sh: per case, the code before the time-blocked history sum
and this one at 2 ranks, and this one at 1 rank; from the runs' -log_view and -memory_view.

  python jobscripts/history_table.py OUT

Reads OUT/{before,after}-<case>-n<ranks>.log, the HDF5 outputs beside them and OUT/dgemm_rate.txt;
writes jobscripts/results/history_block.csv and the table between <!-- history:begin --> and
<!-- history:end --> in jobscripts/README.md and runs/pekeris/README.md."""
import glob
import os
import re
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
from logview import parse, write_csv, put_block  # noqa: E402

def row_of(log):
    text = open(log).read()
    m = re.search(r"(before|after)-([\w-]+?)-n(\d+)\.log", log)
    lv = parse(text)
    st, ev = lv["stages"], lv["events"]
    hist = re.search(r"^SSI_BEM_History\s.*\s(\d+)\s*$", text, re.M)       # last column: total Mflop/s
    blk = re.search(r"time-blocked, (\d+) steps per block", text)
    sub = re.search(r"in sub-blocks of (\d+)", text)
    lags = re.search(r"lags stored (\d+)", text)
    return {"version": m.group(1), "case": m.group(2), "ranks": int(m.group(3)),
            "block": int(blk.group(1)) if blk else 1,
            "sub": int(sub.group(1)) if sub else (int(blk.group(1)) if blk else 1), "lags": int(lags.group(1)) if lags else "",
            "total_s": round(lv["total_s"], 1), "assembly_s": round(st.get("SSI BEM assembly", np.nan), 1),
            "time_loop_s": round(st.get("SSI BEM time loop", np.nan), 1),
            "history_s": round(ev.get("SSI_BEM_History", (0, np.nan))[1], 1),
            "history_GFps": round(int(hist.group(1)) / 1e3, 1) if hist else "",
            "peak_GB_per_rank": round((lv.get("peak_rss_max_rank_bytes") or np.nan) / 1e9, 2)}


def receivers(h5):
    import h5py
    with h5py.File(h5) as f:
        return f["receivers/u"][...]


def main(out):
    rows = [row_of(p) for p in sorted(glob.glob(os.path.join(out, "*-n*.log")))]
    rates = {}
    if os.path.exists(os.path.join(out, "dgemm_rate.txt")):
        for line in open(os.path.join(out, "dgemm_rate.txt")):
            name, val, unit = line.split()
            rates[name] = (float(val), unit)
    for r in rows:
        if r["version"] == "after":
            ref = os.path.join(out, f"before-{r['case']}-n2.h5")
            mine = os.path.join(out, f"after-{r['case']}-n{r['ranks']}.h5")
            if os.path.exists(ref) and os.path.exists(mine):
                a, b = receivers(mine), receivers(ref)
                r["max_rel_diff_vs_before"] = f"{np.abs(a - b).max() / np.abs(b).max():.1e}"
    write_csv(os.path.join(HERE, "results", "history_block.csv"), rows)
    order = {"before": 0, "after": 1}
    rows.sort(key=lambda r: (r["case"], order[r["version"]], -r["ranks"]))
    lines = ["| case | code | ranks | block b / sub-block s | total | assembly | time loop | history sum | history GF/s | "
             "peak GB/rank | receivers vs before |", "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['case']} | {r['version']} | {r['ranks']} | {r['block']} / {r['sub']} | {r['total_s']} s | "
                     f"{r['assembly_s']} s | {r['time_loop_s']} s | {r['history_s']} s | {r['history_GFps']} | "
                     f"{r['peak_GB_per_rank']} | {r.get('max_rel_diff_vs_before', '-')} |")
    by = {(r["case"], r["version"], r["ranks"]): r for r in rows}
    notes = []
    for case in sorted({r["case"] for r in rows}):
        b, a2, a1 = (by.get((case, v, n)) for v, n in (("before", 2), ("after", 2), ("after", 1)))
        if b and a2:
            notes.append(f"- {case}: total {b['total_s']} s -> {a2['total_s']} s at 2 ranks "
                         f"({b['total_s'] / a2['total_s']:.2f}x), history sum {b['history_s']} s -> "
                         f"{a2['history_s']} s ({b['history_s'] / max(a2['history_s'], 1e-9):.2f}x)")
        if a2 and a1:
            notes.append(f"- {case}: strong scaling 1 -> 2 ranks (this code): total {a1['total_s'] / a2['total_s'] / 2:.0%}"
                         f", time loop {a1['time_loop_s'] / a2['time_loop_s'] / 2:.0%}, assembly "
                         f"{a1['assembly_s'] / a2['assembly_s'] / 2:.0%} parallel efficiency")
    if rates:
        notes.append("- this machine, one core (jobscripts/dgemm_rate.py): " + ", ".join(
            f"{k} {v:g} {u}" for k, (v, u) in rates.items()))
        peak = 2 * rates["dgemm_square"][0]
        for r in rows:
            if r["version"] == "after" and r["ranks"] == 2 and r["history_GFps"] != "":
                notes.append(f"- {r['case']}: the history sum at {r['history_GFps']} GF/s on 2 ranks is "
                             f"{r['history_GFps'] / peak:.0%} of 2 x square dgemm ({peak:g} GF/s)")
    block = "\n".join(lines + [""] + notes) + "\n"
    put_block("history", block, (os.path.join(HERE, "README.md"), os.path.join(ROOT, "runs", "pekeris", "README.md")))
    print(block)


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "out/bench/history")
