"""Dynamic stiffness and damping of a rigid square footing embedded in the half-space (issue 42, item 2),
beside the same footing on the surface and beside Pais & Kausel's formulas (NIST GCR 12-917-21,
Tables 2-3a and 2-3b: ``petsc_ssi.analytic.impedance_refs``).

The method is ``petsc-ssi impedance``'s (``petsc_ssi/app/impedance.py``, ``bem/impedance.spectrum``):
the footing (B = a = b = 1 m) gets a rigid translation h(t) u0 with h a smooth step over 4 dt, one
transient run records the soil's resultant R on it, K(omega) = FFT(dR) / FFT(dh) (the traction's
half-step shift applied), K0 = R / h at the last step, and K = K0 [k(a0) + i a0 c(a0)],
a0 = omega B / c_s, each curve normalised by its own K0. The embedded footing is the pit's walls and
bottom (``-ssi_mesh pit``, depth D) moved rigidly (``-ssi_disp_group pit``); the surface footing is the flat
grid's patch on the same ground; both on the quarter model the mode allows (``MODES``: the same answer as the
whole model, to 1e-6 on the surface, tests/bem/test_impedance.py, and to 1e-9 in the pit's static stiffness,
tests/bem/test_embedded_footing.py; ``quarter=False`` runs the embedded footing whole).

The references, in the same normalisation (each by its own static stiffness):
    surface   k = alpha_j (Table 2-3a), c = the bracket of beta_j (2 alpha beta / a0)
    embedded  k = alpha_j (Table 2-3b: the surface modifiers), c = the embedded bracket over the embedded
              static stiffness K_emb = eta K_sur (Table 2-2b): vertical 4 (psi L/B + D/B (1 + L/B)),
              horizontal 4 (L/B + D/B (psi + L/B)), rocking (about the base's centre) the plane-wave sum
              (4/3) (psi + 4 D/B + (1 + psi) (D/B)^3) times a0^2 / (1.8 + a0^2) plus (4/3) (1 + psi) (D/B)^3
              (``impedance_refs.pais_kausel_embedded``: read from [T3]), psi = c_p / c_s (capped at 2.5).
The trusted band of a0 is the impedance command's: two frequency bins of the record, one Rayleigh
wavelength across the ground, four elements per shear wavelength and omega dt <= 0.3.

``python runs/embedment/dynamic_stiffness.py [OUT.csv] [h] [L] [D,D,...]`` (depths D/B, default 0.5,1) writes
the CSV (units in the headers), OUT.png, and prints the table at a0 = 0.5, 1, 1.5, 2 as Markdown
(runs/embedment/README.md);
``python runs/embedment/dynamic_stiffness.py --summary FILE.csv`` prints the ratios the README quotes."""
import csv
import math
import os
import subprocess
import sys

import numpy as np

from petsc_ssi.launch import child_env

SOIL = dict(cp=548.0, cs=316.0, rho=2000.0)
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
# per mode: the footing's translation [m], its rotation [rad] (about the base's centre), the resultant's
# component and kind, the quarter model's planes
MODES = {"vertical": ("0,0,1e-6", "0,0,0", 2, "force", "x=sym,y=sym"),
         "horizontal": ("1e-6,0,0", "0,0,0", 0, "force", "x=anti,y=sym"),
         "rocking": ("0,0,0", "0,1e-6,0", 1, "moment", "x=anti,y=sym"),
         "torsion": ("0,0,0", "0,0,1e-6", 2, "moment", "x=anti,y=anti")}
A0 = (0.5, 1.0, 1.5, 2.0)


def nu():
    r2 = (SOIL["cp"] / SOIL["cs"]) ** 2
    return (r2 - 2) / (2 * (r2 - 1))


def _run(opts, out):
    """One BEM run with -ssi_<key> <value> options (``python -m petsc_ssi`` in a child process: repeated
    runs in one process kept gigabytes resident): (h (steps,), force (steps, 3) [N], moment (steps, 3) [N m]
    about the motion's reference point)."""
    import h5py
    out = os.path.abspath(out)
    opts = dict(opts, problem="bem", scheme="plain", output=out, output_stride=0, output_overwrite=1, warn_beta=0,
                disp_history="smoothstep", **SOIL)
    args = [a for k, v in opts.items() for a in ("-ssi_" + k, str(v))]
    env = child_env(PYTHONPATH=ROOT, OPENBLAS_NUM_THREADS="1")
    p = subprocess.run([sys.executable, "-m", "petsc_ssi"] + args, cwd=ROOT, env=env, capture_output=True, text=True)
    if p.returncode:
        raise RuntimeError(f"petsc-ssi {' '.join(args)} failed:\n{p.stdout[-2000:]}{p.stderr[-2000:]}")
    with h5py.File(out) as f:
        return f["resultants/h"][:], f["resultants/force"][:], f["resultants/moment"][:]


def impedance(mesh, mode, dt, t_end, out, B=1.0, D=0.0):
    """(a0, k, c, K0 [N/m, or N m/rad for rocking]) of ``mode`` for the rigid region of ``mesh`` (options),
    up to where the smooth step's spectrum falls below 1e-3 of its peak (the impedance command's cut).
    Rotations about the centre of the footing's base (0, 0, -D), as the static stiffness's
    (runs/embedment/static_stiffness.py) and Table 2-2b's eta_yy."""
    from petsc_ssi.bem.impedance import spectrum, step_spectrum
    val, rot, comp, kind, _ = MODES[mode]
    h, F, M = _run(dict(mesh, disp_value=val, disp_rotation=rot, disp_ref=f"0,0,{-D:g}", disp_t0=4 * dt, dt=dt,
                        t_end=t_end), out)
    R = (F if kind == "force" else M)[:, comp] / 1e-6
    with np.errstate(divide="ignore", invalid="ignore"):        # beyond the pulse's band (cut below)
        om, K = spectrum(R, h, dt)
    Dh = np.abs(step_spectrum(h, dt)[1])
    low = np.nonzero(Dh < 1e-3 * Dh[0])[0]
    keep = slice(1, int(low[0]) if low.size else len(Dh))
    om, K = om[keep], K[keep]
    K0 = float(R[-1] / h[-1])
    a0 = om * B / SOIL["cs"]
    return a0, K.real / K0, K.imag / (a0 * K0), K0


def band(h, L, dt, t_end, B=1.0):
    """The a0 the impedance command trusts (its docstring): (lower, upper)."""
    from petsc_ssi.analytic.free_field import rayleigh_speed
    cs = SOIL["cs"]
    lo = max(4 * math.pi * B / (cs * t_end), 2 * math.pi * B * rayleigh_speed(cs, SOIL["cp"]) / (cs * L))
    return lo, min(math.pi * B / (2 * h), 0.3 * B / (cs * dt))


def references(mode, a0, D_B):
    """(k, c) of Pais & Kausel on the surface (D_B = 0) or embedded D_B deep."""
    from petsc_ssi.analytic import impedance_refs as ir
    if D_B == 0:
        return ir.pais_kausel(mode, a0, 1.0, nu())[1:]
    try:
        return ir.pais_kausel_embedded(mode, a0, D_B, 1.0, nu())[1:]
    except NotImplementedError:               # (embedded torsion: no transcription of Table 2-3b's c)
        return ir.pais_kausel(mode, a0, 1.0, nu())[1], np.full(np.shape(a0), np.nan)   # (k: alpha_emb = alpha_sur)


def embedment_ref(mode, D_B=0.5):
    """Pais & Kausel's static embedment factor eta (Table 2-2b) of the square."""
    from petsc_ssi.analytic import impedance_refs as ir
    return ir.pais_kausel_embedment(mode, D_B, 1.0)


def embedded(D):
    """The footing's name in the results of ``curves`` for the embedment D/B = D."""
    return f"embedded D/B = {D:g}"


def depth(name):
    """D/B of a footing name of ``curves`` (0 for the surface)."""
    return float(name.split("=")[1]) if name.startswith("embedded") else 0.0


def curves(h=0.5, L=8.0, depths=(0.5,), dt=4.75e-4, t_end=0.1, modes=tuple(MODES), out="dyn.h5", quarter=True):
    """{(footing, mode): (a0, k, c, K0, k_ref, c_ref)} for the surface footing ("surface") and the footing
    embedded D/B = D for each of ``depths`` (``embedded(D)``)."""
    flat = dict(mesh_size=f"{L},{L}", mesh_h=h, mesh_patch="1,1", disp_group="load")
    res = {}
    for mode in modes:
        sym = dict(symmetry=MODES[mode][4])
        cases = [("surface", dict(flat, **sym))]
        for D in depths:
            pit = dict(mesh="pit", mesh_params=f"a=1,b=1,d={D}", mesh_size=f"{L},{L}", mesh_h=h, disp_group="pit")
            cases.append((embedded(D), dict(pit, **sym) if quarter else pit))
        for name, mesh in cases:
            a0, k, c, K0 = impedance(mesh, mode, dt, t_end, out, D=depth(name))
            res[(name, mode)] = (a0, k, c, K0) + tuple(references(mode, a0, depth(name)))
    return res


HEAD = ("footing", "mode", "a0 [-]", "k [-]", "c [-]", "K0 [N/m; N m/rad rocking]", "k_PK [-]", "c_PK [-]", "trusted [0/1]")


def at(a0, y, x):
    return float(np.interp(x, a0, y))


def plot(res, png, lohi):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    modes = sorted({m for _, m in res}, key=list(MODES).index)
    fig, ax = plt.subplots(2, len(modes), figsize=(5 * len(modes), 6.5), squeeze=False)
    for j, mode in enumerate(modes):
        names = [n for n, m in res if m == mode]
        for name, col in zip(names, ("C0", "C3", "C2", "C1")):
            a0, k, c, K0, kr, cr = res[(name, mode)]
            sel = a0 <= 3.0
            lab = name
            ax[0, j].plot(a0[sel], k[sel], color=col, label=f"BEM {lab}")
            ax[0, j].plot(a0[sel], kr[sel], "--", color=col, label=f"Pais & Kausel {lab}")
            ax[1, j].plot(a0[sel], c[sel], color=col, label=f"BEM {lab}")
            if np.isfinite(cr[sel]).any():      # (embedded torsion: no published c)
                ax[1, j].plot(a0[sel], cr[sel], "--", color=col, label=f"Pais & Kausel {lab}")
        for i, what in enumerate(("k = Re K / K0 [-]", "c = Im K / (a0 K0) [-]")):
            ax[i, j].axvspan(*lohi, color="0.92", zorder=0)
            ax[i, j].set_xlabel("a0 = omega B / c_s [-]")
            ax[i, j].set_ylabel(what)
            ax[i, j].set_xlim(0, 3)
        ax[0, j].set_title(f"{mode} (grey: the trusted a0)", fontsize=9)
        if mode == "torsion":
            ax[1, j].set_title("embedded torsion: no published Table 2-3b curve found", fontsize=8)
        ax[1, j].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    plt.close(fig)


def summary(path, lo=0.72, hi=1.997):
    """From a CSV this script wrote: per embedded footing and mode over lo <= a0 <= hi, the ranges of the
    embedded c over Table 2-3b's - 1, the embedded over the surface footing's c, the same of the dashpots K0 c
    (K0 included), the largest |k_embedded - k_surface|, and the surface c over Table 2-3a's - 1."""
    with open(path) as fh:
        rows = list(csv.DictReader(fh))
    out = {}
    names = [n for n in dict.fromkeys(x["footing"] for x in rows) if n != "surface"]
    for name in names:
        for mode in MODES:
            d = {}
            for f in ("surface", name):
                r = [x for x in rows if x["footing"] == f and x["mode"] == mode]
                col = {k: np.array([float(x[k]) for x in r]) for k in ("a0 [-]", "k [-]", "c [-]", "c_PK [-]")}
                d[f] = col, float(r[0][HEAD[5]])
            (e, Ke), (s_, Ks) = d[name], d["surface"]
            a0 = e["a0 [-]"]
            sel = (a0 >= lo) & (a0 <= hi)
            cs = np.interp(a0[sel], s_["a0 [-]"], s_["c [-]"])
            ks = np.interp(a0[sel], s_["a0 [-]"], s_["k [-]"])
            ss = (s_["a0 [-]"] >= lo) & (s_["a0 [-]"] <= hi)
            rng = lambda v: (round(float(v.min()), 3), round(float(v.max()), 3))  # noqa: E731
            out[(name, mode)] = {"c_emb/c_PK - 1": rng(e["c [-]"][sel] / e["c_PK [-]"][sel] - 1),
                                 "c_emb/c_sur": rng(e["c [-]"][sel] / cs),
                                 "C_emb/C_sur": rng(Ke * e["c [-]"][sel] / (Ks * cs)),
                                 "max |k_emb - k_sur|": round(float(np.abs(e["k [-]"][sel] - ks).max()), 3),
                                 "c_sur/c_PK - 1": rng(s_["c [-]"][ss] / s_["c_PK [-]"][ss] - 1)}
            print(name, mode, ", ".join(f"{k} {v}" for k, v in out[(name, mode)].items()))
    return out


def main(argv):
    if len(argv) > 2 and argv[1] == "--summary":
        return summary(argv[2])
    out = argv[1] if len(argv) > 1 else "embedment-dynamic.csv"
    h = float(argv[2]) if len(argv) > 2 else 0.5
    L = float(argv[3]) if len(argv) > 3 else 8.0
    depths = tuple(float(v) for v in (argv[4] if len(argv) > 4 else "0.5,1").split(","))
    dt, t_end = 4.75e-4, 0.1
    res = curves(h, L, depths, dt, t_end, out=out + ".h5")
    os.remove(out + ".h5")
    lo, hi = band(h, L, dt, t_end)
    with open(out, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(HEAD)
        for (name, mode), (a0, k, c, K0, kr, cr) in res.items():
            for i in range(len(a0)):
                w.writerow((name, mode, f"{a0[i]:.6g}", f"{k[i]:.6g}", f"{c[i]:.6g}", f"{K0:.6g}", f"{kr[i]:.6g}",
                            f"{cr[i]:.6g}", int(lo <= a0[i] <= hi)))
    plot(res, os.path.splitext(out)[0] + ".png", (lo, hi))
    print(f"h = {h:g} m, ground {L:g} m x {L:g} m, dt = {dt:g} s, t_end = {t_end:g} s; "
          f"trusted a0 in [{lo:.2f}, {hi:.2f}]")
    print("| footing | mode | K0 [N/m; N m/rad] | a0 [-] | k BEM [-] | k P&K [-] | c BEM [-] | c P&K [-] |")
    print("|---|---|---|---|---|---|---|---|")
    for (name, mode), (a0, k, c, K0, kr, cr) in res.items():
        for x in A0:
            tag = "" if lo <= x <= hi else " (untrusted)"
            print(f"| {name} | {mode} | {K0:.4g} | {x:g}{tag} | {at(a0, k, x):.3f} | {at(a0, kr, x):.3f} | "
                  f"{at(a0, c, x):.3f} | {at(a0, cr, x):.3f} |")
    return res


if __name__ == "__main__":
    main(sys.argv)
