"""How k(a0) and c(a0) of the vertical impedance depend on the time step (runs/impedance/README.md):
the square footing (B = 1 m) on an 8 m surface of 0.5 m elements, `petsc-ssi impedance` with
dt = 1.6, 0.8, 0.4 ms (beta = c_s dt / h = 1.0, 0.5, 0.25) and the same 3.2 ms rise, k and c read
at a0 = 0.5 ... 3.

    .venv/bin/python runs/impedance/dt_study.py        (about 1 minute on 2 cores)

writes runs/impedance/dt_study.csv and prints the table."""
import csv
import os
import subprocess
import sys

import numpy as np

from petsc_ssi.launch import child_env

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
OUT = os.path.join(ROOT, "out", "impedance")
A0 = (0.5, 1.0, 1.5, 2.0, 2.5, 3.0)


def main():
    os.makedirs(OUT, exist_ok=True)
    rows = []
    for dt in (1.6e-3, 8e-4, 4e-4):
        stem = os.path.join(OUT, f"dt{dt:g}")
        subprocess.run(["mpirun", "--allow-run-as-root", "--oversubscribe", "-n", "2", sys.executable, "-m", "petsc_ssi",
                        "impedance", "-ssi_problem", "bem", "-ssi_mesh_size", "8,8", "-ssi_mesh_h", "0.5",
                        "-ssi_mesh_patch", "1,1", "-ssi_disp_group", "load", "-ssi_dt", repr(dt), "-ssi_t_end", "0.1",
                        "-ssi_output_stride", "0", "-ssi_warn_beta", "0", "-ssi_impedance_modes", "vertical",
                        "-ssi_impedance_rise", "3.2e-3", "-ssi_output", stem + ".h5", "-ssi_output_overwrite"],
                       cwd=ROOT, check=True, capture_output=True, env=child_env(OPENBLAS_NUM_THREADS="1"))
        r = list(csv.DictReader(open(stem + "-impedance.csv")))
        a, k, c = (np.array([float(x[q]) for x in r]) for q in ("a0", "k", "c"))
        for q in A0:
            rows.append({"dt_ms": dt * 1e3, "a0": q, "k": round(float(np.interp(q, a, k)), 3),
                         "c": round(float(np.interp(q, a, c)), 3)})
    with open(os.path.join(HERE, "dt_study.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    for r in rows:
        print(r)


if __name__ == "__main__":
    main()
