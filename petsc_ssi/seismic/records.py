"""Earthquake records for the seismic input: read, convert to SI, process, evaluate (numpy/scipy only).

Pipeline (the usual steps of strong-motion processing: Boore & Bommer 2005, Soil Dyn. Earthq. Eng.
25, 93-115):
    read_record(path) -> Record        values in SI (m/s^2, m/s or m), file SHA-256, metadata
    process(record)   -> Motion        scale, window, Hann taper, acceleration, exact integration, baseline
    motion(t, deriv)                   d (deriv 0), v (1), a (2) at any times, vectorised

Formats (``fmt="auto"`` picks by extension, then by content)
    PEER NGA ``.AT2``/``.VT2``/``.DT2``: 4 header lines.  Line 3 names the quantity and the units
        ("ACCELERATION TIME SERIES IN UNITS OF G", "... UNITS OF CM/SEC/SEC", "VELOCITY ... CM/S", ...);
        line 4 gives NPTS and DT as "NPTS=   7814, DT=   .0050 SEC," or (older) "7814  .0050  NPTS, DT".
        Values are free-format floats, any number per line (".3654112E-03" is read).  The value count
        must equal NPTS (truncation guard).  t = k DT, k = 0..NPTS-1.
    Tables: rows "t a" or "t ax ay az", '#' starts a comment, whitespace or commas separate; t finite
        and strictly increasing, non-uniform allowed.  A table states no units, so ``units`` must be
        given, or the file carries a comment line "# units: cm/s2" (``units="auto"`` reads it).
        ``component`` (x, y, z or 0, 1, 2) picks a column of a 4-column table; without it the
        values are (n, 3).
    Everything else through ObsPy (imported only then): miniSEED, SAC, K-NET/KiK-net, Kinemetrics
        EVT, ... One trace is taken; with several, ``component`` selects it by channel code (exact,
        or the last character, E/N/Z/1/2/3; E, N, Z also match K-NET's EW, NS, UD) or by position
        (an int).  Calibration:
          K-NET/KiK-net: ObsPy's reader does NOT apply the scale factor: the samples stay counts and
            stats.calib = 0.01 x (scale factor "2000(gal)/8388608") converts them to m/s^2.  We apply it.
          Kinemetrics EVT: read raw; stats.calib is ObsPy's m/s^2 per count (its apply_calib=True
            gives the same numbers; ObsPy takes g = 9.81 m/s^2 there, 0.035 % above the standard g).
          Any other format (SAC, miniSEED, ...) may hold counts: the samples are taken as they are and
            ``units`` is mandatory (stats.calib is not applied; a warning says so when it is not 1).
    ``units="auto"`` only where the file states its units (AT2 line 3, K-NET, EVT); given units must
    then agree with the file's.  A requested ``quantity`` must agree with the file's.

Units: g = 9.80665 m/s^2, m/s2, cm/s2 = gal, m/s, cm/s, m, cm, mm (aliases: cm/sec/sec, m/s^2, ...).

Processing (``process``), in this order
    1. scale (after the conversion to SI).
    2. window: "all" | (t0, t1) record seconds (samples with t0 <= t <= t1) | ("arias", p0, p1): from
       the last sample where the cumulative Arias intensity is <= p0 I_A to the first where it is
       >= p1 I_A (so the part kept holds at least p1 - p0 of I_A, at most one sample interval more at
       each end).  The Arias intensity that locates the window is the record's acceleration less its
       mean (an offset must not decide where the motion is).
    3. baseline "mean" and "poly6": subtract the pre-event mean (the arithmetic mean of the samples
       before the window when there are at least 2, else of the window), in the record's quantity.
    4. Hann taper of fraction p at EACH end, as ObsPy's Trace.taper(p, "hann") / gmprocess's width:
       w = int(p n) sample intervals (n samples; the mean interval for non-uniform grids), weight
       (1 - cos(pi s / w)) / 2 at distance s from the end.  The total tapered length is 2 p.
    5. the record's quantity becomes acceleration (samples -> piecewise-linear a):
         velocity:     the a whose exact integral passes through every sample v_k, of least
                       int a^2 dt (the trapezoid recurrence leaves a free sawtooth c (-1)^k; c minimises).
         displacement: the cubic spline through the d_k with v = 0 at the start and a = 0 at the end
                       (the natural end: least int a^2 dt).  Its a is piecewise linear, so
       exact re-integration returns the (windowed, tapered, scaled) record at its samples.
    6. time axis: the first kept sample is at t_start = pad_start (motion(t) = 0 before it);
       ``Motion.record_t0`` is its time in the record.
    7. exact integration of the piecewise-linear a, from rest (acceleration record) or from the
       record's first v (velocity) / d (displacement) sample:
         v_{k+1} = v_k + h (a_k + a_{k+1}) / 2,  d_{k+1} = d_k + h v_k + h^2 (2 a_k + a_{k+1}) / 6.
    8. baseline "poly6" (Ancheta et al. 2013, gmprocess baseline_sixth_order): least-squares fit of
       d - d_0 by sum_{k=2..6} c_k tau^k (tau = t - t_start), subtract its second derivative from a at
       the samples, and integrate again (so a, v, d stay exactly consistent; v and d then differ from
       "d minus the polynomial" by the O(h^2) integration error of a smooth quartic).
    4b. high-pass (``highpass`` f_c > 0 Hz; uniform sampling only): the tapered acceleration is padded
       with zeros of total length T_pad = 1.5 n / f_c, half at each end (Boore 2005, "On pads and
       filters": room for the acausal filter's transients, n = 4 the filter's order) and filtered by a zero-phase
       (acausal) Butterworth of order 4 (order 2 forward and backward, scipy ``sosfiltfilt``; gain
       |H|^2 = 1 / (1 + (f_c / f)^4): 0.5 at f_c, 0.99 at 3.4 f_c). The pads are kept (the filtered
       motion starts T_pad / 2 before the record's first kept sample and ends T_pad / 2 after its last), so
       the velocity and displacement of its exact integration return to about zero (what PEER's
       processing does; a record's long-period content below f_c is lost). With a velocity or
       displacement record the filter acts on the acceleration of step 5.
    Baseline "auto" (the option's default, issue 43: processing that does no harm by default): none
       when the tapered record already ends at rest (|v_end| <= 1 % PGV and |d_end| <= 10 % PGD on
       every component: a record corrected by its agency is left as it is), else whichever of mean and
       poly6 leaves it nearest rest (``choose_baseline``); the choice and why are in
       ``Motion.processing`` ('baseline', 'baseline_reason') and the summary.
    Warnings (RecordWarning): the poly6 correction changes PGA by more than 5 %; a correction given
    explicitly leaves the motion further from rest than none would (naming -ssi_seismic_baseline);
    |v_end| > 1 % PGV (naming -ssi_seismic_highpass).

Stats (``Motion.stats_raw``: the scaled record as read, integrated whole; ``Motion.stats``: processed):
PGA, PGV, PGD (peaks over the samples), v_end, d_end, Arias intensity pi/(2 g) int a^2 dt (exact for
piecewise-linear a), D5-95 (between the times where the cumulative Arias intensity, linear between
samples, reaches 5 % and 95 %).  Per component (arrays) for 3-component motions.
"""
import dataclasses
import hashlib
import io
import os
import re
import warnings

import numpy as np

G = 9.80665
QUANTITIES = ("acceleration", "velocity", "displacement")
SI_UNITS = {"acceleration": "m/s2", "velocity": "m/s", "displacement": "m"}
UNITS = {"g": ("acceleration", G), "m/s2": ("acceleration", 1.0), "cm/s2": ("acceleration", 0.01),
         "gal": ("acceleration", 0.01), "m/s": ("velocity", 1.0), "cm/s": ("velocity", 0.01),
         "m": ("displacement", 1.0), "cm": ("displacement", 0.01), "mm": ("displacement", 0.001)}
PEER_EXT = {".at2": "acceleration", ".vt2": "velocity", ".dt2": "displacement"}
OBSPY_CALIBRATED = ("KNET", "KINEMETRICS_EVT")      # samples x stats.calib are m/s^2
BASELINES = ("auto", "poly6", "mean", "none")
STAT_UNITS = {"pga": "m/s2", "pgv": "m/s", "pgd": "m", "v_end": "m/s", "d_end": "m", "arias": "m/s",
              "d5_95": "s"}
_NPTS_NEW = re.compile(r"NPTS\s*=\s*([^,\s]+)\s*,?\s*DT\s*=\s*([^,\s]+)", re.I)
_NPTS_OLD = re.compile(r"^\s*(\S+)\s+(\S+)\s+NPTS\s*,\s*DT", re.I)
_COLUMNS = {"x": 0, "y": 1, "z": 2, "0": 0, "1": 1, "2": 2}
_ALIASES = {"E": "EW", "N": "NS", "Z": "UD"}


class RecordError(ValueError):
    """A record that cannot be read or processed; the message is one line naming the file."""


class RecordWarning(UserWarning):
    """Processing that may have changed the motion more than intended."""


@dataclasses.dataclass(eq=False)
class Record:
    """A record as read, in SI: ``values`` (n,) or (n, 3) at times ``t`` [s]."""
    t: np.ndarray
    values: np.ndarray
    quantity: str
    units_in: str
    source: str
    sha256: str
    dt: float = None
    metadata: dict = dataclasses.field(default_factory=dict)


def _refuse(path, cause):
    raise RecordError(f"record '{path}': {' '.join(str(cause).split())}")


def canonical_units(text):
    """The UNITS key for a unit spelling ('CM/SEC/SEC' -> 'cm/s2', 'G' -> 'g'), or None."""
    u = re.sub(r"\s+", "", str(text)).lower().rstrip(".,;")
    u = u.replace("sec", "s").replace("**2", "2").replace("^2", "2").replace("/s/s", "/s2")
    return u if u in UNITS else None


# ---------------------------------------------------------------------------------------------- reading

def read_record(path, fmt="auto", quantity="auto", units="auto", component=None):
    """Read a record file (module docstring) into a Record in SI; RecordError on any defect.

    fmt: "auto" | "peer" | "table" | "obspy" (ObsPy's own detection) | an ObsPy format name ("KNET",
    "MSEED", "SAC", "KINEMETRICS_EVT", ...).  quantity: "auto" or the quantity the caller expects (a
    mismatch is refused).  units: "auto" (the file's) or a unit of UNITS.  component: a column of a
    4-column table (x, y, z, 0, 1, 2) or a trace of a multi-trace ObsPy file (channel code or index).
    """
    path = os.fspath(path)
    try:
        with open(path, "rb") as fh:
            raw = fh.read()
    except OSError as exc:
        _refuse(path, f"cannot read: {exc.strerror or exc}")
    if not raw.strip():
        _refuse(path, "empty file")
    kind = detect_format(path, raw, fmt)
    reader = {"peer": _read_peer, "table": _read_table, "obspy": _read_obspy}[kind]
    t, vals, file_units, meta = reader(path, raw, fmt, component)
    unit, qty = _resolve(path, file_units, units, quantity)
    if not np.all(np.isfinite(vals)):
        _refuse(path, f"non-finite value (nan or inf) at sample {int(np.nonzero(~np.isfinite(vals))[0][0])}")
    step = np.diff(t)
    if kind != "peer" and step.size and float(step.max()) > MAX_DT:     # (PEER: its DT line, checked as read)
        k = int(np.argmax(step))
        _refuse(path, f"the time step {step[k]:.6g} s between samples {k} and {k + 1} ({t[k]:.6g} s, {t[k + 1]:.6g} s): a "
                      f"strong-motion record is sampled every {MAX_DT:g} s or faster; check that its times are seconds")
    dt = float(step.mean()) if np.allclose(step, step[0], rtol=1e-6, atol=0) else None
    return Record(t=t, values=vals * UNITS[unit][1], quantity=qty, units_in=unit, source=path,
                  sha256=hashlib.sha256(raw).hexdigest(), dt=dt, metadata=dict(meta, format=kind))


def detect_format(path, raw, fmt):
    """The reader of a record file: 'peer', 'table' or 'obspy', from -ssi_seismic_format ``fmt`` (auto: from
    the extension and the first bytes ``raw``)."""
    f = str(fmt).lower()
    if f != "auto":
        return {"peer": "peer", "at2": "peer", "table": "table"}.get(f, "obspy")
    if os.path.splitext(path)[1].lower() in PEER_EXT:
        return "peer"
    if b"\0" in raw[:4096]:
        return "obspy"
    lines = raw.decode("latin-1").splitlines()
    if lines and "PEER" in lines[0].upper() or len(lines) > 3 and _npts_match(lines[3]):
        return "peer"
    rows = [ln for ln in (re.sub(r"#.*", "", x).strip() for x in lines[:50]) if ln][:2]
    if rows and _numeric_row(rows[0]):
        return "table"
    if len(rows) == 2 and _header_row(rows[0]) and _numeric_row(rows[1]):
        return "table"                                      # a table under a row of column names
    return "obspy"


def _numeric_row(line):
    return re.fullmatch(r"[-+0-9.eE,\s]+", line) is not None


def _header_row(line):
    """Column names ('time,acc', 't [s]  a [m/s2]'): words, no digits leading a field."""
    return re.fullmatch(r"[A-Za-z_][\w\s,;/\[\]().*^-]*", line) is not None


def _npts_match(line):
    return _NPTS_NEW.search(line) or _NPTS_OLD.search(line)


def _read_peer(path, raw, fmt, component):
    lines = raw.decode("latin-1").splitlines()
    if component is not None:
        _refuse(path, f"a PEER file holds one component, and a trace or column {component!r} is asked for "
                      f"(-ssi_seismic_component or -ssi_seismic_traces): leave it out")
    if len(lines) < 4:
        _refuse(path, f"PEER header needs 4 lines, the file has {len(lines)}")
    qty, unit = _peer_line3(path, lines[2])
    ext_qty = PEER_EXT.get(os.path.splitext(path)[1].lower())
    if ext_qty and ext_qty != qty:
        _refuse(path, f"line 3 says {qty} but the extension means {ext_qty}")
    npts, dt = _peer_line4(path, lines[3])
    vals = _floats(path, " ".join(lines[4:]).split())
    if vals.size != npts:
        _refuse(path, f"{vals.size} values but NPTS = {npts}" + (" (truncated file?)" if vals.size < npts else ""))
    return np.arange(npts) * dt, vals, unit, dict(_peer_line2(lines[1]), quantity_line=lines[2].strip())


def _peer_line2(line):
    parts = [p.strip() for p in line.split(",")]
    meta = {"header": line.strip(), "event": parts[0], "station": "", "component": ""}
    if len(parts) >= 3:
        meta.update(station=parts[-2], component=parts[-1])
    return meta


def _peer_line3(path, line):
    up = line.upper()
    qty = next((q for q in QUANTITIES if q.upper() in up), None)
    m = re.search(r"UNITS\s+OF\s+(\S+)", up)
    if qty is None or m is None:
        _refuse(path, f"line 3 must name the quantity and the units (got '{line.strip()}')")
    unit = canonical_units(m.group(1))
    if unit is None:
        _refuse(path, f"unknown units '{m.group(1)}' on line 3 (known: {', '.join(UNITS)})")
    if UNITS[unit][0] != qty:
        _refuse(path, f"line 3: units '{m.group(1)}' are not units of {qty}")
    return qty, unit


MAX_DT = 1.0         # s: the coarsest sampling of a record taken as plausible (PEER's DT)


def _peer_line4(path, line):
    m = _npts_match(line)
    if m is None:
        _refuse(path, f"line 4 must give NPTS and DT (got '{line.strip()}')")
    try:
        npts, dt = int(m.group(1)), float(m.group(2).upper().replace("D", "E"))
    except ValueError:
        _refuse(path, f"line 4: NPTS '{m.group(1)}' or DT '{m.group(2)}' is not a number")
    if not (np.isfinite(dt) and dt > 0):
        _refuse(path, f"DT = {m.group(2)} on line 4 (must be finite and > 0)")
    if dt > MAX_DT:             # a strong-motion record samples at 1 Hz or faster: DT = 100 is not seconds
        _refuse(path, f"DT = {m.group(2)} s on line 4: a strong-motion record is sampled every {MAX_DT:g} s or "
                      f"faster; check that line 4 gives DT in seconds")
    if npts < 2:
        _refuse(path, f"NPTS = {npts} on line 4 (need at least 2 samples)")
    return npts, dt


def _floats(path, tokens):
    tokens = [t.replace("D", "E").replace("d", "e") for t in tokens]      # Fortran's 0.1D-02 too
    try:
        return np.array(tokens, dtype=float)
    except ValueError:
        bad = next(i for i, s in enumerate(tokens) if not _is_float(s))
        _refuse(path, f"value {bad + 1} '{tokens[bad]}' is not a number")


def _is_float(s):
    try:
        float(s)
        return True
    except ValueError:
        return False


def _read_table(path, raw, fmt, component):
    text = raw.decode("latin-1")
    lines = re.sub(r"#.*", "", text).splitlines()
    first = next((k for k, ln in enumerate(lines) if ln.strip()), None)
    if first is not None and _header_row(lines[first].strip()):
        lines[first] = ""                                   # a row of column names
    body = "\n".join(lines).replace(",", " ")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)
            data = np.loadtxt(io.StringIO(body), ndmin=2)
    except ValueError as exc:
        _refuse(path, f"not a table of numbers ({str(exc).strip().splitlines()[-1]})")
    if data.shape[0] < 2 or data.shape[1] not in (2, 4):
        _refuse(path, f"need at least 2 rows of 't a' or 't ax ay az' (got shape {data.shape})")
    if not np.all(np.isfinite(data)):
        _refuse(path, f"non-finite value (nan or inf) in data row {int(np.nonzero(~np.isfinite(data))[0][0]) + 1}")
    if np.any(np.diff(data[:, 0]) <= 0):
        k = int(np.nonzero(np.diff(data[:, 0]) <= 0)[0][0])
        _refuse(path, f"t must increase strictly (data row {k + 2}: t = {data[k + 1, 0]:g} after {data[k, 0]:g})")
    vals, comp = _table_column(path, data, component)
    m = re.search(r"^\s*#\s*units?\s*[:=]\s*(\S+)", text, re.M | re.I)
    unit = canonical_units(m.group(1)) if m else None
    if m and unit is None:
        _refuse(path, f"unknown units '{m.group(1)}' in the '# units:' line (known: {', '.join(UNITS)})")
    return data[:, 0].copy(), vals, unit, {"station": "", "event": "", "component": comp}


def _table_column(path, data, component):
    if data.shape[1] == 2:
        if component is not None:
            _refuse(path, f"a 't a' table holds one component, and a column {component!r} is asked for "
                          f"(-ssi_seismic_component or -ssi_seismic_traces): leave it out")
        return data[:, 1].copy(), ""
    if component is None:
        return data[:, 1:].copy(), "x,y,z"
    col = _COLUMNS.get(str(component).lower())
    if col is None:
        _refuse(path, f"component {component!r} (one of x, y, z or 0, 1, 2)")
    return data[:, 1 + col].copy(), "xyz"[col]


def _read_obspy(path, raw, fmt, component):
    try:
        import obspy
    except ImportError:
        _refuse(path, "not a PEER file or a table, and ObsPy (needed for seismological formats) is not installed")
    f = None if str(fmt).lower() in ("auto", "obspy") else str(fmt).upper()
    try:
        with warnings.catch_warnings(record=True) as said:      # ObsPy's own warnings are not swallowed
            warnings.simplefilter("always")
            st = obspy.read(io.BytesIO(raw), format=f)
    except Exception as exc:                               # ObsPy raises many kinds
        msg = re.sub(r"\S*obspy-\S*\.tmp", path, str(exc))   # (ObsPy names its temporary copy, not this file)
        if "Unknown format" in msg:
            msg = "ObsPy does not recognise its format"
        _refuse(path, f"not a PEER file, a table of numbers (optionally under one row of column names) or a "
                      f"format ObsPy reads ({type(exc).__name__}: {msg})")
    for w in said:
        text = " ".join(re.sub(r"\S*obspy-\S*\.tmp", path, str(w.message)).split())
        if "corrupt" in text.lower():                      # samples skipped: the motion has a hole
            _refuse(path, f"ObsPy read it with a warning that data are corrupt ({text}); repair or replace the file")
        warnings.warn(f"record '{path}': ObsPy: {text}", RecordWarning, stacklevel=3)
    ids = [tr.id for tr in st]
    split = sorted({i for i in ids if ids.count(i) > 1})
    if split:                                              # gaps or overlaps: one channel in several segments
        _refuse(path, f"the trace {split[0]} is in {ids.count(split[0])} segments (gaps or overlaps in the "
                      f"recording): they are not one motion; fill or cut the gaps first (ObsPy's Stream.merge, "
                      f"or keep one segment with Stream.slice)")
    tr = _pick_trace(path, st, component)
    form = tr.stats.get("_format", f or "")
    vals = np.asarray(tr.data, dtype=float)
    if form in OBSPY_CALIBRATED:
        vals, unit = vals * float(tr.stats.calib), "m/s2"
    else:
        unit = None
        if float(tr.stats.calib) != 1.0:
            warnings.warn(f"record '{path}': {form} stats.calib = {tr.stats.calib:g} is not applied; "
                          f"the samples are taken in the given units", RecordWarning, stacklevel=3)
    return np.asarray(tr.times(), dtype=float), vals, unit, _obspy_meta(tr, form)


def _pick_trace(path, st, component):
    if component is None:
        if len(st) != 1:
            _refuse(path, f"{len(st)} traces ({', '.join(tr.id for tr in st)}): say which (-ssi_seismic_component C "
                          f"for one record; -ssi_seismic_traces X,Y,Z for -ssi_seismic vertical: a channel code, its "
                          f"suffix or the trace's index per axis)")
        return st[0]
    if isinstance(component, (int, np.integer)):
        if not 0 <= component < len(st):
            _refuse(path, f"component {component} but the file has {len(st)} traces")
        return st[int(component)]
    c = str(component).upper()
    hits = [tr for tr in st if tr.stats.channel.upper() == c] or \
           [tr for tr in st if tr.stats.channel.upper().endswith(c)
            or tr.stats.channel.upper().rstrip("0123456789") == _ALIASES.get(c)]
    if len(hits) != 1:
        _refuse(path, f"component {component!r} matches {len(hits)} of the traces ({', '.join(tr.id for tr in st)})")
    return hits[0]


def _obspy_meta(tr, form):
    s = tr.stats
    event = ""
    if "knet" in s:
        k = s.knet
        event = f"origin {k.evot} lat {k.evla} lon {k.evlo} depth {k.evdp} km M{k.mag}"
    return {"station": ".".join(x for x in (s.network, s.station, s.location) if x), "event": event,
            "component": s.channel, "obspy_format": form, "starttime": str(s.starttime),
            "calib": float(s.calib)}


def _resolve(path, file_units, units, quantity):
    if quantity not in QUANTITIES + ("auto",):
        _refuse(path, f"unknown quantity '{quantity}' (one of auto, {', '.join(QUANTITIES)})")
    given = None if units == "auto" else canonical_units(units)
    if units != "auto" and given is None:
        _refuse(path, f"unknown units '{units}' (one of auto, {', '.join(UNITS)})")
    if file_units is None and given is None:
        _refuse(path, f"the file does not state its units: give them with -ssi_seismic_units (post: --table-units), "
                      f"one of {', '.join(UNITS)}")
    if file_units and given and UNITS[file_units] != UNITS[given]:
        _refuse(path, f"the file is in {file_units}, and -ssi_seismic_units (post: --table-units) says {units}: "
                      f"leave it auto or give {file_units}")
    unit = file_units or given
    if quantity != "auto" and quantity != UNITS[unit][0]:
        _refuse(path, f"quantity mismatch: the file holds {UNITS[unit][0]} ({unit}), {quantity} requested")
    return unit, UNITS[unit][0]


# ---------------------------------------------------------------------------------------------- kinematics

def _as2d(x):
    x = np.asarray(x, dtype=float)
    return x[:, None] if x.ndim == 1 else x


def integrate(t, a, v0=0.0, d0=0.0):
    """(v, d) at the samples, exact for the piecewise-linear a through (t, a); a (n,) or (n, c)."""
    t, a = np.asarray(t, float), np.asarray(a, float)
    h = np.diff(t).reshape((-1,) + (1,) * (a.ndim - 1))
    v = v0 + np.concatenate([np.zeros_like(a[:1]), np.cumsum(h * (a[:-1] + a[1:]) / 2, axis=0)])
    d = d0 + np.concatenate([np.zeros_like(a[:1]),
                             np.cumsum(h * v[:-1] + h * h * (2 * a[:-1] + a[1:]) / 6, axis=0)])
    return v, d


def _l2(x, y, t):
    """int x y dt for piecewise-linear x, y (columns)."""
    h = np.diff(t)[:, None]
    return np.sum(h * (2 * x[:-1] * y[:-1] + x[:-1] * y[1:] + x[1:] * y[:-1] + 2 * x[1:] * y[1:]) / 6, axis=0)


def to_acceleration(t, x, quantity, at_rest=True):
    """(a, v0, d0): the piecewise-linear a (module docstring, step 5) whose exact integral from
    (v0, d0) passes through the samples x (n, c) of the given quantity. A displacement's spline
    starts with zero velocity where ``at_rest`` (a record that starts at rest: processed records,
    whose start ``process`` checks), else with its own slope (not-a-knot: the raw record's
    statistics, whose start may be moving)."""
    x = _as2d(x)
    if quantity == "acceleration":
        return x.copy(), 0.0, 0.0
    if quantity == "velocity":
        sign = (-1.0) ** np.arange(len(t))[:, None]
        q = 2 * np.diff(x, axis=0) / np.diff(t)[:, None]
        p = sign * np.concatenate([np.zeros_like(x[:1]), np.cumsum(-sign[:-1] * q, axis=0)])
        c = -_l2(p, sign, t) / _l2(sign, sign, t)
        return p + c * sign, x[0].copy(), 0.0
    from scipy.interpolate import CubicSpline
    zero = np.zeros(x.shape[1])
    if at_rest:
        spline = CubicSpline(t, x, axis=0, bc_type=((1, zero), (2, zero)))
        return spline(t, 2), 0.0, x[0].copy()
    spline = CubicSpline(t, x, axis=0)
    return spline(t, 2), spline(t[0], 1), x[0].copy()


def _kinematics(t, x, quantity):
    a, v0, d0 = to_acceleration(t, x, quantity, at_rest=False)
    v, d = integrate(t, a, v0, d0)
    return a, v, d


def arias_cumulative(t, a):
    """Cumulative Arias intensity pi/(2 g) int_0^t a^2 [m/s] at the samples, exact for piecewise-linear a."""
    a = _as2d(a)
    h = np.diff(t)[:, None]
    seg = h * (a[:-1] ** 2 + a[:-1] * a[1:] + a[1:] ** 2) / 3
    return np.pi / (2 * G) * np.concatenate([np.zeros_like(a[:1]), np.cumsum(seg, axis=0)])


def _crossing(t, cum, frac):
    """Time where cum (non-decreasing) first reaches frac * cum[-1], linear between samples."""
    target = frac * cum[-1]
    k = int(np.searchsorted(cum, target, side="left"))
    if k == 0 or cum[-1] == 0:
        return float(t[0])
    return float(t[k - 1] + (target - cum[k - 1]) / (cum[k] - cum[k - 1]) * (t[k] - t[k - 1]))


def motion_stats(t, a, v, d):
    """Dict of PGA, PGV, PGD, v_end, d_end, Arias, D5-95 (units STAT_UNITS), per column."""
    a, v, d = _as2d(a), _as2d(v), _as2d(d)
    cum = arias_cumulative(t, a)
    d595 = [_crossing(t, cum[:, j], 0.95) - _crossing(t, cum[:, j], 0.05) for j in range(a.shape[1])]
    out = {"pga": np.abs(a).max(0), "pgv": np.abs(v).max(0), "pgd": np.abs(d).max(0), "v_end": v[-1],
           "d_end": d[-1], "arias": cum[-1], "d5_95": np.array(d595)}
    return {k: (float(x[0]) if x.size == 1 else np.array(x, float)) for k, x in out.items()}


# ---------------------------------------------------------------------------------------------- processing

def parse_window(text):
    """'all' | 't0,t1' | 'arias:p0,p1' (the -ssi_seismic_window syntax) -> process()'s window."""
    s = str(text).strip().lower()
    if s == "all":
        return "all"
    body = s[len("arias:"):] if s.startswith("arias:") else s
    try:
        lo, hi = (float(x) for x in body.split(","))
    except ValueError:
        raise ValueError(f"window '{text}': expected all, t0,t1 or arias:p0,p1") from None
    return ("arias", lo, hi) if s.startswith("arias:") else (lo, hi)


def hann_taper(t, fraction):
    """Weights of a Hann taper of ``fraction`` at each end (ObsPy's int(p n) samples; module docstring)."""
    n = len(t)
    wlen = int(fraction * n)
    if wlen == 0:
        return np.ones(n)
    s = np.minimum(t - t[0], t[-1] - t) / (wlen * (t[-1] - t[0]) / (n - 1))
    return np.where(s < 1, 0.5 * (1 - np.cos(np.pi * np.minimum(s, 1))), 1.0)


def _window(path, t, a, window):
    if isinstance(window, str) and window == "all":
        return 0, len(t) - 1
    if isinstance(window, (tuple, list)) and len(window) == 3 and window[0] == "arias":
        p0, p1 = float(window[1]), float(window[2])
        if not 0 <= p0 < p1 <= 1:
            _refuse(path, f"Arias window fractions {p0:g}, {p1:g} (need 0 <= p0 < p1 <= 1)")
        cum = arias_cumulative(t, a - a.mean(0)).sum(1)
        if cum[-1] <= 0:
            _refuse(path, "Arias window of a record with zero Arias intensity")
        i0 = max(int(np.searchsorted(cum, p0 * cum[-1], side="right")) - 1, 0)
        i1 = min(int(np.searchsorted(cum, p1 * cum[-1], side="left")), len(t) - 1)
    elif isinstance(window, (tuple, list)) and len(window) == 2:
        t0, t1 = float(window[0]), float(window[1])
        i0, i1 = int(np.searchsorted(t, t0, side="left")), int(np.searchsorted(t, t1, side="right")) - 1
    else:
        _refuse(path, f"window {window!r} (all, (t0, t1) or ('arias', p0, p1))")
    if i1 - i0 < 1:
        _refuse(path, f"window {window!r} keeps {max(i1 - i0 + 1, 0)} sample(s) of the record "
                      f"[{t[0]:g}, {t[-1]:g}] s (need 2)")
    return i0, i1


HIGHPASS_ORDER = 4


def _highpass(path, t, a, fc):
    """(t, a) padded by T_pad / 2 = 0.75 n / f_c zeros at each end and high-pass filtered (zero-phase
    Butterworth of order n = 4); t starts at the original t[0] - T_pad / 2."""
    from scipy.signal import butter, sosfiltfilt
    h = np.diff(t)
    dt = float(h.mean())
    if np.abs(h - dt).max() > 1e-6 * dt:
        _refuse(path, "high-pass filter: the record's sampling is not uniform")
    nyq = 0.5 / dt
    if not fc < nyq:
        _refuse(path, f"high-pass corner {fc:g} Hz is not below the Nyquist frequency {nyq:g} Hz")
    npad = int(np.ceil(0.75 * HIGHPASS_ORDER / fc / dt))
    _check_pad_memory(path, fc, dt, npad, a.shape)
    ap = np.vstack([np.zeros((npad, a.shape[1])), a, np.zeros((npad, a.shape[1]))])
    sos = butter(HIGHPASS_ORDER // 2, fc / nyq, btype="highpass", output="sos")
    af = sosfiltfilt(sos, ap, axis=0, padtype=None)
    tp = t[0] + dt * (np.arange(len(ap)) - npad)
    return tp, af, npad


PAD_COPIES = 8          # arrays of the padded record's size alive at once (filter, integration, motion)


def _check_pad_memory(path, fc, dt, npad, shape):
    """Refuse a high-pass whose padded record (2 npad zeros more, ``PAD_COPIES`` arrays of it) would
    not fit in half the memory of the machine (or its cgroup): f_c = 1e-7 Hz padded 6e9 samples, a
    44.7 GiB allocation that ended in MemoryError after the set-up."""
    from ..sysmem import machine_memory
    need = PAD_COPIES * 8.0 * (2 * npad + shape[0]) * shape[1]
    room = 0.5 * machine_memory()
    if need > room:
        fc_min = 0.75 * HIGHPASS_ORDER / dt / max(1.0, (room / (PAD_COPIES * 8.0 * shape[1]) - shape[0]) / 2)
        _refuse(path, f"-ssi_seismic_highpass {fc:g} Hz pads the record with 2 x {npad:.3g} zeros "
                      f"({2 * npad * dt:.3g} s): about {need / 1e9:.3g} GB, more than half the memory "
                      f"({room / 1e9:.3g} GB); give a corner of at least {fc_min:.2g} Hz (a corner below "
                      f"1 / the record's length removes nothing the baseline does not)")


def _check_args(path, scale, taper, baseline, pad_start):
    if not (np.isfinite(scale) and scale != 0):
        _refuse(path, f"-ssi_seismic_scale {scale}: must be finite and non-zero")
    if not 0 <= taper <= 0.5:
        _refuse(path, f"-ssi_seismic_taper {taper}: a fraction at each end, 0 <= taper <= 0.5")
    if baseline not in BASELINES:
        _refuse(path, f"-ssi_seismic_baseline {baseline}: one of {', '.join(BASELINES)}")
    if not (np.isfinite(pad_start) and pad_start >= 0):
        _refuse(path, f"pad_start = {pad_start} (must be finite and >= 0)")


def _poly6_accel(t, d):
    """Second derivative at the samples of the least-squares fit of d - d_0 by sum_{k=2..6} c_k tau^k."""
    span = t[-1] - t[0]
    x = ((t - t[0]) / span)[:, None]
    k = np.arange(2, 7)
    coef = np.linalg.lstsq(x ** k, d - d[0], rcond=None)[0]
    return (k * (k - 1) * x ** (k - 2)) @ coef / span ** 2


def _ratio(x, y):
    return np.divide(x, y, out=np.zeros_like(np.asarray(x, float)), where=np.asarray(y) != 0)


def process(record, scale=1.0, window="all", taper=0.05, baseline="auto", pad_start=0.0, highpass=0.0):
    """Motion from a Record: scale, window, pre-event mean, Hann taper, acceleration, exact integration
    and baseline (module docstring, steps 1-8).  RecordError on bad arguments, RecordWarning on a large
    baseline change, a final velocity left, or a correction that leaves the motion further from rest
    than none would.

    scale: factor after the conversion to SI (finite, non-zero).  window: "all" | (t0, t1) | ("arias",
    p0, p1) (``parse_window`` reads the option syntax).  taper: Hann fraction at each end, 0..0.5.
    baseline: "auto" | "poly6" | "mean" | "none" ("auto": ``choose_baseline``).  pad_start: time of the
    first kept sample in the motion [s].  highpass: corner frequency f_c of the acausal Butterworth
    high-pass [Hz] (0: none; step 4b).
    """
    path = record.source
    _check_args(path, scale, taper, baseline, pad_start)
    if not (np.isfinite(highpass) and highpass >= 0):
        _refuse(path, f"-ssi_seismic_highpass {highpass} Hz: must be finite and >= 0")
    t, x = np.asarray(record.t, float), _as2d(record.values) * scale
    raw = _kinematics(t, x, record.quantity)
    i0, i1 = _window(path, t, raw[0], window)
    if taper == 0:                               # (the values less the pre-event mean a correction removes)
        xw = x[i0:i1 + 1]
        xw = xw if baseline == "none" else xw - (x[:i0] if i0 >= 2 else xw).mean(0)
        _check_start_at_rest(path, t[i0:i1 + 1] - t[i0] + pad_start, xw, record.quantity)

    def run(how):
        return _corrected(path, t, x, i0, i1, record.quantity, taper, how, pad_start, highpass)

    runs = {"none": run("none")} if baseline in ("auto", "none") else {}
    choice = None
    if baseline == "auto":
        choice = choose_baseline(runs, run)
        how = choice["chosen"]
        tm, a, v, d, change, npad = choice["result"]
    else:
        how = baseline
        if how not in runs:
            runs[how] = run(how)
        tm, a, v, d, change, npad = runs[how]
    proc = dict(scale=float(scale), window=window, taper=float(taper), baseline=how,
                baseline_option=baseline, pad_start=float(pad_start), window_samples=(i0, i1),
                highpass=float(highpass), highpass_pad_s=float(npad * (tm[1] - tm[0])) if npad else 0.0)
    if choice is not None:
        proc["baseline_reason"] = choice["reason"]
    elif how != "none":                          # an explicit correction: how far from rest without it
        proc["drift_without"] = drift(run("none"))
    t_rec0 = float(t[i0]) - proc["highpass_pad_s"]
    motion = Motion(t=tm, a=a, v=v, d=d, stats_raw=motion_stats(t, *raw), stats=motion_stats(tm, a, v, d),
                    baseline_pga_change=change, record_t0=t_rec0, source=path, sha256=record.sha256,
                    record_info=_record_info(record), processing=proc, ndim=np.ndim(record.values))
    motion.warn()
    return motion


def _corrected(path, t, x, i0, i1, quantity, taper, baseline, pad_start, highpass):
    """(t, a, v, d, PGA change, pad samples) of the window [i0, i1] of the samples x processed with
    ``baseline`` (none, mean or poly6): steps 3-8 of the module docstring."""
    xw = x[i0:i1 + 1]
    if baseline != "none":
        xw = xw - (x[:i0] if i0 >= 2 else xw).mean(0)
    tm = t[i0:i1 + 1] - t[i0] + pad_start
    a, v0, d0 = to_acceleration(tm, xw * hann_taper(tm, taper)[:, None], quantity)
    npad = 0
    if highpass > 0:
        tm, a, npad = _highpass(path, tm, a, float(highpass))
        tm = tm - tm[0] + pad_start                  # the first (padded) sample at pad_start
        v0, d0 = 0.0 * v0, 0.0 * d0                  # the pads start from rest
    v, d = integrate(tm, a, v0, d0)
    change = np.zeros(a.shape[1])
    if baseline == "poly6":
        a_new = a - _poly6_accel(tm, d)
        change = _ratio(np.abs(a_new).max(0), np.abs(a).max(0)) - 1
        a = a_new
        v, d = integrate(tm, a, v0, d0)
    return tm, a, v, d, change, npad


REST_V, REST_D = 0.01, 0.1      # at rest: |v_end| <= 1 % of PGV and |d_end| <= 10 % of PGD (every component)


def drift(result):
    """(|v_end| / PGV, |d_end| / PGD) per component of a ``_corrected`` result: how far the processed
    motion ends from rest."""
    _, a, v, d, _, _ = result
    return _ratio(np.abs(v[-1]), np.abs(v).max(0)), _ratio(np.abs(d[-1]), np.abs(d).max(0))


def _score(dr):
    """Per component, one number for 'how far from rest' (<= 1: at rest; the velocity counts ten
    times more than the displacement: a permanent displacement may be real)."""
    return np.maximum(np.asarray(dr[0]) / REST_V, np.asarray(dr[1]) / REST_D)


def choose_baseline(runs, run):
    """The baseline of ``-ssi_seismic_baseline auto``, per component: none when the tapered record
    already ends at rest (``REST_V``, ``REST_D``: a corrected record is left as it is), else the one of
    none, mean and poly6 that leaves it nearest rest (ties: the first). ``runs``: {baseline: result} holding 'none';
    ``run(baseline)``: a result. {'chosen' (one name, or 'x/y/z' names per component), 'reason',
    'result'}."""
    d0 = drift(runs["none"])
    words = (f"without a correction the tapered motion ends at a final velocity of {_fmt(100 * d0[0], '.3g')} % of PGV "
             f"and a final displacement of {_fmt(100 * d0[1], '.3g')} % of PGD")
    if np.all(_score(d0) <= 1.0):
        return {"chosen": "none", "reason": words + " (at rest: nothing to correct)", "result": runs["none"]}
    names = ("none", "mean", "poly6")
    for how in names[1:]:
        runs[how] = run(how)
    scores = np.array([_score(drift(runs[k])) for k in names])        # (3, components)
    pick = np.where(scores[0] <= 1.0, 0, np.argmin(scores, axis=0))   # a component at rest keeps its record
    tm, _, _, _, _, npad = runs["none"]
    cols = [np.stack([runs[names[k]][i][:, j] for j, k in enumerate(pick)], axis=1) for i in (1, 2, 3)]
    change = np.array([runs[names[k]][4][j] for j, k in enumerate(pick)])
    result = (tm, cols[0], cols[1], cols[2], change, npad)
    chosen = "/".join(names[k] for k in pick) if len(set(pick.tolist())) > 1 else names[pick[0]]
    db = drift(result)
    return {"chosen": chosen, "result": result,
            "reason": words + f"; {chosen} leaves {_fmt(100 * db[0], '.3g')} % and {_fmt(100 * db[1], '.3g')} %"}


def _check_start_at_rest(path, t, x, quantity):
    """Refuse an untapered velocity or displacement record that does not start at rest: the motion
    is at rest before its first sample, so a first velocity (or a displacement's first value or
    slope) would be a jump, an impulse of acceleration the record does not hold. Limits: 1 % of
    the record's peak of that quantity (the slope against the peak of the differences)."""
    x = _as2d(x)
    if quantity == "acceleration" or len(t) < 2:
        return
    how = ("taper it (-ssi_seismic_taper, e.g. 0.05) or window it from where it is at rest "
           "(-ssi_seismic_window)")
    if quantity == "velocity":
        v0, pgv = np.abs(x[0]), np.abs(x).max(0)
        if np.any(v0 > 0.01 * pgv):
            _refuse(path, f"the velocity record does not start at rest (first sample {_fmt(v0)} m/s, PGV "
                          f"{_fmt(pgv)} m/s): with no taper the run would start it with a jump; {how}")
        return
    slope = np.abs(x[1] - x[0]) / (t[1] - t[0])
    rate = (np.abs(np.diff(x, axis=0)) / np.diff(t)[:, None]).max(0)
    d0, pgd = np.abs(x[0]), np.abs(x).max(0)
    if np.any(slope > 0.01 * rate) or np.any(d0 > 0.01 * pgd):
        _refuse(path, f"the displacement record does not start at rest (first sample {_fmt(d0)} m of PGD "
                      f"{_fmt(pgd)} m, first slope {_fmt(slope)} m/s of the largest {_fmt(rate)} m/s): with no taper "
                      f"the run would start it with a jump; {how}")


def _record_info(record):
    return dict(record.metadata, quantity=record.quantity, units_in=record.units_in, n=len(record.t),
                dt=record.dt)


# ---------------------------------------------------------------------------------------------- the motion

def _fmt(x, spec=".4g"):
    return "/".join(format(float(v), spec) for v in np.atleast_1d(x))


def energy_above(t, a, f):
    """The fraction of the energy (sum of |A(f)|^2) of the acceleration samples ``a`` at times ``t``
    (uniform, or linearly resampled at their smallest step) above the frequency ``f`` [Hz]; per
    column for (n, 3) ``a``."""
    t, a = np.asarray(t, float), np.asarray(a, float)
    h = float(np.min(np.diff(t)))
    if not np.allclose(np.diff(t), h, rtol=1e-6, atol=0):
        tu = np.arange(t[0], t[-1] + 0.5 * h, h)
        a = np.stack([np.interp(tu, t, c) for c in np.atleast_2d(a.T)], axis=1).reshape((len(tu),) + a.shape[1:])
    A = np.abs(np.fft.rfft(a, axis=0)) ** 2
    fr = np.fft.rfftfreq(a.shape[0], h)
    tot = A.sum(axis=0)
    return np.where(tot > 0, A[fr > f].sum(axis=0) / np.where(tot > 0, tot, 1.0), 0.0)


@dataclasses.dataclass(eq=False)
class Motion:
    """Processed control motion: samples t, a, v, d (SI) and the time function motion(t, deriv).

    Between samples a is linear, v quadratic, d cubic (exact integrals); 0 before t_start; after t_end
    a = 0, v = v_end, d = d_end + v_end (t - t_end).  ``a``, ``v``, ``d`` are (n,) or (n, 3)."""
    t: np.ndarray
    a: np.ndarray
    v: np.ndarray
    d: np.ndarray
    stats_raw: dict
    stats: dict
    baseline_pga_change: np.ndarray
    record_t0: float
    source: str
    sha256: str
    record_info: dict
    processing: dict
    ndim: int = 1

    def __post_init__(self):
        if self.ndim == 1:
            self.a, self.v, self.d = (np.asarray(x, float).reshape(-1) for x in (self.a, self.v, self.d))
            self.baseline_pga_change = float(np.asarray(self.baseline_pga_change).reshape(-1)[0])

    t_start = property(lambda self: float(self.t[0]))
    t_end = property(lambda self: float(self.t[-1]))
    duration = property(lambda self: float(self.t[-1] - self.t[0]))

    def __call__(self, t, deriv=0):
        """d (deriv 0), v (1) or a (2) at times t (any shape; result t.shape [+ (3,)])."""
        if deriv not in (0, 1, 2):
            raise ValueError(f"deriv must be 0, 1 or 2 (got {deriv!r})")
        tq = np.asarray(t, dtype=float)
        s_all = tq.reshape(-1)
        tk, a, v, d = self.t, _as2d(self.a), _as2d(self.v), _as2d(self.d)
        k = np.clip(np.searchsorted(tk, s_all, side="right") - 1, 0, len(tk) - 2)
        s = (s_all - tk[k])[:, None]
        slope = (a[k + 1] - a[k]) / (tk[k + 1] - tk[k])[:, None]
        out = [d[k] + s * (v[k] + s * (a[k] / 2 + s * slope / 6)),
               v[k] + s * (a[k] + s * slope / 2), a[k] + s * slope][deriv]
        out[s_all < tk[0]] = 0.0
        after = s_all > tk[-1]
        out[after] = [d[-1] + (s_all[after] - tk[-1])[:, None] * v[-1], v[-1], 0.0][deriv]
        return out[:, 0].reshape(tq.shape)[()] if self.ndim == 1 else out.reshape(tq.shape + out.shape[1:])

    def warn(self):
        """RecordWarning if the baseline changed PGA by more than 5 %, if |v_end| > 1 % PGV, or if an
        explicit correction left the motion further from rest than none would (each names the option)."""
        s, p = self.stats, self.processing
        if np.any(np.abs(self.baseline_pga_change) > 0.05):
            warnings.warn(f"record '{self.source}': the poly6 baseline changes PGA by "
                          f"{_fmt(np.multiply(self.baseline_pga_change, 100), '+.1f')} % (> 5 %): the polynomial "
                          "fits part of the motion itself (long periods); -ssi_seismic_baseline none or mean keeps "
                          "them", RecordWarning, stacklevel=3)
        worse = p.get("drift_without")
        now = drift((None, _as2d(self.a), _as2d(self.v), _as2d(self.d), None, None))
        if worse is not None and np.any(_score(now) > np.maximum(_score(worse), 1.0)):
            warnings.warn(f"record '{self.source}': the {p['baseline']} baseline leaves the motion further from rest "
                          f"than no correction (final velocity {_fmt(100 * now[0], '.3g')} % of PGV, final displacement "
                          f"{_fmt(100 * now[1], '.3g')} % of PGD; without it {_fmt(100 * worse[0], '.3g')} % and "
                          f"{_fmt(100 * worse[1], '.3g')} %): "
                          f"the record looks corrected already; give -ssi_seismic_baseline none (or auto, the default, "
                          "which chooses)", RecordWarning, stacklevel=3)
        elif np.any(np.abs(s["v_end"]) > 0.01 * np.asarray(s["pgv"])):
            warnings.warn(f"record '{self.source}': final velocity {_fmt(s['v_end'])} m/s is more than "
                          f"1 % of PGV {_fmt(s['pgv'])} m/s after the {p.get('baseline', '?')} baseline"
                          + ("" if p.get("highpass") else "; a high-pass filter (-ssi_seismic_highpass, e.g. 0.1 Hz) "
                             "removes the drift a baseline leaves"), RecordWarning, stacklevel=3)

    def summary_lines(self):
        """Human-readable report (units stated), one string per line."""
        r, p = self.record_info, self.processing
        dt = f"dt {r['dt']:g} s" if r.get("dt") else "non-uniform t"
        form = r.get("obspy_format") or r.get("format", "")
        lines = [f"record {self.source} (sha256 {self.sha256}): {form}, {r['quantity']} in {r['units_in']}, "
                 f"{r['n']} samples, {dt}, station '{r.get('station', '')}', component '{r.get('component', '')}'",
                 f"processing: scale {p['scale']:g}, window {p['window']!r} (record from {self.record_t0:g} s), "
                 f"Hann taper {p['taper']:g} of the length at each end, baseline {p['baseline']}"
                 + (f", acausal Butterworth high-pass of order {HIGHPASS_ORDER} at {p['highpass']:g} Hz with "
                    f"{p['highpass_pad_s']:.4g} s of zero pads kept at each end" if p.get("highpass") else ""),
                 f"motion: {len(self.t)} samples, t {self.t_start:g} .. {self.t_end:g} s "
                 f"(duration {self.duration:g} s)",
                 # (the raw column is the record as read times -ssi_seismic_scale (or a target's factor): said so)
                 f"{'':16s}{'raw' if p['scale'] == 1 else 'raw x ' + format(p['scale'], '.4g'):>24s}{'processed':>24s}"]
        names = {"pga": "PGA", "pgv": "PGV", "pgd": "PGD", "v_end": "final v", "d_end": "final d",
                 "arias": "Arias", "d5_95": "D5-95"}
        for key, name in names.items():
            lines.append(f"{name + ' [' + STAT_UNITS[key] + ']':16s}{_fmt(self.stats_raw[key]):>24s}"
                         f"{_fmt(self.stats[key]):>24s}")
        if p.get("target"):                       # -ssi_seismic_target (seismic/scaling.py)
            lines.append(p["target"])
        if p.get("baseline_option") == "auto":
            lines.append(f"baseline auto -> {p['baseline']}: {p.get('baseline_reason', '')}")
        if p.get("baseline") == "poly6":
            lines.append(f"poly6 baseline PGA change: {_fmt(np.multiply(self.baseline_pga_change, 100), '+.2f')} %")
        return lines

    def as_arrays(self):
        """name -> (array, unit): the samples and the raw/processed stats, for HDF5."""
        out = {"t": (self.t, "s"), "acceleration": (self.a, "m/s2"), "velocity": (self.v, "m/s"),
               "displacement": (self.d, "m"),
               "baseline_pga_change": (np.asarray(self.baseline_pga_change), "1")}
        for key, unit in STAT_UNITS.items():
            out[f"raw_{key}"] = (np.asarray(self.stats_raw[key]), unit)
            out[key] = (np.asarray(self.stats[key]), unit)
        return out
