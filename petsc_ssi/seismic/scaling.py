"""Record plausibility and amplitude scaling to a target (issue 43, item 4).

Plausibility (``-ssi_seismic_units_check``, default on): the peak acceleration of each record AS
READ (converted to SI from its units, before -ssi_seismic_scale and any target) must lie between
1e-6 g and 5 g (g = 9.80665 m/s^2). The largest recorded PGAs are about 3 to 4 g; a value far
outside is nearly always a wrong -ssi_seismic_units (a record in cm/s^2 read as g is 980 times too
strong); the one-line refusal names the option, the PGA in g, and which units would give a
plausible one.

Target (``-ssi_seismic_target``): one factor f multiplies the records after their processing (the
processing is linear in the amplitude: the Arias window's fractions, the taper, the high-pass and
the baseline fits do not change with it, so the records are processed again with the scale
f x -ssi_seismic_scale, and the result is the processed motion times f to round-off):
  pga:A          the processed motion's PGA equals A [m/s^2, or A g with a suffix g];
  psa:T:A        its pseudo-spectral acceleration omega^2 SD at the period T [s] and the damping
                 -ssi_seismic_target_damping equals A (ASCE 7 amplitude scaling at one period);
  sa:T:A         the same with the spectral (absolute) acceleration.
With -ssi_seismic vertical and several records, one factor for all (the components keep their
ratios): set by the horizontal components (x, y; z alone if no horizontal one): the larger PGA, or
for psa with both x and y on one time grid the maximum-direction spectrum RotD100 of the pair
(ASCE 7-16 16.2; 180 angles: low by at most 4e-5), else the larger component's value.
"""
import math

import numpy as np

from ..petsc import SSIError

G0 = 9.80665
PGA_MAX_G, PGA_MIN_G = 5.0, 1e-6


def _value(text, what):
    s = str(text).strip().lower()
    mult = 1.0
    if s.endswith("g"):
        s, mult = s[:-1], G0
    try:
        v = float(s) * mult
    except ValueError:
        raise SSIError(f"-ssi_seismic_target: {what} '{text}' is not a number (m/s^2, or with a suffix g)") from None
    if not (math.isfinite(v) and v > 0):
        raise SSIError(f"-ssi_seismic_target: {what} '{text}' must be > 0")
    return v


def parse_target(text):
    """'none' -> None; 'pga:A' -> ('pga', None, A); 'psa:T:A' / 'sa:T:A' -> (kind, T, A) [s, m/s^2]."""
    s = str(text or "").strip().lower()
    if s in ("", "none"):
        return None
    parts = [p.strip() for p in s.split(":")]
    if parts[0] == "pga" and len(parts) == 2:
        return "pga", None, _value(parts[1], "the PGA")
    if parts[0] in ("psa", "sa") and len(parts) == 3:
        try:
            T = float(parts[1])
        except ValueError:
            T = float("nan")
        if not (math.isfinite(T) and T > 0):
            raise SSIError(f"-ssi_seismic_target {text}: the period '{parts[1]}' must be a number > 0 [s]")
        return parts[0], T, _value(parts[2], f"the {parts[0].upper()}")
    raise SSIError(f"-ssi_seismic_target {text}: give none, pga:A, psa:T:A or sa:T:A (A in m/s^2, or with a "
                   "suffix g; T in s)")


def target_validator(text):
    try:
        parse_target(text)
    except SSIError as exc:
        return str(exc).split(": ", 1)[-1]
    return None


def check_units(motions, units_option):
    """SSIError (one line) when a record's PGA as read lies outside [1e-6 g, 5 g]."""
    for axis, m in motions.items():
        scale = abs(float(m.processing["scale"]))
        pga = float(np.max(m.stats_raw["pga"])) / scale           # as read, in SI (before the scale)
        if PGA_MIN_G * G0 <= pga <= PGA_MAX_G * G0 or pga == 0.0:
            continue          # (a zero column of 't ax ay az' driving the other axes: a record of zeros is refused apart)
        unit = m.record_info.get("units_in", "?")
        from .records import UNITS
        factor = UNITS[unit][1] if unit in UNITS else 1.0
        raw = pga / factor                                        # the file's number
        fits = [u for u, (kind, f) in UNITS.items() if kind == UNITS.get(unit, ("", 0))[0]
                and PGA_MIN_G * G0 <= raw * f <= PGA_MAX_G * G0 and u != unit]
        why = "above 5 g" if pga > PGA_MAX_G * G0 else "below 1e-6 g"
        raise SSIError(f"record '{m.source}'" + (f" ({axis})" if axis else "") + f": PGA {pga / G0:.4g} g as read in "
                       f"{unit} ({pga:.4g} m/s^2) is {why}: implausible for an earthquake; check -ssi_seismic_units "
                       f"{units_option}" + (f" (the file's values would give {raw * UNITS[fits[0]][1] / G0:.4g} g in "
                                            f"{fits[0]})" if fits else "")
                       + "; -ssi_seismic_units_check 0 runs it anyway")


def check_scaled(motions, cfg):
    """SSIError (one line) when the motion a run applies, after -ssi_seismic_scale and
    -ssi_seismic_target, peaks outside [1e-6 g, 5 g]: a plausible record made implausible by its
    scale (issue 44: -ssi_seismic_scale 1e12 ran), naming the option that did it."""
    for axis, m in motions.items():
        pga = float(np.max(m.stats["pga"]))
        if PGA_MIN_G * G0 <= pga <= PGA_MAX_G * G0 or pga == 0.0:
            continue
        why = "above 5 g" if pga > PGA_MAX_G * G0 else "below 1e-6 g"
        by = ("-ssi_seismic_target " + str(cfg.get("seismic_target")) if m.processing.get("target")
              else f"-ssi_seismic_scale {cfg.get('seismic_scale', 1.0):g}")
        raise SSIError(f"record '{m.source}'" + (f" ({axis})" if axis else "") + f": the run's PGA {pga / G0:.4g} g "
                       f"({pga:.4g} m/s^2) after {by} is {why}: implausible for an earthquake; check {by.split()[0]}"
                       "; -ssi_seismic_units_check 0 runs it anyway")


def _horizontal(motions):
    h = [a for a in motions if a in ("x", "y")]
    return h if h else list(motions)


def measure(motions, target, damping):
    """(value [m/s^2], how): the quantity ``target`` sets, of the motions as they are."""
    from . import response_spectrum as rs
    kind, T, _ = target
    axes = _horizontal(motions)
    if kind == "pga":
        vals = {a: float(np.max(np.abs(motions[a].a))) for a in axes}
        a = max(vals, key=vals.get)
        return vals[a], "PGA" + (f" of {a} (the larger horizontal component)" if len(axes) > 1 else "")
    q = kind.upper()

    def one(m):                                  # exact peaks (response_spectrum's default)
        return float(rs.response_spectrum(m.t, m.a.reshape(-1), [T], [damping], q).values[q][0, 0])
    if kind == "psa" and len(axes) == 2:
        mx, my = motions[axes[0]], motions[axes[1]]
        if mx.t.size == my.t.size and np.array_equal(mx.t, my.t):
            r = rs.rotd(mx.t, mx.a.reshape(-1), my.a.reshape(-1), [T], [damping], percentiles=(100,))
            return float(r[100].values["PSA"][0, 0]), "RotD100 PSA (maximum direction of x and y)"
    vals = {a: one(motions[a]) for a in axes}
    a = max(vals, key=vals.get)
    return vals[a], q + (f" of {a} (the larger horizontal component)" if len(axes) > 1 else "")


def target_factor(motions, target, damping):
    """(factor, line): the amplitude factor that brings ``motions`` to ``target`` and the log line."""
    kind, T, A = target
    have, how = measure(motions, target, damping)
    if not have > 0:
        raise SSIError(f"-ssi_seismic_target {kind}: the record's {how} is zero: nothing to scale")
    f = A / have
    at = "" if kind == "pga" else f" at T = {T:g} s, damping {damping:g}"
    return f, (f"target {how}{at}: {A:.6g} m/s^2 ({A / G0:.4g} g); the processed record had {have:.6g} m/s^2: "
               f"amplitude factor {f:.6g} (applied to every component; -ssi_seismic_scale x factor)")
