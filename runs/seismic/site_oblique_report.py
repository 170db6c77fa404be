"""The tables of runs/seismic/README.md's "A large building on a large site, an oblique wave" from the files
site_oblique.sh wrote: the run's cost against its estimate (-log_view, -memory_view, petsc-ssi estimate), and what
the building feels (the roof's peak absolute accelerations and spectral peaks in x and y, the roof's twist about z,
the storey drifts, the base shear and the foundation's rocking) beside the free field's record, and a PNG of the
roof's accelerations and twist (site-oblique.png in the run's directory).

    python runs/seismic/site_oblique_report.py out/seismic [NRANKS]
"""
import os
import re
import sys

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "jobscripts"))
from logview import parse  # noqa: E402
sys.path.insert(0, HERE)
from report import spectrum_peak  # noqa: E402  (runs/seismic/report.py: the spectrum's PSA peak)


def estimate_row(path, ranks):
    """(total seconds, GB over the ranks with the processes) of ``petsc-ssi estimate``'s row for ``ranks``."""
    for line in open(path):
        m = re.match(rf"\[ssi\]\s+{ranks}\s+\|(.*)", line)
        if m:
            cells = [c.strip() for c in line.split("|")]
            total = cells[1].split()[-1]
            return _seconds(total), float(cells[3])
    return float("nan"), float("nan")


def _seconds(text):
    """'6m06s', '49.8s', '1h02m' -> seconds."""
    s = 0.0
    for v, u in re.findall(r"([\d.]+)([hms])", text):
        s += float(v) * {"h": 3600, "m": 60, "s": 1}[u]
    return s


def main(d, ranks=2):
    stem = os.path.join(d, f"site-oblique-n{ranks}")
    lv = parse(open(stem + ".log").read())
    ev = lv["events"]
    est_s, est_gb = estimate_row(stem + ".estimate", ranks)
    peak = (lv["peak_rss_bytes"] or np.nan) / 1e9
    print("| ranks | wall [s] | BEM assembly (of it: toeplitz kernels) [s] | of the assembly: interface matrices [s] | "
          "time loop [s] | "
          "history sum [s] | peak over the ranks [GB] | estimate: wall [s], GB |")
    print("|---|---|---|---|---|---|---|---|")
    st = lv["stages"]
    print(f"| {ranks} | {lv['total_s']:.0f} | {st.get('SSI BEM assembly', np.nan):.1f} "
          f"({ev.get('SSI_BEM_Toeplitz', (0, np.nan))[1]:.1f}) | {ev.get('SSI_Capacitance', (0, np.nan))[1]:.1f} | "
          f"{st.get('SSI time loop', np.nan):.1f} | {ev.get('SSI_BEM_History', (0, np.nan))[1]:.1f} | {peak:.2f} | "
          f"{est_s:.0f}, {est_gb:.1f} |")
    S = h5py.File(os.path.join(d, "site-oblique_structure.h5"), "r")
    F = h5py.File(os.path.join(d, "site-oblique.h5"), "r")
    t = S["receivers/t"][()]
    a = S["receivers/acceleration"][()]          # (K, receivers, 3) [m/s^2]: roof centre, two roof corners, base
    u = S["receivers/u"][()]
    rot = S["receivers/rotation"][()]             # [rad]
    pts = S["receivers/points"][()]
    dm = S["demands"]
    # the roof's twist about z from its two opposite corners (1, 2): the rigid rotation that moves them apart
    # as measured, theta_z = ((x1 - x2) (u_y1 - u_y2) - (y1 - y2) (u_x1 - u_x2)) / |p1 - p2|^2
    dx, dy = pts[1, 0] - pts[2, 0], pts[1, 1] - pts[2, 1]
    du = u[:, 1] - u[:, 2]
    twist = (dx * du[:, 1] - dy * du[:, 0]) / (dx * dx + dy * dy)
    print()
    print("| quantity | x | y | z |")
    print("|---|---|---|---|")
    sf = F["seismic"]
    print(f"| free field (the record: horizontal surface motion at the interface's centroid, along the azimuth): "
          f"PGA [m/s^2] | {float(sf['pga'][()]):.3f} | | |")
    pa = np.abs(a[:, 0]).max(axis=0)
    print(f"| roof centre: peak absolute acceleration [m/s^2] | {pa[0]:.3f} | {pa[1]:.3f} | {pa[2]:.3f} |")
    for c in "xy":
        p = os.path.join(d, f"site-oblique-roof-{c}.csv")
        if os.path.exists(p):
            T, s = spectrum_peak(p)
            print(f"| roof centre: PSA peak (5 %) [m/s^2] at period [s], {c} | {s:.3f} at {T:.3f} | | |")
    pc = np.abs(a[:, 1]).max(axis=0)
    print(f"| roof corner (14.4, 10.8, 9): peak absolute acceleration [m/s^2] | {pc[0]:.3f} | {pc[1]:.3f} | {pc[2]:.3f} |")
    i = int(np.argmax(np.abs(twist)))
    print(f"| roof twist about z from its corners [rad], peak and time | {twist[i]:.3g} at {t[i]:.3f} s | | |")
    print(f"| roof centre's own rotation about z [rad], peak | {np.abs(rot[:, 0, 2]).max():.3g} | | |")
    pd = dm["peak_drift_ratio"][()]
    for s_ in range(pd.shape[0]):
        print(f"| storey {s_ + 1}: peak drift ratio [m/m] (total, the rocking in it) | {pd[s_, 0]:.3g} | {pd[s_, 1]:.3g} | |")
    pb = dm["peak_base_shear"][()]
    print(f"| peak base shear [kN] | {pb[0] / 1e3:.4g} | {pb[1] / 1e3:.4g} | |")
    pr = dm["peak_base_rotation"][()]
    print(f"| foundation: peak rocking [rad] (about x, about y) | {pr[0]:.3g} | {pr[1]:.3g} | |")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    ax[0].plot(t, a[:, 0, 0], label="roof centre, x")
    ax[0].plot(t, a[:, 0, 1], label="roof centre, y")
    ax[0].set_ylabel("absolute acceleration [m/s^2]")
    ax[0].legend()
    ax[1].plot(t, twist * 1e3, label="roof twist about z (from two corners)")
    ax[1].set_ylabel("rotation about z [mrad]")
    ax[1].set_xlabel("t [s]")
    ax[1].legend()
    fig.suptitle("28.8 m x 21.6 m building, 72 m site, SV at 20 deg, azimuth 30 deg")
    fig.tight_layout()
    out = os.path.join(d, "site-oblique.png")
    fig.savefig(out, dpi=100)
    print(f"\nwrote {out}")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "out/seismic", int(sys.argv[2]) if len(sys.argv) > 2 else 2)
