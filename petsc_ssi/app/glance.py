"""``petsc-ssi post SSI.h5 --glance FIXED.h5``: what the soil changes, at a glance.

SSI.h5 is the soil output of a coupled run with an earthquake (-ssi_problem ssi -ssi_seismic
vertical; its structure output SSI_structure.h5 beside it, named by its attribute
``structure_output``), FIXED.h5 the output of its fixed-base twin (-ssi_problem fem with the same
record as the base's motion).  Prints a table (and writes --csv, --png) of, with and without the
soil: the identified first frequency and damping ratio, the period lengthening T_ssi / T_fixed,
the peak roof absolute acceleration and, where the structure outputs hold the group ``demands``,
the peak inter-storey drift ratio and base shear ("not recorded" otherwise).

Series (every acceleration [m/s^2] is the MEAN OVER THE STEP ENDING AT t_n, 0 at t = 0)
  SSI roof       SSI_structure.h5 receivers/acceleration of --receiver K (absolute: the
                 coupled structure moves in absolute coordinates), read by
                 app/response.py's load_h5.
  free field     the seismic group of SSI.h5: the processed record x_t, x_acceleration,
                 x_velocity (record time; run time = record time + t0) is, at vertical
                 incidence, the free-field surface motion at every surface point (twice it with
                 -ssi_seismic_control incident).  Its step mean (v(t_n) - v(t_{n-1})) / dt
                 is exact for the piecewise-linear record (records.Motion).  Vertical
                 incidence only: an oblique or Rayleigh wave's free field at the control point
                 is not stored per component (refused).
  fixed roof     FIXED.h5 receivers/absolute_acceleration (relative + ground), load_h5.
  ground         FIXED.h5 receivers/ground_acceleration (the same step mean).
  A step mean is the sample's box filter: the same linear filter on both series of a pair, so
  their ratio is unchanged.  The peak accelerations reported are those of these step means
  (a harmonic's amplitude times sin(pi f dt) / (pi f dt): 0.99 at f dt = 0.05).

Identification (each pair on its own time grid; dt may differ between the runs: said)
  H(f) = roof absolute / ground acceleration.
  1. Smoothed spectral ratio: the Konno-Ohmachi smoothed (b = --ko-b, default 40) amplitude
     spectra |FFT| of roof and ground (zero-padded to the power of 2 >= 2 n samples, no
     window), their ratio on 200 log-spaced frequencies from 2 / (n dt) to 0.25 / dt.  The
     search band is where the smoothed ground spectrum exceeds 1 % of its maximum (or
     --band F1,F2 Hz); f_peak is the ratio's largest value in it (reported and plotted).
     The smoothing widens a sharp peak (the b = 40 window's half-power width is about 11 %
     of f, a 2 % damped peak's 4 %), and a response still ringing at the record's end leaks
     (the ratio of finite DFTs is not H), so no damping is read off it.
  2. SDOF fit (the identified f0 and zeta): output-error least squares of an equivalent
     single-degree-of-freedom oscillator, the parametric model of flexible-base system
     identification (Stewart & Fenves 1998, EESD 27: 869-885):
         roof(t) = c0 g(t) + c1 a_abs(t; f0, zeta),
     a_abs the absolute acceleration of the oscillator on the ground motion g, integrated
     exactly for the piecewise-linear g from rest (seismic.response_spectrum.sdof_filter),
     c0, c1 linear (for an SDOF c0 = 0, c1 = 1; for a building c1 is about the roof's
     participation Gamma_1 phi_1 and c0 about 1 - c1).  Both series are first passed through
     the same causal Butterworth band-pass (order 4): a linear filter commutes with the
     oscillator, so the relation still holds, and the band keeps one mode (higher modes,
     drift out).  By Parseval this fits H(f) = c0 + c1 (1 + 2 i zeta r) / (1 - r^2 + 2 i
     zeta r), r = f / f0, to Y / X weighted by |F X|^2 in the band -- more robust than a
     half-power width on a noisy ratio, and exact for a finite record (no leakage: a
     response still ringing at the record's end is modelled, not truncated).  First a grid
     search (41 f0 log-spaced over the search band, zeta 0.005 .. 0.6) in the band-pass
     f1 / 2 .. 2 f2 of the search band finds the dominant mode f_s; then the band-pass
     f_s / 2 .. 2 f_s (capped at 0.9 x Nyquist), a grid over 0.6 .. 1.6 f_s and
     scipy.optimize.least_squares in (ln f0, zeta).  R^2 = 1 - |residual|^2 / |band-passed
     roof|^2 is printed (below 0.8: the SDOF model explains the band poorly; said).  The
     first mode must dominate the roof's response in the search band: else --band.
  T0 = 1 / f0; period lengthening = T0_ssi / T0_fixed.

Options
  --receiver K        the roof: receiver K of both files (default 0; points compared, said)
  --component C       x (default) | y | z
  --band F1,F2        where to look for the first peak [Hz] (default: see 1.)
  --ko-b B            Konno-Ohmachi bandwidth coefficient (default 40)
  --csv [OUT.csv]     the table: quantity, unit, with_ssi, fixed_base, ssi_over_fixed
                      ('nan': not recorded); standard output without a name
  --png OUT.png       |H(f)| of both (smoothed ratio, raw ratio faint, fitted SDOF dashed),
                      f_peak and f0 marked, log frequency axis
  --overwrite         replace an existing --csv/--png (never an input file)
Errors end with one line ``petsc-ssi post: error: ...`` on stderr and exit status 2.
"""
import argparse
import math
import os
import sys
from dataclasses import dataclass

import numpy as np

from . import post as _post
from . import response as _rsp
from . import twins as _twins
from ..seismic import response_spectrum as rs
from ..seismic.identify import KO_B, IdentificationError, fit_sdof, spectral_ratio

PROG = "petsc-ssi post"
COMPONENTS = ("x", "y", "z")
R2_WARN = 0.8


def _error(msg):
    return _post.PostError(" ".join(str(msg).split()))


# ---------------------------------------------------------------- input pairs

@dataclass(eq=False)
class Pair:
    """A roof's absolute acceleration y and its ground's g (n,) [m/s^2] at t (n,) [s], both
    step means; where they came from (``lines``)."""
    t: np.ndarray
    g: np.ndarray
    y: np.ndarray
    label: str
    roof: str
    ground: str
    point: tuple
    structure_path: str

    @property
    def dt(self):
        return float(np.mean(np.diff(self.t)))


def _attrs(path):
    import h5py
    if not os.path.exists(path):
        raise _error(f"{path}: no such file")
    if os.path.isdir(path) or not h5py.is_hdf5(path):
        raise _error(f"{path}: not an HDF5 output file")
    with h5py.File(path, "r") as f:
        return {k: (v.decode() if isinstance(v, bytes) else v) for k, v in f.attrs.items()}


def free_field(path, times, component):
    """(step means (n,) [m/s^2] of the free-field surface acceleration along ``component`` at the
    run times ``times`` (0 at the first), one line saying what it is) from the seismic group of
    the soil output ``path`` of a vertically incident wave."""
    import h5py
    from ..seismic.records import Motion
    with h5py.File(path, "r") as f:
        s = f["seismic"]
        pre = f"{component}_"
        if pre + "acceleration" not in s:
            have = sorted({k.split("_")[0] for k in s if k.endswith("_acceleration")})
            raise _error(f"{path}: no free-field {component} motion (the record drives "
                         f"{', '.join(have) or 'no component'}): choose --component "
                         f"{' or '.join(have) or 'x'}")
        tk, a, v = (np.asarray(s[pre + k][()], float) for k in ("t", "acceleration", "velocity"))
        t0 = float(s["t0"][()])
    control, said = _twins.control(path)
    factor = 2.0 if control == "incident" else 1.0
    m = Motion(tk, a, v, np.zeros_like(a), {}, {}, 0.0, 0.0, path, "", {}, {})
    t = np.asarray(times, float)
    vel = m(t - t0, 1)
    out = np.zeros_like(t)
    out[1:] = factor * np.diff(vel) / np.diff(t)
    return out, (f"free field: {path} seismic/{pre}acceleration (record time + t0 = {t0:.6g} s), "
                 f"-ssi_seismic_control {control} ({said})"
                 + (", surface = 2 x incident" if factor != 1 else "") + ", step mean [m/s^2]")


def _points_note(a, b):
    if a is None or b is None or np.allclose(a, b, atol=1e-9):
        return None
    return "note: the roof receivers differ: SSI at ({:g}, {:g}, {:g}) m, fixed base at ({:g}, {:g}, {:g}) m" \
        .format(*a, *b)


def load_ssi(path, receiver, component):
    """Pair of the coupled run whose soil output is ``path``: its structure receiver's
    acceleration and the free field at the control point."""
    at = _attrs(path)
    prob = at.get("problem")
    if prob == "ssi-structure":
        raise _error(f"{path}: a structure output; give the coupled run's soil output (the file "
                     f"without _structure), which holds the seismic input")
    if prob != "ssi":
        raise _error(f"{path}: not the soil output of a coupled run (problem '{prob}', not 'ssi')")
    kind = at.get("seismic", "none")
    import h5py
    with h5py.File(path, "r") as f:
        has = "seismic" in f
    if not has or kind in ("none", None):
        raise _error(f"{path}: a coupled run without an earthquake (no seismic group; -ssi_seismic)")
    if kind != "vertical":
        raise _error(f"{path}: -ssi_seismic {kind}: the glance needs the free field at the control point per "
                     f"component, stored for vertical incidence only")
    spath = os.path.join(os.path.dirname(os.path.abspath(path)),
                         str(at.get("structure_output", "")) or "?")
    if not at.get("structure_output") or not os.path.exists(spath):
        raise _error(f"{path}: its structure output {spath} is missing")
    roof = _rsp.load_h5(spath, receiver, (component,), "acceleration", arg="--receiver")
    if roof.dt is None:
        raise _error(f"{spath}: receivers/t is not uniform")
    g, gline = free_field(path, roof.t, component)
    return Pair(roof.t, g, roof.a[:, 0], "with SSI", roof.source, gline, roof.point, spath)


def load_fixed(path, receiver, component):
    """Pair of the fixed-base run ``path``: receivers/absolute_acceleration and
    receivers/ground_acceleration."""
    at = _attrs(path)
    import h5py
    with h5py.File(path, "r") as f:
        ok = "receivers/absolute_acceleration" in f and "receivers/ground_acceleration" in f
    if at.get("problem") != "fem" or not ok:
        raise _error(f"{path}: not a fixed-base run with a support motion (-ssi_problem fem -ssi_seismic vertical; "
                     f"problem '{at.get('problem')}'"
                     + ("" if ok else ", no receivers/absolute_acceleration") + ")")
    roof = _rsp.load_h5(path, receiver, (component,), "auto", arg="--receiver")
    if roof.dt is None:
        raise _error(f"{path}: receivers/t is not uniform")
    t, g, _, _ = _post.read_series(path, "receivers/ground_acceleration", 0, component)
    return Pair(roof.t, g[:, 0], roof.a[:, 0], "fixed base", roof.source,
                f"ground: {path} receivers/ground_acceleration, step mean [m/s^2]", roof.point, path)


# ---------------------------------------------------------------- demands

def demands(path, component):
    """{'drift': (value, storey) or None, 'shear': value or None, 'why': text}: the peaks of the
    group 'demands' of the structure output ``path`` along ``component`` (absolute values)."""
    import h5py
    out = {"drift": None, "shear": None, "why": ""}
    with h5py.File(path, "r") as f:
        d = f.get("demands")
        if not isinstance(d, h5py.Group):
            out["why"] = "not recorded"
            return out
        if component not in ("x", "y"):
            out["why"] = "not recorded (horizontal components only)"
            return out
        j = "xy".index(component)
        if "peak_drift_ratio" in d:
            pd_ = np.abs(np.asarray(d["peak_drift_ratio"][()], float)).reshape(-1, 2)[:, j]
        elif "drift_ratio" in d:
            pd_ = np.abs(np.asarray(d["drift_ratio"][()], float)).reshape(d["drift_ratio"].shape[0], -1, 2)[:, :, j].max(axis=0)
        else:
            pd_ = None
        if pd_ is not None and pd_.size:
            k = int(np.argmax(pd_))
            out["drift"] = (float(pd_[k]), k + 1)
        if "peak_base_shear" in d:
            out["shear"] = float(np.abs(np.asarray(d["peak_base_shear"][()], float).reshape(-1)[j]))
        elif "base_shear" in d:
            out["shear"] = float(np.abs(np.asarray(d["base_shear"][()], float)[:, j]).max())
        out["why"] = "not recorded"
    return out


def given_damping(path, f0):
    """The damping ratio the structure of ``path`` was given at the frequency f0 [Hz]: C = alpha_m M +
    rayleigh_a1 K (file attributes; issue 43), zeta = alpha_m/(2 w) + rayleigh_a1 w/2, plus, with modal
    damping (attributes modal_damping_frequencies_hz, modal_damping_ratios), the ratio of the damped
    mode nearest f0 (a structure on soil vibrates below its fixed-base frequency: its first mode's ratio
    is the one given to it); None when the file does not record it."""
    at = _attrs(path)
    if "alpha_m" not in at:
        return None
    a0, a1 = float(at["alpha_m"]), float(at.get("rayleigh_a1", 0.0))
    w = 2 * math.pi * f0
    z = a0 / (2 * w) + a1 * w / 2
    fm = np.atleast_1d(np.asarray(at.get("modal_damping_frequencies_hz", []), float))
    if fm.size:
        z += float(np.atleast_1d(np.asarray(at["modal_damping_ratios"], float))[np.argmin(np.abs(fm - f0))])
    return z


# ---------------------------------------------------------------- report

def analyse(pair, b=KO_B, band=None):
    if pair.t.size < 16:
        raise _error(f"{pair.label}: {pair.t.size} samples: too few to identify a frequency")
    if not np.any(pair.g):
        raise _error(f"{pair.label}: the ground acceleration is zero ({pair.ground})")
    try:
        ratio = spectral_ratio(pair.t, pair.g, pair.y, b, band)
        return ratio, fit_sdof(pair.t, pair.g, pair.y, ratio.band)
    except IdentificationError as exc:
        raise _error(str(exc)) from None


def table(S, F):
    """[(quantity, unit, ssi, fixed, ratio or None)] of the two analysed pairs (dicts)."""
    def row(q, u, a, b, ratio=True):
        r = a / b if (ratio and a is not None and b is not None and b != 0) else None
        return (q, u, a, b, r)
    zs, zf = S["fit"].zeta, F["fit"].zeta
    rows = [row("first frequency f0 (SDOF fit)", "Hz", S["fit"].f0, F["fit"].f0),
            # (a damping ratio under UNDAMPED is the fit's round-off of an undamped structure: no ratio)
            row("damping ratio zeta (SDOF fit)", "-", zs, zf, ratio=zf >= UNDAMPED),
            # what the structure was given (C = alpha_m M + a1 K of its output's attributes) at the identified f0:
            # the fixed base's identified zeta should equal it; with SSI the soil's radiation adds to it
            row("damping ratio given to the structure at that f0 (Rayleigh, + modal: the nearest damped mode's)", "-",
                given_damping(S["pair"].structure_path, S["fit"].f0),
                given_damping(F["pair"].structure_path, F["fit"].f0), ratio=False),
            row("period T0 = 1/f0 (ratio: period lengthening)", "s", 1 / S["fit"].f0, 1 / F["fit"].f0),
            row(f"peak of the smoothed spectral ratio (Konno-Ohmachi b = {S['b']:g}) at", "Hz",
                S["ratio"].f_peak, F["ratio"].f_peak),
            row("peak value of the smoothed spectral ratio", "-", S["ratio"].h_peak, F["ratio"].h_peak),
            row("roof participation c1 (SDOF fit)", "-", S["fit"].c1, F["fit"].c1, ratio=False),
            row("fit R^2 in the band", "-", S["fit"].r2, F["fit"].r2, ratio=False),
            row("peak roof absolute acceleration", "m/s^2", float(np.abs(S["pair"].y).max()),
                float(np.abs(F["pair"].y).max())),
            row("peak ground acceleration (free field / base)", "m/s^2", float(np.abs(S["pair"].g).max()),
                float(np.abs(F["pair"].g).max()))]
    ds, df = S["demands"], F["demands"]
    rows.append(row("peak inter-storey drift ratio", "-", ds["drift"] and ds["drift"][0],
                    df["drift"] and df["drift"][0]))
    rows.append(row("peak base shear", "N", ds["shear"], df["shear"]))
    return rows


# The spectral ratio's peak is read on the DFT's grid, 1/T apart: beyond 5 % of f0 the glance says so (an
# engineer's 2 s run put the peak 20 % off the SDOF fit's f0 without a word).
RESOLUTION_WARN = 0.05
UNDAMPED = 1e-6        # an identified damping ratio below this is shown as such (the fit's floor of an undamped run)


def _fmt(v, q=""):
    if v is None:
        return "not recorded"
    if q.startswith("damping ratio") and 0 <= v < UNDAMPED:
        return f"< {UNDAMPED:g} (undamped)"
    return f"{v:.4g}"


def text_table(rows, S, F):
    out = ["| quantity | unit | with SSI | fixed base | SSI / fixed |", "|---|---|---|---|---|"]
    for q, u, a, b, r in rows:
        if q == "peak inter-storey drift ratio":
            a_s = _fmt(a) + (f" (storey {S['demands']['drift'][1]})" if a is not None else "")
            b_s = _fmt(b) + (f" (storey {F['demands']['drift'][1]})" if b is not None else "")
        else:
            a_s, b_s = _fmt(a, q), _fmt(b, q)
        out.append(f"| {q} | {u} | {a_s} | {b_s} | {'' if r is None else f'{r:.4g}'} |")
    return out


def write_csv(fh, rows, header):
    fh.write("".join(f"# {ln}\n" for ln in header))
    fh.write("quantity,unit,with_ssi,fixed_base,ssi_over_fixed\n")
    for q, u, a, b, r in rows:
        fh.write(",".join([f'"{q}"', u] + [repr(float("nan") if v is None else float(v)) for v in (a, b, r)]) + "\n")


def plot_png(path, S, F, title=""):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    fig = Figure(figsize=(8, 5))
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    top = 0.0
    for X, col in ((S, "C3"), (F, "C0")):
        ra, fit, lab = X["ratio"], X["fit"], X["pair"].label
        inb = (ra.f >= ra.band[0]) & (ra.f <= ra.band[1])
        keep = (ra.f_raw >= ra.band[0]) & (ra.f_raw <= ra.band[1])
        ax.plot(ra.f_raw[keep], ra.raw[keep], color=col, lw=0.5, alpha=0.25)
        ax.plot(ra.f[inb], ra.smooth[inb], color=col, lw=1.6,
                label=f"{lab}: smoothed |H| (Konno-Ohmachi b = {X['b']:g})")
        ax.plot(ra.f[inb], fit.h(ra.f[inb]), color=col, lw=1.2, ls="--",
                label=f"{lab}: SDOF fit f0 = {fit.f0:.3g} Hz, zeta = {fit.zeta:.3g}")
        ax.plot([ra.f_peak], [ra.h_peak], "v", color=col, ms=8)
        ax.plot([fit.f0], [fit.h(fit.f0)], "o", color=col, mfc="none", ms=9)
        ax.axvline(fit.f0, color=col, lw=0.7, ls=":")
        top = max(top, np.nanmax(ra.smooth[inb]), float(fit.h(fit.f0)))
    ax.set_xscale("log")
    ax.set_xlabel("frequency f [Hz]")
    ax.set_ylabel("|H(f)| = roof absolute / ground acceleration [-]")
    ax.set_ylim(0, 1.3 * top)
    ax.set_title(title + "\n(faint: raw |Y/X|; triangle: smoothed peak; circle: fitted f0; where the ground spectrum > 1 % of its max)", fontsize=8)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    return path


# ---------------------------------------------------------------- command line

class _Parser(argparse.ArgumentParser):
    def error(self, message):
        raise _error(message)


def _band_arg(text):
    try:
        f1, f2 = (float(v) for v in str(text).split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: give F1,F2 in Hz") from None
    if not (np.isfinite(f1) and np.isfinite(f2) and 0 < f1 < f2):
        raise argparse.ArgumentTypeError(f"{text!r}: needs 0 < F1 < F2 (Hz)")
    return f1, f2


def _positive(text):
    try:
        v = float(text)
    except ValueError:
        v = -1.0
    if not (np.isfinite(v) and v > 0):
        raise argparse.ArgumentTypeError(f"{text!r}: a positive number")
    return v


def _parser():
    ap = _Parser(prog=PROG, description=__doc__.splitlines()[0],
                 formatter_class=argparse.RawDescriptionHelpFormatter,
                 epilog="\n".join(__doc__.splitlines()[2:]))
    ap.add_argument("file", nargs="?", metavar="SSI.h5")
    ap.add_argument("--glance", nargs="?", default=None, metavar="FIXED.h5")
    ap.add_argument("--receiver", type=int, default=0, metavar="K")
    ap.add_argument("--component", choices=COMPONENTS, default="x")
    ap.add_argument("--band", type=_band_arg, default=None, metavar="F1,F2")
    ap.add_argument("--ko-b", type=_positive, default=KO_B, metavar="B")
    ap.add_argument("--csv", nargs="?", const="-", default=None, metavar="OUT.csv")
    ap.add_argument("--png", metavar="OUT.png")
    ap.add_argument("--overwrite", action="store_true")
    return ap


def main(argv=None, out=None):
    """``petsc-ssi post SSI.h5 --glance FIXED.h5 ...`` (argv: the arguments after ``post``): 0, or
    2 after one error line on stderr."""
    out = sys.stdout if out is None else out
    try:
        try:
            a = _parser().parse_args(argv)
        except SystemExit as exc:                 # --help
            return exc.code if isinstance(exc.code, int) else 0
        if not a.file or not a.glance:
            raise _error("give the coupled run's soil output and its fixed-base twin: SSI.h5 --glance FIXED.h5")
        inputs = [a.file, a.glance]
        at = _attrs(a.file) if os.path.exists(a.file) else {}
        if at.get("structure_output"):
            inputs.append(os.path.join(os.path.dirname(os.path.abspath(a.file)), str(at["structure_output"])))
        _post.check_outputs([("--csv", a.csv), ("--png", a.png)], inputs, a.overwrite)  # never an input,
        # its sidecars or an HDF5 result; an existing CSV/PNG only with --overwrite
        if _post._same_file(a.file, a.glance):
            raise _error(f"--glance {a.glance}: the same file as SSI.h5")
        ps = load_ssi(a.file, a.receiver, a.component)
        pf = load_fixed(a.glance, a.receiver, a.component)
        _twins.same_control(a.file, a.glance, _error)
        _twins.same_record(a.file, a.glance, _error)
        S, F = ({"pair": p, "b": a.ko_b} for p in (ps, pf))
        for X in (S, F):
            X["ratio"], X["fit"] = analyse(X["pair"], a.ko_b, a.band)
            X["demands"] = demands(X["pair"].structure_path, a.component)
        rows = table(S, F)
        header = _header(S, F, a)
        body = text_table(rows, S, F)
        if a.csv == "-":
            write_csv(out, rows, header)
        else:
            out.write("".join(ln + "\n" for ln in header + body))
            if a.csv:
                with open(a.csv, "w", newline="") as fh:
                    write_csv(fh, rows, header)
                out.write(f"wrote {a.csv}\n")
        if a.png:
            plot_png(a.png, S, F, f"{os.path.basename(a.file)} (with SSI) vs {os.path.basename(a.glance)} "
                     f"(fixed base), receiver {a.receiver}, {a.component}")
            if a.csv != "-":
                out.write(f"wrote {a.png}\n")
    except BrokenPipeError:             # the reader stopped ('post ... | head'): cli._post
        raise
    except (OSError, _post.PostError, rs.SpectrumInputError) as exc:
        print(f"{PROG}: error: {' '.join(str(exc).split())}", file=sys.stderr)
        return 2
    return 0


def _header(S, F, a):
    ps, pf = S["pair"], F["pair"]
    lines = [f"petsc-ssi post --glance: what the soil changes; roof = receiver {a.receiver}, component "
             f"{a.component}; H = roof absolute / ground acceleration"]
    for X in (S, F):
        p, r, fit = X["pair"], X["ratio"], X["fit"]
        where = "" if p.point is None else " at ({:g}, {:g}, {:g}) m".format(*p.point)
        lines += [f"{p.label}: roof{where}: {p.roof}",
                  f"{p.label}: {p.ground}",
                  f"{p.label}: dt {p.dt:.6g} s, {p.t.size} samples, t {p.t[0]:.6g} .. {p.t[-1]:.6g} s; "
                  f"peak looked for in {r.band[0]:.4g} .. {r.band[1]:.4g} Hz; SDOF fit in the band-pass "
                  f"{fit.band[0]:.4g} .. {fit.band[1]:.4g} Hz (Butterworth 4, causal, both series), "
                  f"R^2 {fit.r2:.3f}, c0 {fit.c0:.3g}, c1 {fit.c1:.3g}"]
        if fit.r2 < R2_WARN:
            lines.append(f"{p.label}: warning: the SDOF model explains only {100 * fit.r2:.0f} % of the "
                         f"band-passed roof acceleration: f0 and zeta are uncertain (try --band)")
    if not math.isclose(ps.dt, pf.dt, rel_tol=1e-9):
        lines.append(f"note: the time steps differ (SSI {ps.dt:.6g} s, fixed base {pf.dt:.6g} s): each pair is "
                     f"identified on its own grid")
    note = _points_note(ps.point, pf.point)
    if note:
        lines.append(note)
    for X in (S, F):
        p, fit = X["pair"], X["fit"]
        df = 1.0 / (p.t.size * p.dt)
        if df > RESOLUTION_WARN * fit.f0:
            lines.append(f"{p.label}: warning: the series is {p.t.size * p.dt:.3g} s long, so its spectra resolve "
                         f"frequencies 1/T = {df:.3g} Hz apart (zero padding interpolates, it does not resolve), "
                         f"{100 * df / fit.f0:.0f} % of f0 = {fit.f0:.3g} Hz: the spectral ratio's peak is uncertain "
                         "at that scale (the SDOF fit, in time, is not bound to it); a longer run resolves it")
    if S["demands"]["shear"] is not None or F["demands"]["shear"] is not None:
        lines.append(_post.BASE_SHEAR_NOTE)
        for X in (S, F):
            if X["pair"].structure_path and os.path.exists(X["pair"].structure_path):
                lines.append(f"{X['pair'].label}: " + _post.modelled_part_note(_attrs(X["pair"].structure_path)))
    if S["demands"]["drift"] is not None or F["demands"]["drift"] is not None:
        lines.append("drift: with SSI the storeys' total drift (the foundation's rocking included), on the fixed "
                     "base their deformation drift (group demands of each structure output)")
    lines.append("identification: f_peak = the largest value of the ratio of Konno-Ohmachi smoothed amplitude "
                 f"spectra (b = {a.ko_b:g}); f0, zeta = output-error least-squares fit of an SDOF "
                 "oscillator's absolute acceleration, c0 g + c1 a_abs(f0, zeta), to the band-passed roof "
                 "(petsc-ssi post --glance --help)")
    return lines
