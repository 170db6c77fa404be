"""The fixed-base limit of the seismic input (the numbers behind tests/coupling/test_seismic.py):
a tower of bricks (1 x 1 x 2 m, E 1e7 Pa, rho 2000 kg/m^3, first bending mode about 3 Hz) on a
1 x 1 m footing, under a vertically incident S wave whose surface acceleration is a sin^4 pulse of
0.4 s followed by the reversed pulse (1 m/s^2), on soils of shear-wave speed c_s (c_p = 2 c_s,
rho 1800 kg/m^3) against its fixed-base twin (-ssi_problem fem, the same record as the base's
motion). Prints and writes fixed_base_limit.csv: c_s [m/s], dt [s], max |a_SSI - a_fixed| /
max |a_fixed| of the top's absolute acceleration along x [-], and the ratio of each difference to
the stiffest soil's against (c_s,stiff / c_s)^2.

    python runs/seismic/fixed_base_limit.py        (from the repository root; about half a minute)
"""
import csv
import os
import subprocess
import sys
import tempfile

import h5py
import numpy as np

from petsc_ssi.launch import child_env

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
SOILS = ((500.0, 6e-4), (200.0, 1.5e-3), (20.0, 0.0125))     # c_s and a dt with c_s dt / l <= 1.2
TOWER = ["-ssi_fem_box_cells", "4,4,4", "-ssi_fem_box_size", "1,1,2", "-ssi_fem_box_origin", "-0.5,-0.5,0",
         "-ssi_fem_E", "1e7", "-ssi_fem_rho", "2000", "-ssi_t_end", "0.8", "-ssi_output_stride", "0",
         "-ssi_seismic", "vertical", "-ssi_seismic_units", "m/s2", "-ssi_seismic_taper", "0",
         "-ssi_seismic_baseline", "none"]


def pulse(path):
    t = np.arange(0.0, 1.2 + 1e-9, 0.005)
    a = np.where(t < 0.4, np.sin(np.pi * t / 0.4) ** 4, 0.0) \
        - np.where((t >= 0.4) & (t < 0.8), np.sin(np.pi * (t - 0.4) / 0.4) ** 4, 0.0)
    np.savetxt(path, np.c_[t, a], header="units: m/s2")


def run(args):
    subprocess.run([sys.executable, "-m", "petsc_ssi"] + args, cwd=ROOT, check=True, capture_output=True,
                   env=child_env())


def top(path, key):
    with h5py.File(path, "r") as f:
        return f[f"receivers/{key}"][()][:, 0, 0]


def difference(tmp, record, cs, dt):
    fixed, coupled = os.path.join(tmp, f"fixed-{cs:g}.h5"), os.path.join(tmp, f"ssi-{cs:g}.h5")
    common = TOWER + ["-ssi_seismic_record", record, "-ssi_dt", str(dt)]
    run(["-ssi_problem", "fem", "-ssi_fem_fixed", "base", "-ssi_receivers", "0,0,2", "-ssi_output", fixed] + common)
    run(["-ssi_problem", "ssi", "-ssi_cp", str(2 * cs), "-ssi_cs", str(cs), "-ssi_rho", "1800", "-ssi_mesh_size",
         "2,2", "-ssi_mesh_h", "0.5", "-ssi_mesh_patch", "0.5,0.5", "-ssi_warn_beta", "0",
         "-ssi_structure_receivers", "0,0,2", "-ssi_output", coupled] + common)
    a_fixed = top(fixed, "absolute_acceleration")
    a_ssi = top(coupled.replace(".h5", "_structure.h5"), "acceleration")
    return float(np.abs(a_ssi - a_fixed).max() / np.abs(a_fixed).max())


def main():
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        record = os.path.join(tmp, "pulse.txt")
        pulse(record)
        for cs, dt in SOILS:
            rows.append({"c_s [m/s]": cs, "dt [s]": dt, "difference [-]": difference(tmp, record, cs, dt)})
    d0, c0 = rows[0]["difference [-]"], rows[0]["c_s [m/s]"]
    for r in rows:
        r["difference / stiffest [-]"] = r["difference [-]"] / d0
        r["(c_s,stiff / c_s)^2 [-]"] = (c0 / r["c_s [m/s]"]) ** 2
    with open(os.path.join(HERE, "fixed_base_limit.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    for r in rows:
        print(", ".join(f"{k} {v:.4g}" for k, v in r.items()))


if __name__ == "__main__":
    main()
