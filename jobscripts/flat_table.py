#!/usr/bin/env python3
"""The table of jobscripts/flat_bench.sh (issue 29): per run the wall time and the stages of
-log_view (BEM assembly, of which the integration of the element cache's pairs, the Mats, the
time loop stage, of it the history sum and the BEM solves, the interface matrices of a coupled run), the peak resident memory of
-memory_view (largest rank and all ranks), the lag matrices stored (the run's log), and the largest
difference from the old code's run of the same case: of every receiver and interface series and
field snapshot, relative to that dataset's maximum (a coupled run's old code against itself gives
the run-to-run spread). Writes jobscripts/results/flat.csv and the table between
<!-- flat:begin/end --> in jobscripts/README.md.

    python jobscripts/flat_table.py OUT BEFORE"""
import os
import re
import sys

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from logview import parse, put_block, write_csv  # noqa: E402

RUNS = [("paper-before", "Lamb, paper case", None), ("paper-after", "Lamb, paper case", "paper-before"),
        ("paper-after-single3", "Lamb, paper case, -ssi_lag_single_from 3", "paper-before"),
        ("building-before", "paper's building, bonded", None),
        ("building-before-rerun", "paper's building, bonded (old code again)", "building-before"),
        ("building-after", "paper's building, bonded", "building-before")]


def max_rel_diff(a, b):
    """The largest |a - b| / max|a| over the float datasets both files hold (receivers, interface series,
    snapshots of u and p; round-off diagnostics and run records left out), and the dataset."""
    worst, where = 0.0, ""
    skip = ("residual", "error", "timing", "wall", "record")
    files = [(a, b)] + [(a.replace(".h5", "_structure.h5"), b.replace(".h5", "_structure.h5"))]
    for fa, fb in files:
        if not (os.path.exists(fa) and os.path.exists(fb)):
            continue
        with h5py.File(fa, "r") as A, h5py.File(fb, "r") as B:
            def visit(name, obj):
                nonlocal worst, where
                if (not isinstance(obj, h5py.Dataset) or obj.dtype.kind != "f" or name not in B
                        or any(s in name for s in skip) or B[name].shape != obj.shape):
                    return
                x, y = obj[()], B[name][()]
                sc = float(np.abs(x).max()) if x.size else 0.0
                if sc > 0:
                    d = float(np.abs(x - y).max()) / sc
                    if d > worst:
                        worst, where = d, name
            A.visititems(visit)
    return worst, where


def main(out, before):
    rows = []
    for name, what, ref in RUNS:
        path = os.path.join(out, name + ".log")
        if not os.path.exists(path):
            continue
        text = open(path).read()
        lv = parse(text)
        ev = {k: v[1] for k, v in lv["events"].items()}
        m = re.search(r"\] assembly .*?stored (\S+) GB", text)
        row = {"run": name, "case": what, "code": before if "before" in name else "this checkout",
               "wall_s": lv["total_s"], "assembly_s": ev.get("SSI_BEM_Assembly"),
               "integration_s": ev.get("SSI_BEM_Integrate"), "lag_mats_s": ev.get("SSI_BEM_LagMats"),
               "time_loop_s": next((v for k, v in lv["stages"].items() if k.endswith("time loop")), None),
               "history_s": ev.get("SSI_BEM_History"), "bem_solve_s": ev.get("SSI_BEM_Solve"),
               "interface_matrices_s": ev.get("SSI_Capacitance"),
               "peak_GB_largest_rank": (lv.get("peak_rss_max_rank_bytes") or np.nan) / 1e9,
               "peak_GB_all_ranks": (lv.get("peak_rss_bytes") or np.nan) / 1e9,
               "lags_stored_GB": float(m.group(1)) if m else np.nan}
        if ref:
            d, where = max_rel_diff(os.path.join(out, ref + ".h5"), os.path.join(out, name + ".h5"))
            row["max_rel_diff"], row["largest_in"] = d, where
        rows.append(row)
    write_csv(os.path.join(HERE, "results", "flat.csv"), rows)

    def f(v, fmt="{:.1f}"):
        return "-" if v is None or (isinstance(v, float) and np.isnan(v)) else fmt.format(v)
    lines = ["| case | code | wall [s] | BEM assembly [s] (integration) | Mats [s] | time loop [s] | history sum [s] "
             "| BEM solves [s] | interface matrices [s] | peak memory, largest rank / all ranks [GB] | lags stored [GB] "
             "| largest difference from the old code (dataset) |", "|---" * 12 + "|"]
    for r in rows:
        diff = f"{r['max_rel_diff']:.1e} ({r['largest_in']})" if "max_rel_diff" in r else "-"
        lines.append(f"| {r['case']} | {r['code']} | {f(r['wall_s'])} | {f(r['assembly_s'])} ({f(r['integration_s'])}) "
                     f"| {f(r['lag_mats_s'])} | {f(r['time_loop_s'])} | {f(r['history_s'])} | {f(r['bem_solve_s'])} | "
                     f"{f(r['interface_matrices_s'])} | {f(r['peak_GB_largest_rank'], '{:.2f}')} / "
                     f"{f(r['peak_GB_all_ranks'], '{:.2f}')} | {f(r['lags_stored_GB'], '{:.3g}')} | {diff} |")
    block = "\n".join(lines)
    print(block)
    put_block("flat", block, [os.path.join(HERE, "README.md")])


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "out/bench/flat", sys.argv[2] if len(sys.argv) > 2 else "162a0c5")
