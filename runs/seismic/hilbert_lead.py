"""The tapered lead of a Hilbert-transform wave (Rayleigh, post-critical SV) against its tolerance
(-ssi_seismic_hilbert_tol): the numbers the issue note and runs/seismic/README.md cite.

A 1 m x 1 m x 2 m brick block (E 3e7 Pa) on the paper's foundation soil (c_p 42, c_s 20 m/s, rho
1800 kg/m^3) under a Rayleigh wave whose vertical surface displacement is a 1 mm sin^4 pulse of 0.2 s
(its integral is not zero: H[g]'s lead falls as 1/t). Runs with tolerances 0.05, 0.01 (the default)
and 0.001, and prints each run's lead (the wave's start before the record) and the largest difference
of the roof's acceleration from the 0.001 run on the record's time axis, relative to its peak. Then
the lead of the repository's test AT2 record high-passed at 0.1 Hz on the paper's Lamb soil.

    python runs/seismic/hilbert_lead.py        (about a minute on one core)
"""
import os
import subprocess
import sys
import tempfile

import h5py
import numpy as np

from petsc_ssi.launch import child_env

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))


def run(args):
    p = subprocess.run([sys.executable, "-m", "petsc_ssi"] + args, cwd=ROOT, capture_output=True, text=True,
                       env=child_env())
    if p.returncode != 0:
        raise SystemExit(p.stdout + p.stderr)
    return p.stdout


def block(tmp, tol, rec):
    out = os.path.join(tmp, f"b{tol}.h5")
    log = run(["-ssi_problem", "ssi", "-ssi_cp", "42", "-ssi_cs", "20", "-ssi_rho", "1800", "-ssi_mesh_size", "2,2",
               "-ssi_mesh_h", "0.5", "-ssi_mesh_patch", "0.5,0.5", "-ssi_fem_box_cells", "4,4,4", "-ssi_fem_box_size",
               "1,1,2", "-ssi_fem_box_origin", "-0.5,-0.5,0", "-ssi_fem_E", "3e7", "-ssi_fem_rho", "2000", "-ssi_dt",
               "0.006", "-ssi_warn_beta", "0", "-ssi_seismic", "rayleigh", "-ssi_seismic_record", rec,
               "-ssi_seismic_taper", "0", "-ssi_seismic_baseline", "none", "-ssi_seismic_hilbert_tol", str(tol),
               "-ssi_structure_receivers", "0,0,2", "-ssi_output", out, "-ssi_output_stride", "0"])
    with h5py.File(out.replace(".h5", "_structure.h5"), "r") as f:
        t, a = f["receivers/t"][()], f["receivers/acceleration"][()][:, 0, :]
    with h5py.File(out, "r") as f:
        t0 = float(f["seismic/t0"][()])
    lead = [ln for ln in log.splitlines() if "the wave starts" in ln][0].split("the wave starts")[1].split()[0]
    return t - t0, a, float(lead)


def main():
    with tempfile.TemporaryDirectory() as tmp:
        t = np.arange(0.0, 0.4 + 1e-9, 1.25e-3)
        rec = os.path.join(tmp, "dpulse.txt")
        np.savetxt(rec, np.c_[t, np.where(t < 0.2, np.sin(np.pi * t / 0.2) ** 4, 0.0)], header="units: mm")
        runs = {tol: block(tmp, tol, rec) for tol in (0.001, 0.01, 0.05)}
        tr, ar, _ = runs[0.001]
        peak = np.abs(ar).max()
        print("Rayleigh wave, 1 mm sin^4 displacement pulse of 0.2 s, block's roof acceleration [m/s^2]")
        print("| -ssi_seismic_hilbert_tol | lead before the record [s] | max difference from tol 0.001 / peak |")
        print("|---|---|---|")
        for tol in (0.05, 0.01, 0.001):
            t1, a1, lead = runs[tol]
            keep = (t1 >= 0.0) & (t1 <= 0.4)
            ai = np.stack([np.interp(t1[keep], tr, ar[:, j]) for j in range(3)], axis=1)
            print(f"| {tol:g} | {lead:.4g} | {np.abs(a1[keep] - ai).max() / peak:.3g} |")
        log = run(["-ssi_problem", "bem", "-ssi_mesh_size", "4,4", "-ssi_mesh_h", "1", "-ssi_cp", "548", "-ssi_cs",
                   "316", "-ssi_dt", "0.005", "-ssi_t_end", "0.05", "-ssi_seismic", "rayleigh", "-ssi_seismic_record",
                   os.path.join(ROOT, "tests", "seismic", "data", "nga_west2.AT2"), "-ssi_seismic_highpass", "0.1",
                   "-ssi_output", os.path.join(tmp, "nga.h5")])
        line = [ln for ln in log.splitlines() if "the wave starts" in ln][0]
        print("\ntests/seismic/data/nga_west2.AT2 high-passed at 0.1 Hz:" + line.split("tapered")[1])


if __name__ == "__main__":
    main()
