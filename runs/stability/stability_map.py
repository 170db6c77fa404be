#!/usr/bin/env python3
"""Stability maps of the BEM time marching on Lamb's problem (issue 6).

Part "map": the plain (eq. 6) and the stabilised (eq. 7) scheme over a grid of
beta = c_s dt / l (l = h/2, the distance between two nodes of a nine-node
element, as in the paper) and element sizes h, on a 6 m x 6 m surface (quarter
model, two symmetry planes, Heaviside pressure of 1 kPa on the central h x h
element of the quarter), c_p = 548, c_s = 316 m/s, rho = 2000 kg/m^3. Each run
lasts max(1000, 3 L) steps, L = causal lag count r_max/(c_s dt) + 2: the
instabilities found here set in only after the last lag has entered the
recurrence (about 2 L steps), so 1000 steps alone miss them at small beta.

Part "interp": the stabilised scheme at the paper's dt = 7.5e-4 s on a 12 m x
12 m quarter model of 1 m elements (beta = 0.47), lags beyond T_L replaced by
Chebyshev-Lagrange or multi-linear interpolation of k matrices; T_L from
tau_L = c_s T_L / r with r = 3 m (the receiver), below and above the Rayleigh
arrival tau_R = 1.0877; k = 2..16; 1000 steps. Also the largest deviation of
the receiver's vertical displacement from the run with exact lags.

Part "precision": the map's cases with h = 1 and 1.5 m again, lags from the third on stored in single
precision (-ssi_lag_single_from 3): does the float32 rounding of the far lags (a perturbation of
about 1e-8 instead of 1e-16 of the recurrence) move the stability boundary or seed an instability?
Compared with the map's double runs, class by class, and by their final norms.

Classification (petsc_ssi.bem.stability.classify): the late growth rate r =
slope of ln|u^n| per step fitted by least squares over the last third of the
run; stable r < 1e-4, slowly growing 1e-4 <= r < 2e-3, unstable r >= 2e-3 or
blow-up (runs are cut when |u| exceeds 1e6 x the largest norm of the first
half, the guard rule with factor 1e6). The CSV also gives the step at which
the default guard (factor 100) would have stopped the run.

Usage (from the repository root):
  python runs/stability/stability_map.py                 # everything not yet in the CSVs, then plots
  python runs/stability/stability_map.py --part map --minutes 5   # a chunk of about 5 minutes
  python runs/stability/stability_map.py --max-cost 0    # also the costly cases (h = 0.5 m, beta <= 0.05)
  python runs/stability/stability_map.py --list          # the case ids (for job arrays)
  python runs/stability/stability_map.py --case ID       # one case (a cluster array task)
  python runs/stability/stability_map.py --plot-only     # figures and README tables from the CSVs
Resumable: cases already in the CSV are skipped. Each case runs in its own
process, holding the lock file --lock (default /tmp/ssi_cpu.lock; --lock ''
for none) while it runs; rows are appended under a lock on the CSV, so array
tasks may run at the same time.
"""
import argparse
import csv
import fcntl
import json
import math
import os
import subprocess
import sys
import time
from petsc_ssi.launch import child_env

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, ROOT)

CS, CP = 316.0, 548.0
SIZE = 6.0                       # m, full extent of the map's surface
BETAS = (0.03, 0.05, 0.07, 0.1, 0.15, 0.2, 0.3, 0.5, 0.8, 1.2, 2.0)
HS = (0.5, 1.0, 1.5)
SCHEMES = ("plain", "stabilized")
PAPER_BETA = (0.3, 0.8)
CUT_FACTOR = 1e6                 # runs are cut at this guard factor (blow-up)
GUARD_DEFAULT = 100.0
# interpolation part
I_SIZE, I_H, I_DT, I_R = 12.0, 1.0, 7.5e-4, 3.0
TAUS = (0.6, 0.9, 1.2, 1.5)
KS = (2, 4, 8, 16)
TAU_R = 1.0877
MAP_CSV = os.path.join(HERE, "stability_map.csv")
INTERP_CSV = os.path.join(HERE, "stability_interp.csv")
PREC_CSV = os.path.join(HERE, "stability_precision.csv")
PREC_HS = (1.0, 1.5)
SINGLE_FROM = 3
FIELDS = ["case", "part", "scheme", "h", "size", "beta", "beta_p_min", "dt", "interp", "tau_L", "k",
          "steps_planned", "steps_run", "lags", "rate", "class", "cut", "guard100_step", "onset_step",
          "norm_late", "norm_plateau", "dev_pct", "wall_s"]


def steps_for(size, dt):
    lags = int(math.floor(math.sqrt(2.0) * size / (CS * dt))) + 2
    return max(1000, 3 * lags), lags


def cases():
    out = []
    for part, prefix, hs in (("map", "map", HS), ("precision", "prec", PREC_HS)):
        for scheme in SCHEMES:
            for h in hs:
                for b in BETAS:
                    dt = b * (h / 2) / CS
                    out.append({"case": f"{prefix}-{scheme}-h{h:g}-b{b:g}", "part": part, "scheme": scheme, "h": h,
                                "size": SIZE, "beta": b, "dt": dt, "interp": "none", "tau_L": "", "k": ""})
    out.append({"case": "interp-exact", "part": "interp", "scheme": "stabilized", "h": I_H, "size": I_SIZE,
                "beta": CS * I_DT / (I_H / 2), "dt": I_DT, "interp": "none", "tau_L": "", "k": ""})
    for meth in ("chebyshev", "linear"):
        for tau in TAUS:
            for k in KS:
                out.append({"case": f"interp-{meth}-tau{tau:g}-k{k}", "part": "interp", "scheme": "stabilized",
                            "h": I_H, "size": I_SIZE, "beta": CS * I_DT / (I_H / 2), "dt": I_DT,
                            "interp": meth, "tau_L": tau, "k": k})
    return out


def cost(c):
    """Estimated work of a case: steps x lags x DOFs^2 (about 1e9 per second on this machine)."""
    n, lags = steps_for(c["size"], c["dt"])
    if c["part"] == "interp":
        n = 1000
    nodes = (2 * round(c["size"] / 2 / c["h"]) + 1) ** 2
    return n * lags * (3 * nodes) ** 2


def options(c):
    n, _ = steps_for(c["size"], c["dt"])
    if c["part"] == "interp":
        n = 1000
    h = c["h"]
    o = {"mesh_size": f"{c['size']:g},{c['size']:g}", "mesh_h": h, "mesh_patch": f"{h:g},{h:g}",
         "symmetry": "x=sym,y=sym", "load_group": "load", "load_p0": 1000, "cs": CS, "cp": CP, "rho": 2000,
         "dt": repr(c["dt"]), "t_end": repr(n * c["dt"]), "scheme": c["scheme"], "output_stride": 0,
         "warn_beta": 0, "guard": 1, "guard_factor": CUT_FACTOR, "interp": c["interp"]}
    if c["part"] == "precision":
        o["lag_single_from"] = SINGLE_FROM
    if c["part"] == "interp":
        o["receivers"] = f"{I_R:g},0,0"
        if c["interp"] != "none":
            o.update(interp_tl=repr(c["tau_L"] * I_R / CS), interp_k=c["k"])
    return o, n


# ---------------------------------------------------------------- one case (worker process)
def worker(c, outdir):
    import numpy as np
    from petsc_ssi.petsc import init, SSIError
    PETSc = init([sys.argv[0]])
    from petsc_ssi import options as opt
    import petsc_ssi.app.kinds  # noqa: F401  (every option declared)
    from petsc_ssi.app.kinds import run_bem
    from petsc_ssi.bem import stability as st
    o, n = options(c)
    o["output"] = os.path.join(outdir, c["case"] + ".h5")
    o["output_overwrite"] = 1
    db = PETSc.Options()
    for k, v in o.items():
        db.setValue("ssi_" + k, str(v))
    cfg = opt.resolve(("common", "bem"))
    t0 = time.perf_counter()
    cut, uz = False, None
    try:
        res = run_bem(cfg)
        un, lags = res["unorm"], res["stats"]["lags"]
        if res["u"] is not None:
            uz = res["u"][:, 0, 2]
    except SSIError as exc:
        if not hasattr(exc, "unorm"):
            raise
        un, cut = exc.unorm, True
        lags = steps_for(c["size"], c["dt"])[1]
    wall = time.perf_counter() - t0
    np.save(os.path.join(outdir, c["case"] + ".npy"), un)
    if uz is not None:
        np.save(os.path.join(outdir, c["case"] + "-uz.npy"), uz)
    cls, rate = st.classify(un, cut)
    fin = un[np.isfinite(un)]
    plateau = float(np.median(un[min(len(un) // 4, 200):len(un) // 2])) if len(un) > 8 else float("nan")
    onset = next((i + 1 for i, v in enumerate(un) if not np.isfinite(v) or v > 10 * plateau), None)
    dev = ""
    if uz is not None and c["interp"] != "none":
        ref = os.path.join(outdir, "interp-exact-uz.npy")
        if os.path.exists(ref):
            r = np.load(ref)
            m = min(len(r), len(uz))
            dev = 100 * float(np.abs(uz[:m] - r[:m]).max() / np.abs(r[:m]).max())
    g = st.guard_step(un, GUARD_DEFAULT)
    return {**{k: c[k] for k in ("case", "part", "scheme", "h", "size", "beta", "dt", "interp", "tau_L", "k")},
            "beta_p_min": CP * c["dt"] / (c["h"] / 2), "steps_planned": n, "steps_run": len(un), "lags": lags,
            "rate": rate, "class": cls, "cut": int(cut), "guard100_step": g or "", "onset_step": onset or "",
            "norm_late": float(fin[-1]) if len(fin) else float("nan"), "norm_plateau": plateau,
            "dev_pct": dev, "wall_s": round(wall, 2)}


# ---------------------------------------------------------------- driver
def done_cases(path):
    if not os.path.exists(path):
        return set()
    with open(path) as fh:
        return {r["case"] for r in csv.DictReader(fh)}


def append_row(path, row):
    with open(path + ".lock", "w") as lk:
        fcntl.flock(lk, fcntl.LOCK_EX)
        new = not os.path.exists(path)
        with open(path, "a", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=FIELDS)
            if new:
                w.writeheader()
            w.writerow(row)


def run_case(c, outdir, lock):
    cmd = [sys.executable, os.path.abspath(__file__), "--worker", json.dumps(c), "--out", outdir]
    env = child_env(OPENBLAS_NUM_THREADS="1")
    t0 = time.time()
    fh = open(lock, "a") if lock else None
    try:
        if fh:
            fcntl.flock(fh, fcntl.LOCK_EX)
        p = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, env=env)
    finally:
        if fh:
            fh.close()
    if p.returncode != 0:
        print(f"[stability] {c['case']} FAILED:\n{p.stdout[-2000:]}\n{p.stderr[-2000:]}", flush=True)
        return None
    row = json.loads(p.stdout.strip().splitlines()[-1])
    csvp = {"map": MAP_CSV, "interp": INTERP_CSV, "precision": PREC_CSV}[c["part"]]
    append_row(csvp, row)
    print(f"[stability] {c['case']:34s} {row['class']:15s} rate {row['rate']:.3g}/step "
          f"{row['steps_run']}/{row['steps_planned']} steps, {time.time() - t0:.1f}s", flush=True)
    return row


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--part", choices=("map", "interp", "precision", "all"), default="all")
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "stability"))
    ap.add_argument("--lock", default="/tmp/ssi_cpu.lock")
    ap.add_argument("--minutes", type=float, default=0.0, help="stop starting new cases after this long (0: no limit)")
    ap.add_argument("--max-cost", type=float, default=2.5e11,
                    help="skip cases whose steps x lags x DOFs^2 exceeds this (0: run all; ~1e9 per second)")
    ap.add_argument("--list", action="store_true")
    ap.add_argument("--case", help="run this one case id (or its index in --list)")
    ap.add_argument("--plot-only", action="store_true")
    ap.add_argument("--worker", help=argparse.SUPPRESS)
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    if a.worker:
        c = json.loads(a.worker)
        row = worker(c, a.out)
        sys.stdout.write("\n" + json.dumps(row) + "\n")
        return
    allc = cases()
    if a.list:
        for i, c in enumerate(allc):
            print(i, c["case"])
        return
    if not a.plot_only:
        todo = allc
        if a.case is not None:
            todo = [allc[int(a.case)]] if a.case.isdigit() else [c for c in allc if c["case"] == a.case]
        elif a.part != "all":
            todo = [c for c in allc if c["part"] == a.part]
        done = done_cases(MAP_CSV) | done_cases(INTERP_CSV) | done_cases(PREC_CSV)
        t0 = time.time()
        for c in todo:
            if c["case"] in done:
                continue
            if a.max_cost and cost(c) > a.max_cost and a.case is None:
                print(f"[stability] {c['case']}: skipped, estimated cost {cost(c):.2g} > --max-cost", flush=True)
                continue
            if a.minutes and time.time() - t0 > 60 * a.minutes:
                print("[stability] time limit reached; run again to continue", flush=True)
                return
            run_case(c, a.out, a.lock)
        if a.case is not None:
            return
    from report import report
    report(HERE, a.out)


if __name__ == "__main__":
    main()
