"""A footing on a pit filled with the half-space's own soil against the same footing on the plain half-space
(issue 42, item 4: "a surface footing on that filled excavation has the impedance of the footing on the
plain half-space, converging likewise").

Set-up (meshes/pit_footing.geo): a concrete block 2c x 2c x hf (c = 0.5 m, hf = 0.5 m; E = 3e10 N/m^2,
nu = 0.2, rho = 2500 kg/m^3) centred on the ground z = 0 of the paper's soil (c_p 548, c_s 316 m/s,
rho 2000 kg/m^3), loaded on its top by a vertical and a horizontal force of the same history, a sin^2
pulse of T = 40 ms (the vertical force V0 = 1e5 N down as a pressure on the top, the horizontal H0 = 1e5 N
along x shared equally by the top's nodes):
  * filled: the block stands on a soil region of bricks (cp/cs/rho of the half-space) filling a pit of
    2a x 2b x d = 2 x 2 x 1 m, coupled to the BEM on the pit's walls and bottom (-ssi_mesh pit);
  * plain: the same block on the flat ground (-ssi_mesh grid -ssi_mesh_patch c,c), its base the interface.
Both on a 6 m x 6 m ground of soil elements h, bricks h/2, the same dt = 2.5 ms x h (beta = c_s dt / h
= 0.79), 0.12 s. By linearity and the symmetry of the block the top centre's u_z is the vertical load's and
its u_x the horizontal load's (translation and rocking).
The measure: max_t |u_filled - u_plain| / max_t |u_plain| of the top centre's u_z and u_x, and the
compliance's spectrum |U_filled(f) / U_plain(f)| - 1 over the load's band.

    python runs/soil_region/footing.py [OUTDIR] [h,...]       (default out/soil_region/footing 1,0.5)

writes OUTDIR/{filled,plain}-h{h}.h5, OUTDIR/footing.csv and OUTDIR/footing.png (runs/soil_region keeps copies)
and prints the table.
"""
import os
import subprocess
import sys
import time

import numpy as np

from petsc_ssi.launch import child_env

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CS, CP, RHO = 316.0, 548.0, 2000.0
A, D, C, HF = 1.0, 1.0, 0.5, 0.5             # pit half-width, depth; footing half-width, height [m]
V0, H0, T = 1e5, 1e5, 0.04                   # forces [N], pulse length [s]
T_END = 0.16


def pulse_table(path):
    """h(t) = sin^2(pi t / T) on [0, T], 0 after."""
    t = np.linspace(0.0, T, 81)
    np.savetxt(path, np.c_[np.r_[t, T + 1e-6], np.r_[np.sin(np.pi * t / T) ** 2, 0.0]])
    return path


def args(case, h, out, table):
    """The petsc-ssi command line of a case 'filled' or 'plain' with soil elements h [m]."""
    n_top = (int(round(2 * C / (h / 2))) + 1) ** 2
    common = ["-ssi_problem", "ssi", "-ssi_cp", str(CP), "-ssi_cs", str(CS), "-ssi_rho", str(RHO),
              "-ssi_mesh_size", "6,6", "-ssi_mesh_h", str(h), "-ssi_dt", str(0.0025 * h), "-ssi_t_end", str(T_END),
              "-ssi_fem_mesh", "meshes/pit_footing.geo",
              "-ssi_fem_part_footing_element", "hex8", "-ssi_fem_part_footing_E", "3e10",
              "-ssi_fem_part_footing_nu", "0.2", "-ssi_fem_part_footing_rho", "2500",
              "-ssi_fem_load_group", "top", "-ssi_fem_load_p0", str(V0 / (2 * C) ** 2),
              "-ssi_fem_point_load", f"top,{H0 / n_top!r},0,0",
              "-ssi_fem_load_history", "table", "-ssi_fem_load_table", table,
              "-ssi_structure_receivers", f"0,0,{HF};0,0,0", "-ssi_receivers", "2,0,0",
              "-ssi_output", out, "-ssi_output_overwrite", "1", "-ssi_warn_beta", "0"]
    if case == "filled":
        return common + ["-ssi_mesh", "pit", "-ssi_mesh_params", f"a={A},b={A},d={D}",
                         "-ssi_fem_mesh_params", f"a={A},b={A},d={D},c={C},hf={HF},h={h},fill=1",
                         "-ssi_fem_parts", "soil,footing", "-ssi_fem_part_soil_element", "hex8",
                         "-ssi_fem_part_soil_cp", str(CP), "-ssi_fem_part_soil_cs", str(CS),
                         "-ssi_fem_part_soil_rho", str(RHO), "-ssi_fem_interface", "walls,bottom"]
    return common + ["-ssi_mesh", "grid", "-ssi_mesh_patch", f"{C},{C}",
                     "-ssi_fem_mesh_params", f"a={A},b={A},d={D},c={C},hf={HF},h={h},fill=0",
                     "-ssi_fem_parts", "footing", "-ssi_fem_interface", "base"]


def run(case, h, outdir, nranks=1):
    """Run one case; return (output path, wall time [s])."""
    os.makedirs(outdir, exist_ok=True)
    table = pulse_table(os.path.join(outdir, "pulse.txt"))
    out = os.path.join(outdir, f"{case}-h{h:g}.h5")
    cmd = [sys.executable, "-m", "petsc_ssi", "run"] + args(case, h, out, table)
    if nranks > 1:
        cmd = ["mpirun", "--allow-run-as-root", "--oversubscribe", "-n", str(nranks)] + cmd
    env = child_env(OPENBLAS_NUM_THREADS="1")
    t0 = time.time()
    p = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, env=env)
    if p.returncode:
        raise RuntimeError(f"{' '.join(cmd)}\n{p.stdout[-2000:]}\n{p.stderr[-2000:]}")
    return out, time.time() - t0


def top_centre(out, k=0):
    """(t [s], u (K, 3) [m]) of the block's top centre (structure receiver 0; k = 1: its base centre)."""
    import h5py
    with h5py.File(out.replace(".h5", "_structure.h5")) as f:
        return f["receivers/t"][:], f["receivers/u"][:, k, :]


def compare(filled, plain):
    """{component: max|u_f - u_p| / max|u_p|} for x (horizontal load) and z (vertical load), and the
    spectra (f [Hz], |U_f/U_p - 1| per component: the compliances' difference, amplitude and phase) over the
    band where |U_p| is at least a tenth of its peak."""
    t, uf = top_centre(filled)
    tp, up = top_centre(plain)
    assert np.allclose(t, tp)
    err = {c: float(np.abs(uf[:, k] - up[:, k]).max() / np.abs(up[:, k]).max()) for c, k in (("x", 0), ("z", 2))}
    # the horizontal response split: the base centre's u_x (translation) and top minus base (rocking x hf)
    bf, bp = top_centre(filled, 1)[1][:, 0], top_centre(plain, 1)[1][:, 0]
    err["x base"] = float(np.abs(bf - bp).max() / np.abs(bp).max())
    rf, rp = uf[:, 0] - bf, up[:, 0] - bp
    err["x top - base"] = float(np.abs(rf - rp).max() / np.abs(rp).max())
    n = 8 * len(t)
    f = np.fft.rfftfreq(n, t[1] - t[0])
    ratio, band = {}, {}
    for c, k in (("x", 0), ("z", 2)):
        Uf, Up = np.fft.rfft(uf[:, k], n), np.fft.rfft(up[:, k], n)
        keep = np.abs(Up) >= 0.1 * np.abs(Up).max()
        keep &= np.cumprod(keep) > 0                  # the band from f = 0 up to the first drop below a tenth
        ratio[c], band[c] = np.abs(Uf / Up - 1)[keep], f[keep].max()
    return err, band, ratio, (t, uf, up)


def main(argv):
    outdir = argv[1] if len(argv) > 1 else os.path.join(ROOT, "out", "soil_region", "footing")
    hs = [float(s) for s in (argv[2] if len(argv) > 2 else "1,0.5").split(",")]
    rows, curves, parts = [], {}, []
    for h in hs:
        walls = {}
        paths = {}
        for case in ("plain", "filled"):
            paths[case], walls[case] = run(case, h, outdir)
        err, band, ratio, hist = compare(paths["filled"], paths["plain"])
        curves[h] = hist
        for c in ("z", "x"):
            rows.append((h, c, np.abs(hist[2][:, "xz".index(c) * 2]).max(), np.abs(hist[1][:, "xz".index(c) * 2]).max(),
                         err[c], band[c], np.abs(ratio[c]).max(), walls["plain"], walls["filled"]))
        parts.append((h, err["x base"], err["x top - base"]))
    header = ("h [m],component [-],peak u plain [m],peak u filled [m],max|u_filled - u_plain| / peak [-],"
              "band f_max [Hz],max |U_filled/U_plain - 1| in the band [-],wall plain [s],wall filled [s]")
    lines = [header] + [f"{h:g},{c},{pk:.4e},{pf:.4e},{e:.4e},{b:.1f},{r:.4e},{wp:.1f},{wf:.1f}"
                        for h, c, pk, pf, e, b, r, wp, wf in rows]
    csv = os.path.join(outdir, "footing.csv")
    with open(csv, "w") as fh:
        fh.write("\n".join(lines) + "\n")
    print("\n".join(lines))
    print("the horizontal force's response split, max|u_filled - u_plain| / peak [-]:")
    for h, eb, er in parts:
        print(f"  h = {h:g} m: base centre u_x (translation) {eb:.3e}, top minus base u_x (rocking x hf) {er:.3e}")
    plot(curves, os.path.join(outdir, "footing.png"))


def plot(curves, png):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    for k, (c, title) in enumerate((("z", "vertical force: top centre u_z"), ("x", "horizontal force: top centre u_x"))):
        j = "xz".index(c) * 2
        for h, (t, uf, up) in sorted(curves.items(), reverse=True):
            ax[k].plot(1e3 * t, 1e6 * up[:, j], "-", label=f"plain half-space, h = {h:g} m")
            ax[k].plot(1e3 * t, 1e6 * uf[:, j], "--", label=f"on the filled pit, h = {h:g} m")
        ax[k].set_xlabel("t [ms]")
        ax[k].set_ylabel(f"u_{c} [um]")
        ax[k].set_title(title)
        ax[k].grid(alpha=0.3)
    ax[0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(png, dpi=110)


if __name__ == "__main__":
    main(sys.argv)
