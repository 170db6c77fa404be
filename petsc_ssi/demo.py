"""``make demo``: the Lamb problem (Pekeris) on the CI-sized case.

Runs runs/pekeris/small.opts on the available cores (mpirun -n 2 when two
cores and mpirun are there, else one rank), then writes the plot of u~
against tau beside the HDF5/XDMF output and prints the receiver errors
against the Pekeris solution for the same loaded patch.
"""
import os
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def main():
    opts = os.path.join(ROOT, "runs", "pekeris", "small.opts")
    out = os.path.join(ROOT, "out", "demo", "pekeris-small.h5")
    cmd = [sys.executable, "-m", "petsc_ssi", "-options_file", opts, "-ssi_output", out,
           "-ssi_monitor", "-ssi_monitor_every", "10", "-ssi_plot"]
    ncores = os.cpu_count() or 1
    if ncores >= 2 and shutil.which("mpirun"):
        cmd = ["mpirun", "--allow-run-as-root", "-n", "2"] + cmd
    print("[demo] " + " ".join(cmd), flush=True)
    rc = subprocess.call(cmd, cwd=ROOT)
    if rc:
        return rc
    from .verify import lamb_errors
    errs = lamb_errors(out)
    for r, ev, eh in errs:
        print(f"[demo] r = {r:g} m: relative L2 error of u~ over tau in [0, 2.5]: "
              f"vertical {100 * ev:.1f}%, radial {100 * eh:.1f}% (vs Pekeris, same patch)")
    print(f"[demo] wrote {out}, {out[:-3]}.xmf (ParaView), {out[:-3]}.png, {out[:-3]}.json")
    return 0


if __name__ == "__main__":
    sys.exit(main())
