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

With --damping=Z the layer's bricks carry stiffness-proportional damping C = a1 K of ratio Z at the
layer's frequency f0 (-ssi_fem_rayleigh 0,a1, a1 = 2 Z / (2 pi f0): the ratio grows as f / f0), the
half-space stays elastic, and the 1D reference is the same damped layer: its wave number and impedance
with the complex modulus G1 (1 + i omega a1) (``one_d``; checked against the damped 1D finite element
column, ``one_d_column``). No mass-proportional term: in a region of total motion under seismic input
a0 M would damp the ground's own motion (the layer's rigid translation against a fixed frame: the 1D
layer's ratio then falls to 1 / (1 + a0 rho1 H / (rho c_s)) at low frequency, tried with Z at 10 and 40
Hz). The waves the walls send in die out as they cross the layer, as exp(-Z k x) near f0, so the box's
centre can tend to the 1D layer as W grows, which the elastic layer's trapped waves prevent.

Run: python runs/soil_region/soft_layer.py [W1,W2,...] [ranks] [full] [--post] [--damping=Z]   (default
6,10,20,30, 1 rank, quarter models, elastic; --post: read the outputs of an earlier run instead of running)
Writes soft_layer.csv (frequency [Hz], |TF| per width [1], the 1D |TF| [1]), soft_layer.png, and the time
histories soft_layer_time.csv/png beside this file (soft_layer_zZ*.csv/png with --damping=Z), and prints
each width's peak (frequency, amplitude) beside the estimates above.
"""
import collections
import os
import subprocess
import sys
import time

import numpy as np

from petsc_ssi.launch import child_env

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "runs", "seismic"))
import input_motion  # noqa: E402
CS, CP, RHO = 316.0, 548.0, 2000.0
CS1, CP1, RHO1 = 158.0, 274.0, 1800.0
H, DT, T_END, PULSE = 2.0, 0.0025, 0.4, 0.01
ALPHA = RHO1 * CS1 / (RHO * CS)
F0 = CS1 / (4 * H)


def rayleigh(zeta):
    """(a0 [1/s], a1 [s]) of the layer's damping C = a0 M + a1 K: stiffness-proportional, ratio zeta at f0
    (a0 = 0; module docstring)."""
    return 0.0, 2.0 * zeta / (2 * np.pi * F0)


def record(path):
    """The 10 ms sin^4 acceleration pulse and its reverse (zero net velocity), 1 m/s^2 [table 't a']: the
    record of runs/seismic/input_motion.py."""
    return input_motion.pulse(path, PULSE)


def run(W, ranks, out, quarter=True, command="run", zeta=0.0):
    """The coupled run of a box of width W [m]: soil elements 1 m, bricks 0.5 m, ground W + 6 m wide.
    quarter: the quarter model x >= 0, y >= 0 (-ssi_symmetry x=anti,y=sym: the wave moves the ground in x,
    so the plane x = 0 is one of antisymmetry and y = 0 one of symmetry), 1/16 of the whole model's lags.
    zeta: the layer's damping ratio at f0 (stiffness-proportional, ``rayleigh``; module docstring)."""
    n = int(round(2 * W))
    box = ([f"{n // 2},{n // 2},{int(2 * H)}", f"{W / 2},{W / 2},{H}", f"0,0,{-H}", "xmax,ymax,base"] if quarter
           else [f"{n},{n},{int(2 * H)}", f"{W},{W},{H}", f"{-W / 2},{-W / 2},{-H}", "xmin,xmax,ymin,ymax,base"])
    args = ["-m", "petsc_ssi", command, "-ssi_problem", "ssi", "-ssi_mesh", "pit",
            "-ssi_mesh_params", f"a={W / 2},b={W / 2},d={H}", "-ssi_mesh_size", f"{W + 6},{W + 6}",
            "-ssi_mesh_h", "1", "-ssi_dt", str(DT), "-ssi_t_end", str(T_END), "-ssi_seismic", "vertical",
            "-ssi_seismic_record", record(os.path.join(os.path.dirname(out), "pulse.txt")),
            "-ssi_seismic_units", "m/s2", "-ssi_seismic_taper", "0", "-ssi_seismic_baseline", "none",
            "-ssi_fem_mesh", "box", "-ssi_fem_box_cells", box[0], "-ssi_fem_box_size", box[1],
            "-ssi_fem_box_origin", box[2], "-ssi_fem_interface", box[3], "-ssi_fem_cp", str(CP1),
            "-ssi_fem_cs", str(CS1), "-ssi_fem_rho", str(RHO1), "-ssi_structure_receivers", "0,0,0",
            "-ssi_receivers", f"{W / 2 + 2},0,0", "-ssi_output", out, "-ssi_output_overwrite", "1",
            "-ssi_output_stride", "0", "-ssi_warn_beta", "0", "-ssi_monitor"]
    if quarter:
        args += ["-ssi_symmetry", "x=anti,y=sym"]
    if zeta:
        args += ["-ssi_fem_rayleigh", "{:.17g},{:.17g}".format(*rayleigh(zeta))]
    cmd = [sys.executable] + args
    if ranks > 1:
        cmd = ["mpirun", "--allow-run-as-root", "-n", str(ranks)] + cmd
    # the run's output streamed, its last lines kept for the error. env=child_env(): started from a process that
    # has initialised MPI (a pytest process after an in-process run), the inherited OMPI_MCA_ess=singleton made
    # mpirun exit 1 without a line (the slow tier's flaky failure; petsc_ssi/launch.py)
    p = subprocess.Popen(cmd, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=child_env())
    tail = collections.deque(maxlen=60)
    for line in p.stdout:
        sys.stdout.write(line)
        tail.append(line)
    if p.wait() != 0:
        raise RuntimeError(f"{' '.join(cmd)} exited with status {p.returncode}; its last lines:\n" + "".join(tail))


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


def one_d(f, complex_=False, zeta=0.0):
    """|U_top / U_outcrop| of the 1D layer (module docstring); complex_: the complex ratio to the outcrop
    motion at the ground surface z = 0 (the record's), e^(+i omega t) as numpy's inverse transform: the
    textbook ratio references the outcrop at the layer's base (its incident wave's phase at z = -H), so the
    surface outcrop's ratio carries e^(i omega H / c_s) (the half-space's wave reaches z = 0 H/c_s later).
    zeta: the layer's Rayleigh damping (``rayleigh``): rho1 (u'' + a0 u') = G1 (1 + a1 d/dt) u_zz gives
    k^2 = (omega / c_s1)^2 (1 - i a0 / omega) / (1 + i omega a1) and the impedance k G1 (1 + i omega a1) /
    omega in place of rho1 c_s1 (either root of k: the ratio is even in it)."""
    a0, a1 = rayleigh(zeta)
    w = 2 * np.pi * np.asarray(f, float)
    ws = np.where(w != 0, w, 1.0)
    k = w / CS1 * np.sqrt((1 - 1j * a0 / ws) / (1 + 1j * w * a1)) if zeta else w / CS1 + 0j
    alpha = k * RHO1 * CS1 ** 2 * (1 + 1j * w * a1) / (ws * RHO * CS) if zeta else ALPHA
    # f = 0: the limit, 1 / (1 + a0 rho1 H / (rho c_s)) (1 without mass-proportional damping: the layer moves
    # with the outcrop); negative f: the conjugate ratio (the ratio is even in k)
    r = np.where(w != 0, 1.0 / (np.cos(k * H) + 1j * alpha * np.sin(k * H)), 1.0 / (1 + a0 * RHO1 * H / (RHO * CS)))
    return r * np.exp(1j * w * H / CS) if complex_ else np.abs(r)


def one_d_column(t_end, outcrop, ne=100, dt=2e-5, zeta=0.0):
    """An independent check of ``one_d(complex_=True)``: the 1D layer as ne linear finite elements on the
    half-space's exact 1D boundary (a dashpot rho c_s at the base loaded by 2 rho c_s v_inc, the incident
    velocity at the base v_inc(t) = v_outcrop(t + H/c_s) / 2), Newmark's average acceleration at dt.
    ``outcrop(t)``: the outcrop (free surface) displacement [m]; zeta: the layer's Rayleigh damping a0 M + a1 K
    (``rayleigh``). Returns (t [s], u_x at the top [m])."""
    h = H / ne
    n = ne + 1
    K, M = np.zeros((n, n)), np.zeros((n, n))
    for e in range(ne):
        K[e:e + 2, e:e + 2] += RHO1 * CS1 ** 2 / h * np.array([[1.0, -1.0], [-1.0, 1.0]])
        M[e:e + 2, e:e + 2] += RHO1 * h / 6 * np.array([[2.0, 1.0], [1.0, 2.0]])
    a0, a1 = rayleigh(zeta)
    C = a0 * M + a1 * K
    C[0, 0] += RHO * CS                                # node 0 at the base
    nt = int(round(t_end / dt))
    t = np.arange(nt + 1) * dt
    vo = np.gradient(outcrop(t), dt)
    f0 = 2 * RHO * CS * np.interp(t + H / CS, t, vo) / 2
    b = 4.0 / dt ** 2
    Ainv = np.linalg.inv(b * M + 2.0 / dt * C + K)
    u, v, a = np.zeros(n), np.zeros(n), np.zeros(n)
    top = np.zeros(nt + 1)
    for i in range(nt):
        rhs = M @ (b * u + 4.0 / dt * v + a) + C @ (2.0 / dt * u + v)
        rhs[0] += f0[i + 1]
        un = Ainv @ rhs
        an = b * (un - u) - 4.0 / dt * v - a
        v, a, u = v + 0.5 * dt * (a + an), an, un
        top[i + 1] = u[-1]
    return t, top


def lowpass(f, f1=25.0, f2=40.0):
    """A cosine taper from 1 at f1 to 0 at f2 [Hz]: the band the box's discretisation holds (6 bricks and
    10 steps per wavelength and period of the layer at 40 Hz)."""
    w = np.ones_like(f)
    m = (f > f1) & (f < f2)
    w[m] = 0.5 * (1 + np.cos(np.pi * (f[m] - f1) / (f2 - f1)))
    w[f >= f2] = 0.0
    return w


def time_histories(out, nfft_factor=16, zeta=0.0):
    """(t [s], v_x at the layer's surface centre [m/s], the 1D layer's v_x for the same outcrop motion [m/s],
    the record's time origin t0 [s]), both low-passed by ``lowpass`` (velocities: the record's displacement
    keeps a permanent offset); the 1D one exact in the frequency domain (``one_d(complex_=True)``,
    zero-padded 16 x: its reverberation has died out before it wraps; zeta: the layer's damping, ``one_d``)."""
    import h5py
    with h5py.File(out.replace(".h5", "_structure.h5")) as fs, h5py.File(out) as f:
        t, u = fs["receivers/t"][:], fs["receivers/u"][:, 0, 0]
        D, td, t0 = f["seismic/x_displacement"][:], f["seismic/x_t"][:], float(f["seismic/t0"][()])
    uff = np.interp(t - t0, td, D, left=0.0)
    n = nfft_factor * len(t)
    fr = np.fft.rfftfreq(n, t[1] - t[0])
    w = lowpass(fr)
    dt = t[1] - t[0]
    v, vff = np.gradient(u, dt), np.gradient(uff, dt)
    box = np.fft.irfft(np.fft.rfft(v, n) * w, n)[:len(t)]
    one = np.fft.irfft(np.fft.rfft(vff, n) * one_d(fr, True, zeta) * w, n)[:len(t)]
    return t, box, one, t0


def edge_time(W, t0):
    """The earliest time [s] the waves the box's walls send in reach its centre: the record's time origin
    t0 plus (W/2) / c_s (Love waves in a layer on a stiffer half-space travel between c_s1 and the
    half-space's c_s; the walls meet the incident wave when the surface does, within H/c_s)."""
    return t0 + 0.5 * W / CS


def window_errors(out, W, zeta=0.0):
    """(max |v_box - v_1D| / max |v_1D| for t <= edge_time, the same over the whole run, rms of v_box /
    rms of v_1D after edge_time) of ``time_histories``."""
    t, box, one, t0 = time_histories(out, zeta=zeta)
    te = edge_time(W, t0)
    e = np.abs(box - one) / np.abs(one).max()
    late = t > te
    rms = float(np.sqrt(np.mean(box[late] ** 2) / np.mean(one[late] ** 2))) if late.any() else float("nan")
    return float(e[t <= te].max()), float(e.max()), rms


def main():
    post = "--post" in sys.argv           # the outputs of an earlier run of this script, not run again
    zeta = float(next((a.split("=", 1)[1] for a in sys.argv if a.startswith("--damping=")), 0.0))
    argv = [a for a in sys.argv if a != "--post" and not a.startswith("--damping=")]
    tag = f"-z{zeta:g}" if zeta else ""
    name = f"soft_layer_z{zeta:g}" if zeta else "soft_layer"
    widths = [float(w) for w in (argv[1] if len(argv) > 1 else "6,10,20,30").split(",")]
    ranks = int(argv[2]) if len(argv) > 2 else 1
    quarter = not (len(argv) > 3 and argv[3] == "full")
    os.makedirs(os.path.join(ROOT, "out", "soft_layer"), exist_ok=True)
    cols, f, walls = {}, None, {}
    for W in widths:
        out = os.path.join(ROOT, "out", "soft_layer", f"W{W:g}{tag}.h5")
        t0 = time.perf_counter()
        if not post:
            run(W, ranks, out, quarter=quarter, zeta=zeta)
        walls[W] = time.perf_counter() - t0
        f, tf = transfer(out)
        cols[W] = tf
    keep = f <= 40.0                      # 6 bricks and 10 steps per wavelength and period of the layer
    f = f[keep]
    print("| W [m] | W/H [-] | t_edge = t0 + W / 2 c_s [s] | max \\|v - v_1D\\| / max \\|v_1D\\|, t <= t_edge [-] | "
          "the same, whole run [-] | rms v / rms v_1D after t_edge [-] |")
    print("|---|---|---|---|---|---|")
    hist = {}
    for W in widths:
        out = os.path.join(ROOT, "out", "soft_layer", f"W{W:g}{tag}.h5")
        hist[W] = time_histories(out, zeta=zeta)
        e_edge, e_all, rms = window_errors(out, W, zeta)
        print(f"| {W:g} | {W / H:g} | {edge_time(W, hist[W][3]):.4f} | {e_edge:.3f} | {e_all:.3f} | {rms:.2f} |")
    t = hist[widths[0]][0]
    np.savetxt(os.path.join(HERE, f"{name}_time.csv"),
               np.column_stack([t] + [hist[W][1] for W in widths] + [hist[widths[-1]][2]]), delimiter=",",
               header="t_s," + ",".join(f"vx_W{W:g}m_m_per_s" for W in widths) + ",vx_1D_m_per_s", comments="", fmt="%.6g")
    table = np.column_stack([f] + [cols[W][keep] for W in widths] + [one_d(f, zeta=zeta)])
    head = "f_Hz," + ",".join(f"TF_W{W:g}m_1" for W in widths) + ",TF_1D_1"
    np.savetxt(os.path.join(HERE, f"{name}.csv"), table, delimiter=",", header=head, comments="", fmt="%.6g")
    one = one_d(f, zeta=zeta)
    print(f"1D: peak {one.max():.3f} at {f[np.argmax(one)]:.2f} Hz; elastic: {1 / ALPHA:.3f} at f0 = c_s1/4H = "
          f"{F0:.2f} Hz (alpha = {ALPHA:.3f})" + (f"; layer damped a1 K, {zeta:g} at f0 (a1 = {rayleigh(zeta)[1]:.4g} s)"
                                                     if zeta else ""))
    for W in widths:
        tf = cols[W][keep]
        k = int(np.argmax(tf))
        fr = F0 * np.sqrt(1 + 2 * (2 * H / W) ** 2)
        dev = np.abs(tf - one)[f <= 35.0].max() / one.max()
        print(f"W = {W:g} m (W/H = {W / H:g}): peak {tf[k]:.3f} at {f[k]:.2f} Hz ({tf[k] / one.max() - 1:+.1%} of the "
              f"1D peak); max |TF - TF_1D| up to 35 Hz {dev:.1%} of the 1D peak; rigid-walled box's first mode "
              f"{fr:.2f} Hz; run {walls[W]:.1f} s on {ranks} rank(s), {'quarter' if quarter else 'whole'} model")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 4.2))
    for W in widths:
        ax.plot(f, cols[W][keep], label=f"box W = {W:g} m, H = {H:g} m (FEM soil region on the BEM half-space)")
        ax.axvline(F0 * np.sqrt(1 + 2 * (2 * H / W) ** 2), ls=":", lw=0.8, color=ax.lines[-1].get_color())
    ax.plot(f, one_d(f, zeta=zeta), "k--", label="1D layer on the half-space (infinitely wide)")
    ax.set_xlabel("frequency f [Hz]")
    ax.set_ylabel("|V_surface centre / V_free surface| [1]")
    damp = f", damping a1 K: {zeta:g} at f0" if zeta else ""
    ax.set_title(f"soft layer (c_s1 = {CS1:g} m/s{damp}) on the half-space (c_s = {CS:g} m/s), vertical S\n"
                 "dotted: the rigid-walled box's first mode", fontsize=9)
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(HERE, f"{name}.png"), dpi=120)
    fig, ax = plt.subplots(figsize=(7, 4.2))
    for W in widths:
        tw, box, one, t0 = hist[W]
        ax.plot(tw, 1e3 * box, lw=1, label=f"box W = {W:g} m")
        ax.axvline(edge_time(W, t0), ls=":", lw=0.8, color=ax.lines[-1].get_color())
    ax.plot(tw, 1e3 * one, "k--", lw=1.2, label="1D layer on the half-space")
    ax.set_xlim(0, 0.25)
    ax.set_xlabel("time t [s]")
    ax.set_ylabel("v_x, surface centre [mm/s]")
    ax.set_title(f"soft layer in a box under vertical S{damp}: the centre against the 1D layer\n"
                 "(low-passed 25-40 Hz); dotted: t0 + W / 2 c_s, the earliest the walls' waves reach the centre",
                 fontsize=9)
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(HERE, f"{name}_time.png"), dpi=120)


if __name__ == "__main__":
    main()
