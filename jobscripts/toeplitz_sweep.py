"""The toeplitz lag store against the dense store on general cases the tests do not name (issue 41's "build the
general case"): cells that are not square, grids off the origin with odd cell counts, a grid with a hole, symmetry
planes with loads on and across them, oblique seismic waves of every kind under an off-centre massless footing,
interpolated far lags on 3 ranks, prescribed motion on 3 ranks and the coupled box with contact off the centre.
Each case runs on the dense store and on the toeplitz store (its own rank count), and every recorded field is
compared as the tests compare them (``tests/bem/test_history_block.scales``: against the largest value of its
kind in the dense run), except a massless footing's force and moment, zero by construction (its round-off),
measured against the run's largest traction times 1 m^2 (1 m^3 for the moment), and a coupled run's structure:
its motion (displacements, velocities, rotations, receivers) against each field's largest value.

    python jobscripts/toeplitz_sweep.py [OUT [CASE ...]]      (OUT default out/bench/toeplitz_sweep)

Prints a table (case, ranks of the toeplitz run, fields compared, the largest difference over its scale and the
field it is in) and writes OUT/toeplitz_sweep.csv. A case that fails to run prints its error's last line."""
import csv
import os
import subprocess
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [os.path.join(ROOT, "tests", "bem"), os.path.join(ROOT, "tests")]
from test_history_block import fields, scales  # noqa: E402
from petsc_ssi.launch import child_env  # noqa: E402

PY = sys.executable
MPI = ["mpirun", "--allow-run-as-root", "--oversubscribe"]
STEP = ["-ssi_problem", "bem", "-ssi_dt", "0.0025", "-ssi_t_end", "0.05", "-ssi_load_p0", "1000",
        "-ssi_output_stride", "5", "-ssi_warn_beta", "0"]
SEIS = ["-ssi_problem", "bem", "-ssi_cp", "42", "-ssi_cs", "20", "-ssi_rho", "1800", "-ssi_mesh_size", "4,3",
        "-ssi_mesh_h", "0.5", "-ssi_disp_group", "box:0,1,-0.5,0.5", "-ssi_disp_rigid", "massless", "-ssi_dt", "0.01",
        "-ssi_receivers", "1.5,0.5,0;-1,0,0", "-ssi_warn_beta", "0", "-ssi_seismic_units", "m/s2",
        "-ssi_seismic_taper", "0", "-ssi_seismic_baseline", "none", "-ssi_output_stride", "5"]
SLOW = ["-ssi_cp", "200", "-ssi_cs", "100", "-ssi_t_end", "0.1", "-ssi_output_stride", "7"]


def grid_msh(path, nx, ny, hx, hy, x0, y0, drop=()):
    """A gmsh file of nx x ny nine-node hx x hy rectangles from (x0, y0), with exact coordinates; the cells (i, j)
    in ``drop`` left out (a hole, a missing corner)."""
    from petsc_ssi.mesh.gmsh import write_msh
    xn, yn = x0 + 0.5 * hx * np.arange(2 * nx + 1), y0 + 0.5 * hy * np.arange(2 * ny + 1)
    X, Y = np.meshgrid(xn, yn, indexing="ij")
    nodes = np.stack([X.ravel(), Y.ravel(), np.zeros(X.size)], 1)
    idx = lambda i, j: i * (2 * ny + 1) + j             # noqa: E731
    cells = [[idx(2 * i, 2 * j), idx(2 * i + 2, 2 * j), idx(2 * i + 2, 2 * j + 2), idx(2 * i, 2 * j + 2),
              idx(2 * i + 1, 2 * j), idx(2 * i + 2, 2 * j + 1), idx(2 * i + 1, 2 * j + 2), idx(2 * i, 2 * j + 1),
              idx(2 * i + 1, 2 * j + 1)] for i in range(nx) for j in range(ny) if (i, j) not in drop]
    used = np.unique(np.array(cells))
    new = np.full(len(nodes), -1)
    new[used] = np.arange(len(used))
    write_msh(path, nodes[used], {"surface": ("quad9", new[np.array(cells)])})


def cases(out):
    """{name: (dense args, toeplitz ranks, dense ranks)}: the toeplitz run adds -ssi_lag_store toeplitz."""
    r75, hole = os.path.join(out, "r75.msh"), os.path.join(out, "hole.msh")
    grid_msh(r75, 7, 5, 1.0, 0.8, -1.3, -2.1)
    grid_msh(hole, 7, 5, 1.0, 0.8, -1.3, -2.1, drop={(3, 2), (0, 0), (6, 4)})
    pulse = os.path.join(out, "pulse.txt")
    t = np.arange(0.0, 0.6 + 1e-9, 0.01)          # (pulses +1, -2, +1: the ground's velocity and displacement
    p = lambda s: np.where((t >= s) & (t < s + 0.2), np.sin(np.pi * (t - s) / 0.2) ** 4, 0.0)      # noqa: E731
    a = p(0.0) - 2.0 * p(0.2) + p(0.4)              # back to rest, as -ssi_seismic rayleigh's Hilbert transform needs)
    np.savetxt(pulse, np.c_[t, a], header="t [s]  a [m/s^2]: sin^4 pulses of 0.2 s, +1, -2, +1")
    rec = ["-ssi_seismic_record", pulse]
    edge = ["-ssi_load_group", "box:3.5,5.8,-2.1,-0.4", "-ssi_receivers", "3,0,0;0,0,0;-0.5,1,0"]
    sym = STEP + ["-ssi_mesh_size", "10,8", "-ssi_mesh_h", "1", "-ssi_receivers", "3,1,0;0.5,0.5,0;2,3,0"]
    return {
        "1 x 0.9375 m cells, load at an edge": (STEP + ["-ssi_mesh_size", "8,7.5", "-ssi_mesh_h", "1", "-ssi_load_group",
                                                        "box:1.5,3.9,-3.8,-2.0", "-ssi_receivers", "3,0,0;-2,2,0"], 1, 1),
        "7 x 5 cells of 1 x 0.8 m off the origin": (STEP + ["-ssi_mesh", r75] + edge, 2, 1),
        "the same with a hole and two corners missing": (STEP + ["-ssi_mesh", hole] + edge, 2, 1),
        "x=sym, load touching the plane": (sym + ["-ssi_symmetry", "x=sym", "-ssi_load_group", "box:0,2.1,1.4,3.9"], 2, 1),
        "x=anti,y=sym, area load across y = 0": (sym + ["-ssi_symmetry", "x=anti,y=sym", "-ssi_load_area",
                                                        "0.3,2.7,-1.3,1.3", "-ssi_load_history", "box",
                                                        "-ssi_load_t0", "0.01"], 2, 1),
        "SV 25 deg, azimuth 33 deg, massless footing off the centre": (SEIS + rec + ["-ssi_seismic", "sv",
                                                                      "-ssi_seismic_angle", "25",
                                                                      "-ssi_seismic_azimuth", "33"], 1, 1),
        "P 40 deg, azimuth -120 deg": (SEIS + rec + ["-ssi_seismic", "p", "-ssi_seismic_angle", "40",
                                                     "-ssi_seismic_azimuth", "-120"], 2, 1),
        "SH 60 deg, azimuth 200 deg": (SEIS + rec + ["-ssi_seismic", "sh", "-ssi_seismic_angle", "60",
                                                     "-ssi_seismic_azimuth", "200"], 2, 1),
        "Rayleigh, azimuth 70 deg": (SEIS + rec + ["-ssi_seismic", "rayleigh", "-ssi_seismic_azimuth", "70"], 2, 1),
        "linear far lags, grading 1.7, 3 ranks": (STEP + SLOW + ["-ssi_mesh", r75] + edge + [
            "-ssi_interp", "linear", "-ssi_interp_tl", "0.0173", "-ssi_interp_k", "7", "-ssi_interp_grading", "1.7"], 3, 1),
        "Chebyshev far lags, plain scheme": (STEP + SLOW + ["-ssi_mesh", r75] + edge + [
            "-ssi_interp", "chebyshev", "-ssi_interp_tl", "0.021", "-ssi_interp_k", "3", "-ssi_scheme", "plain"], 2, 1),
        "prescribed motion on a strip, 3 ranks": (STEP + ["-ssi_mesh_size", "6,2", "-ssi_mesh_h", "1", "-ssi_disp_group",
                                                          "box:-0.5,0.5,-1,1", "-ssi_disp_value", "0,0,1e-6",
                                                          "-ssi_disp_history", "smoothstep", "-ssi_disp_t0", "0.01",
                                                          "-ssi_receivers", "1.2,0.1,0"], 3, 1),
        "coupled box with contact off the centre, 2 ranks": (
            ["-ssi_problem", "ssi", "-ssi_cp", "42", "-ssi_cs", "20", "-ssi_rho", "1800", "-ssi_mesh_size", "3,2",
             "-ssi_mesh_h", "0.5", "-ssi_fem_box_cells", "4,4,1", "-ssi_fem_box_size", "1,1,0.25", "-ssi_fem_box_origin",
             "-1,-0.5,0", "-ssi_fem_E", "3e8", "-ssi_fem_rho", "2000", "-ssi_dt", "0.0125", "-ssi_t_end", "0.5",
             "-ssi_fem_load_group", "top", "-ssi_fem_load_p0", "1000", "-ssi_fem_load_history", "box",
             "-ssi_fem_load_t0", "0.05", "-ssi_contact", "unilateral", "-ssi_receivers", "1,0,0", "-ssi_output_stride",
             "5", "-ssi_warn_beta", "0"], 2, 2),
    }


def run(args, n, path):
    cmd = (MPI + ["-n", str(n)] if n > 1 else []) + [PY, "-m", "petsc_ssi"] + args + [
        "-ssi_output", path, "-ssi_output_overwrite"]
    p = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, timeout=900,
                       env=child_env(OPENBLAS_NUM_THREADS="1"))
    if p.returncode:
        raise RuntimeError(((p.stdout + p.stderr).strip().splitlines() or ["(no output)"])[-1])


# a coupled run's structure fields compared (each against its own largest value): its motion. Not its storey
# demands (base shear, overturning moment): sums of the storeys' inertia forces m a that nearly cancel on a stiff
# box (0.75 N of shear under a 1 kN load), so their round-off is relative to the terms, not to their sum
STRUCTURE_FIELDS = ("displacement", "velocity", "acceleration", "rotation")


def compare(a, b):
    """(fields, the largest difference over its scale, that field): ``scales``, a massless footing's resultants
    against the largest traction x 1 m^2 (force) or 1 m^3 (moment)."""
    A, B = fields(a), fields(b)
    if set(A) != set(B):
        return len(A), float("inf"), "fields differ: " + " ".join(sorted(set(A) ^ set(B)))
    S = scales(A)
    tmax = max((np.abs(v).max() for k, v in A.items() if "traction" in k), default=0.0)
    worst, where = 0.0, ""
    for k in A:
        s = S[k]
        if k.startswith("resultants/"):
            s = max(s, tmax)
        if s <= 0:
            continue
        r = float(np.abs(A[k] - B[k]).max() / s)
        if r > worst:
            worst, where = r, k
    sa, sb = (p[:-3] + "_structure.h5" for p in (a, b))        # (a coupled run's structure: against its own peaks)
    if os.path.exists(sa):
        import h5py
        with h5py.File(sa) as fa, h5py.File(sb) as fb:
            names = []
            fa.visititems(lambda n, o: names.append(n) if isinstance(o, h5py.Dataset) and o.dtype.kind == "f" and (
                n.split("_")[0] in STRUCTURE_FIELDS or n.startswith("receivers/")) else None)
            for n in names:
                x, y = fa[n][...], fb[n][...]
                m = float(np.abs(x).max(initial=0.0))
                if m > 0:
                    r = float(np.abs(x - y).max() / m)
                    if r > worst:
                        worst, where = r, "structure:" + n
            return len(A) + len(names), worst, where
    return len(A), worst, where


def main():
    out = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "out", "bench", "toeplitz_sweep"))
    os.makedirs(out, exist_ok=True)
    want = sys.argv[2:]
    rows = []
    for i, (name, (args, n, nd)) in enumerate(cases(out).items()):
        if want and name not in want and str(i) not in want:
            continue
        t0 = time.perf_counter()
        d, z = os.path.join(out, f"case{i}-dense.h5"), os.path.join(out, f"case{i}-toeplitz.h5")
        try:
            run(args, nd, d)
            run(args + ["-ssi_lag_store", "toeplitz"], n, z)
            nf, worst, where = compare(d, z)
            row = [name, nd, n, nf, f"{worst:.2e}", where]
        except (RuntimeError, subprocess.TimeoutExpired) as e:
            row = [name, nd, n, 0, "failed", str(e)[-200:]]
        rows.append(row)
        print(f"[sweep] {name}: {row[4]} ({row[5]}) in {time.perf_counter() - t0:.0f} s", flush=True)
    head = ["case", "dense ranks", "toeplitz ranks", "fields", "largest difference / scale", "in field"]
    with open(os.path.join(out, "toeplitz_sweep.csv"), "w", newline="") as fh:
        csv.writer(fh).writerows([head] + rows)
    print("| " + " | ".join(head) + " |\n|" + "---|" * len(head))
    for r in rows:
        print("| " + " | ".join(str(x) for x in r) + " |")
    return 1 if any(r[4] == "failed" or float(r[4]) > 1e-10 for r in rows) else 0


if __name__ == "__main__":
    sys.exit(main())
