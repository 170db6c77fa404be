#!/usr/bin/env python3
"""The table of jobscripts/assembly_bench.sh: per case, the assembly before its rework and now at 2
ranks, and now at 1 rank; from the runs' -log_view (stage SSI BEM assembly; events SSI_BEM_Assembly:
integration and accumulation, SSI_BEM_Integrate: the shared element cache, SSI_BEM_LagMats: the
Mats; the older code has no SSI_BEM_Integrate/LagMats events) and -memory_view, and whether the
matrices are the same (OUT/matrices.txt, from jobscripts/compare_lags.py).

  python jobscripts/assembly_table.py OUT

Writes jobscripts/results/assembly.csv and the table between <!-- assembly:begin --> and
<!-- assembly:end --> in jobscripts/README.md and runs/pekeris/README.md."""
import glob
import os
import re
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
from logview import parse, write_csv, put_block  # noqa: E402
from history_table import receivers  # noqa: E402

def row_of(log):
    text = open(log).read()
    m = re.search(r"(before|after)-([\w-]+?)-n(\d+)\.log", log)
    lv = parse(text)
    st, ev = lv["stages"], lv["events"]
    e = lambda k: round(ev[k][1], 1) if k in ev else ""
    return {"version": m.group(1), "case": m.group(2), "ranks": int(m.group(3)),
            "total_s": round(lv["total_s"], 1), "assembly_s": round(st.get("SSI BEM assembly", np.nan), 1),
            "kernels_s": e("SSI_BEM_Assembly"), "integrate_s": e("SSI_BEM_Integrate"), "lagmats_s": e("SSI_BEM_LagMats"),
            "time_loop_s": round(st.get("SSI BEM time loop", np.nan), 1),
            "peak_GB_per_rank": round((lv.get("peak_rss_max_rank_bytes") or np.nan) / 1e9, 2)}


def main(out):
    rows = [row_of(p) for p in sorted(glob.glob(os.path.join(out, "*-n*.log"))) if "-lags-" not in p]
    for r in rows:
        if r["version"] == "after":
            ref = os.path.join(out, f"before-{r['case']}-n2.h5")
            mine = os.path.join(out, f"after-{r['case']}-n{r['ranks']}.h5")
            if os.path.exists(ref) and os.path.exists(mine):
                a, b = receivers(mine), receivers(ref)
                r["receivers_vs_before"] = f"{np.abs(a - b).max() / np.abs(b).max():.1e}"
    write_csv(os.path.join(HERE, "results", "assembly.csv"), rows)
    order = {"before": 0, "after": 1}
    rows.sort(key=lambda r: (r["case"], order[r["version"]], -r["ranks"]))
    s = lambda v: f"{v} s" if v != "" else "-"
    lines = ["| case | code | ranks | total | assembly stage | integration + accumulation | of which shared cache | "
             "Mats from triplets | time loop | peak GB/rank | receivers vs before |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['case']} | {r['version']} | {r['ranks']} | {s(r['total_s'])} | {s(r['assembly_s'])} | "
                     f"{s(r['kernels_s'])} | {s(r['integrate_s'])} | {s(r['lagmats_s'])} | {s(r['time_loop_s'])} | "
                     f"{r['peak_GB_per_rank']} | {r.get('receivers_vs_before', '-')} |")
    by = {(r["case"], r["version"], r["ranks"]): r for r in rows}
    notes = []
    for case in sorted({r["case"] for r in rows}):
        b, a2, a1 = (by.get((case, v, n)) for v, n in (("before", 2), ("after", 2), ("after", 1)))
        if b and a2:
            notes.append(f"- {case}: assembly stage {b['assembly_s']} s -> {a2['assembly_s']} s at 2 ranks "
                         f"({b['assembly_s'] / a2['assembly_s']:.2f}x), total {b['total_s']} s -> {a2['total_s']} s")
        if a2 and a1:
            notes.append(f"- {case}: strong scaling 1 -> 2 ranks (this code): total {a1['total_s'] / a2['total_s'] / 2:.0%}"
                         f", assembly {a1['assembly_s'] / a2['assembly_s'] / 2:.0%} parallel efficiency")
    mt = os.path.join(out, "matrices.txt")
    if os.path.exists(mt):
        notes += ["", "Lag matrices of both versions (jobscripts/compare_lags.py):"]
        notes += [f"- {line.strip()}" for line in open(mt) if line.strip()]
    block = "\n".join(lines + [""] + notes) + "\n"
    put_block("assembly", block, (os.path.join(HERE, "README.md"), os.path.join(ROOT, "runs", "pekeris", "README.md")))
    print(block)


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "out/bench/assembly")
