"""``petsc-ssi post FILE.h5 [--receivers] [--csv] [--plot PNG] [--info]``.

Reads an output file with h5py (serial; no PETSc needed):
  --receivers --csv   one row per receiver and step, header
                      ``receiver,x,y,z,t,ux,uy,uz`` (SI units)
  --plot PNG          receiver time histories (with the Pekeris patch solution
                      when the run was a Lamb problem)
  --info              what the file holds
"""
import argparse
import sys

import numpy as np


def receivers(path):
    import h5py
    with h5py.File(path, "r") as f:
        if "receivers" not in f:
            raise SystemExit(f"petsc-ssi post: error: {path} holds no receiver series")
        g = f["receivers"]
        return g["points"][:], g["t"][:], g["u"][:]


def write_csv(path, out=sys.stdout):
    pts, t, u = receivers(path)
    out.write("receiver,x,y,z,t,ux,uy,uz\n")
    for k, p in enumerate(pts):
        for i, ti in enumerate(t):
            ux, uy, uz = u[i, k]
            out.write(f"{k},{p[0]:.9g},{p[1]:.9g},{p[2]:.9g},{ti:.9g},{ux:.9e},{uy:.9e},{uz:.9e}\n")


def info(path, out=sys.stdout):
    import h5py
    with h5py.File(path, "r") as f:
        for k, v in f.attrs.items():
            out.write(f"{k}: {v}\n")
        out.write("datasets: " + ", ".join(sorted(f.keys())[:12]) + (" ..." if len(f.keys()) > 12 else "") + "\n")


def main(argv=None):
    ap = argparse.ArgumentParser(prog="petsc-ssi post", description=__doc__.splitlines()[0])
    ap.add_argument("file")
    ap.add_argument("--receivers", action="store_true", help="receiver series")
    ap.add_argument("--csv", action="store_true", help="as CSV on standard output")
    ap.add_argument("--plot", metavar="PNG", help="plot receiver histories to PNG")
    ap.add_argument("--info", action="store_true")
    a = ap.parse_args(argv)
    try:
        if a.info:
            info(a.file)
        if a.receivers and a.csv:
            write_csv(a.file)
        if a.plot:
            from .plot import receiver_plot
            receiver_plot(a.file, png=a.plot)
        if not (a.info or (a.receivers and a.csv) or a.plot):
            ap.error("nothing to do: give --receivers --csv, --plot PNG or --info")
    except OSError as exc:
        print(f"petsc-ssi post: error: {exc}", file=sys.stderr)
        return 2
    return 0
