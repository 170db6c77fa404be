"""A building under the earthquake, founded on the ground and on a 3 m basement (runs/basement/README.md):
the peaks of both runs side by side and their histories.

    python runs/basement/compare.py [DIR]       (default out/basement: the outputs of run.sh; out/basement-paper
                                                 for BUILDING=paper)

reads DIR/{surface,basement}.h5 and their _structure.h5, writes DIR/basement.csv (one row per quantity, units
in the names) and DIR/basement.png (roof absolute acceleration, first-storey drift ratio and base shear of
both against time) and prints the CSV. runs/basement keeps copies of the CSV and PNG.

Quantities (x, the wave's polarisation; the full model's values):
  * the free field's PGA at the ground surface (the soil output's seismic group, the record as applied);
  * the peak absolute acceleration of each structure receiver (the run's -ssi_structure_receivers: the demo's
    roof centre (0, 0, 6), first floor (0, 0, 3) and ground floor, the foundation slab's centre (0, 0, 0):
    with the basement, the basement's top; the paper's building has (0, 0, 9) above them);
  * the peak drift ratio of each storey, total (the base's rocking in it) and of deformation alone;
  * the peak rocking theta_y of the ground floor (the rigid rotation fitted to the slab's u_z at z = 0);
  * the peak base shear and overturning moment about (0, 0, 0): the force the structure exerts on the soil
    through its interface (fem/demands.py), i.e. with the basement the force on the pit's walls and bottom,
    the basement's own inertia included.
"""
import os
import sys

import h5py
import numpy as np

CASES = ("surface", "basement")


def load(d, case):
    out = {}
    with h5py.File(os.path.join(d, f"{case}_structure.h5")) as f:
        out["t"] = f["receivers/t"][:]
        out["acc"] = f["receivers/acceleration"][:, :, 0]          # (K, receivers): roof first, ground floor last
        out["z"] = f["receivers/points"][:, 2]
        g = f["demands"]
        out["td"] = g["t"][:]
        out["shear"] = g["base_shear"][:, 0]
        out["moment"] = g["overturning_moment"][:, 1]
        out["drift"] = g["drift_ratio"][:, :, 0]                     # (K, storeys) x
        out["drift_def"] = g["drift_ratio_deformation"][:, :, 0]
        out["rot"] = g["base_rotation"][:, 1]                        # theta_y of the ground floor (z = 0)
    with h5py.File(os.path.join(d, f"{case}.h5")) as f:
        out["pga"] = float(f["seismic/x_pga"][()])
    return out


def table(r):
    o0 = r["surface"]
    rows = [("free-field PGA [m/s^2]", lambda o: o["pga"])]
    for i, z in enumerate(o0["z"]):
        rows.append((f"peak absolute acceleration at (0 0 {z:g}) [m/s^2]", lambda o, i=i: np.abs(o["acc"][:, i]).max()))
    for k in range(o0["drift"].shape[1]):
        rows.append((f"peak drift ratio storey {k + 1} [-]", lambda o, k=k: np.abs(o["drift"][:, k]).max()))
    for k in range(o0["drift"].shape[1]):
        rows.append((f"peak deformation drift ratio storey {k + 1} [-]", lambda o, k=k: np.abs(o["drift_def"][:, k]).max()))
    rows += [("peak rocking theta_y of the ground floor [rad]", lambda o: np.abs(o["rot"]).max()),
             ("peak base shear at the interface [N]", lambda o: np.abs(o["shear"]).max()),
             ("peak overturning moment about (0 0 0) [N m]", lambda o: np.abs(o["moment"]).max())]
    return [(name, fn(r["surface"]), fn(r["basement"])) for name, fn in rows]


def main(d):
    r = {c: load(d, c) for c in CASES}
    rows = table(r)
    lines = ["quantity,surface-founded,on the basement,basement / surface [-]"]
    lines += [f"{n},{a:.4g},{b:.4g},{b / a:.3f}" for n, a, b in rows]
    with open(os.path.join(d, "basement.csv"), "w") as fh:
        fh.write("\n".join(lines) + "\n")
    print("\n".join(lines))
    plot(r, os.path.join(d, "basement.png"))


def plot(r, png):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(3, 1, figsize=(9, 8), sharex=True)
    for c, st in zip(CASES, ("-", "-")):
        o = r[c]
        lab = "founded on the ground" if c == "surface" else "on a 3 m basement"
        ax[0].plot(o["t"], o["acc"][:, 0], st, lw=0.8, label=lab)
        ax[1].plot(o["td"], 1e3 * o["drift"][:, 0], st, lw=0.8, label=lab)
        ax[2].plot(o["td"], 1e-3 * o["shear"], st, lw=0.8, label=lab)
    ax[0].set_ylabel("roof absolute a_x [m/s^2]")
    ax[1].set_ylabel("storey 1 drift ratio x [1e-3]")
    ax[2].set_ylabel("base shear V_x at the interface [kN]")
    ax[2].set_xlabel("t [s]")
    for a in ax:
        a.grid(alpha=0.3)
    ax[0].legend(fontsize=8)
    n = r["surface"]["drift"].shape[1]
    what = {2: "demo building (2 x 2 bays, 2 storeys", 3: "the paper's building (4 x 3 bays, 3 storeys"}.get(n, f"building ({n} storeys")
    ax[0].set_title(f"{what}, full model), K-NET AKT013 E-W x 22.8, c_s 100 m/s")
    fig.tight_layout()
    fig.savefig(png, dpi=110)


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                                              "out", "basement"))
