"""The coupled (FEM-BEM) demo building (runs/seismic/building.opts) under the K-NET record plus 50-90 Hz
noise (fixed_base.py's 'knet+hf'), first second: the implicit coupling (structure by the midpoint rule,
the traction as an interval mean) and the staggered coupling (the Green scheme, the traction as an
impulse) at dt = 5 ms and 2.5 ms (issue 46, item 4).

Prints, and writes runs/integrators/coupled.csv: per coupling and dt the roof's (structure receiver 0,
z = 6 m) peak acceleration [m/s^2] (total motion), peak displacement [m], the peak base shear [N] over
the first 1 s, and whether the run warned about the record (fem/integrator_response.py ``record_note``).

    .venv/bin/python runs/integrators/fixed_base.py     (first: writes out/integrators/knet_hf.txt)
    .venv/bin/python runs/integrators/coupled.py        (about 25 minutes on one core)
"""
import csv
import os
import subprocess
import sys

import numpy as np

from petsc_ssi.launch import child_env

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
OUT = os.path.join(ROOT, "out", "integrators")
PY = sys.executable
T_END = 1.0


def run(coupling, dt):
    stem = os.path.join(OUT, f"ssi-{coupling}-{dt:g}")
    cmd = [PY, "-m", "petsc_ssi", "-options_file", "runs/seismic/building.opts", "-ssi_seismic_record",
           os.path.join(OUT, "knet_hf.txt"), "-ssi_coupling", coupling, "-ssi_dt", repr(dt), "-ssi_t_end", str(T_END),
           "-ssi_output_stride", str(int(round(0.1 / dt))), "-ssi_output", stem + ".h5", "-ssi_output_overwrite"]
    p = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, env=child_env(OPENBLAS_NUM_THREADS="1"))
    text = p.stdout + p.stderr
    notes = [ln for ln in text.splitlines() if "static response" in ln]
    if p.returncode:
        return dict(acc=np.nan, u=np.nan, shear=np.nan, notes=notes, status=f"failed ({p.returncode}): "
                    + " | ".join(ln for ln in text.splitlines() if "error" in ln)[:300])
    import h5py
    with h5py.File(stem + "_structure.h5", "r") as f:
        r = f["receivers"]
        acc = float(np.abs(r["acceleration"][:, 0, 0]).max())
        u = float(np.abs(r["u"][:, 0, 0]).max())
        shear = float(np.abs(f["demands/base_shear"][:, 0]).max()) if "demands" in f else np.nan
    return dict(acc=acc, u=u, shear=shear, notes=notes, status="completed")


def main():
    if not os.path.exists(os.path.join(OUT, "knet_hf.txt")):
        raise SystemExit("run runs/integrators/fixed_base.py first (it writes out/integrators/knet_hf.txt)")
    rows = []
    for coupling, dt in (("implicit", 5e-3), ("implicit", 2.5e-3), ("staggered", 5e-3), ("staggered", 2.5e-3)):
        r = run(coupling, dt)
        rows.append({"coupling": coupling, "structure integrator": {"implicit": "midpoint"}.get(coupling, "green"),
                     "dt [s]": dt, "roof peak acceleration [m/s^2]": r["acc"], "roof peak displacement [m]": r["u"],
                     "peak base shear [N]": r["shear"], "warned [0/1]": int(bool(r["notes"])), "status": r["status"]})
        print(f"{coupling:9s} dt {dt:g} s: roof |a| {r['acc']:.4f} m/s^2, roof |u| {r['u']:.4e} m, base shear "
              f"{r['shear']:.4e} N, {r['status']}, warned: {'yes' if r['notes'] else 'no'}", flush=True)
        for line in r["notes"]:
            print("    " + line.strip(), flush=True)
    with open(os.path.join(HERE, "coupled.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        for r in rows:
            w.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in r.items()})
    print(f"wrote {os.path.join(HERE, 'coupled.csv')}")


if __name__ == "__main__":
    main()
