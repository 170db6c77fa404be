"""Foundation input motion of a rigid massless footing and the Haskind reciprocity of the blocked
footing: the numbers runs/seismic/README.md cites (section 'Foundation input motion') and
tests/bem/test_input_motion.py and tests/bem/test_haskind.py assert.

Soil c_p 42, c_s 20 m/s, rho 1800 kg/m^3; a 1 m x 1 m footing (box -0.5..0.5) on a 2 m x 2 m surface;
records: a sin^4 acceleration pulse of length T then the reversed pulse (1 m/s^2); for the Rayleigh wave
+, -, -, +, -, +, +, - pulses, whose displacement returns to rest with a zero integral (its Hilbert
transform exists and its precursor is short).

1. ``petsc-ssi input-motion`` under vertical S (x, y) and P (z) at once (T = 0.1 s, 0.5 m elements):
   the footing against the free field.
2. ``petsc-ssi input-motion`` under SH at 60 degrees along x (c_app = 23.1 m/s), y=anti half model,
   T = 0.05 .. 0.8 s (a0 = 2 pi B / (c_app T), B = 0.5 m): peak translation u_y and torsion theta_z
   and their accelerations against the free field's at the centre, the largest differences to it, and
   the rocking theta_x the horizontal-rocking coupling adds.
3. ``petsc-ssi input-motion`` under a Rayleigh wave along x (y=sym), T = 0.2 and 0.4 s: the
   largest differences of u_x, u_z and the rocking theta_y to the free field at the centre.
4. Haskind: the blocked footing's force against minus the impedance tractions convolved with the
   free field (tests/bem/test_haskind.py's ``haskind``), SH 60 degrees on 0.5 and 0.25 m elements
   and P 30 degrees on 0.5 m.

Prints the tables and writes input_motion.csv (quantity, case, value) beside this script.

    python runs/seismic/input_motion.py        (from the repository root; about a minute)
"""
import csv
import os
import pathlib
import subprocess
import sys
import tempfile

import h5py
import numpy as np

from petsc_ssi.launch import child_env

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
SOIL = ["-ssi_cp", "42", "-ssi_cs", "20", "-ssi_rho", "1800", "-ssi_mesh_size", "2,2", "-ssi_mesh_h", "0.5",
        "-ssi_mesh_patch", "0.5,0.5", "-ssi_disp_group", "box:-0.5,0.5,-0.5,0.5", "-ssi_dt", "0.006",
        "-ssi_seismic_units", "m/s2", "-ssi_seismic_taper", "0", "-ssi_seismic_baseline", "none",
        "-ssi_output_stride", "0"]


def pulse(path, T, cols=(1.0,), rest=False):
    n = 8 if rest else 2         # rest: +, -, -, +, -, +, +, -: the displacement returns to 0 and its integral is 0
                                 # (a Rayleigh wave's H[g] exists and its precursor falls as 1/t^2, not 1/t)
    t = np.arange(0.0, n * T + 1e-9, T / 80)
    a = sum(sg * np.where((t >= k * T) & (t < (k + 1) * T), np.sin(np.pi * (t - k * T) / T) ** 4, 0.0)
            for k, sg in enumerate((1, -1, -1, 1, -1, 1, 1, -1)[:n]))
    np.savetxt(path, np.c_[t, np.outer(a, cols)], header="units: m/s2")
    return path


def input_motion(tmp, name, args):
    out = os.path.join(tmp, name + ".h5")
    p = subprocess.run([sys.executable, "-m", "petsc_ssi", "input-motion"] + SOIL + args + ["-ssi_output", out],
                       cwd=ROOT, capture_output=True, text=True, env=child_env())
    if p.returncode:
        raise SystemExit(p.stdout[-3000:] + p.stderr[-3000:])
    with h5py.File(out, "r") as f:
        g = {k: f["input_motion"][k][()] for k in f["input_motion"]}
        fm = np.c_[f["resultants/force"][()], f["resultants/moment"][()]]
    q = np.c_[g["translation"], g["rotation"]]
    wq = q @ g["step_stiffness"].T
    g["residual"] = max(np.abs(fm[:, :3]).max() / np.abs(wq[:, :3]).max(),
                        np.abs(fm[:, 3:]).max() / max(np.abs(wq[:, 3:]).max(), 1e-300))
    return g


def main():
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        rec = pulse(os.path.join(tmp, "v.txt"), 0.1, (1.0, -0.5, 0.7))
        g = input_motion(tmp, "vertical", ["-ssi_seismic", "vertical", "-ssi_seismic_record", rec, "-ssi_t_end", "0.3"])
        s = np.abs(g["free_field_translation"]).max()
        v = [np.abs(g["translation"] - g["free_field_translation"]).max() / s, 0.5 * np.abs(g["rotation"]).max() / s,
             g["residual"]]
        print("vertical S (x, y) + P (z), T = 0.1 s: max|u - u_ff|/max|u_ff| = %.2g, B max|theta|/max|u_ff| = %.2g, "
              "resultant/(W q) = %.2g" % tuple(v))
        rows += [("vertical: max|u - u_ff|/max|u_ff|", "T=0.1", v[0]), ("vertical: B max|theta|/max|u_ff|", "T=0.1", v[1]),
                 ("vertical: resultant / step-stiffness force", "T=0.1", v[2])]
        c_app = 20.0 / np.sin(np.radians(60.0))
        print("\nSH 60 deg along x, y=anti: peaks of the footing / free field at the centre")
        print("   T [s]   a0    u_y   a_y   th_z  alpha_z  max|du_y|/max|u_ff|  max|dth_z|/max|th_ff|  th_x/th_ff,z  resultant")
        for T in (0.05, 0.1, 0.2, 0.4, 0.8):
            rec = pulse(os.path.join(tmp, f"p{T}.txt"), T)
            g = input_motion(tmp, f"sh{T}", ["-ssi_seismic", "sh", "-ssi_seismic_angle", "60", "-ssi_seismic_record",
                                               rec, "-ssi_symmetry", "y=anti"])
            q = np.c_[g["translation"], g["rotation"]]
            ff = np.c_[g["free_field_translation"], g["free_field_rotation"]]
            a = np.c_[g["acceleration"], g["angular_acceleration"]]
            aff = np.c_[g["free_field_acceleration"], g["free_field_angular_acceleration"]]

            def ratio(x, y, k):
                return np.abs(x[:, k]).max() / np.abs(y[:, k]).max()
            vals = dict(a0=2 * np.pi * 0.5 / (c_app * T), u_y=ratio(q, ff, 1), a_y=ratio(a, aff, 1),
                        th_z=ratio(q, ff, 5), alpha_z=ratio(a, aff, 5),
                        err_u_y=np.abs(q[:, 1] - ff[:, 1]).max() / np.abs(ff[:, 1]).max(),
                        err_th_z=np.abs(q[:, 5] - ff[:, 5]).max() / np.abs(ff[:, 5]).max(),
                        th_x=np.abs(q[:, 3]).max() / np.abs(ff[:, 5]).max(), resultant=g["residual"])
            print("  %5.2f  %5.3f  %.4f %.4f %.4f %.4f   %.4g   %.4g   %.3g   %.2g" % (
                T, vals["a0"], vals["u_y"], vals["a_y"], vals["th_z"], vals["alpha_z"], vals["err_u_y"],
                vals["err_th_z"], vals["th_x"], vals["resultant"]))
            rows += [(f"SH60: {k}", f"T={T}", v) for k, v in vals.items()]
        print("\nRayleigh along x, y=sym: max |q - q_ff| / max |q_ff| at the centre")
        for T in (0.2, 0.4):
            rec = pulse(os.path.join(tmp, f"r{T}.txt"), T, rest=True)
            g = input_motion(tmp, f"ray{T}", ["-ssi_seismic", "rayleigh", "-ssi_seismic_record", rec,
                                              "-ssi_symmetry", "y=sym"])
            q = np.c_[g["translation"], g["rotation"]]
            ff = np.c_[g["free_field_translation"], g["free_field_rotation"]]
            errs = {n: np.abs(q[:, k] - ff[:, k]).max() / np.abs(ff[:, k]).max()
                    for n, k in (("u_x", 0), ("u_z", 2), ("theta_y", 4))}
            print(f"  T = {T}: " + ", ".join(f"{n} {e:.3g}" for n, e in errs.items()))
            rows += [(f"Rayleigh: max diff {n}", f"T={T}", e) for n, e in errs.items()]
        sys.path.insert(0, os.path.join(ROOT, "tests"))
        sys.path.insert(0, os.path.join(ROOT, "tests", "bem"))
        from test_haskind import haskind
        print("\nHaskind, blocked footing: max|F - H| / max|F|")
        names = {0: "F_x", 1: "F_y", 2: "F_z", 3: "M_x", 4: "M_y", 5: "M_z"}
        for wave, angle, sym, modes, h, dt in (("sh", 60, "y=anti", (1, 3, 5), 0.5, 0.006),
                                                ("sh", 60, "y=anti", (1, 3, 5), 0.25, 0.003),
                                                ("p", 30, "y=sym", (0, 2, 4), 0.5, 0.006)):
            d = pathlib.Path(tmp) / f"hk-{wave}-{h}"
            d.mkdir()
            err = haskind(d, wave, angle, sym, modes, h, dt)
            case = f"{wave.upper()}{angle} h={h} dt={dt}"
            print("  " + case + ": " + ", ".join(f"{names[k]} {e:.2g}" for k, e in err.items()))
            rows += [(f"Haskind: {names[k]}", case, e) for k, e in err.items()]
    with open(os.path.join(HERE, "input_motion.csv"), "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["quantity", "case", "value"])
        for q, c, v in rows:
            w.writerow([q, c, f"{float(v):.6g}"])
    print(f"\nwrote {os.path.join(HERE, 'input_motion.csv')}")


if __name__ == "__main__":
    main()
