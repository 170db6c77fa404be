#!/usr/bin/env python3
"""The table of jobscripts/subblock_bench.sh: per run (blocks of b steps in sub-blocks of s, or step by
step) the time loop, the history sum and its two parts from -log_view (SSI_BEM_HistPanel: the block
and sub-block panel products; SSI_BEM_HistStep: the terms left to each step), the flops of each part
(max over ranks) and the receivers' largest difference to the step-by-step run, relative to their
largest value; writes jobscripts/results/subblock.csv and the table between <!-- subblock:begin -->
and <!-- subblock:end --> in jobscripts/README.md.

    python jobscripts/subblock_table.py OUT CASE"""
import glob
import os
import re
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from logview import parse, write_csv, put_block  # noqa: E402


def flops(text, event):
    m = re.search(rf"^{event}\s+\d+\s+\S+\s+\S+\s+\S+\s+(\S+)", text, re.M)
    return float(m.group(1)) if m else 0.0


def receivers(h5):
    import h5py
    with h5py.File(h5) as f:
        return f["receivers/u"][...]


def main(out, case):
    ref = os.path.join(out, f"{case}-b1.h5")
    rows = []
    for log in glob.glob(os.path.join(out, f"{case}-b*.log")):
        text = open(log).read()
        name = os.path.basename(log)[len(case) + 1:-4]
        m = re.match(r"b(\d+)(?:-s(\d+))?$", name)
        b, s = int(m.group(1)), int(m.group(2) or m.group(1))
        lv = parse(text)
        ev = lv["events"]
        r = {"case": case, "block": b, "sub": s, "time_loop_s": round(lv["stages"].get("SSI BEM time loop", np.nan), 2),
             "history_s": round(ev.get("SSI_BEM_History", (0, np.nan))[1], 2),
             "panel_s": round(ev.get("SSI_BEM_HistPanel", (0, 0.0))[1], 2),
             "step_s": round(ev.get("SSI_BEM_HistStep", (0, 0.0))[1], 2),
             "panel_Gflop": round(flops(text, "SSI_BEM_HistPanel") / 1e9, 1),
             "step_Gflop": round(flops(text, "SSI_BEM_HistStep") / 1e9, 1)}
        h5 = log[:-4] + ".h5"
        if b > 1 and os.path.exists(ref) and os.path.exists(h5):
            a, c = receivers(h5), receivers(ref)
            r["receivers_vs_b1"] = f"{np.abs(a - c).max() / np.abs(c).max():.1e}"
        rows.append(r)
    rows.sort(key=lambda r: (r["block"], -r["sub"]))       # step by step, then one level, then finer
    write_csv(os.path.join(HERE, "results", "subblock.csv"), rows)
    lines = ["| case | block b | sub-block s | time loop | history sum | panel products | per-step rest | "
             "panel Gflop/rank | per-step Gflop/rank | receivers vs step by step |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        parts = (f"{r['panel_s']} s | {r['step_s']} s | {r['panel_Gflop']} | {r['step_Gflop']}" if r["block"] > 1
                 else "- | - | - | -")                       # step by step: no HistPanel/HistStep events
        lines.append(f"| {r['case']} | {r['block']} | {r['sub']} | {r['time_loop_s']} s | {r['history_s']} s | "
                     f"{parts} | {r.get('receivers_vs_b1', '-')} |")
    put_block("subblock", "\n".join(lines) + "\n", (os.path.join(HERE, "README.md"),))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2] if len(sys.argv) > 2 else "paper")
