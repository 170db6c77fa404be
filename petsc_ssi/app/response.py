"""``petsc-ssi post FILE.h5 --response-spectrum [options]``: elastic response spectra of a receiver.

The numerics are petsc_ssi.seismic.response_spectrum (exact piecewise-linear integration of
the SDOF oscillator, Nigam & Jennings; RotDnn after Boore 2010).  This module only picks the
acceleration series, checks the arguments and writes the results.

Input: an output file FILE.h5 of a run, or a table (--table FILE)
  Structure outputs (OUT_structure.h5): receivers/t (K,) [s] from t = 0 and, per receiver,
    receivers/u [m], velocity [m/s] and acceleration [m/s^2], each (K, R, 3).
    ``acceleration`` at t_n is the mean acceleration over the step ending there,
    (v_n - v_{n-1}) / dt, 0 at t = 0 (io/structure.py ReceiverSeries).  It is used as it
    is: a harmonic of frequency f keeps the amplitude factor sin(pi f dt) / (pi f dt)
    (0.96 at f dt = 0.15) and lags by dt / 2 -- a delay of the whole record, which changes
    no spectral value.
  Soil outputs (OUT.h5): receivers/u [m] only, at t = dt, 2 dt, ...  The acceleration is
    the second central difference on the uniform grid (refused on a non-uniform one),
        a_n = (u_{n+1} - 2 u_n + u_{n-1}) / dt^2,          n = 1 .. K-2,
    with the error a_n - u''(t_n) = dt^2 / 12 u''''(t_n) + O(dt^4): exact for a cubic
    displacement (up to rounding, about 4 eps max|u| / dt^2).  A harmonic keeps the
    amplitude factor (sin(pi f dt) / (pi f dt))^2 (0.93 at f dt = 0.15) and no phase
    error.  The FIRST AND LAST SAMPLES HAVE NO CENTRED DIFFERENCE AND ARE DROPPED (a
    one-sided difference would be first-order only): the spectrum is of the K - 2 samples
    t_1 .. t_{K-2}, and the oscillator starts at rest at t_1, so the ground acceleration
    of the first step is not seen.
  --source auto (default): the recorded acceleration where the file holds one, else the
    differentiated displacement; ``acceleration`` or ``displacement`` insist on one.
  --table FILE: rows 't a' or 't ax ay az' (seismic/records.py: '#' comments, whitespace
    or commas, t strictly increasing, non-uniform allowed), in m/s^2 unless the file
    has a line '# units: U' or --table-units U is given (g, m/s2, cm/s2, gal).

Options
  --receiver K          receiver index (default 0)
  --component C         x (default) | y | z | all (a spectrum per component)
  --rotd                RotD50 and RotD100 of the horizontal pair x, y (180 angles, 1 deg)
  --geomean             geometric mean sqrt(S_x S_y) of the as-recorded x and y spectra
  --damping Z[,Z...]    damping ratios in [0, 1) (default 0.05)
  --periods SPEC        T1:T2:N (N log-spaced periods from T1 to T2 s) | T,T,... (sorted,
                        0 allowed: the rigid limit PGA) | standard (default:
                        standard_periods(): 100 log-spaced 0.01 .. 10 s and NGA-West2's 21)
  --peaks exact|nodes   exact (default): each peak found WITHIN its step from the closed form
                        of the exactly integrated oscillator (the extremum of the closed form
                        in the step, seismic/response_spectrum.py _exact_peaks): no sub-steps
                        needed; what remains is round-off (1e-12 of the peak against closed
                        forms and 200-fold oversampling in tests/seismic/test_response_spectrum.py)
                        and, in principle, a pair of extrema inside one quarter period of the
                        oscillator, which sampling misses as well.  nodes: the largest value at
                        the samples and sub-steps (the earlier method)
  --oversample N|auto   sub-steps per time step (default auto: 1 with --peaks exact;
                        ceil(10 dt / T_min) with --peaks nodes, the numerics' advice: a peak
                        between nodes is then missed by at most 1 - cos(pi / 10) = 4.9 %; the
                        summary states the bound; 20 dt / T_min gives 1.2 %)
  --ratio B.h5          spectral ratio A / B (e.g. SSI over fixed base) of every quantity,
  --ratio-receiver K    with B's receiver K (default: --receiver), same component(s),
  --ratio-table FILE    or of a table; nan where B is 0
  --csv [OUT.csv]       '#' lines stating what was computed, then one row per
                        (damping, period): period [s], damping [-], SA [m/s^2],
                        PSA [m/s^2], PSV [m/s], SD [m], SV [m/s] (several spectra: the
                        columns carry their label, e.g. 'RotD50 PSA [m/s^2]'; a ratio:
                        'PSA ratio [-]').  Standard output without a name.
  --png OUT.png         PSA (--plot-quantity Q) against period on a log axis
  --overwrite           replace an existing --csv/--png file (never an input file, its
                        sidecars .xmf/.json/.lock, or any HDF5 file)
Prints what was computed (input, receiver, component, acceleration source, dt, samples,
PGA, periods, damping, sub-steps) and the peak of each spectrum.  Errors end with one line
``petsc-ssi post: error: ...`` on stderr naming the argument, and exit status 2.
"""
import argparse
import math
import os
import re
import sys
from dataclasses import dataclass

import numpy as np

from . import post as _post          # module object: post.py may import this module in turn
from ..seismic import response_spectrum as rs

COMPONENTS = ("x", "y", "z")
SOURCES = ("auto", "acceleration", "displacement")
G = 9.80665
PROG = "petsc-ssi post"


def _error(msg):
    return _post.PostError(" ".join(str(msg).split()))


# ---------------------------------------------------------------- input series

@dataclass(eq=False)
class GroundSeries:
    """Acceleration a (n, c) [m/s^2] at times t (n,) [s] of the components ``components``,
    and where it came from (``lines()``)."""
    t: np.ndarray
    a: np.ndarray
    components: tuple
    path: str
    kind: str                 # "recorded" | "differentiated" | "table"
    source: str               # one line: the dataset or table and how a was obtained
    receiver: int = None
    point: tuple = None

    @property
    def n(self):
        return self.t.size

    @property
    def dt(self):
        """The step [s] of a uniform grid (to 1e-6 relative), else None."""
        h = np.diff(self.t)
        return float(h.mean()) if h.size and np.ptp(h) <= 1e-6 * h.mean() else None

    @property
    def pga(self):
        return np.abs(self.a).max(axis=0)

    def lines(self, tag=""):
        where = ""
        if self.receiver is not None:
            where = f", receiver {self.receiver}"
            if self.point is not None:
                where += " at ({:g}, {:g}, {:g}) m".format(*self.point)
        grid = (f"dt {self.dt:.9g} s (uniform)" if self.dt is not None else
                f"non-uniform dt {np.diff(self.t).min():.6g} .. {np.diff(self.t).max():.6g} s")
        pga = ", ".join(f"{c} {p:.6g} m/s^2 ({p / G:.4g} g)" for c, p in zip(self.components, self.pga))
        return [f"{tag}input: {os.path.abspath(self.path)}{where}, component "
                f"{', '.join(self.components)}",
                f"{tag}acceleration: {self.source}",
                f"{tag}samples: n {self.n}, {grid}, t {self.t[0]:.9g} .. {self.t[-1]:.9g} s",
                f"{tag}PGA: {pga}"]


def second_difference(t, u):
    """(t[1:-1], a): the second central difference a_n = (u_{n+1} - 2 u_n + u_{n-1}) / dt^2 of
    u (n,) or (n, c) on the uniform grid t (n,) [s], at the inner samples (module docstring:
    error dt^2 / 12 u'''' + O(dt^4), exact for a cubic; the first and last samples dropped).
    PostError on fewer than 3 samples or a grid non-uniform beyond 1e-6 relative."""
    t, u = np.asarray(t, dtype=float), np.asarray(u, dtype=float)
    if t.ndim != 1 or t.size < 3 or u.shape[0] != t.size:
        raise _error(f"the second difference needs at least 3 samples on one time grid "
                     f"(t has {t.size}, the displacement {u.shape[0] if u.ndim else 0})")
    h = np.diff(t)
    dt = float(h.mean())
    if not np.all(h > 0) or np.max(np.abs(h - dt)) > 1e-6 * dt:
        raise _error(f"non-uniform time grid (steps {h.min():.9g} .. {h.max():.9g} s): the "
                     f"second central difference of the displacement needs a uniform one")
    return t[1:-1].copy(), (u[2:] - 2.0 * u[1:-1] + u[:-2]) / dt ** 2


def load_h5(path, receiver=0, components=("x",), source="auto", arg="--receiver"):
    """GroundSeries of ``receiver`` of the output file ``path``: the recorded
    receivers/acceleration, or the second difference of receivers/u (``source``; module
    docstring).  ``arg`` names the receiver option in error messages."""
    import h5py
    if not os.path.exists(path):
        raise _error(f"{path}: no such file")
    if os.path.isdir(path) or not h5py.is_hdf5(path):
        raise _error(f"{path}: not an HDF5 file (a table 't a' or 't ax ay az' goes with --table FILE)")
    with _post.open_h5(path) as f:
        g = f.get("receivers")
        if not isinstance(g, h5py.Group) or "t" not in g:
            raise _error(f"{path} holds no receiver series (no receivers/t)")
        # a fixed base moving with a record (relative-motion form) also holds the absolute
        # acceleration (relative + ground): that is what the structure feels, and what the
        # coupled run records
        absolute = "absolute_acceleration" in g
        has_a, has_u = "acceleration" in g, "u" in g
        if source == "acceleration" and not has_a:
            raise _error(f"--source acceleration: {path} holds no receivers/acceleration (soil "
                         f"receivers hold displacement only: use --source displacement or auto)")
        if not (has_a or has_u) or (source == "displacement" and not has_u):
            raise _error(f"{path} holds no receivers/u" + ("" if has_a else " nor receivers/acceleration"))
        name = "acceleration" if (has_a and source != "displacement") else "u"
        if name == "acceleration" and absolute:
            name = "absolute_acceleration"
        shape = g[name].shape
        if len(shape) != 3 or shape[2] != 3:
            raise _error(f"{path}: receivers/{name} has shape {shape}, not (K, R, 3)")
        if isinstance(receiver, bool) or not isinstance(receiver, (int, np.integer)) \
                or not 0 <= receiver < shape[1]:
            raise _error(f"{arg} {receiver}: out of range, {path} has {shape[1]} receivers"
                         + (f" (0 .. {shape[1] - 1})" if shape[1] else ""))
        point = tuple(float(v) for v in g["points"][receiver]) if "points" in g else None
    t, x, _, _ = _post.read_series(path, f"receivers/{name}", int(receiver), "all")
    x = x[:, [COMPONENTS.index(c) for c in components]]
    if name in ("acceleration", "absolute_acceleration"):
        return GroundSeries(t, x, tuple(components), path, "recorded",
                            f"recorded acceleration receivers/{name} [m/s^2]: the mean over "
                            "the step ending at t_n, (v_n - v_{n-1}) / dt"
                            + (" (relative to the moving base + the ground's)" if absolute else ""),
                            int(receiver), point)
    t, a = second_difference(t, x)
    return GroundSeries(t, a, tuple(components), path, "differentiated",
                        "differentiated displacement: second central difference of receivers/u "
                        "[m] (error dt^2/12 u''''), first and last sample dropped",
                        int(receiver), point)


def load_table(path, components=None, units=None, arg="--table"):
    """GroundSeries of a table 't a' / 't ax ay az' (acceleration; ``units``: None = the file's
    '# units:' line, else m/s2).  components: None (every column) or names from x, y, z."""
    from ..seismic.records import RecordError, read_record
    if units is None:
        try:
            with open(path, "rb") as fh:
                text = fh.read().decode("latin-1")
        except OSError as exc:
            raise _error(f"{arg} {path}: cannot read: {exc.strerror or exc}") from None
        stated = re.search(r"^\s*#\s*units?\s*[:=]\s*\S+", text, re.M | re.I) is not None
        units, note = ("auto", "as the file states") if stated else ("m/s2", "assumed: the file states none")
    else:
        note = "given"
    try:
        rec = read_record(path, fmt="table", quantity="acceleration", units=units)
    except RecordError as exc:
        raise _error(f"{arg}: {exc}") from None
    a = rec.values[:, None] if rec.values.ndim == 1 else rec.values
    if a.shape[1] == 1:
        if components not in (None, ("x",)):
            raise _error(f"{arg} {path}: a 't a' table holds one component, not "
                         f"{', '.join(components)}")
        comps = ("a",)
    else:
        comps = COMPONENTS if components is None else tuple(components)
        a = a[:, [COMPONENTS.index(c) for c in comps]]
    return GroundSeries(rec.t, a, comps, path, "table",
                        f"table ({'t a' if rec.values.ndim == 1 else 't ax ay az'}) in "
                        f"{rec.units_in} ({note}), in m/s^2")


# ---------------------------------------------------------------- argument values

def parse_periods(text):
    """(periods [s], description) of 'T1:T2:N' (N log-spaced), 'T,T,...' (sorted, unique) or
    'standard'.  argparse.ArgumentTypeError naming --periods otherwise."""
    bad = argparse.ArgumentTypeError
    s = str(text).strip()
    if s.lower() in ("standard", "default", ""):
        p = rs.standard_periods()
        return p, f"standard_periods(): {p.size} periods {p[0]:g} .. {p[-1]:g} s"
    if ":" in s:
        parts = s.split(":")
        try:
            if len(parts) != 3:
                raise ValueError
            t1, t2, n = float(parts[0]), float(parts[1]), int(parts[2])
        except ValueError:
            raise bad(f"{text!r}: give T1:T2:N (N log-spaced periods from T1 to T2 s), a list "
                      f"T,T,... or 'standard'") from None
        if not (np.isfinite(t1) and np.isfinite(t2) and 0 < t1 < t2 and n >= 2):
            raise bad(f"{text!r}: T1:T2:N needs 0 < T1 < T2 (s) and N >= 2")
        return np.geomspace(t1, t2, n), f"{n} log-spaced periods {t1:g} .. {t2:g} s"
    try:
        p = np.array([float(v) for v in s.split(",")])
    except ValueError:
        raise bad(f"{text!r}: not a list of periods in s (give T1:T2:N, T,T,... or 'standard')") from None
    if not np.all(np.isfinite(p)) or np.any(p < 0):
        raise bad(f"{text!r}: periods must be finite and >= 0 s")
    p = np.unique(p)
    return p, f"{p.size} periods {p[0]:g} .. {p[-1]:g} s"


def parse_damping(text):
    """Damping ratios [-] of 'Z,Z,...' in [0, 1); argparse.ArgumentTypeError otherwise."""
    try:
        z = np.array([float(v) for v in str(text).split(",")])
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: not a list of damping ratios (e.g. 0.02,0.05)") from None
    if z.size == 0 or not np.all(np.isfinite(z)) or np.any((z < 0) | (z >= 1)):
        hint = ""
        if np.all(np.isfinite(z)) and np.any(z >= 1):
            hint = f" ({z[z >= 1][0]:g} % is {z[z >= 1][0] / 100:g})"
        raise argparse.ArgumentTypeError(f"{text!r}: damping ratios must lie in [0, 1){hint}")
    return z


def _oversample_arg(text):
    if str(text).lower() == "auto":
        return "auto"
    try:
        k = int(text)
    except ValueError:
        k = 0
    if k < 1:
        raise argparse.ArgumentTypeError(f"{text!r}: give 'auto' or an integer >= 1")
    return k


def auto_oversample(t, periods):
    """ceil(10 h_max / T_min) for the smallest period T_min > 0 (1 without one)."""
    pos = np.asarray(periods)[np.asarray(periods) > 0]
    if pos.size == 0:
        return 1
    return max(1, math.ceil(10 * float(np.diff(t).max()) / float(pos.min()) - 1e-9))


def _miss_bound(t, periods, k):
    """Largest relative peak miss 1 - cos(omega h / 2) over the periods > 0, h = h_max / k."""
    pos = np.asarray(periods)[np.asarray(periods) > 0]
    if pos.size == 0:
        return 0.0, None
    x = min(np.pi, np.pi * float(np.diff(t).max()) / k / float(pos.min()))
    return 1 - math.cos(x), float(pos.min())


# ---------------------------------------------------------------- spectra

MAX_SUBSTEPS = 10 ** 7     # sub-steps of the oscillators' march (a few minutes) beyond which a spectrum is refused


def spectra(series, periods=None, damping=(0.05,), rotd=False, geomean=False, oversample="auto", peaks="exact"):
    """([(label, ResponseSpectrum)], sub-steps): a spectrum per component (labels x, y, z or
    a), or RotD50, RotD100 (``rotd``) and/or GM (``geomean``) of the components x, y."""
    periods = rs.standard_periods() if periods is None else periods
    k = (1 if peaks == "exact" else auto_oversample(series.t, periods)) if oversample == "auto" else int(oversample)
    steps = k * (len(series.t) - 1)
    if steps > MAX_SUBSTEPS:
        # each sub-step is one pass of the recurrence over every oscillator (about 20 us in Python):
        # 1e8 sub-steps per sample ran for days
        pos = np.asarray(periods)[np.asarray(periods) > 0]
        why = (f"--oversample {oversample}" if oversample != "auto" else
               f"--oversample auto (10 dt / T_min with the shortest period {float(pos.min()):g} s in --periods)")
        raise _error(f"{why}: {k} sub-steps per time step over {len(series.t) - 1} steps are {steps:.3g} sub-steps, "
                     f"more than {MAX_SUBSTEPS:.0e} (about {steps * 2e-5 / 3600:.2g} h); give a smaller --oversample "
                     f"(auto gives {auto_oversample(series.t, periods)}) or a longer shortest period in --periods")
    pos = np.asarray(periods)[np.asarray(periods) > 0]
    if peaks == "exact" and len(pos) and len(series.t) > 1:
        # exact peaks search each step in pieces of at most a quarter period: 4 dt / T pieces a step
        # for the shortest period (--periods 1e-7 asked 4e5 a step and took the machine's memory)
        pieces = int(np.ceil(4.0 * float(np.max(np.diff(series.t))) / (k * float(pos.min()))))
        if pieces * steps > MAX_SUBSTEPS:
            raise _error(f"--periods: the shortest period {float(pos.min()):g} s needs {pieces} quarter-period pieces "
                         f"in each of the {steps} (sub-)steps for its exact peaks, {pieces * steps:.3g} sub-steps in "
                         f"all, more than {MAX_SUBSTEPS:.0e}; give a longer shortest period (at least "
                         f"{4.0 * float(np.max(np.diff(series.t))) * steps / MAX_SUBSTEPS / k:.3g} s)")
    out = []
    if rotd or geomean:
        if series.components[:2] != ("x", "y"):
            raise _error(f"--rotd/--geomean need the x and y components; {series.path} gives "
                         f"{', '.join(series.components)}")
        ax, ay = series.a[:, 0], series.a[:, 1]
        px, py = float(np.abs(ax).max()), float(np.abs(ay).max())
        if geomean and min(px, py) <= ROUNDOFF * max(px, py):
            raise _error(f"--geomean: the {'x' if px < py else 'y'} component of {series.path} peaks at "
                         f"{min(px, py):.3g} m/s^2 against {max(px, py):.3g}: it carries no motion (a one-component "
                         f"run), and the geometric mean would be 0 at every period; take the components alone")
        if rotd:
            for s in rs.rotd(series.t, ax, ay, periods, damping, oversample=k, peaks=peaks).values():
                out.append((s.label, s))
        if geomean:
            sx = rs.response_spectrum(series.t, ax, periods, damping, oversample=k, peaks=peaks)
            sy = rs.response_spectrum(series.t, ay, periods, damping, oversample=k, peaks=peaks)
            out.append(("GM", rs.geometric_mean(sx, sy)))
    else:
        for j, c in enumerate(series.components):
            out.append((c, rs.response_spectrum(series.t, series.a[:, j], periods, damping,
                                                oversample=k, peaks=peaks)))
    return out, k


ROUNDOFF = 1e-9        # a component peaking below this share of the largest one carries round-off, not motion


def noise_notes(*series):
    """Notes for components whose acceleration peaks below ROUNDOFF of their series' largest: a
    spectrum (and a ratio) of round-off says nothing."""
    out = []
    for s in series:
        peaks = np.abs(np.asarray(s.a, float)).max(axis=0)
        for c, pk in zip(s.components, np.atleast_1d(peaks)):
            if pk <= ROUNDOFF * float(np.max(peaks)):
                out.append(f"note: {os.path.basename(s.path)}'s {c} component peaks at {pk:.3g} m/s^2 against "
                           f"{float(np.max(peaks)):.3g}: round-off, not motion; its spectra and ratios are noise")
    return out


def ratio_notes(A, B):
    """Notes for a ratio A / B whose B component carries no motion against A's (peaks below ROUNDOFF of
    A's: round-off, a component the other run's record did not drive): every ratio is then about
    1 / ROUNDOFF (1e16 seen), not an amplification."""
    out = []
    pa = np.atleast_1d(np.abs(np.asarray(A.a, float)).max(axis=0))
    pb = np.atleast_1d(np.abs(np.asarray(B.a, float)).max(axis=0))
    for c, x, y in zip(B.components, pa, pb):
        if x > 0 and y <= ROUNDOFF * x:
            out.append(f"note: B's {c} component ({os.path.basename(B.path)}) peaks at {y:.3g} m/s^2 against A's "
                       f"{x:.3g}: it carries no motion, so its ratios ({x / y if y else float('inf'):.3g} at the peak) "
                       f"are not amplifications; compare with a run whose record drives {c}")
    return out


def ratios(spec_a, spec_b):
    """[(label, a / b)] of two lists from ``spectra`` with the same labels."""
    return [(la, rs.spectral_ratio(sa, sb)) for (la, sa), (_, sb) in zip(spec_a, spec_b)]


def _columns(specs, ratio=False):
    """Column names (with units) and values (n_damping * n_periods,) after period, damping."""
    names, cols = [], []
    for lab, s in specs:
        for q in s.quantities:
            pre = f"{lab} " if len(specs) > 1 else ""
            names.append(f"{pre}{q}{' ratio' if ratio else ''} [{s.units[q]}]")
            cols.append(np.asarray(s[q]).ravel())
    return names, cols


def write_table(fh, specs, header=(), ratio=False):
    """'#' header lines, then 'period [s],damping [-],<label> <Q> [unit],...' and one row per
    (damping, period) (damping outer), values as repr(float) (exact round trip)."""
    s0 = specs[0][1]
    names, cols = _columns(specs, ratio)
    z, T = np.meshgrid(s0.damping, s0.periods, indexing="ij")
    data = np.column_stack([T.ravel(), z.ravel()] + cols)
    fh.write("".join(f"# {ln}\n" for ln in header))
    fh.write(",".join([f"period [{rs.UNITS['period']}]", f"damping [{rs.UNITS['damping']}]"] + names) + "\n")
    fh.write("".join(",".join(map(repr, row)) + "\n" for row in data.tolist()))


def plot_png(path, specs, quantity="PSA", title="", ratio=False):
    """``quantity`` of every spectrum and damping against period (log axis, T = 0 left out),
    axes with units, matplotlib Agg without pyplot."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    fig = Figure(figsize=(8, 5))
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    for lab, s in specs:
        keep = s.periods > 0
        for i, z in enumerate(s.damping):
            ax.plot(s.periods[keep], s[quantity][i, keep], lw=1.4,
                    label=f"{lab}, damping {z:g}" if s.damping.size > 1 else f"{lab}")
    if ratio:
        ax.axhline(1.0, color="0.4", lw=0.8, ls="--")
    ax.set_xscale("log")
    ax.set_xlabel(f"period T [{rs.UNITS['period']}]")
    unit = specs[0][1].units[quantity]
    ax.set_ylabel(f"{quantity} ratio A / B [{unit}]" if ratio else f"{quantity} [{unit}]")
    ax.set_title(title, fontsize=8)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    return path


def peak_lines(specs, quantity="PSA", ratio=False):
    """One line per spectrum and damping: the largest ``quantity`` over T > 0 and its period
    (a ratio: also the smallest)."""
    out = []
    for lab, s in specs:
        keep = np.nonzero(s.periods > 0)[0]
        if keep.size == 0 or quantity not in s.values:
            continue
        unit = s.units[quantity]
        for i, z in enumerate(s.damping):
            v = s[quantity][i, keep]
            if np.all(np.isnan(v)):
                out.append(f"{lab}, damping {z:g}: {quantity} ratio undefined (B is 0)")
                continue
            j = keep[np.nanargmax(v)]
            ln = f"{lab}, damping {z:g}: max {quantity}{' ratio' if ratio else ''} " \
                 f"{s[quantity][i, j]:.6g} [{unit}] at T = {s.periods[j]:.6g} s"
            if ratio:
                m = keep[np.nanargmin(v)]
                ln += f", min {s[quantity][i, m]:.6g} at T = {s.periods[m]:.6g} s"
            out.append(ln)
    return out


# ---------------------------------------------------------------- command line

class _Parser(argparse.ArgumentParser):
    def error(self, message):                     # one line, no usage (exit status 2)
        raise _error(message)


def _parser():
    ap = _Parser(prog=f"{PROG} --response-spectrum", description=__doc__.splitlines()[0],
                 formatter_class=argparse.RawDescriptionHelpFormatter,
                 epilog="\n".join(__doc__.splitlines()[2:]))
    ap.add_argument("file", nargs="?", metavar="FILE.h5")
    ap.add_argument("--response-spectrum", action="store_true", help="this command (accepted, no effect)")
    ap.add_argument("--table", metavar="FILE", help="table 't a' or 't ax ay az' instead of FILE.h5")
    ap.add_argument("--table-units", metavar="U", help="units of the table values (default: its "
                    "'# units:' line, else m/s2)")
    ap.add_argument("--source", choices=SOURCES, default="auto")
    ap.add_argument("--receiver", type=int, default=0, metavar="K")
    ap.add_argument("--component", choices=COMPONENTS + ("all",), default=None)
    ap.add_argument("--rotd", action="store_true", help="RotD50 and RotD100 of x and y")
    ap.add_argument("--geomean", action="store_true", help="geometric mean of the x and y spectra")
    ap.add_argument("--damping", type=parse_damping, default=np.array([0.05]), metavar="Z[,Z...]")
    ap.add_argument("--periods", type=parse_periods, default=None, metavar="SPEC")
    ap.add_argument("--oversample", type=_oversample_arg, default="auto", metavar="N|auto")
    ap.add_argument("--peaks", choices=("exact", "nodes"), default="exact")
    ap.add_argument("--ratio", metavar="B.h5", help="spectral ratio A / B")
    ap.add_argument("--ratio-receiver", type=int, default=None, metavar="K")
    ap.add_argument("--ratio-table", metavar="FILE", help="spectral ratio A / (the table's)")
    ap.add_argument("--csv", nargs="?", const="-", default=None, metavar="OUT.csv")
    ap.add_argument("--png", metavar="OUT.png")
    ap.add_argument("--plot-quantity", choices=rs.QUANTITIES, default="PSA")
    ap.add_argument("--overwrite", action="store_true")
    return ap


def _validate(a):
    """Argument combinations; the components to read."""
    if a.file and a.table:
        raise _error(f"give FILE.h5 or --table FILE, not both ({a.file}, --table {a.table})")
    if not (a.file or a.table):
        raise _error("give an output file FILE.h5 or --table FILE")
    if a.table_units is not None and not (a.table or a.ratio_table):
        raise _error("--table-units goes with --table or --ratio-table")
    if a.table and a.source != "auto":
        raise _error(f"--source {a.source}: a --table holds acceleration")
    if a.ratio and a.ratio_table:
        raise _error("give --ratio B.h5 or --ratio-table FILE, not both")
    if a.ratio_receiver is not None and not a.ratio:
        raise _error("--ratio-receiver goes with --ratio B.h5")
    if (a.rotd or a.geomean) and a.component is not None:
        raise _error(f"--component {a.component}: --rotd/--geomean take the x and y components")
    if a.rotd and a.plot_quantity not in ("PSA", "PSV", "SD"):
        raise _error(f"--plot-quantity {a.plot_quantity}: RotD spectra hold PSA, PSV, SD")
    if a.rotd or a.geomean:
        return ("x", "y")
    if a.component == "all":
        return None if a.table else COMPONENTS
    return (a.component or "x",)


def _load(path, table, receiver, comps, a, arg):
    if table:
        return load_table(table, comps, a.table_units, arg=arg)
    return load_h5(path, receiver, comps or COMPONENTS, a.source, arg=arg)


def main(argv=None, out=None):
    """``petsc-ssi post ... --response-spectrum`` (argv: the arguments after ``post``): 0, or 2
    after one error line on stderr."""
    out = sys.stdout if out is None else out
    if _post.world_rank() > 0:      # serial (post's rule): rank 0 works and reports; the others only
        try:                        # check the file, for the same exit status
            for p in (x for x in (argv or []) if x.endswith((".h5", ".hdf5"))):
                _post.open_h5(p).close()
        except _post.PostError:
            return 2
        return 0
    try:
        try:
            a = _parser().parse_args(argv)
        except SystemExit as exc:                 # --help
            return exc.code if isinstance(exc.code, int) else 0
        comps = _validate(a)
        periods, ptext = a.periods if a.periods is not None else parse_periods("standard")
        inputs = [p for p in (a.file, a.table, a.ratio, a.ratio_table) if p]
        _post.check_outputs([("--csv", a.csv), ("--png", a.png)], inputs, a.overwrite)
        if a.ratio and a.file:                   # twins: the same record, scale, control and axes (app/twins.py)
            from . import twins
            for p in (a.file, a.ratio):
                _post.open_h5(p).close()         # (its own one-line refusal for a missing or foreign file)
            twins.check(a.file, a.ratio, _error)
        A = _load(a.file, a.table, a.receiver, comps, a, "--table" if a.table else "--receiver")
        specs, k = spectra(A, periods, a.damping, a.rotd, a.geomean, a.oversample, a.peaks)
        B = None
        if a.ratio or a.ratio_table:
            rrec = a.receiver if a.ratio_receiver is None else a.ratio_receiver
            B = _load(a.ratio, a.ratio_table, rrec, comps, a,
                      "--ratio-table" if a.ratio_table else "--ratio-receiver")
            if len(B.components) != len(A.components):
                raise _error(f"--ratio: A has the components {', '.join(A.components)}, "
                             f"B {', '.join(B.components)}")
            specs_b, kb = spectra(B, periods, a.damping, a.rotd, a.geomean, a.oversample, a.peaks)
            specs = ratios(specs, specs_b)
        header = _summary(A, B, specs, ptext, periods, a, k, kb if B is not None else None)
        if not (a.rotd or a.geomean):
            header += noise_notes(*([A] if B is None else [A, B]))
        if B is not None:
            header += ratio_notes(A, B)
        peaks = peak_lines(specs, a.plot_quantity, ratio=B is not None)
        if a.csv == "-":
            write_table(out, specs, header + peaks, ratio=B is not None)
        else:
            out.write("".join(ln + "\n" for ln in header + peaks))
            if a.csv:
                with open(a.csv, "w", newline="") as fh:
                    write_table(fh, specs, header, ratio=B is not None)
                out.write(f"wrote {a.csv}\n")
        if a.png:
            title = _title(A) + (f"\n/ {_title(B)}" if B is not None else "")
            plot_png(a.png, specs, a.plot_quantity, title, ratio=B is not None)
            if a.csv != "-":
                out.write(f"wrote {a.png}\n")
    except BrokenPipeError:             # the reader stopped ('post ... | head'): cli._post
        raise
    except (OSError, _post.PostError, rs.SpectrumInputError) as exc:
        msg = " ".join(str(exc).split())
        print(f"{PROG}: error: {msg}", file=sys.stderr)
        return 2
    return 0


def _title(s):
    where = f" receiver {s.receiver}" if s.receiver is not None else ""
    how = {"recorded": "recorded acceleration", "table": "table",
           "differentiated": "acceleration = 2nd difference of displacement"}[s.kind]
    return f"{os.path.basename(s.path)}{where}, {', '.join(s.components)}: {how}"


def _summary(A, B, specs, ptext, periods, a, k, kb):
    what = ("RotD50, RotD100 of x and y (Boore 2010, 180 angles)" if a.rotd else "") + \
        (" and " if a.rotd and a.geomean else "") + ("geometric mean of x and y" if a.geomean else "")
    if not what:
        what = "component " + ", ".join(A.components)
    quants = ", ".join(f"{q} [{rs.UNITS[q]}]" for q in specs[0][1].quantities)
    lines = [f"petsc-ssi post --response-spectrum: elastic SDOF response spectra ({what}); "
             + (f"ratio A / B of {', '.join(specs[0][1].quantities)} [-]" if B is not None else quants)]
    lines += A.lines("A " if B is not None else "")
    if B is not None:
        lines += B.lines("B ")
    z = ", ".join(f"{v:g}" for v in a.damping)
    lines.append(f"periods: {ptext}; damping [-]: {z}")
    for tag, s, kk in (("A ", A, k), ("B ", B, kb)):
        if s is None:
            continue
        miss, tmin = _miss_bound(s.t, periods, kk)
        if a.peaks == "exact":
            lines.append(f"{tag if B is not None else ''}sub-steps per time step: {kk}; peaks exact: each found within "
                         "its step from the closed form of the exactly integrated oscillator (round-off remains)")
        else:
            lines.append(f"{tag if B is not None else ''}sub-steps per time step: {kk}"
                         + (f" (a peak between nodes is missed by at most {100 * miss:.2g} % at "
                            f"T = {tmin:g} s)" if tmin else ""))
    lines.append("columns: period [s], damping [-], then per spectrum "
                 + (f"{', '.join(specs[0][1].quantities)} ratio [-]" if B is not None else quants)
                 + "; one row per (damping, period)")
    return lines
