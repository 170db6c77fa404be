"""An open trench between a vertical surface source and a line of receivers (issue 42, item 5): the
amplitude reduction factor behind it against the trench's depth over the Rayleigh wavelength.

Set-up (``Layout``; SI units; the soil of the paper: c_p 548 m/s, c_s 316 m/s, rho 2000 kg/m^3,
nu = 0.25, so c_R = 0.9194 c_s = 290.6 m/s):
  * the source: a vertical pressure p0 = 1 kPa on a 1 m x 2 m patch of the ground (``-ssi_load_group
    box:...``) with the history of a tone burst, ``cycles`` periods of sin(2 pi f0 t) under a Hann
    window (a table, ``-ssi_load_history table``); f0 = c_R / lambda_R for the chosen Rayleigh
    wavelength lambda_R (4 m: 72.6 Hz; the burst's spectrum is within 6 dB of its peak from about
    0.7 f0 to 1.3 f0);
  * the trench: ``-ssi_mesh pit -ssi_mesh_params a=,b=,d=,x=`` (``mesh/surface.pit``: a long narrow
    excavation off the centre, open: its walls and bottom are free surfaces of the soil), of width
    2a, length 2b across the line source -> receivers, depth d; its edges lie on the flat grid's lines
    so the ground's elements are those of the run without the trench;
  * the receivers: on the ground behind the trench, a grid x in ``rx``, y in ``ry`` (y >= 0; the
    set-up is symmetric about y = 0);
  * the amplitude reduction factor (Woods 1968): at each receiver ARF = max_t |u_z| with the trench
    over max_t |u_z| without it (the same ground mesh, dt and source); ``arf`` gives the mean over the
    receivers, and the least and largest.

The reference trend: Woods's field tests (1968) found an open trench screens well (ARF <= 0.25) when
it is deep: d / lambda_R >= 0.6 around the source (active isolation), about 1.33 for a trench away
from the source (passive isolation); Segol, Lee & Abel (1978, J. Eng. Mech. Div. ASCE, 2D FE)
report that the screening is mainly a function of d / lambda_R and significant beyond 0.6. The
papers' curves were not available to this script (runs/trench/README.md says what is compared).

``python runs/trench/trench.py [OUT.csv] [d,d,...]`` (depths in m) runs the sweep on ``SWEEP``, writes
the CSV (units in the headers), OUT.png (ARF against d / lambda_R) and prints the table as Markdown;
``python runs/trench/trench.py --checks`` prints how the mean ARF moves with h, dt and the ground's extent."""
import csv
import os
import subprocess
import sys

import numpy as np

from petsc_ssi.launch import child_env

SOIL = dict(cp=548.0, cs=316.0, rho=2000.0)
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def rayleigh_speed():
    from petsc_ssi.analytic.free_field import rayleigh_speed as cr
    return cr(SOIL["cs"], SOIL["cp"])


class Layout:
    """The geometry [m], the source's wavelength lambda_R [m] and the time grid [s] of one study."""

    def __init__(self, L, h, lam, src, trench_x, width, length, rx, ry, dt, t_end, cycles=3):
        self.L, self.h, self.lam, self.src = L, h, lam, src
        self.trench_x, self.width, self.length = trench_x, width, length
        self.rx, self.ry, self.dt, self.t_end, self.cycles = rx, ry, dt, t_end, cycles

    @property
    def f0(self):
        """The burst's frequency [Hz]: c_R / lambda_R."""
        return rayleigh_speed() / self.lam

    def receivers(self):
        """(n, 3) receiver points [m] on the ground behind the trench."""
        return np.array([(x, y, 0.0) for x in self.rx for y in self.ry])

    def options(self, depth):
        """The run's -ssi_ options (without output): the flat grid for depth None, else the trench."""
        x0, x1 = self.src
        opts = dict(problem="bem", mesh_size=f"{self.L[0]},{self.L[1]}", mesh_h=self.h, dt=self.dt,
                    t_end=self.t_end, load_group=f"box:{x0},{x1},-1,1", load_p0=1000, load_history="table",
                    receivers=";".join(f"{x:g},{y:g},{z:g}" for x, y, z in self.receivers()),
                    output_stride=0, output_overwrite=1, warn_beta=0, scheme="plain", **SOIL)
        if depth is not None:
            opts.update(mesh="pit", mesh_params=f"a={self.width / 2:g},b={self.length / 2:g},d={depth:g},"
                                                f"x={self.trench_x:g}")
        return opts


# the sweep (runs/trench/README.md): a 20 m x 12 m ground of 1 m elements (8 node spacings a wavelength),
# the source's patch centred 5 m (1.25 lambda_R) before the trench's front wall, a trench 1 m wide
# (0.25 lambda_R) and 8 m long (2 lambda_R); receivers from 1 m to 7 m behind it (0.25 to 1.75 lambda_R),
# y = 0, 1, 2 m; dt = 1.2 ms (beta = c_s dt / (h/2) = 0.76, 11.5 steps a period)
SWEEP = Layout(L=(20, 12), h=1.0, lam=4.0, src=(-7, -6), trench_x=-1.5, width=1.0, length=8.0,
               rx=(0, 1, 2, 3, 4, 5, 6), ry=(0, 1, 2), dt=0.0012, t_end=0.1)
# the default tier's small twin: a 14 m x 8 m ground, the trench 6 m long, receivers 1 m to 4 m behind it
SMALL = Layout(L=(14, 8), h=1.0, lam=4.0, src=(-5, -4), trench_x=-2.5, width=1.0, length=6.0,
               rx=(-1, 0, 1, 2), ry=(0, 1), dt=0.0012, t_end=0.075)


def burst(path, f0, cycles):
    """Write the tone burst sin(2 pi f0 t) sin^2(pi t / T), T = cycles / f0, as a 't h' table [s, -]."""
    T = cycles / f0
    t = np.linspace(0.0, T, 40 * cycles + 1)
    np.savetxt(path, np.c_[t, np.sin(2 * np.pi * f0 * t) * np.sin(np.pi * t / T) ** 2], header="t [s]  h [-]")


def run(lay, depth, out):
    """One BEM run (``python -m petsc_ssi`` in a child process: repeated runs in one process kept
    about 1.7 GB each of this size resident): (t [s] (steps,), u [m] (steps, receivers, 3)) at the
    receivers."""
    import h5py
    out = os.path.abspath(out)
    table = out + ".burst.txt"
    burst(table, lay.f0, lay.cycles)
    opts = dict(lay.options(depth), output=out, load_table=table)
    args = [a for k, v in opts.items() for a in ("-ssi_" + k, str(v))]
    env = child_env(PYTHONPATH=ROOT, OPENBLAS_NUM_THREADS="1")
    p = subprocess.run([sys.executable, "-m", "petsc_ssi"] + args, cwd=ROOT, env=env, capture_output=True, text=True)
    os.remove(table)
    if p.returncode:
        raise RuntimeError(f"petsc-ssi {' '.join(args)} failed:\n{p.stdout[-2000:]}{p.stderr[-2000:]}")
    with h5py.File(out) as f:
        return f["receivers/t"][:], f["receivers/u"][:]


def peaks(u):
    """max_t |u_z| [m] per receiver."""
    return np.abs(u[:, :, 2]).max(0)


def apparent_speed(lay, t, u):
    """The speed [m/s] of the peak of |u_z| along the receivers' line y = 0 (least squares of arrival
    time against x): the flat run's check that the wave behind the trench is the Rayleigh wave."""
    pts = lay.receivers()
    on = pts[:, 1] == 0
    a = np.abs(u[:, on, 2])
    k = np.clip(a.argmax(0), 1, len(t) - 2)
    j = np.arange(a.shape[1])
    y0, y1, y2 = a[k - 1, j], a[k, j], a[k + 1, j]
    ta = t[k] + 0.5 * (y0 - y2) / (y0 - 2 * y1 + y2) * (t[1] - t[0])     # the parabola's vertex
    return 1.0 / np.polyfit(pts[on, 0], ta, 1)[0]


def arf(lay, depths, out):
    """Rows (d [m], d / lambda_R, mean ARF, least ARF, largest ARF) for each trench depth, and the
    flat run's (t, u) and apparent speed."""
    t, flat = run(lay, None, out)
    ref = peaks(flat)
    rows = []
    for d in depths:
        r = peaks(run(lay, d, out)[1]) / ref
        rows.append((d, d / lay.lam, float(r.mean()), float(r.min()), float(r.max())))
    return rows, (t, flat, apparent_speed(lay, t, flat))


HEAD = ("d [m]", "d/lambda_R [-]", "ARF mean [-]", "ARF min [-]", "ARF max [-]")


def plot(rows, png, lay):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    r = np.array(rows)
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    ax.fill_between(r[:, 1], r[:, 3], r[:, 4], alpha=0.2, color="C0", label="BEM: least to largest over the receivers")
    ax.plot(r[:, 1], r[:, 2], "o-", color="C0", label="BEM: mean over the receivers (petsc_ssi)")
    ax.fill_betweenx([0.25, 0.5], 0.6, 1.0, color="C1", alpha=0.25,
                     label="band commonly quoted from Woods (1968): ARF 0.25-0.5 at d/lambda_R 0.6-1 "
                           "(not read from the paper)")
    ax.plot([0.6], [0.25], "s", color="C1",
            label="Woods's criterion as cited: ARF <= 0.25 from d/lambda_R = 0.6 (active isolation)")
    ax.plot([1.33], [0.25], "D", color="C3",
            label="Woods's criterion as cited: ARF <= 0.25 from d/lambda_R = 1.33 (passive isolation)")
    ax.axhline(1.0, color="k", lw=0.5)
    ax.set_xlabel("trench depth / Rayleigh wavelength d/lambda_R [-]")
    ax.set_ylabel("amplitude reduction factor ARF [-]")
    ax.set_title(f"open trench {lay.width:g} m x {lay.length:g} m, lambda_R = {lay.lam:g} m, f0 = {lay.f0:.1f} Hz",
                 fontsize=9)
    ax.set_xlim(0, 1.45)
    ax.set_ylim(0, 1.1)
    ax.legend(fontsize=7, loc="upper right")
    fig.tight_layout()
    fig.savefig(png, dpi=120)
    plt.close(fig)


def variant(lay, **changes):
    """A copy of ``lay`` with some fields changed."""
    import copy
    new = copy.copy(lay)
    new.__dict__.update(changes)
    return new


def checks(out):
    """What the sweep's numbers depend on, each a pair of mean ARFs: the element size (SMALL, d = 1 m,
    h = 1 and 0.5 m), the time step (SMALL, d = 1 m, dt = 1.2 and 0.8 ms) and the ground's extent (SWEEP,
    d = 2 m, 20 m x 12 m and 28 m x 16 m, the receivers and trench where they were)."""
    rows = []
    for what, a, b, d in (("h [m]", SMALL, variant(SMALL, h=0.5), 1.0),
                          ("dt [s]", SMALL, variant(SMALL, dt=0.0008), 1.0),
                          ("ground [m]", SWEEP, variant(SWEEP, L=(28, 16)), 2.0)):
        ra, rb = arf(a, (d,), out)[0][0], arf(b, (d,), out)[0][0]
        va, vb = {"h [m]": (a.h, b.h), "dt [s]": (a.dt, b.dt), "ground [m]": (a.L, b.L)}[what]
        rows.append((what, d, va, ra[2], vb, rb[2]))
        print(f"| {what} | {d:g} | {va} | {ra[2]:.3f} | {vb} | {rb[2]:.3f} | {rb[2] / ra[2] - 1:+.1%} |", flush=True)
    return rows


def main(argv):
    if len(argv) > 1 and argv[1] == "--checks":
        print("| varied | d [m] | value a | ARF mean a [-] | value b | ARF mean b [-] | b/a - 1 |")
        print("|---|---|---|---|---|---|---|")
        return checks("trench-checks.h5")
    out = argv[1] if len(argv) > 1 else "trench.csv"
    depths = [float(v) for v in (argv[2] if len(argv) > 2 else "0.5,1,1.5,2,3,4").split(",")]
    rows, (_, _, c) = arf(SWEEP, depths, out + ".h5")
    os.remove(out + ".h5")
    with open(out, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(HEAD)
        w.writerows(rows)
    plot(rows, os.path.splitext(out)[0] + ".png", SWEEP)
    print(f"flat run: the peak travels at {c:.1f} m/s behind the trench's place (c_R = {rayleigh_speed():.1f} m/s)")
    print("| " + " | ".join(HEAD) + " |")
    print("|" + "---|" * len(HEAD))
    for r in rows:
        print(f"| {r[0]:g} | {r[1]:.3g} | {r[2]:.3f} | {r[3]:.3f} | {r[4]:.3f} |")
    return rows


if __name__ == "__main__":
    main(sys.argv)
