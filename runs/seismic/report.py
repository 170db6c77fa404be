"""Tables and figures of runs/seismic (the demo's building under the K-NET record) from the files
run.sh wrote: cost per rank count from -log_view/-memory_view, the engineering summary (peak
roof acceleration with and without SSI, the period of the spectral peak, the free field's PGA),
and a PNG of the roof's absolute acceleration with SSI and on a fixed base beside the free field.

    python runs/seismic/report.py out/seismic      (prints the README tables, writes roof.png)

The PNGs go into the run's directory (out/seismic/roof.png, oblique.png), never over the ones kept
in the repository beside this script (copy them there to refresh the README's figures).
"""
import csv
import glob
import os
import sys

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "jobscripts"))
from logview import parse  # noqa: E402


def cost_rows(d):
    rows = []
    for path in sorted(glob.glob(os.path.join(d, "*-n*.log_view"))):
        case, ranks = os.path.basename(path)[:-9].rsplit("-n", 1)
        text = open(path).read()
        log = path[:-len(".log_view")] + ".log"                 # -memory_view prints to standard output
        if os.path.exists(log):
            text += "\n" + open(log).read()
        lv = parse(text)
        st = lv["stages"]
        rows.append({"case": case, "ranks": int(ranks), "wall [s]": lv["total_s"],
                     "set-up + assembly [s]": sum(v for k, v in st.items() if "setup" in k.lower() or "assembly" in k.lower()),
                     "time loop [s]": sum(v for k, v in st.items() if "time loop" in k.lower()),
                     "peak memory, all ranks [GB]": (lv["peak_rss_bytes"] or np.nan) / 1e9})
    return rows


def series(path, key):
    with h5py.File(path, "r") as f:
        return f["receivers/t"][()], f[f"receivers/{key}"][()]


def spectrum_peak(path):
    rows = [r for r in csv.reader(open(path)) if r and not r[0].startswith("#")]
    head, data = rows[0], np.array(rows[1:], float)
    k = head.index("PSA [m/s^2]")
    i = int(np.argmax(data[:, k]))
    return data[i, 0], data[i, k]


def main(d):
    rows = cost_rows(d)
    print("| case | ranks | wall [s] | set-up + assembly [s] | time loop [s] | peak memory, all ranks [GB] |")
    print("|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['case']} | {r['ranks']} | {r['wall [s]']:.1f} | {r['set-up + assembly [s]']:.1f} | "
              f"{r['time loop [s]']:.1f} | {r['peak memory, all ranks [GB]']:.2f} |")
    ts, a_ssi = series(os.path.join(d, "building_structure.h5"), "acceleration")
    tf, a_fix = series(os.path.join(d, "fixed-base.h5"), "absolute_acceleration")
    tg, u_ff = series(os.path.join(d, "building.h5"), "u")
    with h5py.File(os.path.join(d, "building.h5"), "r") as f:
        pga = float(f["seismic/x_pga"][()])
    print()
    print("| quantity (roof, x) | with SSI | fixed base | ratio |")
    print("|---|---|---|---|")
    pa, pf = np.abs(a_ssi[:, 0, 0]).max(), np.abs(a_fix[:, 0, 0]).max()
    print(f"| peak absolute acceleration [m/s^2] | {pa:.3f} | {pf:.3f} | {pa / pf:.3f} |")
    for name, path in (("with SSI", "roof-ssi.csv"), ("fixed base", "roof-fixed.csv")):
        if os.path.exists(os.path.join(d, path)):
            T, s = spectrum_peak(os.path.join(d, path))
            print(f"| PSA peak ({name}) [m/s^2] at T [s] | {s:.3f} at {T:.3f} | | |")
    print(f"\nfree-field PGA (processed record) {pga:.3f} m/s^2")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(8, 4))
    ax.plot(tf, a_fix[:, 0, 0], label="roof, fixed base (absolute)")
    ax.plot(ts, a_ssi[:, 0, 0], label="roof, with SSI")
    dt = tg[1] - tg[0]
    a_g = np.gradient(np.gradient(u_ff[:, 0, 0], dt), dt)
    ax.plot(tg, a_g, lw=0.8, color="0.4", label="free field (soil receiver 0, from u)")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("acceleration along x [m/s^2]")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "roof.png"), dpi=120)
    print(f"wrote {os.path.join(d, 'roof.png')}")


def _accel(t, u):
    """The acceleration of a displacement series by second differences (m/s^2)."""
    dt = t[1] - t[0]
    return np.gradient(np.gradient(u, dt, axis=0), dt, axis=0)


def oblique(d):
    """Vertical and oblique incidence side by side (building.h5 and building-oblique.h5): the soil
    (soil receiver 0, 6 m from the centre on x: the total field, free + scattered), the foundation
    (structure receiver 2, the slab's centre) and the roof (structure receiver 0): peak accelerations
    along x and z, and the foundation's peak rocking (rotation about y); oblique.png: their time
    histories."""
    cases = [("vertical S", "building"), ("SV at 20 deg", "building-oblique")]
    if not all(os.path.exists(os.path.join(d, f"{c}.h5")) for _, c in cases):
        return
    print()
    print("| quantity | vertical S | SV at 20 deg |")
    print("|---|---|---|")
    data = {}
    for name, c in cases:
        tg, ug = series(os.path.join(d, f"{c}.h5"), "u")
        ts, a = series(os.path.join(d, f"{c}_structure.h5"), "acceleration")
        with h5py.File(os.path.join(d, f"{c}_structure.h5"), "r") as f:
            rot = f["receivers/rotation"][()]
        data[name] = (tg, _accel(tg, ug[:, 0]), ts, a, rot)
    rows = [("soil at (6, 0, 0), total field: peak a_x [m/s^2]", lambda v: np.abs(v[1][:, 0]).max()),
            ("soil at (6, 0, 0), total field: peak a_z [m/s^2]", lambda v: np.abs(v[1][:, 2]).max()),
            ("foundation centre: peak a_x [m/s^2]", lambda v: np.abs(v[3][:, 2, 0]).max()),
            ("foundation centre: peak a_z [m/s^2]", lambda v: np.abs(v[3][:, 2, 2]).max()),
            ("foundation: peak rocking, rotation about y [rad]", lambda v: np.abs(v[4][:, 2, 1]).max()),
            ("roof centre: peak a_x [m/s^2]", lambda v: np.abs(v[3][:, 0, 0]).max())]
    for label, f in rows:
        print(f"| {label} | {f(data[cases[0][0]]):.4g} | {f(data[cases[1][0]]):.4g} |")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axs = plt.subplots(3, 1, figsize=(8, 7), sharex=True)
    for name, _ in cases:
        tg, ag, ts, a, rot = data[name]
        axs[0].plot(tg, ag[:, 0], lw=0.8, label=f"{name}: a_x")
        axs[0].plot(tg, ag[:, 2], lw=0.8, label=f"{name}: a_z")
        axs[1].plot(ts, a[:, 2, 0], lw=0.8, label=f"{name}: a_x")
        axs[1].plot(ts, a[:, 2, 2], lw=0.8, label=f"{name}: a_z")
        axs[2].plot(ts, a[:, 0, 0], lw=0.8, label=f"{name}: a_x")
    for ax, title in zip(axs, ("soil receiver (6, 0, 0): total field (free field + scattered)",
                               "foundation centre (0, 0, 0)", "roof centre (0, 0, 6)")):
        ax.set_title(title, fontsize=9)
        ax.set_ylabel("acceleration [m/s^2]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, ncol=2)
    axs[-1].set_xlabel("t [s]")
    fig.tight_layout()
    fig.savefig(os.path.join(d, "oblique.png"), dpi=120)
    print(f"wrote {os.path.join(d, 'oblique.png')}")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "out/seismic")
    oblique(sys.argv[1] if len(sys.argv) > 1 else "out/seismic")
