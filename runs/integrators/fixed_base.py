"""The demo building on a fixed base (runs/seismic/fixed-base.opts) under a record with energy at
50-90 Hz: the Green scheme against Newmark at dt = 5 ms, and both at dt = 1 ms (issue 46).

The record: the K-NET test record ObsPy ships (runs/seismic/README.md; sampled at 100 Hz, so
nothing above 50 Hz), 'knet', and the same record resampled at 2 ms (linearly, as the run reads
it) plus band-limited noise (a sum of 81 sines, 50-90 Hz, random phases, seed 46) whose peak is
1.5 times the record's peak in the window 20-25 s, 'knet+hf': a noise-rich record whose PGA comes
from content above 50 Hz. Both go through the opts' processing (scale 22.8, window, taper, poly6).

When the Green run warns, both schemes run again at the dt the warning names.
Prints, and writes runs/integrators/fixed_base.csv: per record, scheme and dt the roof's (receiver 0,
z = 6 m) peak absolute acceleration [m/s^2] and displacement [m], the peak base shear [N], their
ratios to the Newmark run at the same dt, and whether the run warned (the record's energy above the
scheme's safe band, fem/integrator_response.py ``record_note``).

    .venv/bin/python runs/integrators/fixed_base.py          (about 2 minutes on one core)
"""
import csv
import os
import re
import subprocess
import sys

import numpy as np

from petsc_ssi.launch import child_env

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
OUT = os.path.join(ROOT, "out", "integrators")
PY = sys.executable


def knet_path():
    import obspy
    return os.path.join(os.path.dirname(obspy.__file__), "io", "nied", "tests", "data", "test.knet")


def hf_record(path, seed=46, factor=1.5, band=(50.0, 90.0), h=0.002):
    """Write the K-NET record at step h plus band-limited noise as a 't a' table [s, m/s^2]."""
    sys.path.insert(0, ROOT)
    from petsc_ssi.seismic.records import read_record
    r = read_record(knet_path())
    t0, a0 = np.asarray(r.t, float), np.asarray(r.values, float).reshape(-1)
    t = np.arange(t0[0], t0[-1] + 0.5 * h, h)
    a = np.interp(t, t0, a0)
    rng = np.random.default_rng(seed)
    fr = np.linspace(band[0], band[1], 81)
    noise = np.sin(2 * np.pi * fr[None, :] * t[:, None] + rng.uniform(0, 2 * np.pi, len(fr))[None, :]).sum(1)
    win = (t >= 20.0) & (t <= 25.0)
    noise *= factor * np.abs(a[win]).max() / np.abs(noise[win]).max()
    np.savetxt(path, np.column_stack([t, a + noise]), fmt="%.6f %.9e", header="units: m/s2")
    return path


def run(record, scheme, dt, stem):
    out = os.path.join(OUT, stem + ".h5")
    cmd = [PY, "-m", "petsc_ssi", "-options_file", "runs/seismic/fixed-base.opts", "-ssi_seismic_record", record,
           "-ssi_fem_integrator", scheme, "-ssi_dt", repr(dt), "-ssi_output_stride", str(int(round(0.1 / dt))),
           "-ssi_output", out, "-ssi_output_overwrite"]
    p = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, env=child_env(OPENBLAS_NUM_THREADS="1"))
    if p.returncode:
        raise SystemExit(f"{' '.join(cmd)} failed:\n{p.stdout[-3000:]}\n{p.stderr[-3000:]}")
    notes = [ln for ln in (p.stdout + p.stderr).splitlines() if "static response" in ln]
    import h5py
    with h5py.File(out, "r") as f:
        r = f["receivers"]
        acc = float(np.abs(r["absolute_acceleration"][:, 0, 0]).max())
        u = float(np.abs(r["u"][:, 0, 0]).max())
        shear = float(np.abs(f["demands/base_shear"][:, 0]).max())
    return dict(acc=acc, u=u, shear=shear, notes=notes)


def main():
    os.makedirs(OUT, exist_ok=True)
    records = {"knet": knet_path(), "knet+hf": hf_record(os.path.join(OUT, "knet_hf.txt"))}
    rows = []
    for name, rec in records.items():
        dts = [5e-3, 1e-3]
        while dts:
            dt = dts.pop(0)
            res = {s: run(rec, s, dt, f"{name.replace('+', '_')}-{s}-{dt:g}") for s in ("newmark", "green")}
            named = re.search(r"-ssi_dt ([0-9.e-]+) keeps", " ".join(res["green"]["notes"]))
            if named:                       # and at the step the warning names
                dts.insert(0, float(named.group(1)))
            for s, r in res.items():
                n = res["newmark"]
                rows.append({"record": name, "scheme": s, "dt [s]": dt,
                             "roof peak absolute acceleration [m/s^2]": r["acc"], "roof peak displacement [m]": r["u"], "peak base shear [N]": r["shear"],
                             "acceleration / newmark's [-]": r["acc"] / n["acc"], "displacement / newmark's [-]":
                             r["u"] / n["u"], "base shear / newmark's [-]": r["shear"] / n["shear"],
                             "warned [0/1]": int(bool(r["notes"]))})
                print(f"{name:8s} {s:8s} dt {dt:g} s: roof |a| {r['acc']:.4f} m/s^2 (x{r['acc'] / n['acc']:.3f} "
                      f"newmark), roof |u| {r['u']:.4e} m (x{r['u'] / n['u']:.3f}), base shear {r['shear']:.4e} N "
                      f"(x{r['shear'] / n['shear']:.3f}), warned: {'yes' if r['notes'] else 'no'}")
                for line in r["notes"]:
                    print("    " + line.strip())
    with open(os.path.join(HERE, "fixed_base.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        for r in rows:
            w.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in r.items()})
    print(f"wrote {os.path.join(HERE, 'fixed_base.csv')}")


if __name__ == "__main__":
    main()
