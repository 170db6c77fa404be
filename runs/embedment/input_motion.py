"""Foundation input motion of a massless rigid square footing embedded in the half-space under a vertical S
wave (issue 42, item 2: kinematic interaction of an embedded footing), beside the NIST GCR 12-917-21
embedment transfer functions.

The footing is the pit's walls and bottom (``-ssi_mesh pit``, B = a = b = 1 m, depth D) as a massless
rigid body (``-ssi_disp_group pit -ssi_disp_rigid massless``): each step its rigid motion is the one that
makes the soil's TOTAL traction on it, scattered + free field (``bem/input_motion.py``,
``free_field_resultant``), resultant-free. The wave: ``-ssi_seismic vertical`` with the x component of
the record, an acceleration pulse (one sin^4 lobe of T = 8 ms), the free field's surface motion at the
control point. The reference point of the footing's motion is the
centre of its base (0, 0, -D) (``-ssi_disp_ref``).

Transfer functions (from the Fourier spectra of the accelerations, footing over the free field's at the
ground surface, up to where the record's spectrum falls below 1 % of its peak):
    H_u(f)     = |A_x(f)| / |A_ff,x(f)|          (translation of the base's centre)
    H_theta(f) = B |alpha_y(f)| / |A_ff,x(f)|    (rocking about y, times B)
NIST GCR 12-917-21 (ch. 4, after Elsabee & Morray 1977 and Kim & Stewart 2003), as recalled (its text
was not in the stored corpora):
    H_u     = cos(2 pi f D / V_s), not below 0.453
    H_theta = 0.26 (1 - cos(2 pi f D / V_s)) up to f = V_s / (4 D), 0.26 beyond
(H_theta's normalisation by B as recalled: read it as the trend and the order of magnitude). The
trusted band of the BEM is that of ``petsc-ssi impedance`` (four elements per shear wavelength,
omega dt <= 0.3; runs/embedment/README.md).

``python runs/embedment/input_motion.py [OUT.csv] [D,D,...] [h]`` writes the CSV (units in the headers),
OUT.png and prints the table at a few frequencies as Markdown."""
import csv
import math
import os
import subprocess
import sys

import numpy as np

from petsc_ssi.launch import child_env

SOIL = dict(cp=548.0, cs=316.0, rho=2000.0)
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
FREQS = (10.0, 25.0, 40.0, 55.0, 70.0, 85.0)


def record(path, T):
    """An acceleration record 't a' [s, m/s^2]: one sin^4 lobe of 1 m/s^2 and T seconds, then rest (its
    spectrum has no zero below 2 / T: the transfer functions start at f = 0)."""
    t = np.arange(0.0, T + 1e-12, T / 80)
    np.savetxt(path, np.c_[t, np.sin(np.pi * t / T) ** 4], header="units: m/s2")


def run(D, h, L, dt, t_end, T, out):
    """One massless-footing run: (t [s], footing acceleration (K, 3) [m/s^2], angular acceleration (K, 3)
    [rad/s^2], the free field's acceleration at the ground surface (K, 3) [m/s^2])."""
    import h5py
    out = os.path.abspath(out)
    rec = out + ".record.txt"
    record(rec, T)
    opts = dict(problem="bem", mesh="pit", mesh_params=f"a=1,b=1,d={D}", mesh_size=f"{L},{L}", mesh_h=h,
                disp_group="pit", disp_rigid="massless", disp_ref=f"0,0,{-D}", seismic="vertical",
                seismic_record_x=rec, seismic_units="m/s2", seismic_taper=0, seismic_baseline="none",
                seismic_ref="0,0", dt=dt, t_end=t_end, scheme="plain", output=out, output_stride=0,
                output_overwrite=1, warn_beta=0, **SOIL)
    args = [a for k, v in opts.items() for a in ("-ssi_" + k, str(v))]
    env = child_env(PYTHONPATH=ROOT, OPENBLAS_NUM_THREADS="1")
    p = subprocess.run([sys.executable, "-m", "petsc_ssi"] + args, cwd=ROOT, env=env, capture_output=True, text=True)
    os.remove(rec)
    if p.returncode:
        raise RuntimeError(f"petsc-ssi {' '.join(args)} failed:\n{p.stdout[-2000:]}{p.stderr[-2000:]}")
    with h5py.File(out) as f:
        g, s = f["input_motion"], f["seismic"]
        a, al = g["acceleration"][:], g["angular_acceleration"][:]
        t = dt * np.arange(1, len(a) + 1)
        # the free field at the ground surface, u_x(0, t) = D(t - t0) (D the processed record's displacement;
        # its group 'seismic'), sampled on the run's steps and differenced as the footing's motion is
        # (bem.input_motion.second_difference): the free field the output gives is at x_ref, the base
        tr, dr, t0 = s["x_t"][:], s["x_displacement"][:], float(s["t0"][()])
        v_end = float(s["x_v_end"][()])
        tau = t - t0
        us = np.where(tau <= tr[-1], np.interp(tau, tr, dr, left=0.0), dr[-1] + v_end * (tau - tr[-1]))
    from petsc_ssi.bem.input_motion import second_difference
    return t, a, al, second_difference(us, dt)[:, None] * np.array([1.0, 0.0, 0.0])


def residual(out):
    """max |F_scattered + F_ff| / max |W q| over the steps, forces and moments apart (the larger): the
    footing's condition, the total traction's resultant zero, as the output ``out`` holds it."""
    import h5py
    with h5py.File(out) as f:
        g = f["input_motion"]
        q = np.c_[g["translation"][:], g["rotation"][:]]
        total = np.c_[f["resultants/force"][:], f["resultants/moment"][:]] + g["free_field_resultant"][:]
        wq = q @ g["step_stiffness"][:].T
    return max(np.abs(total[:, :3]).max() / np.abs(wq[:, :3]).max(),
               np.abs(total[:, 3:]).max() / np.abs(wq[:, 3:]).max())


def nist(f, D):
    """(H_u, H_theta) of NIST GCR 12-917-21 as recalled (module docstring) at frequencies f [Hz]."""
    x = 2 * np.pi * np.asarray(f, float) * D / SOIL["cs"]
    hu = np.maximum(np.cos(np.minimum(x, np.pi)), 0.453)
    ht = np.where(x <= np.pi / 2, 0.26 * (1 - np.cos(x)), 0.26)
    return hu, ht


def transfer(D, h=0.5, L=8.0, dt=4.75e-4, t_end=0.06, T=0.008, out="fim.h5", B=1.0):
    """(f [Hz], H_u, H_theta, the free field's spectrum relative to its peak) of the footing D deep."""
    t, a, al, aff = run(D, h, L, dt, t_end, T, out)
    n = 8 * (1 << int(math.ceil(math.log2(len(t)))))
    f = np.fft.rfftfreq(n, dt)
    Aff = np.abs(np.fft.rfft(aff[:, 0], n))
    keep = np.cumprod(Aff >= 0.01 * Aff.max()).astype(bool)     # up to where it first falls below 1 %
    Hu = np.abs(np.fft.rfft(a[:, 0], n)) / Aff
    Ht = B * np.abs(np.fft.rfft(al[:, 1], n)) / Aff
    return f[keep], Hu[keep], Ht[keep], (Aff / Aff.max())[keep]


HEAD = ("D [m]", "f [Hz]", "a0 = 2 pi f B / c_s [-]", "H_u BEM [-]", "H_u NIST [-]", "H_theta BEM [-]",
        "H_theta NIST [-]", "trusted [0/1]")


def plot(res, png, hi):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    for j, (D, (f, hu, ht, _)) in enumerate(res.items()):
        nu_, nt_ = nist(f, D)
        ax[0].plot(f, hu, color=f"C{j}", label=f"BEM D/B = {D:g}")
        ax[0].plot(f, nu_, "--", color=f"C{j}", label=f"NIST (as recalled) D/B = {D:g}")
        ax[1].plot(f, ht, color=f"C{j}", label=f"BEM D/B = {D:g}")
        ax[1].plot(f, nt_, "--", color=f"C{j}", label=f"NIST (as recalled) D/B = {D:g}")
    for i, what in enumerate(("H_u = |u_base| / |u_ff,surface| [-]", "H_theta = B |theta_y| / |u_ff,surface| [-]")):
        ax[i].axvspan(hi, ax[i].get_xlim()[1], color="0.92", zorder=0)
        ax[i].set_xlabel("f [Hz] (grey: beyond the trusted band)")
        ax[i].set_ylabel(what)
        ax[i].legend(fontsize=7)
    fig.suptitle("massless square footing (B = 1 m) in a pit, vertical S wave: foundation input motion", fontsize=9)
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    plt.close(fig)


def main(argv):
    out = argv[1] if len(argv) > 1 else "embedment-fim.csv"
    depths = [float(v) for v in (argv[2] if len(argv) > 2 else "0.5,1").split(",")]
    h = float(argv[3]) if len(argv) > 3 else 0.5
    dt = 4.75e-4
    hi = min(SOIL["cs"] / (4 * h), 0.3 / (2 * math.pi * dt))          # four elements a shear wavelength; omega dt
    res = {D: transfer(D, h=h, dt=dt, out=out + ".h5") for D in depths}
    os.remove(out + ".h5")
    with open(out, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(HEAD)
        for D, (f, hu, ht, _) in res.items():
            nu_, nt_ = nist(f, D)
            for i in range(len(f)):
                w.writerow((D, f"{f[i]:.6g}", f"{2 * math.pi * f[i] / SOIL['cs']:.4g}", f"{hu[i]:.5g}", f"{nu_[i]:.5g}",
                            f"{ht[i]:.5g}", f"{nt_[i]:.5g}", int(f[i] <= hi)))
    plot(res, os.path.splitext(out)[0] + ".png", hi)
    print(f"h = {h:g} m, dt = {dt:g} s; trusted f <= {hi:.1f} Hz")
    print("| D/B [-] | f [Hz] | a0 [-] | H_u BEM [-] | H_u NIST [-] | H_theta BEM [-] | H_theta NIST [-] |")
    print("|---|---|---|---|---|---|---|")
    for D, (f, hu, ht, _) in res.items():
        nu_, nt_ = nist(f, D)
        for x in FREQS:
            if x > f[-1]:
                continue
            tag = "" if x <= hi else " (untrusted)"
            print(f"| {D:g} | {x:g}{tag} | {2 * math.pi * x / SOIL['cs']:.2f} | {np.interp(x, f, hu):.3f} | "
                  f"{np.interp(x, f, nu_):.3f} | {np.interp(x, f, ht):.3f} | {np.interp(x, f, nt_):.3f} |")
    return res


if __name__ == "__main__":
    main(sys.argv)
