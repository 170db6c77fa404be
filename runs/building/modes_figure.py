"""Fig. 14 of the paper for the fixed-base building: classify the modes, compare the half model, draw.

  .venv/bin/python runs/building/modes_figure.py [FULL.h5 [HALF.h5]] [--released RELEASED.h5]
                                                                    (from the repository root)

Reads the `petsc-ssi modes` outputs (defaults: out/building/modes-full.h5 and
out/building/modes-half.h5; see runs/building/README.md for the commands) and

- classifies every mode of the full model from its shape: the share of |u|^2 that is vertical
  (slab bending) or horizontal, the roof's mean ux, uy and twist, and the parity about the
  planes y = 0 and x = 0 (+1 symmetric, -1 antisymmetric: <u, S u(mirror)> / <u, u>);
- matches each half-model mode to the full model's modes (frequency and MAC on the nodes
  y >= 0, which the two meshes share) and prints the relative frequency difference;
- with the released-slab model (default out/building/modes-released.h5, the same command with
  -ssi_fem_part_floors_release rotations -ssi_fem_part_roof_release rotations), classifies its
  modes too, pairs each with the monolithic mode of largest MAC (translations, same nodes) and
  writes runs/building/modes_release.csv (monolithic vs released frequencies);
- writes runs/building/modes.png: the first
  translational x1 mode and the first slab-bending mode, drawn in 3D from the HDF5 output
  (shells coloured by |u|, frames as lines, undeformed frame in grey).
"""
import os
import sys

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
PNG = os.path.join(HERE, "modes.png")


def load(path):
    with h5py.File(path, "r") as f:
        X = f["coordinates"][:]
        freqs = np.asarray(f.attrs["frequencies_hz"], float)
        U = np.array([f[f"mode_shape_{k:06d}"][:] for k in range(len(freqs))])
        R = np.array([f[f"mode_shape_rotation_{k:06d}"][:] for k in range(len(freqs))])
        topo = f["topology"][:]
    quads, lines, i = [], [], 0
    while i < topo.size:                       # XDMF mixed topology: 5 = quad, 2 = polyline (2, n)
        t = int(topo[i])
        if t == 5:
            quads.append(topo[i + 1:i + 5])
            i += 5
        elif t == 2:
            n = int(topo[i + 1])
            lines.append(topo[i + 2:i + 2 + n])
            i += 2 + n
        else:
            raise ValueError(f"unexpected XDMF cell type {t}")
    return dict(X=X, f=freqs, U=U, R=R, quads=np.array(quads, np.int64), lines=np.array(lines, np.int64))


def mirror_index(X, axis):
    """Index of the mirror image (about the plane x_axis = 0) of each node (-1 if none)."""
    key = {tuple(np.round(x, 6)): i for i, x in enumerate(X)}
    Y = X.copy()
    Y[:, axis] *= -1
    return np.array([key.get(tuple(np.round(y, 6)), -1) for y in Y])


def parity(U, mi, axis):
    ok = mi >= 0
    S = np.ones(3)
    S[axis] = -1
    a = U[ok]
    b = U[mi[ok]] * S
    return float(np.sum(a * b) / max(np.sum(a * a), 1e-300))


def classify(m):
    X, H = m["X"], m["X"][:, 2].max()
    my, mx = mirror_index(X, 1), mirror_index(X, 0)
    roof = np.isclose(X[:, 2], H)
    rows = []
    for k, (f, U) in enumerate(zip(m["f"], m["U"]), 1):
        vert = float(np.sum(U[:, 2] ** 2) / np.sum(U ** 2))
        ux, uy = U[roof, 0].mean(), U[roof, 1].mean()
        r = X[roof, :2]
        twist = np.mean(r[:, 0] * U[roof, 1] - r[:, 1] * U[roof, 0]) / np.mean(np.sum(r ** 2, axis=1))
        Rz = np.sqrt(np.mean(r[:, 0] ** 2 + r[:, 1] ** 2))          # twist x radius: a displacement
        py, px = parity(U, my, 1), parity(U, mx, 0)
        # storey displacements (mean ux, uy over the slab nodes of each level) -> the mode's order
        levels = sorted({round(z, 6) for z in X[:, 2] if np.isclose(z / 3.0, round(z / 3.0))})
        if vert > 0.5:
            kind = "slab bending"
        else:
            c = {"x1": abs(ux), "x2": abs(uy), "torsion": abs(twist) * Rz}
            kind = max(c, key=c.get)
            prof = [U[np.isclose(X[:, 2], z), {"x1": 0, "x2": 1, "torsion": 0}[kind]].mean() for z in levels[1:]]
            if kind == "torsion":
                prof = [np.mean(X[np.isclose(X[:, 2], z), 0] * U[np.isclose(X[:, 2], z), 1]
                                - X[np.isclose(X[:, 2], z), 1] * U[np.isclose(X[:, 2], z), 0]) for z in levels[1:]]
            s = np.sign(prof)
            order = 1 + int(np.sum(s[1:] != s[:-1]))
            kind = f"{kind} ({order}{['st', 'nd', 'rd'][min(order, 3) - 1]})"
        rows.append(dict(mode=k, f=float(f), kind=kind, vertical_share=vert, sym_y=py, sym_x=px,
                         roof_ux=float(ux), roof_uy=float(uy), roof_twist=float(twist)))
    return rows


def match_half(full, half):
    """For each half mode: the full mode of largest MAC on the shared nodes y >= 0."""
    key = {tuple(np.round(x, 6)): i for i, x in enumerate(full["X"])}
    idx = np.array([key[tuple(np.round(x, 6))] for x in half["X"]])
    out = []
    for k, (fh, Uh) in enumerate(zip(half["f"], half["U"]), 1):
        a = Uh.ravel()
        macs = [float(np.dot(a, Uf[idx].ravel()) ** 2 / (np.dot(a, a) * np.dot(Uf[idx].ravel(), Uf[idx].ravel())))
                for Uf in full["U"]]
        j = int(np.argmax(macs))
        out.append(dict(half_mode=k, f_half=float(fh), full_mode=j + 1 if macs[j] > 0.9 else None,
                        f_full=float(full["f"][j]) if macs[j] > 0.9 else None, mac=macs[j]))
    return out


def _venv_mpl_toolkits(matplotlib):
    """Use the mpl_toolkits of the matplotlib that is imported. In .venv (--system-site-packages)
    Debian's /usr/lib/python3/dist-packages/mpl_toolkits is a regular package (it has an
    __init__.py) and so wins over the pip matplotlib's namespace package: its mplot3d (for
    Debian's matplotlib) fails to import and projection='3d' is unknown."""
    import mpl_toolkits
    mine = os.path.join(os.path.dirname(os.path.dirname(matplotlib.__file__)), "mpl_toolkits")
    if os.path.isdir(mine) and mine not in list(mpl_toolkits.__path__):
        mpl_toolkits.__path__.insert(0, mine)


def draw(ax, m, k, scale, title):
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection, Line3DCollection
    X, U = m["X"], m["U"][k]
    Y = X + scale * U
    mag = np.linalg.norm(U, axis=1)
    q = m["quads"]
    col = np.mean(mag[q], axis=1)
    import matplotlib.cm as cm
    pc = Poly3DCollection(Y[q], facecolors=cm.viridis(col / max(col.max(), 1e-300)), edgecolors="k",
                          linewidths=0.05, alpha=0.9)
    ax.add_collection3d(pc)
    ln = m["lines"]
    ax.add_collection3d(Line3DCollection(X[ln], colors="0.75", linewidths=0.5))
    ax.add_collection3d(Line3DCollection(Y[ln], colors="C3", linewidths=1.2))
    lo, hi = X.min(axis=0) - 1, X.max(axis=0) + 1
    ax.set_xlim(lo[0], hi[0]); ax.set_ylim(lo[1], hi[1]); ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect(hi - lo)
    ax.set_xlabel("x (x1) [m]"); ax.set_ylabel("y [m]"); ax.set_zlabel("z [m]")
    ax.view_init(elev=22, azim=-60)
    ax.set_title(title, fontsize=9)


def compare_release(full, rows, rel_path):
    """Monolithic vs released slabs: each released mode with the monolithic mode of largest MAC."""
    rel = load(rel_path)
    rrows = classify(rel)
    out = []
    for r, Ur in zip(rrows, rel["U"]):
        a = Ur.ravel()
        macs = [float(np.dot(a, Uf.ravel()) ** 2 / (np.dot(a, a) * np.dot(Uf.ravel(), Uf.ravel()))) for Uf in full["U"]]
        j = int(np.argmax(macs))
        out.append(dict(mode_released=r["mode"], f_released=r["f"], kind_released=r["kind"],
                        mode_monolithic=j + 1, f_monolithic=rows[j]["f"], kind_monolithic=rows[j]["kind"],
                        mac=macs[j], shift_pct=100 * (r["f"] - rows[j]["f"]) / rows[j]["f"]))
    path = os.path.join(HERE, "modes_release.csv")
    with open(path, "w") as fh:
        fh.write("mode_released,f_released_hz,kind_released,mode_monolithic,f_monolithic_hz,kind_monolithic,MAC,"
                 "shift_pct\n")
        for r in out:
            fh.write(f"{r['mode_released']},{r['f_released']:.4f},{r['kind_released']},{r['mode_monolithic']},"
                     f"{r['f_monolithic']:.4f},{r['kind_monolithic']},{r['mac']:.4f},{r['shift_pct']:.2f}\n")
    print(open(path).read().rstrip())
    print(f"wrote {os.path.relpath(path, ROOT)}")
    return out


def main(argv):
    rel_path = os.path.join(ROOT, "out", "building", "modes-released.h5")
    if "--released" in argv:
        i = argv.index("--released")
        rel_path = argv[i + 1]
        argv = argv[:i] + argv[i + 2:]
    full_path = argv[0] if argv else os.path.join(ROOT, "out", "building", "modes-full.h5")
    half_path = argv[1] if len(argv) > 1 else os.path.join(ROOT, "out", "building", "modes-half.h5")
    full = load(full_path)
    rows = classify(full)
    print("mode,frequency_hz,kind,vertical_share,parity_y,parity_x")
    for r in rows:
        print(f"{r['mode']},{r['f']:.4f},{r['kind']},{r['vertical_share']:.3f},{r['sym_y']:+.3f},{r['sym_x']:+.3f}")
    if os.path.isfile(rel_path):
        compare_release(full, rows, rel_path)
    matches = []
    if os.path.isfile(half_path):
        half = load(half_path)
        matches = match_half(full, half)
        print("half_mode,f_half_hz,full_mode,f_full_hz,rel_diff,MAC")
        for r in matches:
            if r["full_mode"]:
                print(f"{r['half_mode']},{r['f_half']:.8g},{r['full_mode']},{r['f_full']:.8g},"
                      f"{(r['f_half'] - r['f_full']) / r['f_full']:.2e},{r['mac']:.10f}")
            else:
                print(f"{r['half_mode']},{r['f_half']:.8g},-,-,-,{r['mac']:.4f} (beyond the full model's modes)")

    import matplotlib
    matplotlib.use("Agg")
    _venv_mpl_toolkits(matplotlib)
    import matplotlib.pyplot as plt
    kx = next(r["mode"] for r in rows if r["kind"].startswith("x1"))
    kb = next(r["mode"] for r in rows if r["kind"] == "slab bending")
    fig = plt.figure(figsize=(12, 5.5))
    for i, (k, what, s) in enumerate(((kx, "first translational x1 mode", 1.5), (kb, "first slab-bending mode", 1.5))):
        ax = fig.add_subplot(1, 2, i + 1, projection="3d")
        draw(ax, full, k - 1, s, f"mode {k}: {full['f'][k - 1]:.2f} Hz, {what}\n"
                                 f"(fixed base; max |u| = 1, drawn x {s} m)")
    fig.suptitle("Three-storey building (paper Sec. 5.2, Fig. 14), fixed base: petsc-ssi modes", fontsize=10)
    fig.tight_layout()
    fig.savefig(PNG, dpi=130)
    print(f"wrote {os.path.relpath(PNG, ROOT)}")


if __name__ == "__main__":
    main(sys.argv[1:])
