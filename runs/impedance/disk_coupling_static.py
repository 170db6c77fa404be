#!/usr/bin/env python3
"""The rigid disk's static horizontal-rocking coupling from an independent solver (issue 46, the
rocking terms): petsc_ssi/analytic/disk_static.py (a welded rigid disk on the half-space with the
Boussinesq-Cerruti surface Green's function; its docstring has the model) at three numbers of rings,
with the observed order and Richardson's limit of each stiffness, beside the BEM's impedance run of
the same disk (runs/impedance/disk-impedance.csv, written by `petsc-ssi impedance` with disk.opts:
its a0 = 0 rows) in the same units.

    .venv/bin/python runs/impedance/disk_coupling_static.py [--nu 0.3333] [--levels 8,12,18]

writes runs/impedance/disk_coupling_static.csv (stiffnesses in units of G R and G R^3; the coupling
in units of R K_x and of sqrt(K_x K_r)) and the table between <!-- disk_coupling:begin/end --> in
runs/impedance/README.md (about a minute).
"""
import argparse
import csv
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, ROOT)
from petsc_ssi.analytic.disk_static import k_z_bonded, stiffness  # noqa: E402


def bem_row():
    """The BEM's static limits K0 of the disk (disk-impedance.csv, a0 = 0), in the same units."""
    path = os.path.join(HERE, "disk-impedance.csv")
    K0 = {}
    with open(path) as fh:
        for r in csv.DictReader(fh):
            if float(r["a0"]) == 0.0:
                K0[r["mode"]] = float(r["K0"])
    G, R = 2000.0 * 316.0 ** 2, 1.0                 # disk.opts: rho 2000 kg/m^3, c_s 316 m/s, R = 1 m
    kx, kz, kr = K0["horizontal"], K0["vertical"], K0["rocking"]
    return {"rings": "BEM (petsc-ssi impedance, disk.opts: 0.25 m elements, 6 m surface)", "sectors": "",
            "unknowns": "", "K_x / (G R)": kx / (G * R), "K_z / (G R)": kz / (G * R), "K_r / (G R^3)": kr / (G * R ** 3),
            "K_z / bonded closed form": kz / k_z_bonded(G, 1.0 / 3.0, R),
            "K_hr / (R K_x)": K0["horizontal-rocking"] / (R * kx), "K_rh / (R K_x)": K0["rocking-horizontal"] / (R * kx),
            "K_hr / sqrt(K_x K_r)": K0["horizontal-rocking"] / math.sqrt(kx * kr),
            "K_rh / sqrt(K_x K_r)": K0["rocking-horizontal"] / math.sqrt(kx * kr)}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--nu", type=float, default=1.0 / 3.0)
    ap.add_argument("--levels", default="8,12,18")
    a = ap.parse_args()
    G, nu, R = 1.0, a.nu, 1.0
    rows = []
    for nr in (int(v) for v in a.levels.split(",")):
        nt = 4 * nr
        K = stiffness(nr, nt, G, nu)
        kx, kz, kr = K[0, 0], K[1, 1], K[2, 2]
        row = {"rings": nr, "sectors": nt, "unknowns": 3 * nr * nt,
               "K_x / (G R)": kx / (G * R), "K_z / (G R)": kz / (G * R), "K_r / (G R^3)": kr / (G * R ** 3),
               "K_z / bonded closed form": kz / k_z_bonded(G, nu, R),
               "K_r / frictionless closed form": kr / (8 * G * R ** 3 / (3 * (1 - nu))),
               "K_x / (8 G R / (2 - nu))": kx / (8 * G * R / (2 - nu)),
               "K_hr / (R K_x)": K[2, 0] / (R * kx), "K_rh / (R K_x)": K[0, 2] / (R * kx),
               "K_hr / sqrt(K_x K_r)": K[2, 0] / math.sqrt(kx * kr), "K_rh / sqrt(K_x K_r)": K[0, 2] / math.sqrt(kx * kr)}
        rows.append(row)
        print(" ".join(f"{k}={v:.5g}" if isinstance(v, float) else f"{k}={v}" for k, v in row.items()), flush=True)
    base = list(rows)
    if len(base) >= 3:
        for key in ("K_hr / (R K_x)", "K_rh / (R K_x)", "K_x / (G R)", "K_z / (G R)", "K_r / (G R^3)"):
            e0, e1, e2 = (r[key] for r in base[-3:])
            h0, h1, h2 = (1.0 / r["rings"] for r in base[-3:])
            ratio = (e0 - e1) / (e1 - e2)
            p = math.log(abs(ratio)) / math.log(h0 / h1) if ratio > 0 else float("nan")
            lim = e2 + (e2 - e1) / ((h1 / h2) ** p - 1) if p == p else float("nan")
            print(f"{key}: observed order {p:.2f}, Richardson limit {lim:.5g}")
            rows.append({"rings": f"extrapolated ({key}; order {p:.2f})", key: lim})
    keys = list(rows[0])
    if abs(nu - 1.0 / 3.0) < 1e-9:
        rows.append(bem_row())
        print(" ".join(f"{k}={v:.5g}" if isinstance(v, float) else f"{k}={v}" for k, v in rows[-1].items()))
    with open(os.path.join(HERE, "disk_coupling_static.csv"), "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow([f"{k} [-]" if k not in ("rings", "sectors", "unknowns") else k for k in keys])
        for r in rows:
            w.writerow([f"{r[k]:.6g}" if isinstance(r.get(k), float) else r.get(k, "") for k in keys])



    cols = ["K_x / (G R)", "K_z / (G R)", "K_r / (G R^3)", "K_hr / (R K_x)", "K_rh / (R K_x)", "K_hr / sqrt(K_x K_r)",
            "K_rh / sqrt(K_x K_r)"]
    lines = ["| model | " + " | ".join(cols) + " |", "|---" * (len(cols) + 1) + "|"]
    for r in base:
        lines.append(f"| independent, {r['rings']} rings x {r['sectors']} sectors | "
                     + " | ".join(f"{r[c]:.4f}" for c in cols) + " |")
    lines.append("| independent, Richardson's limit | " + " | ".join(
        next((f"{x[c]:.4f}" for x in rows if str(x["rings"]).startswith(f"extrapolated ({c};")), "")
        for c in cols) + " |")
    if rows[-1]["rings"].startswith("BEM"):
        lines.append(f"| {rows[-1]['rings']} | " + " | ".join(f"{rows[-1][c]:.4f}" for c in cols) + " |")
    lines.append(f"\nnu = {nu:.4g}; the independent solver's K_z is {base[-1]['K_z / bonded closed form']:.4f} of the "
                 "bonded punch's closed form 4 G R ln(3 - 4 nu) / (1 - 2 nu) at its finest level.")
    readme = os.path.join(HERE, "README.md")
    text = open(readme).read()
    b, e = "<!-- disk_coupling:begin -->", "<!-- disk_coupling:end -->"
    if b in text and abs(nu - 1.0 / 3.0) < 1e-9:
        i, j = text.index(b) + len(b), text.index(e)
        open(readme, "w").write(text[:i] + "\n" + "\n".join(lines) + "\n" + text[j:])
    print("\n".join(lines))


if __name__ == "__main__":
    main()
