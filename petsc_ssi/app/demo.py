"""``make demo``: the Lamb problem (Pekeris) on the CI-sized case, then a reduced building.

1. Runs runs/pekeris/small.opts on the available cores (mpirun -n 2 when two
   cores and mpirun are there, else one rank), writes the plot of u~ against
   tau beside the HDF5/XDMF output and prints the receiver errors against the
   Pekeris solution for the same loaded patch.
2. Runs runs/building/demo.opts: the paper's building reduced to 2 x 2 bays
   and two storeys (frames and shells) on the half-space, shaken by a pressure
   pulse on the soil 8 m away; writes the accelerations at the roof (A) and the
   foundation (B) with their spectra, and a snapshot of soil and structure.
"""
import os
import shutil
import subprocess
import sys

from ..launch import child_env

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))      # the repository (this file: petsc_ssi/app/demo.py)


def _mpi(cmd):
    ncores = os.cpu_count() or 1
    if ncores >= 2 and shutil.which("mpirun"):
        return ["mpirun", "--allow-run-as-root", "-n", "2"] + cmd
    return cmd


def building_figures(out):
    """Accelerations at A (roof) and B (foundation) and their spectra; a snapshot of the soil's
    vertical displacement and the deformed structure. Returns the PNG paths and the peaks."""
    import h5py
    import numpy as np
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from ..spectrum import amplitude_spectrum, peaks
    stem = out[:-3]
    with h5py.File(stem + "_structure.h5", "r") as f:
        t, acc = f["receivers/t"][:], f["receivers/acceleration"][:]
    fig, axs = plt.subplots(2, 2, figsize=(11, 6.5))
    found = {}
    for i, (name, comp) in enumerate((("A (roof)", 0), ("A (roof)", 2), ("B (foundation)", 0),
                                      ("B (foundation)", 2))):
        k = 0 if name.startswith("A") else 1
        lab = f"{name} {'x' if comp == 0 else 'z'}"
        axs[0, k].plot(t, acc[:, k, comp], label="x" if comp == 0 else "z")
        f, a, info = amplitude_spectrum(t, acc[:, k, comp], pad=8)
        fp, ap, _ = peaks(f, a, 3, min_separation=info["resolution"], fmin=info["resolution"])
        axs[1, k].plot(f, a, label="x" if comp == 0 else "z")
        axs[1, k].plot(fp, ap, "o", ms=4)
        found[lab] = fp
    for k, name in enumerate(("A (roof)", "B (foundation)")):
        axs[0, k].set(title=f"acceleration at {name}", xlabel="t [s]", ylabel="a [m/s^2]")
        axs[1, k].set(title=f"spectrum at {name} (zero-padded x8)", xlabel="f [Hz]", xlim=(0, 40),
                      ylabel="|A(f)| [m/s^2] (a sine of amplitude a peaks at a)")
        axs[0, k].legend(); axs[1, k].legend()
    fig.tight_layout()
    png1 = stem + "-accelerations.png"
    fig.savefig(png1, dpi=110)
    plt.close(fig)
    with h5py.File(out, "r") as f, h5py.File(stem + "_structure.h5", "r") as g:
        times = f["time"][:]
        k = int(np.argmin(np.abs(times - 0.35)))
        X, U = f["coordinates"][:], f[f"displacement_{k:06d}"][:]
        Xs, Us = g["coordinates"][:], g[f"displacement_{k:06d}"][:]
    fig, axs = plt.subplots(1, 2, figsize=(12, 5))
    XX = np.vstack([X, X * [1, -1, 1]])
    UZ = np.r_[U[:, 2], U[:, 2]]
    c = axs[0].tricontourf(XX[:, 0], XX[:, 1], UZ, 30, cmap="RdBu_r")
    fig.colorbar(c, ax=axs[0], label="u_z [m]")
    axs[0].set(title=f"soil surface u_z at t = {times[k]:.3g} s (half model mirrored)", xlabel="x [m]",
               ylabel="y [m]", aspect="equal")
    s = 0.3 / max(np.abs(Us).max(), 1e-30)
    axs[1].plot(Xs[:, 0], Xs[:, 2], ".", color="0.7", ms=3, label="undeformed")
    axs[1].plot(Xs[:, 0] + s * Us[:, 0], Xs[:, 2] + s * Us[:, 2], ".", ms=3, label=f"deformed x {s:.3g}")
    axs[1].set(title="structure, elevation (x-z)", xlabel="x [m]", ylabel="z [m]", aspect="equal")
    axs[1].legend()
    fig.tight_layout()
    png2 = stem + "-snapshot.png"
    fig.savefig(png2, dpi=110)
    plt.close(fig)
    return png1, png2, found


def main():
    rc = lamb()
    if rc:
        return rc
    return building()


def building():
    opts = os.path.join(ROOT, "runs", "building", "demo.opts")
    out = os.path.join(ROOT, "out", "demo", "building.h5")
    cmd = _mpi([sys.executable, "-m", "petsc_ssi", "-options_file", opts, "-ssi_output", out, "-ssi_output_overwrite",
                "-ssi_monitor", "-ssi_monitor_every", "40"])
    print("[demo] the reduced building on the half-space: " + " ".join(cmd), flush=True)
    rc = subprocess.call(cmd, cwd=ROOT, env=child_env())
    if rc:
        return rc
    png1, png2, found = building_figures(out)
    for lab, fp in found.items():
        print(f"[demo] acceleration at {lab}: spectral peaks at {', '.join(f'{v:.2f}' for v in fp)} Hz")
    print(f"[demo] wrote {out} and {out[:-3]}_structure.h5 (+ .xmf for ParaView), {png1}, {png2}")
    return 0


def lamb():
    opts = os.path.join(ROOT, "runs", "pekeris", "small.opts")
    out = os.path.join(ROOT, "out", "demo", "pekeris-small.h5")
    cmd = [sys.executable, "-m", "petsc_ssi", "-options_file", opts, "-ssi_output", out, "-ssi_output_overwrite",
           "-ssi_monitor", "-ssi_monitor_every", "10", "-ssi_plot"]
    ncores = os.cpu_count() or 1
    if ncores >= 2 and shutil.which("mpirun"):
        cmd = ["mpirun", "--allow-run-as-root", "-n", "2"] + cmd
    print("[demo] " + " ".join(cmd), flush=True)
    rc = subprocess.call(cmd, cwd=ROOT, env=child_env())
    if rc:
        return rc
    from ..verify import lamb_errors
    errs = lamb_errors(out)
    for r, ev, eh in errs:
        print(f"[demo] r = {r:g} m: relative L2 error of u~ over tau in [0, 2.5]: "
              f"vertical {100 * ev:.1f}%, radial {100 * eh:.1f}% (vs Pekeris, same patch)")
    print(f"[demo] wrote {out}, {out[:-3]}.xmf (ParaView), {out[:-3]}.png, {out[:-3]}.json")
    return 0


if __name__ == "__main__":
    sys.exit(main())
