#!/usr/bin/env python3
"""The table of jobscripts/scaling_repeat.sh: per case and rank count the fastest and the median of
the repeated runs' total and time loop (-log_view), and the 1 -> 2 rank efficiency T_1 / (2 T_2)
of the fastest runs and of the medians, and the assembly stage's median; writes
jobscripts/results/TAG.csv and the table between <!-- TAG:begin --> and <!-- TAG:end --> in
jobscripts/README.md (TAG: scaling_repeat, or huge_pages for jobscripts/huge_pages_bench.sh).

    python jobscripts/scaling_repeat_table.py OUT [TAG]"""
import glob
import os
import re
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from logview import parse, write_csv, put_block  # noqa: E402


def main(out, tag="scaling_repeat"):
    runs = {}
    for log in glob.glob(os.path.join(out, "*-n*-r*.log")):
        m = re.match(r"(.+)-n(\d+)-r(\d+)\.log$", os.path.basename(log))
        lv = parse(open(log).read())
        if lv["total_s"] is None:
            continue
        runs.setdefault((m.group(1), int(m.group(2))), []).append(
            (lv["total_s"], lv["stages"].get("SSI BEM time loop", np.nan),
             lv["stages"].get("SSI BEM assembly", np.nan)))
    rows = []
    for case in sorted({c for c, _ in runs}):
        if not ((case, 1) in runs and (case, 2) in runs):
            continue
        t = {n: np.array(runs[(case, n)]) for n in (1, 2)}
        r = {"case": case, "runs": min(len(t[1]), len(t[2]))}
        for n in (1, 2):
            r[f"total_min_n{n}_s"] = round(float(t[n][:, 0].min()), 2)
            r[f"total_median_n{n}_s"] = round(float(np.median(t[n][:, 0])), 2)
            r[f"loop_min_n{n}_s"] = round(float(t[n][:, 1].min()), 2)
            r[f"loop_median_n{n}_s"] = round(float(np.median(t[n][:, 1])), 2)
            r[f"assembly_median_n{n}_s"] = round(float(np.median(t[n][:, 2])), 2)
        for what in ("total", "loop"):
            for stat in ("min", "median"):
                r[f"eff_{what}_{stat}"] = round(r[f"{what}_{stat}_n1_s"] / (2 * r[f"{what}_{stat}_n2_s"]), 3)
        r["totals_n1_s"] = " ".join(f"{x:.1f}" for x in t[1][:, 0])
        r["totals_n2_s"] = " ".join(f"{x:.1f}" for x in t[2][:, 0])
        rows.append(r)
    write_csv(os.path.join(HERE, "results", f"{tag}.csv"), rows)
    lines = ["| case | runs | total, 1 rank: fastest / median | 2 ranks | efficiency (fastest / median) | "
             "time loop, 1 rank | 2 ranks | efficiency | assembly (median), 1 rank / 2 ranks | every total, 1 rank | "
             "2 ranks |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['case']} | {r['runs']} | {r['total_min_n1_s']} / {r['total_median_n1_s']} s | "
                     f"{r['total_min_n2_s']} / {r['total_median_n2_s']} s | "
                     f"{100 * r['eff_total_min']:.0f} % / {100 * r['eff_total_median']:.0f} % | "
                     f"{r['loop_min_n1_s']} / {r['loop_median_n1_s']} s | {r['loop_min_n2_s']} / {r['loop_median_n2_s']} s | "
                     f"{100 * r['eff_loop_min']:.0f} % / {100 * r['eff_loop_median']:.0f} % | "
                     f"{r['assembly_median_n1_s']} / {r['assembly_median_n2_s']} s | "
                     f"{r['totals_n1_s']} | {r['totals_n2_s']} |")
    put_block(tag, "\n".join(lines) + "\n", (os.path.join(HERE, "README.md"),))


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "out/bench/scaling_repeat", *sys.argv[2:3])
