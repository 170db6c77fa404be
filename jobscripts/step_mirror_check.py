#!/usr/bin/env python3
"""Tables of jobscripts/step_mirror_check.sh's runs (OUT: its directory).

    python jobscripts/step_mirror_check.py OUT [RUNS]

Per run: the step matrix's factor entries (its log line), the events SSI_BEM_Factor (the step matrix's build,
the blocks and the LU) and the time loop's SSI_BEM_Solve (seconds a solve), the assembly stage's MatLUFactorNum
and MatMatSolve (both LUs; the interface columns' multi-right-hand-side solves), the assembly line's seconds and
the largest bem_residual. Then the largest difference of every recorded field (the soil's and the structure's
HDF5 files) of mirror against off and of load and load-other (another rank count) against save, over that field's largest absolute value."""
import os
import re
import sys

import h5py
import numpy as np


def event(text, name, stage=None):
    """(count, seconds) of a -log_view event (in ``stage``'s section if given; the last occurrence)."""
    if stage:
        m = re.search(rf"--- Event Stage \d+: {re.escape(stage)}\n(.*?)(?:--- Event Stage|\Z)", text, re.S)
        text = m.group(1) if m else ""
    hits = re.findall(rf"^{re.escape(name)}\s+(\d+)\s+\S+\s+(\S+)", text, re.M)
    return (int(hits[-1][0]), float(hits[-1][1])) if hits else (0, float("nan"))


def row(out, name):
    text = open(os.path.join(out, name + ".log"), errors="replace").read()
    ent = re.search(r"\[ssi\] step matrix: \d+ DOFs, MUMPS LU, (\S+) M entries", text)
    blocks = re.search(r"(\d) independent blocks", text)
    asm = re.search(r"\[ssi\] assembly (\S+?)s:", text)
    n, solve = event(text, "SSI_BEM_Solve", "SSI time loop")
    with h5py.File(os.path.join(out, name + ".h5")) as f:
        res = float(np.max(f["interface/bem_residual"][...]))
    return {"run": name, "factor_entries_M": ent.group(1) if ent else "", "blocks": blocks.group(1) if blocks else "1",
            "assembly_s": asm.group(1) if asm else "", "SSI_BEM_Factor_s": event(text, "SSI_BEM_Factor")[1],
            "step_solve_ms": 1e3 * solve / max(n, 1), "LU_numeric_s": event(text, "MatLUFactorNum", "SSI BEM assembly")[1],
            "columns_MatMatSolve_s": event(text, "MatMatSolve", "SSI BEM assembly")[1], "max_bem_residual": res}


def largest(out, a, b):
    """{file/field: max |a - b| / max |b|} over the two runs' soil and structure files."""
    worst = {}
    for suffix in ("", "_structure"):
        fa, fb = (os.path.join(out, f"{n}{suffix}.h5") for n in (a, b))
        with h5py.File(fa) as A, h5py.File(fb) as B:
            def visit(name, obj):
                if (isinstance(obj, h5py.Dataset) and obj.dtype.kind == "f" and name in B and obj.size
                        and obj.shape == B[name].shape and "residual" not in name and "error" not in name):
                    x, y = obj[...], B[name][...]
                    top = np.abs(y).max()
                    if top > 0:
                        worst[f"{suffix or 'soil'}:{name}"] = float(np.abs(x - y).max() / top)
            A.visititems(visit)
    return worst


def main(out, runs=None):
    """``runs``: the runs of this invocation (step_mirror_check.sh's RUNS), else every run whose log is in OUT."""
    want = runs.split() if runs else ("mirror", "off", "save", "load", "load-other")
    names = [n for n in want if os.path.exists(os.path.join(out, n + ".log"))]
    if not names:
        sys.exit(f"step_mirror_check.py: no run's log in {out}")
    rows = [row(out, n) for n in names]
    keys = list(rows[0])
    print("| " + " | ".join(keys) + " |")
    print("|" + "---|" * len(keys))
    for r in rows:
        print("| " + " | ".join(f"{r[k]:.4g}" if isinstance(r[k], float) else str(r[k]) for k in keys) + " |")
    if "save" in names and os.path.exists(os.path.join(out, "lags")):
        print(f"\nlag file: {os.path.getsize(os.path.join(out, 'lags')) / 1e9:.3g} GB")
    for a, b in (("mirror", "off"), ("load", "save"), ("load-other", "save")):
        if a not in names or b not in names:
            continue
        w = largest(out, a, b)
        k = max(w, key=w.get)
        print(f"{a} against {b}: largest difference {w[k]:.3g} of the field's largest value ({k}; {len(w)} fields)")


if __name__ == "__main__":
    main(*sys.argv[1:3])
