"""Unilateral contact of a stiff block in a pit under a horizontal pulse pair (issue 42, item 2; Wolf and
Darbre 1986): the wall's opening and the bottom's uplift against time, and the steps whose active set
settled, for -ssi_contact_separation free (open nodes free in every direction) and auto (a node whose
released shear pushes it into the soil keeps its tangential bond and releases its normal traction only).

The case of jobscripts/pit_contact.sh: pit 2 x 2 x 1 m (-ssi_mesh pit, soil elements 1 m), block of bricks
2 x 2 x 1.5 m (0.5 m cells, E 3e10 N/m^2, rho 2500 kg/m^3) filling it, matched on its walls and bottom;
vertically incident S wave whose surface acceleration is a sin^4 pulse of +1 m/s^2 then one of -1 m/s^2
(40 ms each) scaled to SCALE m/s^2 (default 10); dt 2.5 ms, 56 steps; the contact preload PRELOAD (default
earth:0.5: the lateral earth pressure at rest K0 rho g |z| on the walls, K0 = 0.5, none at the rim, and the
weight on the bottom; -ssi_contact_preload).

    PYTHONPATH=. .venv/bin/python runs/basement/pit_contact.py OUTDIR [PRELOAD [SCALE]]

writes OUTDIR/pit_contact.csv (per law and step: time, settled, open nodes, the largest gap of each wall
x = -1 m and x = +1 m and of the bottom z = -1 m, its edges at the walls apart) and OUTDIR/pit_contact.png.
"""
import os
import subprocess
import sys

import numpy as np

from petsc_ssi.launch import child_env

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "runs", "seismic"))
import input_motion  # noqa: E402
T = 0.04                                      # s: each sin^4 pulse of the pair


def pulse(path):
    """The sin^4 pulse pair of length T each (1 m/s^2), the record of runs/seismic/input_motion.py."""
    return input_motion.pulse(path, T)


def args(record, out, separation, preload, scale):
    return ["-ssi_problem", "ssi", "-ssi_mesh", "pit", "-ssi_mesh_params", "a=1,b=1,d=1", "-ssi_mesh_size", "6,6",
            "-ssi_mesh_h", "1", "-ssi_dt", "0.0025", "-ssi_t_end", "0.14", "-ssi_seismic", "vertical",
            "-ssi_seismic_record", record, "-ssi_seismic_units", "m/s2", "-ssi_seismic_scale", str(scale), "-ssi_seismic_taper", "0",
            "-ssi_seismic_baseline", "none", "-ssi_fem_mesh", "box", "-ssi_fem_box_cells", "4,4,3",
            "-ssi_fem_box_size", "2,2,1.5", "-ssi_fem_box_origin", "-1,-1,-1",
            "-ssi_fem_interface", "xmin,xmax,ymin,ymax,base", "-ssi_fem_E", "3e10", "-ssi_fem_nu", "0.2",
            "-ssi_fem_rho", "2500", "-ssi_contact", "unilateral", "-ssi_contact_preload", str(preload),
            "-ssi_contact_separation", separation, "-ssi_warn_beta", "0", "-ssi_output", out,
            "-ssi_output_overwrite", "1"]


def series(path):
    """Per step: t [s], settled (0/1), open nodes, max gap [m] on the walls x = -1, x = +1 (their nodes above
    the bottom), the bottom's interior (|x| < 1 m) and its edges x = -1, x = +1 (shared with the walls)."""
    import h5py
    with h5py.File(path) as f:
        g = f["interface"]
        t, x, gap = g["t"][:], g["x"][:], g["gap"][:]
        its, nopen = g["iterations"][:], g["n_open"][:]
    bottom = np.isclose(x[:, 2], -1.0)
    sets = [~bottom & np.isclose(x[:, 0], -1.0), ~bottom & np.isclose(x[:, 0], 1.0),
            bottom & (np.abs(x[:, 0]) < 1.0 - 1e-9), bottom & np.isclose(x[:, 0], -1.0),
            bottom & np.isclose(x[:, 0], 1.0)]
    return t, its, nopen, np.stack([np.maximum(gap[:, s].max(axis=1), 0.0) for s in sets], axis=1)


def run(outdir, separation, preload, scale, record):
    out = os.path.join(outdir, f"pit_{separation}.h5")
    p = subprocess.run([sys.executable, "-m", "petsc_ssi", "run"] + args(record, out, separation, preload, scale),
                       cwd=ROOT, capture_output=True, text=True, env=child_env())
    if p.returncode:
        raise SystemExit(p.stdout[-2000:] + p.stderr[-2000:])
    t, its, nopen, gaps = series(out)
    import re
    bad = {int(m) for m in re.findall(r"step (\d+) \(t = [^)]*\): the contact status did not settle", p.stdout + p.stderr)}
    settled = np.array([k + 1 not in bad for k in range(len(t))])
    return t, settled, nopen, gaps, len(bad)


def main(outdir, preload="earth:0.5", scale=10.0):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    os.makedirs(outdir, exist_ok=True)
    record = pulse(os.path.join(outdir, "pulse.txt"))
    rows, fig, axes = [], *plt.subplots(1, 2, figsize=(11, 4), sharey=True)
    names = ("wall x = -1 m", "wall x = +1 m", "bottom, |x| < 1 m", "bottom edge x = -1 m", "bottom edge x = +1 m")
    for ax, sep in zip(axes, ("free", "auto")):
        t, settled, nopen, gaps, cycled = run(outdir, sep, preload, scale, record)
        print(f"-ssi_contact_separation {sep}: {len(t) - cycled} of {len(t)} steps settled "
              f"({cycled} hit -ssi_contact_max_iter); most open nodes {nopen.max()} of 57")
        for k in range(len(t)):
            rows.append([sep, t[k], int(settled[k]), int(nopen[k])] + list(gaps[k]))
        for j, (name, ls) in enumerate(zip(names, ("-", "-", "-", "--", "--"))):
            ax.plot(t, gaps[:, j] * 1e6, ls, label=name)
        ax.set_title(f"-ssi_contact_separation {sep}: {len(t) - cycled} of {len(t)} steps settled", fontsize=10)
        ax.set_xlabel("t [s]")
    axes[0].set_ylabel("largest gap (opening, uplift) [um]")
    axes[1].legend(fontsize=8)
    fig.suptitle(f"stiff block in a 2 x 2 x 1 m pit, horizontal pulse pair of {scale:g} m/s^2, preload {preload}",
                 fontsize=11)
    fig.tight_layout()
    fig.savefig(os.path.join(outdir, "pit_contact.png"), dpi=110)
    with open(os.path.join(outdir, "pit_contact.csv"), "w") as fh:
        fh.write("separation,t [s],settled,open nodes,gap wall x=-1 [m],gap wall x=+1 [m],gap bottom |x|<1 [m],"
                 "gap bottom edge x=-1 [m],gap bottom edge x=+1 [m]\n")
        for r in rows:
            fh.write(",".join([r[0], f"{r[1]:.6g}", str(r[2]), str(r[3])] + [f"{v:.6g}" for v in r[4:]]) + "\n")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2] if len(sys.argv) > 2 else "earth:0.5", float(sys.argv[3]) if len(sys.argv) > 3 else 10.0)
