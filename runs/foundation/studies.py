#!/usr/bin/env python3
"""The numbers quoted in runs/foundation/README.md besides the benchmark table:
every one is measured here and written between <!-- ssi-studies:begin/end -->.

  momentum    anti-unilateral lift-off: the soil's net impulse vs the block's drift
              velocity (from the benchmark's 1-rank output)
  timeconv    sym-bonded peak base settlement at dt, dt/2, dt/4, implicit and staggered
  interp      the paper's k = 2 interpolation against exact lags (sym-bonded, sym-unilateral)
  long        sym-bonded over 3 s (480 steps): |u| of the soil at 0.5, 1, 2, 3 s
  footing     rigid-footing stiffness vs Pais & Kausel on growing meshes, and the
              lift-off eccentricity e* from the bonded edge tractions (small cases)

    python runs/foundation/studies.py [STUDY ...]     (default: all; from the repository root)
Runs go to out/foundation-studies/; the benchmark outputs are read from out/bench/
(bash jobscripts/foundation_bench.sh first).
"""
import os
import re
import subprocess
import sys

import h5py
import numpy as np

from petsc_ssi.launch import child_env

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
OUT = os.path.join(ROOT, "out", "foundation-studies")
README = os.path.join(ROOT, "runs", "foundation", "README.md")
PY = sys.executable


def run(opts, out, *extra):
    path = os.path.join(OUT, out)
    cmd = [PY, "-m", "petsc_ssi", "-options_file", f"runs/foundation/{opts}.opts", "-ssi_output", path, "-ssi_output_overwrite",
           "-ssi_output_stride", "0"] + list(extra)
    subprocess.run(cmd, cwd=ROOT, check=True, capture_output=True, env=child_env())
    return h5py.File(path, "r")["interface"]


def momentum():
    g = h5py.File(os.path.join(ROOT, "out", "bench", "foundation-anti-unilateral-n1.h5"), "r")["interface"]
    t, ff, uf = g["t"][:], g["force_fe"][:], g["uf"][:, :, 2].mean(axis=1)
    dt = t[1] - t[0]
    impulse = ff[:, 2].sum() * dt
    v = (uf[-1] - uf[-9]) / (8 * dt)
    mass = 2000.0 * 1.0 * 1.0 * 0.5
    return [f"- momentum (anti-unilateral): net vertical soil impulse {impulse:.4g} N s on {mass:g} kg "
            f"= {impulse / mass:.4g} m/s; measured drift velocity of the base {v:.4g} m/s "
            f"(relative difference {abs(v - impulse / mass) / abs(v):.1e})"]


def timeconv():
    lines = ["- time convergence (sym-bonded, -ssi_t_end 0.2, soil mesh fixed): peak mean base settlement [mm]",
             "", "| coupling | dt = 6.25 ms | 3.125 ms | 1.5625 ms | difference ratios |", "|---|---|---|---|---|"]
    for mode in ("implicit", "staggered"):
        peaks = []
        for dt in ("6.25e-3", "3.125e-3", "1.5625e-3"):
            g = run("sym-bonded", f"tc-{mode}-{dt}.h5", "-ssi_dt", dt, "-ssi_t_end", "0.2", "-ssi_coupling", mode,
                    "-ssi_warn_beta", "0")
            peaks.append(-1e3 * g["uf"][:, :, 2].mean(axis=1).min())
        d = np.abs(np.diff(peaks))
        lines.append(f"| {mode} | " + " | ".join(f"{p:.5f}" for p in peaks) + f" | {d[0] / d[1]:.2g} |")
    return lines + [""]


def interp():
    lines = []
    for case in ("sym-bonded", "sym-unilateral"):
        a = h5py.File(os.path.join(ROOT, "out", "bench", f"foundation-{case}-n1.h5"), "r")["interface"]
        b = run(case, f"exact-{case}.h5", "-ssi_interp", "none")
        ua, ub, t = a["uf"][:, :, 2], b["uf"][:, :, 2], a["t"][:]
        e = np.abs(ua - ub).max(axis=1) / np.abs(ub).max()
        same = np.array_equal(a["closed"][:], b["closed"][:])
        lines.append(f"- interpolation k = 2 vs exact lags ({case}): largest difference of the interface u_z "
                     f"{100 * e.max():.2g}% of the peak at t = {t[e.argmax()]:.4g} s, "
                     f"{100 * e[t <= 0.17].max():.2g}% before T_L; same status history: {same}")
    return lines


def long():
    path = os.path.join(OUT, "long.h5")
    subprocess.run([PY, "-m", "petsc_ssi", "-options_file", "runs/foundation/sym-bonded.opts", "-ssi_t_end", "3",
                    "-ssi_output", path, "-ssi_output_overwrite", "-ssi_output_stride", "0", "-ssi_receivers", "0,0,0;1,0,0;2,0,0"],
                   cwd=ROOT, check=True, capture_output=True, env=child_env())
    with h5py.File(path, "r") as f:
        t, u = f["receivers/t"][:], f["receivers/u"][:]
    nrm = np.linalg.norm(u.reshape(len(t), -1), axis=1)
    pick = [np.argmin(np.abs(t - s)) for s in (0.5, 1.0, 2.0, 3.0)]
    return ["- long run (sym-bonded, 480 steps): largest soil receiver |u| "
            f"{nrm.max():.3g} m; at t = " + ", ".join(f"{t[k]:.2g} s: {nrm[k]:.2g} m" for k in pick)]


def footing():
    sys.path.insert(0, os.path.join(ROOT, "tests"))
    sys.path.insert(0, os.path.join(ROOT, "tests", "coupling"))
    from pathlib import Path
    import test_coupled as tc
    os.makedirs(OUT, exist_ok=True)
    ramp = os.path.join(OUT, "ramp.txt")
    with open(ramp, "w") as fh:
        fh.write("0 0\n0.3 1\n10 1\n")
    kw = dict(fem_load_group="top", fem_load_p0=1000, fem_load_history="table", fem_load_table=ramp)
    lines = [f"- rigid footing (stiff block under a slowly applied load), K = P/u_z against Pais & Kausel "
             f"4.7 G B/(1 - nu) = {tc.KZ:.4g} N/m:"]
    for L, h in ((2.0, 0.5), (3.0, 0.5), (5.0, 0.5), (3.0, 0.25)):
        K = 1000.0 / abs(tc.settled_uz(tc.rigid(Path(OUT), L=L, h=h, **kw)))
        lines.append(f"  soil mesh {L:g} m, h = {h:g} m: K = {K:.4g} N/m ({100 * (K / tc.KZ - 1):+.1f}%)")
    kwr = dict(fem_load_history="table", fem_load_table=ramp)
    cen = tc.rigid(Path(OUT), fem_load_group="top", fem_load_p0=1000.0, **kwr)["interface"]
    F = 100.0
    mom = tc.rigid(Path(OUT), fem_load_group="top", fem_load_p0=1e-30,
                   fem_point_load=f"0.5,0,0.25,0,0,{-F};-0.5,0,0.25,0,0,{F}", **kwr)["interface"]
    pP, pM = cen["pN"][-8:].mean(0), mom["pN"][-8:].mean(0) / (F / 1000.0)
    ok = pM > 0
    estar = float((-pP[ok] / pM[ok]).min())
    lines.append(f"- lift-off onset: e* = {estar:.4g} m = {estar / 0.5:.3g} B (disc 0.376 B, strip 0.5 B)")
    return lines


STUDIES = {"momentum": momentum, "timeconv": timeconv, "interp": interp, "long": long, "footing": footing}


def main(names):
    os.makedirs(OUT, exist_ok=True)
    lines = []
    for n in names or list(STUDIES):
        print(f"[studies] {n}", flush=True)
        lines += STUDIES[n]()
    text = "\n".join(lines)
    print(text)
    if not names:
        s = open(README).read()
        a, b = "<!-- ssi-studies:begin -->", "<!-- ssi-studies:end -->"
        s = re.sub(re.escape(a) + ".*?" + re.escape(b), a + "\n" + text + "\n" + b, s, flags=re.S)
        open(README, "w").write(s)


if __name__ == "__main__":
    main(sys.argv[1:])
