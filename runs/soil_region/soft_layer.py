"""A soft layer in a box of finite elements on the half-space under vertically incident S (issue 42,
item 5): the surface motion at the box's centre against the 1D layer-on-half-space transfer function, and
the box width's effect.

The ground: the paper's soil (c_p 548, c_s 316 m/s, rho 2000 kg/m^3) with a pit W x W x H (H = 2 m), the
pit filled with bricks of a softer soil (c_s1 158, c_p1 274 m/s, rho1 1800 kg/m^3: a soil region,
-ssi_fem_cs/-ssi_fem_cp/-ssi_fem_rho) coupled to the BEM on its walls and bottom. The input: a vertically
incident S wave whose free-surface motion (on the half-space without the layer) is a 10 ms sin^4 pulse
pair in acceleration (broad band). The transfer function is the ratio of the spectra of the velocity at
the layer's surface centre and of the free-surface velocity of the half-space (the record's), against

  1D (an infinitely wide layer):  |U_top / U_outcrop| = 1 / |cos(k H) + i alpha sin(k H)|,
                                  k = 2 pi f / c_s1, alpha = rho1 c_s1 / (rho c_s) (0.45 here),
  peak 1/alpha = 2.22 at f0 = c_s1 / 4H = 19.75 Hz;
  a box with rigid walls (its first mode, the lateral walls as nodes):  f = f0 sqrt(1 + 2 (2H/W)^2),

so a narrow box resonates higher than the 1D layer and tends to it as W/H grows.

Run: python runs/soil_region/soft_layer.py [W1,W2,...] [ranks]   (default 6,10 and 1 rank)
Writes soft_layer.csv (frequency [Hz], |TF| per width [1], the 1D |TF| [1]) and soft_layer.png beside this
file, and prints each width's peak (frequency, amplitude) beside the estimates above.
"""
import os
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "runs", "seismic"))
import input_motion  # noqa: E402
CS, CP, RHO = 316.0, 548.0, 2000.0
CS1, CP1, RHO1 = 158.0, 274.0, 1800.0
H, DT, T_END, PULSE = 2.0, 0.0025, 0.4, 0.01
ALPHA = RHO1 * CS1 / (RHO * CS)
F0 = CS1 / (4 * H)


def record(path):
    """The 10 ms sin^4 acceleration pulse and its reverse (zero net velocity), 1 m/s^2 [table 't a']: the
    record of runs/seismic/input_motion.py."""
    return input_motion.pulse(path, PULSE)


def run(W, ranks, out):
    """The coupled run of a box of width W [m]: soil elements 1 m, bricks 0.5 m, ground W + 6 m wide."""
    n = int(round(2 * W))
    args = ["-m", "petsc_ssi", "run", "-ssi_problem", "ssi", "-ssi_mesh", "pit",
            "-ssi_mesh_params", f"a={W / 2},b={W / 2},d={H}", "-ssi_mesh_size", f"{W + 6},{W + 6}",
            "-ssi_mesh_h", "1", "-ssi_dt", str(DT), "-ssi_t_end", str(T_END), "-ssi_seismic", "vertical",
            "-ssi_seismic_record", record(os.path.join(os.path.dirname(out), "pulse.txt")),
            "-ssi_seismic_units", "m/s2", "-ssi_seismic_taper", "0", "-ssi_seismic_baseline", "none",
            "-ssi_fem_mesh", "box", "-ssi_fem_box_cells", f"{n},{n},{int(2 * H)}",
            "-ssi_fem_box_size", f"{W},{W},{H}", "-ssi_fem_box_origin", f"{-W / 2},{-W / 2},{-H}",
            "-ssi_fem_interface", "xmin,xmax,ymin,ymax,base", "-ssi_fem_cp", str(CP1), "-ssi_fem_cs", str(CS1),
            "-ssi_fem_rho", str(RHO1), "-ssi_structure_receivers", "0,0,0", "-ssi_receivers", f"{W / 2 + 2},0,0",
            "-ssi_output", out, "-ssi_output_overwrite", "1", "-ssi_output_stride", "0", "-ssi_warn_beta", "0",
            "-ssi_monitor"]
    cmd = [sys.executable] + args
    if ranks > 1:
        cmd = ["mpirun", "--allow-run-as-root", "-n", str(ranks)] + cmd
    subprocess.run(cmd, cwd=ROOT, check=True)


def transfer(out, nfft_factor=4):
    """(f [Hz], |V_top / V_ff|): the spectra of the layer's surface centre velocity and of the free
    surface's (the record's displacement, differentiated the same way)."""
    import h5py
    with h5py.File(out.replace(".h5", "_structure.h5")) as fs, h5py.File(out) as f:
        t, u = fs["receivers/t"][:], fs["receivers/u"][:, 0, 0]
        D, td, t0 = f["seismic/x_displacement"][:], f["seismic/x_t"][:], float(f["seismic/t0"][()])
    uff = np.interp(t - t0, td, D, left=0.0)
    dt = t[1] - t[0]
    n = nfft_factor * len(t)
    V, Vff = np.fft.rfft(np.gradient(u, dt), n), np.fft.rfft(np.gradient(uff, dt), n)
    with np.errstate(divide="ignore", invalid="ignore"):     # (the pulse's spectral zeros, above 100 Hz)
        return np.fft.rfftfreq(n, dt), np.abs(V / Vff)


def one_d(f):
    k = 2 * np.pi * f / CS1
    return 1.0 / np.abs(np.cos(k * H) + 1j * ALPHA * np.sin(k * H))


def main():
    widths = [float(w) for w in (sys.argv[1] if len(sys.argv) > 1 else "6,10").split(",")]
    ranks = int(sys.argv[2]) if len(sys.argv) > 2 else 1
    os.makedirs(os.path.join(ROOT, "out", "soft_layer"), exist_ok=True)
    cols, f = {}, None
    for W in widths:
        out = os.path.join(ROOT, "out", "soft_layer", f"W{W:g}.h5")
        run(W, ranks, out)
        f, tf = transfer(out)
        cols[W] = tf
    keep = f <= 40.0                      # 6 bricks and 10 steps per wavelength and period of the layer
    f = f[keep]
    table = np.column_stack([f] + [cols[W][keep] for W in widths] + [one_d(f)])
    head = "f_Hz," + ",".join(f"TF_W{W:g}m_1" for W in widths) + ",TF_1D_1"
    np.savetxt(os.path.join(HERE, "soft_layer.csv"), table, delimiter=",", header=head, comments="", fmt="%.6g")
    print(f"1D: peak {1 / ALPHA:.3f} at f0 = c_s1/4H = {F0:.2f} Hz (alpha = {ALPHA:.3f})")
    for W in widths:
        tf = cols[W][keep]
        k = int(np.argmax(tf))
        fr = F0 * np.sqrt(1 + 2 * (2 * H / W) ** 2)
        print(f"W = {W:g} m (W/H = {W / H:g}): peak {tf[k]:.3f} at {f[k]:.2f} Hz; rigid-walled box's first mode "
              f"{fr:.2f} Hz")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 4.2))
    for W in widths:
        ax.plot(f, cols[W][keep], label=f"box W = {W:g} m, H = {H:g} m (FEM soil region on the BEM half-space)")
        ax.axvline(F0 * np.sqrt(1 + 2 * (2 * H / W) ** 2), ls=":", lw=0.8, color=ax.lines[-1].get_color())
    ax.plot(f, one_d(f), "k--", label="1D layer on the half-space (infinitely wide)")
    ax.set_xlabel("frequency f [Hz]")
    ax.set_ylabel("|V_surface centre / V_free surface| [1]")
    ax.set_title(f"soft layer (c_s1 = {CS1:g} m/s) on the half-space (c_s = {CS:g} m/s), vertical S\n"
                 "dotted: the rigid-walled box's first mode", fontsize=9)
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(HERE, "soft_layer.png"), dpi=120)


if __name__ == "__main__":
    main()
