#!/usr/bin/env python3
"""The estimate against the measured coupled buildings (jobscripts/building_estimate.sh): per building and
rank count, the measured wall of the run (-log_view's total), of its BEM assembly stage and of its time
loop, and `petsc-ssi estimate`'s predictions of the same; the ratio predicted / measured.
Writes OUT/buildings.csv and the table between <!-- buildings:begin/end --> in jobscripts/README.md.

  python jobscripts/building_estimate_table.py out/bench/buildings
"""
import os
import re
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from logview import parse, write_csv, put_block  # noqa: E402


def estimate_rows(path):
    """{ranks: {column: value}} of an estimate's table."""
    text = open(path).read()
    head = [ln for ln in text.splitlines() if "ranks nodes |" in ln][0].split("|")
    cols = head[1].split() + ["total"]
    rows = {}
    for ln in text.splitlines():
        m = re.match(r"\[ssi\]\s+(\d+)\s+\d+\s+\|(.*?)\|\s*(\S+)\s*\|", ln)
        if m:
            vals = [float(v) for v in m.group(2).split()] + [_seconds(m.group(3))]
            rows[int(m.group(1))] = dict(zip(cols, vals))
    return rows


def _seconds(text):
    m = re.match(r"(?:(\d+)h)?(?:(\d+)m)?(?:([0-9.]+)s)?$", text)
    h, mi, s = (float(g) if g else 0.0 for g in m.groups())
    return 3600 * h + 60 * mi + s


def main(out):
    rows = []
    for name in ("demo", "paper", "seismic"):
        est_path = os.path.join(out, f"{name}.estimate")
        if not os.path.exists(est_path):
            continue
        est = estimate_rows(est_path)
        for n in (1, 2):
            log = os.path.join(out, f"{name}-n{n}.log")
            if not os.path.exists(log):
                continue
            text = open(log).read()
            lv = parse(text)
            m = re.search(r"# load average after the run: ([0-9.]+)", text)
            load = float(m.group(1)) if m else float("nan")
            st = lv["stages"]
            loop = sum(v for k, v in st.items() if "time loop" in k.lower())
            asm = sum(v for k, v in st.items() if "assembly" in k.lower())
            e = est[n]
            pred_asm = e["assembly_s"] + e.get("coupling_setup_s", 0.0)
            rows.append({"building": name, "ranks": n, "measured_total_s": round(lv["total_s"], 2),
                         "estimate_total_s": round(e["total"], 2),
                         "ratio_total": round(e["total"] / lv["total_s"], 3),
                         "measured_assembly_s": round(asm, 2), "estimate_assembly_s": round(pred_asm, 2),
                         "measured_loop_s": round(loop, 2), "estimate_loop_s": round(e["time_loop_s"], 2),
                         "ratio_loop": round(e["time_loop_s"] / loop, 3) if loop else float("nan"),
                         "load_average_after": load})
    if not rows:
        sys.exit(f"no logs in {out}")
    write_csv(os.path.join(out, "buildings.csv"), rows)
    lines = ["| building | ranks | measured total [s] | estimate [s] | estimate / measured | assembly stages measured / "
             "estimated [s] | time loop measured / estimated [s] | loop estimate / measured | load average after "
             "(2 cores) |", "|---" * 9 + "|"]
    for r in rows:
        lines.append(f"| {r['building']} | {r['ranks']} | {r['measured_total_s']} | {r['estimate_total_s']} | "
                     f"{r['ratio_total']} | {r['measured_assembly_s']} / {r['estimate_assembly_s']} | "
                     f"{r['measured_loop_s']} / {r['estimate_loop_s']} | {r['ratio_loop']} | "
                     f"{r['load_average_after']:g} |")
    block = "\n".join(lines)
    print(block)
    put_block("buildings", block, [os.path.join(HERE, "README.md")])


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "out/bench/buildings")
