"""Impedance functions of three rigid footings against the published curves, and the cost of the
impedance command at 1 and 2 ranks (issue 12's benchmark).

    .venv/bin/python runs/impedance/footings.py            (about 12 minutes on 2 cores)

Runs ``petsc-ssi impedance`` on
    square.opts     2 m x 2 m (B = 1 m), paper's soil (nu = 0.251)    vs Pais & Kausel (1988)
    rectangle.opts  4 m x 2 m (L/B = 2, long side along x)            vs Pais & Kausel (1988)
    disk.opts       radius 1 m, c_p = 2 c_s (nu = 1/3)                vs Veletsos & Verbic (1973)
at -n 2, and the square again at -n 1 (the cost at 1 and 2 ranks; each mode is one transient run,
whose wall time the command prints). Copies each case's CSV and PNG here, writes footings.csv
(k, c and the references at a0 = 0.5, 1, 1.5, 2 per case and mode), cost.csv (wall time per mode,
case and rank count) and the two tables of README.md between their markers.
"""
import csv
import os
import re
import shutil
import subprocess
import sys
import time

import numpy as np

from petsc_ssi.launch import child_env

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
OUT = os.path.join(ROOT, "out", "impedance")
CASES = ("square", "rectangle", "disk")
A0 = (0.5, 1.0, 1.5, 2.0)
LINE = re.compile(r"\[impedance\] (\w+): K0 = (\S+) .*trusted a0 in \[(\S+), (\S+)\].*; ([\d.]+) s")


def run(case, n):
    cmd = [sys.executable, "-m", "petsc_ssi", "impedance", "-options_file", f"runs/impedance/{case}.opts"]
    if n > 1:
        cmd = ["mpirun", "--allow-run-as-root", "--oversubscribe", "-n", str(n)] + cmd
    t = time.perf_counter()
    p = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True,
                       env=child_env(OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1"))
    wall = time.perf_counter() - t
    if p.returncode:
        sys.exit(f"{' '.join(cmd)} failed:\n{p.stdout[-3000:]}{p.stderr[-3000:]}")
    modes = {m.group(1): (float(m.group(2)), float(m.group(3)), float(m.group(4)), float(m.group(5)))
             for m in LINE.finditer(p.stdout)}
    coupling = re.findall(r"\[impedance\] (coupling .*|reciprocity .*)", p.stdout)
    return modes, wall, coupling


def read_csv(case):
    out = {}
    with open(os.path.join(OUT, f"{case}-impedance.csv")) as fh:
        for row in csv.DictReader(fh):
            out.setdefault(row["mode"], []).append(row)
    return out


def main():
    os.makedirs(OUT, exist_ok=True)
    cost, comp, notes = [], [], []
    for case, n in [(c, 2) for c in CASES] + [("square", 1)]:
        modes, wall, coupling = run(case, n)
        print(f"{case} at -n {n}: {wall:.1f} s", flush=True)
        for mode, (K0, lo, hi, t) in modes.items():
            cost.append(dict(case=case, ranks=n, mode=mode, wall_s=t, K0=K0, a0_lo=lo, a0_hi=hi))
        cost.append(dict(case=case, ranks=n, mode="total (command)", wall_s=round(wall, 1), K0="", a0_lo="",
                         a0_hi=""))
        if n == 2:
            notes += [f"{case}: {c}" for c in coupling]
            for ext in ("csv", "png"):
                shutil.copy(os.path.join(OUT, f"{case}-impedance.{ext}"), HERE)
            table = read_csv(case)
            for mode in ("vertical", "horizontal", "rocking", "torsion"):
                rows = table.get(mode, [])
                a0 = np.array([float(r["a0"]) for r in rows])
                for a in A0:
                    r = rows[int(np.argmin(np.abs(a0 - a)))]
                    comp.append(dict(case=case, mode=mode, a0=float(r["a0"]), trusted=r["trusted"],
                                     k=float(r["k"]), k_ref=float(r["k_ref"]), c=float(r["c"]),
                                     c_ref=float(r["c_ref"]), K0=float(r["K0"])))
    for name, rows in (("cost.csv", cost), ("footings.csv", comp)):
        with open(os.path.join(HERE, name), "w", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)
    readme = os.path.join(HERE, "README.md")
    text = open(readme).read()
    t1 = ["| footing | mode | a0 | k | k reference | c | c reference |", "|---|---|---|---|---|---|---|"]
    for r in comp:
        ref = (lambda v: "-" if np.isnan(v) else f"{v:.3f}")
        t1.append(f"| {r['case']} | {r['mode']} | {r['a0']:.2f}{'' if r['trusted'] == '1' else ' (untrusted)'} | "
                  f"{r['k']:.3f} | {ref(r['k_ref'])} | {r['c']:.3f} | {ref(r['c_ref'])} |")
    t1 += [""] + [f"- {n}" for n in notes]
    t2 = ["| footing | ranks | vertical | horizontal | rocking | torsion | whole command |",
          "|---|---|---|---|---|---|---|"]
    for case, n in [(c, 2) for c in CASES] + [("square", 1)]:
        per = {r["mode"]: r["wall_s"] for r in cost if r["case"] == case and r["ranks"] == n}
        t2.append(f"| {case} | {n} | " + " | ".join(f"{per[m]:.1f} s" if m in per else "-" for m in
                                                    ("vertical", "horizontal", "rocking", "torsion"))
                  + f" | {per['total (command)']:.1f} s |")
    for tag, lines in (("footings", t1), ("cost", t2)):
        b, e = f"<!-- {tag}:begin -->", f"<!-- {tag}:end -->"
        if b in text:
            text = text[:text.index(b) + len(b)] + "\n" + "\n".join(lines) + "\n" + text[text.index(e):]
        else:
            print(f"README.md has no {b} marker; the table:\n" + "\n".join(lines))
    open(readme, "w").write(text)
    print("wrote cost.csv, footings.csv and the README tables")


if __name__ == "__main__":
    main()
