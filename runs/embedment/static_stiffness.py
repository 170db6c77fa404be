"""Static stiffness of a rigid square footing embedded in the half-space, against Pais & Kausel's
embedment factors (issue 42, item 2; NIST GCR 12-917-21, Table 2-2b).

The footing is the pit's walls and bottom (``-ssi_mesh pit``, half-width B = a = b = 1 m, depth D = d)
moved rigidly (``-ssi_disp_group pit``); a surface footing (the patch of the same mesh size) is the
reference. One step of dt = 1000 s makes the lag-1 kernels Kelvin's static ones (every pair lies
within c_s dt), so a single solve is the static problem: K = resultant / motion. The embedment factor
eta = K_embedded / K_surface of the same element size and extent cancels much of the mesh's error
(the surface footing is itself 8 % stiff at h = B/2: tests/bem/test_rigid_motion.py).

Pais & Kausel (1988) for a square (L/B = 1), as transcribed from NIST GCR 12-917-21 Table 2-2b:
    eta_z  = 1 + (0.25 + 0.25 / (L/B)) (D/B)^0.8
    eta_x  = 1 + (0.33 + 1.34 / (1 + L/B)) (D/B)^0.8
    eta_zz = 1 + (1.3 + 1.32 / (L/B)) (D/B)^0.9                      (torsion)
    eta_yy = 1 + D/B + 1.6 / (0.35 + (L/B)^4) (D/B)^2                (rocking)
The rocking stiffness of the embedded footing is taken about the centre of its base (0, 0, -D): the
one that converges towards the table's factor (about the ground-level centre the BEM's factor moves
away from it as the mesh is refined).

``python runs/embedment/static_stiffness.py [OUT.csv] [h,h,...] [--whole] [--ground=L]`` writes the table
(columns with units) and prints it as Markdown (runs/embedment/README.md): quarter models (``SYMMETRY``)
unless --whole, on an L x L ground (8 m, 4 B from the centre, unless --ground)."""
import csv
import sys

import numpy as np

MODES = {"vertical": ("0,0,1e-6", "0,0,0", 2, "force"), "horizontal": ("1e-6,0,0", "0,0,0", 0, "force"),
         "torsion": ("0,0,0", "0,0,1e-6", 2, "moment"), "rocking": ("0,0,0", "0,1e-6,0", 1, "moment")}
# the quarter model's planes per mode (the footing and the ground are symmetric about x = 0 and y = 0; the
# motion is symmetric or antisymmetric about each): -ssi_symmetry
SYMMETRY = {"vertical": "x=sym,y=sym", "horizontal": "x=anti,y=sym", "torsion": "x=anti,y=anti",
            "rocking": "x=anti,y=sym"}
SOIL = dict(cp=548.0, cs=316.0, rho=2000.0)


def eta_pais_kausel(mode, D_B, L_B=1.0):
    """Pais & Kausel's embedment factor (module docstring; ``impedance_refs.pais_kausel_embedment``)."""
    from petsc_ssi.analytic.impedance_refs import pais_kausel_embedment
    return pais_kausel_embedment(mode, D_B, L_B)


def _run(opts, out):
    """One static BEM run in this process with -ssi_<key> <value> options; the resultants' last step."""
    import h5py
    from petsc_ssi.petsc import init
    PETSc = init([sys.argv[0]])
    import petsc_ssi.app.kinds as kinds
    db = PETSc.Options()
    opts = dict(opts, problem="bem", dt=1000, t_end=1000, scheme="plain", output=out, output_stride=0,
                output_overwrite=1, warn_beta=0, **SOIL)
    for k, v in opts.items():
        db.setValue("ssi_" + k, str(v))
    try:
        kinds.run_bem(kinds.resolve("bem"))
    finally:
        for k in opts:
            db.delValue("ssi_" + k)
    with h5py.File(out) as f:
        return f["resultants/force"][-1], f["resultants/moment"][-1]


def stiffness(mesh, mode, ref, out, quarter=False):
    """The static stiffness [N/m or N m/rad] of ``mode`` for the rigid region of ``mesh`` (options),
    rotations about ``ref``: the resultant of the soil's traction sigma n (n out of the soil) over the
    motion (1e-6): a footing pushed down compresses the soil, t_z < 0, so F = K u."""
    val, rot, k, kind = MODES[mode]
    opts = dict(mesh, disp_value=val, disp_rotation=rot, disp_ref=ref)
    if quarter:
        opts["symmetry"] = SYMMETRY[mode]
    F, M = _run(opts, out)
    return (F if kind == "force" else M)[k] / 1e-6


def embedment_factors(h, depths, modes=tuple(MODES), L=8.0, out="embedment.h5", quarter=False):
    """Rows (h [m], D/B, mode, K_surface, K_embedded, eta, eta_PK, eta / eta_PK - 1) for B = 1 m; quarter: the
    quarter models of ``SYMMETRY`` (the same numbers to round-off, a sixteenth of the matrices)."""
    flat = dict(mesh_size=f"{L},{L}", mesh_h=h, mesh_patch="1,1", disp_group="load")
    ks = {m: stiffness(flat, m, "0,0,0", out, quarter) for m in modes}
    rows = []
    for D in depths:
        pit = dict(mesh="pit", mesh_params=f"a=1,b=1,d={D}", mesh_size=f"{L},{L}", mesh_h=h, disp_group="pit")
        for m in modes:
            ke = stiffness(pit, m, f"0,0,{-D}" if m == "rocking" else "0,0,0", out, quarter)
            eta, ref = ke / ks[m], eta_pais_kausel(m, D)
            rows.append((h, D, m, ks[m], ke, eta, ref, eta / ref - 1))
    return rows


HEAD = ("h [m]", "D/B [-]", "mode", "K_surface [N/m or N m/rad]", "K_embedded [N/m or N m/rad]", "eta_BEM [-]",
        "eta_PK [-]", "eta_BEM/eta_PK - 1 [-]")


def main(argv):
    flags = [a for a in argv[1:] if a.startswith("--")]
    argv = [argv[0]] + [a for a in argv[1:] if not a.startswith("--")]
    quarter = "--whole" not in flags
    L = float(next((f.split("=")[1] for f in flags if f.startswith("--ground=")), 8.0))
    out = argv[1] if len(argv) > 1 else "embedment.csv"
    hs = [float(v) for v in (argv[2] if len(argv) > 2 else "1,0.5,0.25").split(",")]
    rows = [r for h in hs for r in embedment_factors(h, (0.5, 1.0), L=L, out=out + ".h5", quarter=quarter)]
    with open(out, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(HEAD)
        w.writerows(rows)
    print("| " + " | ".join(HEAD) + " |")
    print("|" + "---|" * len(HEAD))
    for r in rows:
        print(f"| {r[0]:g} | {r[1]:g} | {r[2]} | {r[3]:.4g} | {r[4]:.4g} | {r[5]:.3f} | {r[6]:.3f} | {100 * r[7]:+.1f} % |")
    conv = convergence(rows)
    if conv:
        print()
        print("| D/B [-] | mode | eta on h, h/2, h/4 [-] | observed order p [-] | eta extrapolated [-] | eta_PK [-] | "
              "extrapolated/eta_PK - 1 [-] |")
        print("|---|---|---|---|---|---|---|")
        for D, m, etas, p, ex, ref in conv:
            print(f"| {D:g} | {m} | {', '.join(f'{e:.3f}' for e in etas)} | {p:.2f} | {ex:.3f} | {ref:.3f} | "
                  f"{100 * (ex / ref - 1):+.1f} % |")
    return np.array([r[7] for r in rows])


def convergence(rows):
    """Per (D/B, mode) with factors on three meshes h, h/2, h/4 (the last three of ``rows``' element
    sizes, halving): (D/B, mode, the three factors, the observed order p = log2(d1 / d2) of their successive
    differences d1, d2, the Richardson extrapolation eta_4 + d2 / (2^p - 1), eta_PK); [] if there are not
    three halving meshes or the differences change sign (no monotone convergence to read)."""
    hs = sorted({r[0] for r in rows}, reverse=True)[-3:]
    if len(hs) < 3 or not all(abs(hs[i] / hs[i + 1] - 2) < 1e-9 for i in range(2)):
        return []
    out = []
    for D, m in dict.fromkeys((r[1], r[2]) for r in rows):
        etas = [next(r[5] for r in rows if r[:3] == (h, D, m)) for h in hs]
        d1, d2 = etas[1] - etas[0], etas[2] - etas[1]
        if d1 * d2 <= 0 or abs(d2) >= abs(d1):
            continue
        p = float(np.log2(d1 / d2))
        out.append((D, m, etas, p, etas[2] + d2 / (2 ** p - 1), eta_pais_kausel(m, D)))
    return out


if __name__ == "__main__":
    main(sys.argv)
