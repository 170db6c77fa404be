"""Static stiffness of a rigid square footing from the late-time limit of a held rigid motion,
against Pais and Kausel (1988) (issue 12: the static limits).

Footing 2B x 2B (B = 1 m) on the paper's soil (c_p 548, c_s 316 m/s, rho 2000 kg/m^3: G = 2.0e8 Pa,
nu = 0.251); four modes, each with the symmetry planes its motion allows (a quarter model):

    vertical    u0 = (0, 0, -1e-6)     x=sym,  y=sym     K_z   = 4.7 G B / (1 - nu)
    horizontal  u0 = (1e-6, 0, 0)      x=anti, y=sym     K_x   = 9.2 G B / (2 - nu)
    rocking     theta0 = (0, 1e-6, 0)  x=anti, y=sym     K_ry  = 4.0 G B^3 / (1 - nu)
    torsion     theta0 = (0, 0, 1e-6)  x=anti, y=anti    K_rz  = 8.3 G B^3

held from the first step (-ssi_disp_history heaviside); K = the force (moment) of the last step over
the motion, once the last 30 steps agree to 2e-3. Meshes: element size h = 0.5 m on surfaces of
6 m and 12 m (the extent), and h = 0.25 m on 6 m (the element size); beta = c_s dt / h = 0.5.
The error falls like h^(1/2) (the traction of a rigid footing is singular like d^(-1/2) at its
edges), so the last column is the Richardson extrapolation K(h) + (K(h) - K(2h)) / (sqrt(2) - 1).

    .venv/bin/python runs/impedance/static_stiffness.py      (about 3 minutes on 2 cores)

writes runs/impedance/static_stiffness.csv, static_stiffness.png and the table in README.md.
"""
import csv
import os
import subprocess
import sys

import numpy as np

from petsc_ssi.launch import child_env

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
OUT = os.path.join(ROOT, "out", "impedance")
G = 2000.0 * 316.0 ** 2
NU = ((548 / 316) ** 2 - 2) / (2 * ((548 / 316) ** 2 - 1))
MODES = {  # name: (motion option, value, symmetry, result, component, reference)
    "vertical": ("-ssi_disp_value", "0,0,-1e-6", "x=sym,y=sym", "force", 2, 4.7 * G / (1 - NU), -1e-6),
    "horizontal": ("-ssi_disp_value", "1e-6,0,0", "x=anti,y=sym", "force", 0, 9.2 * G / (2 - NU), 1e-6),
    "rocking": ("-ssi_disp_rotation", "0,1e-6,0", "x=anti,y=sym", "moment", 1, 4.0 * G / (1 - NU), 1e-6),
    "torsion": ("-ssi_disp_rotation", "0,0,1e-6", "x=anti,y=anti", "moment", 2, 8.3 * G, 1e-6),
}
MESHES = [(6.0, 0.5), (12.0, 0.5), (6.0, 0.25)]          # (surface extent L, element size h)


def run(mode, L, h):
    opt, val, sym, what, comp, ref, amp = MODES[mode]
    dt = 0.5 * h / 316.0
    out = os.path.join(OUT, f"static-{mode}-L{L:g}-h{h:g}.h5")
    cmd = ["mpirun", "--allow-run-as-root", "--oversubscribe", "-n", "2", sys.executable, "-m", "petsc_ssi",
           "-ssi_problem", "bem", "-ssi_mesh_size", f"{L:g},{L:g}", "-ssi_mesh_h", f"{h:g}", "-ssi_mesh_patch", "1,1",
           "-ssi_disp_group", "load", opt, val, "-ssi_symmetry", sym, "-ssi_dt", repr(dt),
           "-ssi_t_end", repr(max(0.1, 3.0 * L / 316.0)), "-ssi_output_stride", "0", "-ssi_warn_beta", "0",
           "-ssi_output", out, "-ssi_output_overwrite"]
    subprocess.run(cmd, cwd=ROOT, check=True, capture_output=True, env=child_env(OPENBLAS_NUM_THREADS="1"))
    import h5py
    with h5py.File(out) as f:
        x = f["resultants"][what][:, comp] / amp
        wall = __import__("json").load(open(out[:-3] + ".json"))["stats"]["wall_s"]
    settled = float(np.ptp(x[-30:]) / abs(x[-1]))
    return float(x[-1]), settled, wall


def main():
    os.makedirs(OUT, exist_ok=True)
    rows = []
    for mode, spec in MODES.items():
        ref = spec[5]
        k = {}
        for L, h in MESHES:
            K, settled, wall = run(mode, L, h)
            assert settled < 2e-3, (mode, L, h, settled)
            k[(L, h)] = K
            rows.append({"mode": mode, "extent_m": L, "h_m": h, "K": K, "K_over_reference": K / ref,
                         "settled": settled, "wall_s": wall})
            print(f"{mode:10s} L {L:4g} h {h:4g}: K/K_ref = {K / ref:.4f} ({wall:.1f} s)", flush=True)
        ext = k[(6.0, 0.25)] + (k[(6.0, 0.25)] - k[(6.0, 0.5)]) / (np.sqrt(2) - 1)
        rows.append({"mode": mode, "extent_m": 6.0, "h_m": 0.0, "K": ext, "K_over_reference": ext / ref,
                     "settled": 0.0, "wall_s": 0.0})
    with open(os.path.join(HERE, "static_stiffness.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    table = ["| mode | Pais-Kausel K | L 6 m, h 0.5 m | L 12 m, h 0.5 m | L 6 m, h 0.25 m | extrapolated h -> 0 |",
             "|---|---|---|---|---|---|"]
    for mode, spec in MODES.items():
        r = {(x["extent_m"], x["h_m"]): x["K_over_reference"] for x in rows if x["mode"] == mode}
        table.append(f"| {mode} | {spec[5]:.4g} | {r[(6.0, 0.5)]:.3f} | {r[(12.0, 0.5)]:.3f} | {r[(6.0, 0.25)]:.3f} | "
                     f"{r[(6.0, 0.0)]:.3f} |")
    readme = os.path.join(HERE, "README.md")
    text = open(readme).read()
    b, e = "<!-- static:begin -->", "<!-- static:end -->"
    i, j = text.index(b) + len(b), text.index(e)
    open(readme, "w").write(text[:i] + "\n" + "\n".join(table) + "\n" + text[j:])
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 4))
    for mode in MODES:
        r = {x["h_m"]: x["K_over_reference"] for x in rows if x["mode"] == mode and x["extent_m"] == 6.0}
        hs = [0.0, 0.25, 0.5]
        ax.plot(np.sqrt(hs[1:]), [r[h] for h in hs[1:]], "o-", label=mode)
        ax.plot([0.0], [r[0.0]], "x", color=ax.lines[-1].get_color())
    ax.axhline(1.0, color="k", lw=0.8)
    ax.set_xlabel("sqrt(h / 1 m)   (x: extrapolated to h = 0)")
    ax.set_ylabel("K / K (Pais and Kausel 1988)")
    ax.set_title("Static stiffness of a square footing, B = 1 m, 6 m x 6 m surface")
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(HERE, "static_stiffness.png"), dpi=120)
    print("\n".join(table))


if __name__ == "__main__":
    main()
