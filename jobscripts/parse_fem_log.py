#!/usr/bin/env python3
"""Parse -log_view files of FEM runs into a CSV and the README table.

Each log is named MESH_SOLVER_npN.log (jobscripts/fem_bench.sh). From the
event table it takes the max-over-ranks time of FEM_assembly, FEM_factor and
FEM_timeloop, the counts of KSPSolve and PCApply (PCApply/KSPSolve = Krylov
iterations per solve), and the total run time. The markdown table replaces
the text between '<!-- fem-bench start -->' and '<!-- fem-bench end -->' of
--readme.
"""
import argparse
import csv
import os
import re
import sys

EVENTS = ("FEM_assembly", "FEM_factor", "FEM_timeloop", "KSPSolve", "PCApply")
START, END = "<!-- fem-bench start -->", "<!-- fem-bench end -->"


def parse(path):
    """Dict of one run: mesh, solver, ranks, event times [s] and counts."""
    name = os.path.basename(path)[:-4]
    m = re.match(r"(?P<mesh>.+)_(?P<solver>mumps|cg_hypre|cg_jacobi)_np(?P<np>\d+)$", name)
    if not m:
        raise SystemExit(f"{path}: name must be MESH_SOLVER_npN.log")
    row = {"mesh": m["mesh"], "solver": m["solver"], "ranks": int(m["np"])}
    text = open(path).read()
    t = re.search(r"^Time \(sec\):\s+(\S+)", text, re.M)
    row["total_s"] = float(t.group(1)) if t else float("nan")
    for ev in EVENTS:
        # name, count max, ratio, time max, ratio, ... (first occurrence: main stage)
        hit = re.search(rf"^{ev}\s+(\d+)\s+\S+\s+(\S+)", text, re.M)
        row[f"{ev}_count"] = int(hit.group(1)) if hit else 0
        row[f"{ev}_s"] = float(hit.group(2)) if hit else 0.0
    out = path + ".out"
    if os.path.exists(out):
        d = re.search(r"(\d+) nodes, (\d+) hex8, (\d+) dofs", open(out).read())
        row["dofs"] = int(d.group(3)) if d else 0
        row["cells"] = int(d.group(2)) if d else 0
    steps = max(row["KSPSolve_count"] - 1, 1)            # one probe solve at factorisation
    row["steps"] = steps
    row["per_step_ms"] = 1e3 * row["FEM_timeloop_s"] / steps
    row["its_per_solve"] = row["PCApply_count"] / max(row["KSPSolve_count"], 1)
    return row


def table(rows):
    head = ("| mesh | hex8 | dofs | solver | ranks | assembly [s] | factorisation [s] | time loop [s] "
            "| per step [ms] | Krylov its/solve | total [s] |")
    lines = [head, "|" + "---|" * 11]
    for r in rows:
        lines.append(f"| {r['mesh']} | {r.get('cells', '')} | {r.get('dofs', '')} | {r['solver']} | "
                     f"{r['ranks']} | {r['FEM_assembly_s']:.3g} | {r['FEM_factor_s']:.3g} | "
                     f"{r['FEM_timeloop_s']:.3g} | {r['per_step_ms']:.3g} | {r['its_per_solve']:.3g} | "
                     f"{r['total_s']:.3g} |")
    return "\n".join(lines)


def update_readme(path, text):
    body = open(path).read() if os.path.exists(path) else f"{START}\n{END}\n"
    if START not in body or END not in body:
        body += f"\n{START}\n{END}\n"
    pre, rest = body.split(START, 1)
    _, post = rest.split(END, 1)
    with open(path, "w") as fh:
        fh.write(pre + START + "\n" + text + "\n" + END + post)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("logs", nargs="+")
    ap.add_argument("--csv")
    ap.add_argument("--readme")
    ap.add_argument("--load", help="file with `uptime` lines before/after the runs")
    a = ap.parse_args(argv)
    rows = sorted((parse(p) for p in a.logs), key=lambda r: (r.get("dofs", 0), r["solver"], r["ranks"]))
    if a.csv:
        with open(a.csv, "w", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)
    md = table(rows)
    if a.load and os.path.exists(a.load):
        loads = [ln.split("load average:")[-1].strip() for ln in open(a.load) if "load average" in ln]
        md += "\n\nLoad average (1, 5, 15 min) before / after the runs: " + " / ".join(loads) + "."
    print(md)
    if a.readme:
        update_readme(a.readme, md)
    return 0


if __name__ == "__main__":
    sys.exit(main())
