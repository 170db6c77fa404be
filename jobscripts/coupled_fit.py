#!/usr/bin/env python3
"""Fit the coupled step's constants (``coupling/cost.py`` FALLBACK: r_cpl, the dense interface products' flop rate,
and c_cstep, the step's bookkeeping) to coupled runs' logs (-log_view), and print the model against each log.

    python jobscripts/coupled_fit.py [--check] LOG...      (--check: the committed constants, no fit)

Per log: the coupling's seconds a step measured, (SSI_FEM_Step + SSI_Contact) / steps, less the n_fs = 2 solves
with the structure's D at the run's own timing (its log line 'a solve with the structure's D ... ms as timed');
against the model's flops a step (``coupling.cost.step_seconds``: 2 (3 N_Z / p) m_Z + 2 (n_fem / p) m_D + 4 (3 n_I)^2,
with N_Z the soil nodes of Z's rows, the region's or every soil node, m_Z and m_D the columns kept, the orbits'
representatives' on a mirror-symmetric region), fitted by least squares on relative errors. Each count is read from
the run's log: the structure's DOFs ('[fem] mesh ...: N dofs'), the interface's nodes, the region's soil DOFs ('on the
N soil DOFs within', else the BEM's 'N DOFs;'), the columns solved ('A BEM and B FEM solves', else 3 n_I).
"""
import os
import re
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.dirname(HERE))
from logview import parse  # noqa: E402


def counts(path):
    """The log's counts and measured seconds (module docstring), or None when it is not a finished coupled run."""
    text = open(path, errors="replace").read()
    lv = parse(text)
    ev = lv["events"]
    if "SSI_Contact" not in ev or "SSI_FEM_Step" not in ev:
        return None
    num = lambda pat: int(re.search(pat, text).group(1)) if re.search(pat, text) else None
    n_fem = num(r"\[fem\] mesh [^\n]*?, (\d+) dofs")
    n_i = num(r"\[ssi\] interface: (\d+) nodes")
    nz3 = num(r"on the (\d+) soil DOFs within") or num(r"\[ssi\] BEM: [^\n]*?, (\d+) DOFs;")
    m = re.search(r"(\d+) BEM and (\d+) FEM solves", text)
    t = re.search(r"a solve with the structure's D ([\d.e+-]+) ms as timed", text)
    if None in (n_fem, n_i, nz3) or t is None:
        return None
    mz, md = (int(m.group(1)), int(m.group(2))) if m else (3 * n_i, 3 * n_i)
    steps = ev["SSI_Contact"][0]
    return {"ranks": int(lv["ranks"] or 1), "n_fem": n_fem, "n_i": n_i, "nz3": nz3, "mz": mz, "md": md,
            "t_fs": float(t.group(1)) * 1e-3, "steps": steps,
            "per_step": (ev["SSI_FEM_Step"][1] + ev["SSI_Contact"][1]) / steps}


def flops(c):
    """The model's flops a step of the coupling's dense products (``coupling.cost.step_seconds``)."""
    p, n = c["ranks"], 3 * c["n_i"]
    return 2.0 * (c["nz3"] / p) * c["mz"] + 2.0 * (c["n_fem"] / p) * c["md"] + 4.0 * n * n


def main(logs, check=False):
    from petsc_ssi.coupling.cost import FALLBACK
    runs = [(p, c) for p in logs for c in [counts(p)] if c is not None]
    for p in logs:
        if p not in [r[0] for r in runs]:
            print(f"[coupled_fit] skip {p}: not a finished coupled run with the counts in its log", file=sys.stderr)
    F = np.array([flops(c) for _, c in runs])
    y = np.array([c["per_step"] - FALLBACK["n_fs"] * c["t_fs"] for _, c in runs])
    if check:
        inv_r, cst = 1.0 / FALLBACK["r_cpl"], FALLBACK["c_cstep"]
    else:
        w = 1.0 / np.abs(y)
        inv_r, cst = np.linalg.lstsq(np.c_[F, np.ones_like(F)] * w[:, None], y * w, rcond=None)[0]
    print("| log | interface nodes | structure DOFs | flops a step [M] | coupling a step measured / model [ms] |")
    print("|---|---|---|---|---|")
    for (p, c), f in zip(runs, F):
        model = FALLBACK["n_fs"] * c["t_fs"] + f * inv_r + cst
        print(f"| {os.path.relpath(p)} | {c['n_i']} | {c['n_fem']} | {f / 1e6:.1f} | {1e3 * c['per_step']:.2f} / "
              f"{1e3 * model:.2f} ({100 * (model / c['per_step'] - 1):+.0f} %) |")
    print(("committed: " if check else "fitted: ") + f'"r_cpl": {1.0 / inv_r:.3g}, "c_cstep": {cst:.3g}')


if __name__ == "__main__":
    args = sys.argv[1:]
    main([a for a in args if a != "--check"], check="--check" in args)
