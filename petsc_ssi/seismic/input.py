"""The earthquake of a run: records read and processed into control motions, the plane wave(s) they
drive, and the free field u_ff(points, t) the scattered-field form needs (``SeismicInput``).

The formulation (Padron, Aznarez & Maeso 2008, Soil Dyn. Earthq. Eng. 28; Wolf 1985, Dynamic
Soil-Structure Interaction, ch. 7): the soil's
total field is u = u_ff + u_sc, with u_ff the free field of the half-space (incident plus
reflected waves, traction-free on z = 0, ``analytic.free_field``). The BEM carries the scattered
field u_sc (it radiates and starts from rest; its history sum runs over scattered values); on the
flat free surface t_ff = 0, so the BE matrices are those of an impedance run and the wave enters
only through the known interface displacement u_sc = u_b - u_ff. Outputs are total fields.

``-ssi_seismic vertical`` takes one record per component (x, y: vertically incident S polarised
along x and y; z: vertically incident P) and the surface motion is uniform; ``sh``, ``sv``, ``p``
take one record and an incidence angle and azimuth, ``rayleigh`` a record of the vertical surface
motion. The record is the surface (outcrop) motion at the control point by default
(``-ssi_seismic_control``). Rank 0 reads and processes the records; every rank gets the same
motions (collective, one-line errors on every rank before any heavy work).
"""
import dataclasses
import warnings

import numpy as np

from ..petsc import SSIError, collective, printf, warn
from ..analytic.free_field import PlaneWave, FreeFieldError, critical_angle
from .records import read_record, process, parse_window, RecordError, RecordWarning

AXES = "xyz"


def _ref_point(text, default):
    if str(text).strip().lower() == "auto":
        return np.asarray(default, float)[:2]
    try:
        v = [float(s) for s in str(text).split(",")]
    except ValueError:
        v = []
    if len(v) != 2 or not np.all(np.isfinite(v)):
        raise SSIError(f"-ssi_seismic_ref '{text}': expected 'auto' or 'x,y' in m")
    return np.asarray(v)


def _window(text):
    """-ssi_seismic_window as ``records.process`` takes it (``records.parse_window``)."""
    try:
        return parse_window(text)
    except ValueError as exc:
        raise SSIError(f"-ssi_seismic_{exc}") from None


def _start(cfg):
    """-ssi_seismic_start: None for auto, else the time shift in seconds."""
    text = str(cfg.seismic_start).strip().lower()
    if text == "auto":
        return None
    try:
        t0 = float(text)
    except ValueError:
        raise SSIError(f"-ssi_seismic_start '{text}': expected auto or seconds") from None
    if not np.isfinite(t0):                 # nan ran to the end with NaN in every dataset
        raise SSIError(f"-ssi_seismic_start '{text}': expected auto or a finite number of seconds")
    return t0


def record_lines(motions, tag):
    """The processing report of every motion (``Motion.summary_lines``), each line led by ``tag``."""
    return [f"{tag}   record" + (f" ({axis})" if axis else "") + ": " + s
            for axis, m in motions.items() for s in m.summary_lines()]


def motion_arrays(motions, t0):
    """{name: (array, unit)} of an output group 'seismic': every processed motion (names led by its
    axis), the record files' SHA-256 and paths, and the time shift t0."""
    out = {}
    for axis, m in motions.items():
        pre = f"{axis}_" if axis else ""
        for name, (arr, unit) in m.as_arrays().items():
            out[pre + name] = (arr, unit)
        out[pre + "sha256"] = (np.bytes_(m.sha256), "SHA-256 of the record file")
        out[pre + "source"] = (np.bytes_(str(m.source)), "path")
        out[pre + "record_t0"] = (np.array(float(m.record_t0)), "s: the record's time at the motion's t = 0 (record "
                                  "time = motion time t + record_t0; before the record's first kept sample when a "
                                  "high-pass pad leads it)")
    out["t0"] = (np.array(t0), "s (run time = motion time t + t0)")
    return out


def record_start(motions, t0):
    """Run time [s] of the first kept sample of the records (after a high-pass's leading pad)."""
    return t0 + max(float(m.processing.get("highpass_pad_s", 0.0)) for m in motions.values())


def late_end(t_end, motions, t0, lead):
    """The warning for a run whose ``t_end`` comes before the records' first kept sample (``lead``:
    what precedes it, for the message), or None."""
    start = record_start(motions, t0)
    if t_end > start:
        return None
    return (f"-ssi_t_end {t_end:g} s ends before the record starts (at {start:.6g} s of run time: {lead}): the run "
            f"sees none of it; give a later -ssi_t_end or leave it out (the run then lasts the record)")


def report(source, t_end, comm, lead):
    """Collective: a seismic source's (``SeismicInput`` or ``SupportMotion``) log lines and notes,
    and ``late_end``'s warning for a run that ends at ``t_end`` [s] (``lead``: what precedes the
    record, for the message)."""
    for line in source.summary_lines():
        printf(line)
    for note in source.notes:
        warn(note, comm)
    late = late_end(t_end, source.motions, source.t0, lead)
    if late:
        warn(late, comm)


def _records(cfg):
    """{axis: Record} of -ssi_seismic_record* ('' for the one record of an oblique or Rayleigh wave)."""
    c = cfg

    def read(path, comp=None):
        return read_record(path, fmt=c.seismic_format, quantity=c.seismic_quantity, units=c.seismic_units,
                           component=comp)
    if c.seismic != "vertical":
        return {"": read(c.seismic_record, c.seismic_component or None)}
    traces = [x.strip() for x in c.seismic_traces.split(",")] if c.get("seismic_traces") else [None] * 3
    traces = [int(x) if x is not None and x.isdigit() else x for x in traces]     # an index, or a channel
    if not c.seismic_record:
        return _distinct({a: read(c.get(f"seismic_record_{a}"), tr) for a, tr in zip(AXES, traces)
                          if c.get(f"seismic_record_{a}") and tr != "-"}, c)
    if c.get("seismic_traces"):                                    # one multi-trace file, a trace per axis
        return _distinct({a: read(c.seismic_record, tr) for a, tr in zip(AXES, traces) if tr != "-"}, c)
    rec = read(c.seismic_record)
    if np.ndim(rec.values) == 2:                                   # a 't ax ay az' table
        return {a: dataclasses.replace(rec, values=rec.values[:, k]) for k, a in enumerate(AXES)}
    axis = (c.seismic_component or "x").strip().lower()[:1]
    if axis not in AXES:
        raise SSIError(f"-ssi_seismic_component {c.seismic_component}: with -ssi_seismic vertical and a "
                       "one-component record, the component it drives: x, y or z")
    return {axis: rec}


def _distinct(recs, cfg):
    """SSIError if one trace of one multi-trace file, or one column of a 't ax ay az' table, drives two axes
    (-ssi_seismic_traces E,E,E drove x, y and z with the east component: a diagonal motion nobody
    recorded; x,x,x did the same with a table's first column). One single-component file given for two
    axes (-ssi_seismic_record_x and _y) is the user's explicit choice and runs."""
    seen = {}
    for axis, r in recs.items():
        m = r.metadata
        if "obspy_format" not in m and not m.get("component"):
            continue
        k = (r.sha256, m.get("station"), m.get("component"), m.get("starttime"))
        if k in seen:
            what = "trace" if "obspy_format" in m else "column"
            raise SSIError(f"-ssi_seismic_traces {cfg.get('seismic_traces') or '(none)'}: the {what} {m.get('component')} "
                           f"of {r.source} drives both {seen[k]} and {axis}; give each axis its own {what} "
                           f"(e.g. {'E,N,Z' if what == 'trace' else 'x,y,z'})")
        seen[k] = axis
    return recs


def read_motions(cfg):
    """{axis: Motion}: the records of ``cfg`` read and processed (``records.process``); one rank's
    work (RecordError, SSIError on a defect)."""
    c = cfg
    out = {}
    recs = _records(cfg)

    def proc(rec, scale):
        return process(rec, scale=scale, window=_window(c.seismic_window), taper=c.seismic_taper,
                       baseline=c.seismic_baseline, highpass=c.seismic_highpass)
    from .scaling import check_units, parse_target, target_factor         # issue 43: units, target
    target = parse_target(c.get("seismic_target", "none"))
    for axis, rec in recs.items():
        if target is None:
            m = proc(rec, c.seismic_scale)
        else:                          # processed again with the target's factor: its warnings then
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RecordWarning)
                m = proc(rec, c.seismic_scale)
        if m.duration < c.dt:
            raise SSIError(f"record '{rec.source}': it lasts {m.duration:.4g} s, less than one step "
                           f"dt = {c.dt:g} s")
        out[axis] = m
    if not any(float(np.max(np.abs(m.a))) > 0.0 for m in out.values()):     # (a zero column of 't ax ay az': fine)
        srcs = sorted({str(m.source) for m in out.values()})
        raise SSIError(f"record '{', '.join(srcs)}': its acceleration is zero everywhere after processing: no motion "
                       "to apply")
    if c.get("seismic_units_check", True):
        check_units(out, c.seismic_units)
    if target is not None:
        f, line = target_factor(out, target, c.seismic_target_damping)
        out = {axis: proc(rec, c.seismic_scale * f) for axis, rec in recs.items()}
        for m in out.values():
            m.processing["target"] = line
    if c.get("seismic_units_check", True):
        from .scaling import check_scaled
        check_scaled(out, c)
    return out


def _unused_angle_notes(cfg):
    """Notes for an azimuth that does not change the wave: -ssi_seismic vertical (each record drives its
    axis) and P at vertical incidence (it moves z alone)."""
    if not cfg.user_set("seismic_azimuth") or cfg.seismic_azimuth == 0.0:
        return []
    if cfg.seismic == "vertical":
        return [f"-ssi_seismic_azimuth {cfg.seismic_azimuth:g} is not used by -ssi_seismic vertical (each "
                "record drives its own axis x, y or z)"]
    if cfg.seismic == "p" and cfg.seismic_angle == 0.0:
        return [f"-ssi_seismic_azimuth {cfg.seismic_azimuth:g} does not change P at vertical incidence (it moves "
                "z alone)"]
    return []


NYQUIST_SHARE = 0.05     # of a record's acceleration energy above the run's Nyquist frequency: said


def _nyquist_notes(motions, dt):
    """A note per record with more than NYQUIST_SHARE of its acceleration's energy above 1 / (2 dt):
    the run takes the record's mean over each step, which filters (and partly folds) that content."""
    from .records import energy_above
    out = []
    fn = 0.5 / dt
    for axis, m in motions.items():
        share = float(np.max(energy_above(m.t, m.a, fn)))
        if share > NYQUIST_SHARE:
            out.append(f"record '{m.source}'" + (f" ({axis})" if axis else "") + f": {100 * share:.0f} % of its "
                       f"acceleration's energy lies above the run's Nyquist frequency 1 / (2 dt) = {fn:.4g} Hz; the "
                       f"run takes its mean over each step of {dt:g} s, which filters it: a smaller -ssi_dt resolves it")
    return out


def _scheme_notes(motions, cfg, scheme):
    """A note per record with energy where the structure's integrator ``scheme`` amplifies a load
    (fem/integrator_response.py ``record_note``: the Green scheme's 1/cos^2(pi f dt)). The domain that
    takes the record names the scheme: a fixed base its -ssi_fem_integrator, the staggered coupling its
    Green scheme (``coupling.step.StaggeredStep.record_scheme``); None (no note) for the implicit
    coupling (the interface force is solved with the soil, not a prescribed load: the demo building under a
    record with 50-90 Hz energy has its roof peak at 5 ms within 2.2 % of 2.5 ms,
    runs/integrators/coupled.csv) and without a structure."""
    if scheme is None:
        return []
    from ..fem.integrator_response import record_note
    advice = ("-ssi_fem_integrator newmark does not amplify it" if cfg.get("problem", "bem") == "fem" else
              "-ssi_coupling implicit (the default) solves the soil's force with the structure instead of "
              "handing it over as an impulse")
    notes = (record_note(scheme, cfg.dt, m.t, m.a, m.source, axis, advice=advice) for axis, m in motions.items())
    return [n for n in notes if n]


def collective_motions(cfg, comm, scheme=None):
    """Collective: (motions, notes): ``read_motions`` on rank 0, broadcast; the processing's
    warnings (``RecordWarning``) as one-line notes, and ``scheme``'s (the structure's integrator that
    takes the record as a load, ``_scheme_notes``); one-line SSIError on every rank on a defect."""
    motions, notes = None, _unused_angle_notes(cfg)
    with collective(comm, "-ssi_seismic", "{what}: {error}"):
        if comm.getRank() == 0:
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always", RecordWarning)
                try:
                    motions = read_motions(cfg)
                except RecordError as exc:
                    raise SSIError(str(exc)) from None
            notes += list(dict.fromkeys(str(w.message) for w in caught        # (once: a target processes twice)
                                        if issubclass(w.category, RecordWarning)))
            notes += _nyquist_notes(motions, cfg.dt)
            notes += _scheme_notes(motions, cfg, scheme)
    return comm.tompi4py().bcast((motions, notes), root=0)


class SupportMotion:
    """Collective: the record of -ssi_seismic vertical as the uniform motion of a fixed base (the
    structure alone, relative-motion form: M u_rel'' + C u_rel' + K u_rel = -M iota a_g(t)), shifted
    like the coupled run's free field (-ssi_seismic_start; auto: one step) so that a structure and
    its fixed-base twin see the same times. ``mean_acceleration(axis, t0, t1)``: the mean of a_g over
    [t0, t1] (exact for the piecewise-linear record: the velocity difference over the length)."""

    def __init__(self, cfg, comm, scheme=None):
        if cfg.seismic != "vertical":
            raise SSIError(f"-ssi_seismic {cfg.seismic}: a fixed base moves as one: the structure alone (-ssi_problem "
                           "fem) takes -ssi_seismic vertical (one record per component)")
        self.cfg, self.kind = cfg, cfg.seismic
        # the base moves as the free surface: the record itself (control surface), or twice the incident
        # wave it gives (control incident: at vertical incidence S and P double at the free surface)
        self.factor = 2.0 if cfg.seismic_control == "incident" else 1.0
        self.motions, self.notes = collective_motions(cfg, comm, scheme)
        t0 = _start(cfg)
        if t0 is not None and t0 < 0:
            raise SSIError(f"-ssi_seismic_start {t0:g}: a negative shift drops the first {-t0:g} s of the record (the "
                           "fixed base starts at t = 0); give a shift >= 0, or auto (one step)")
        self.t0 = cfg.dt if t0 is None else t0
        self.duration = self.t0 + max(m.t[-1] for m in self.motions.values())

    def velocity(self, axis, t):
        """The ground's velocity along ``axis`` at times t (any shape) [m/s]."""
        m = self.motions.get(axis)
        t = np.asarray(t, float)
        return np.zeros_like(t) if m is None else self.factor * m(t - self.t0, 1)

    def mean_acceleration(self, axis, t0, t1):
        """The mean ground acceleration along ``axis`` over [t0, t1] (arrays allowed) [m/s^2]."""
        return (self.velocity(axis, t1) - self.velocity(axis, t0)) / (np.asarray(t1) - np.asarray(t0))

    def acceleration(self, axis, t):
        """The ground's acceleration along ``axis`` at times t (any shape) [m/s^2]."""
        m = self.motions.get(axis)
        t = np.asarray(t, float)
        return np.zeros_like(t) if m is None else self.factor * m(t - self.t0, 2)

    def summary_lines(self):
        lines = [f"[fem] support motion (-ssi_seismic vertical, fixed base, relative-motion form): start t0 = "
                 f"{self.t0:.6g} s, record until {self.duration:.6g} s, control {self.cfg.seismic_control}"
                 + (" (the base moves as the free surface: twice the incident record)" if self.factor != 1.0
                    else "")]
        return lines + record_lines(self.motions, "[fem]")

    def arrays(self):
        out = motion_arrays(self.motions, self.t0)
        out["control"] = (np.bytes_(self.cfg.seismic_control), "-ssi_seismic_control: surface (the base moves as "
                          "the record) or incident (as twice the record: the free surface at vertical incidence)")
        return out


class SeismicInput:
    """Collective: the seismic input of ``cfg`` (group "seismic") on a soil of speeds ``cs``, ``cp``
    and density ``rho``; ``points``: every soil node the run touches (the automatic start keeps the
    free field zero there for t <= 0); ``ref``: the default control point (x, y); ``dt``: the step;
    ``scheme``: the integrator of a structure that takes the record as a load (``_scheme_notes``).

    ``u(points, t)``: the free-field displacement (n, 3) [m] (sum of the waves); ``summary_lines``,
    ``arrays`` (the output group 'seismic', units in ``units``), ``key`` (the records' SHA-256, for
    checkpoints), ``duration`` (s, from t = 0 to the end of the shifted record)."""

    def __init__(self, cfg, comm, cs, cp, rho, points, ref, dt, scheme=None):
        self.cfg, self.kind = cfg, cfg.seismic
        self.motions = None
        self.precursor = None           # (taper_before, width, tail level) of a tapered H[g] (free_field)
        self.motions, self.notes = collective_motions(cfg, comm, scheme)
        with collective(comm, f"-ssi_seismic {self.kind}", "{what}: {error}"):
            self.waves = self._waves(cs, cp, rho, _ref_point(cfg.seismic_ref, ref))
            self._start(np.asarray(points, float), dt)
        self.key = {a: m.sha256 for a, m in self.motions.items()}

    # ------------------------------------------------------------ waves
    def _waves(self, cs, cp, rho, x0):
        c = self.cfg
        try:
            if self.kind == "vertical":
                return [PlaneWave("vertical_p" if a == "z" else "vertical_s", cs, cp, m, x0=x0,
                                  polarisation=90.0 if a == "y" else 0.0, control=c.seismic_control, rho=rho)
                        for a, m in self.motions.items()]
            m = self.motions[""]
            wave = {"sh": "sh", "sv": "sv", "p": "p", "rayleigh": "rayleigh"}[self.kind]
            grid = np.arange(-0.5 * m.duration, 2.0 * m.duration + m.t[-1], max(np.min(np.diff(m.t)), 1e-4))
            w = PlaneWave(wave, cs, cp, m, angle=c.seismic_angle if wave != "rayleigh" else 0.0,
                          azimuth=c.seismic_azimuth, x0=x0, control=c.seismic_control,
                          component=c.seismic_direction, postcritical=c.seismic_postcritical, rho=rho,
                          t_grid=grid)
            if w.needs_hilbert:
                self._at_rest(m)
                self.precursor = w.taper_precursor(c.seismic_hilbert_tol)
            return [w]
        except FreeFieldError as exc:
            msg = str(exc)
            if self.kind == "sv" and "critical" in msg:
                msg = (f"SV at {c.seismic_angle:g} degrees is beyond the critical angle "
                       f"{critical_angle(cs, cp):.4f} degrees of this soil; add -ssi_seismic_postcritical")
            raise SSIError(msg) from None

    def _at_rest(self, m):
        """Refuse a record whose displacement does not return to rest (a Hilbert transform, which a
        Rayleigh or post-critical SV field holds, does not exist for a permanent offset or drift):
        the final displacement within 1 % of PGD, the final velocity within 1 % of PGV (the record
        processing's own warning level)."""
        pgd, pgv, d_end, v_end = (float(np.max(np.abs(m.stats[k]))) for k in ("pgd", "pgv", "d_end", "v_end"))
        if d_end > 0.01 * pgd or v_end > 0.01 * pgv:
            raise SSIError(f"the record's displacement does not return to rest (final displacement {d_end:.3g} m, "
                           f"final velocity {v_end:.3g} m/s, PGD {pgd:.3g} m): the Hilbert transform that "
                           f"-ssi_seismic {self.kind} needs does not exist for a permanent offset; high-pass filter "
                           f"the record (-ssi_seismic_highpass, e.g. 0.1 Hz)")

    def _start(self, points, dt):
        auto = max(w.auto_start(points, dt) for w in self.waves)
        t0 = _start(self.cfg)
        if t0 is None:
            t0 = auto
        else:
            need = auto - dt
            if t0 < need:
                raise SSIError(f"-ssi_seismic_start {t0:g}: the free field would not be at rest at t = 0 at every "
                               f"soil node (the wave needs t0 >= {need:.6g} s here); use auto")
        for w in self.waves:
            w.t0 = t0
        self.t0 = t0
        self.duration = t0 + max(m.t[-1] for m in self.motions.values())

    # ------------------------------------------------------------ evaluation
    def _sum(self, what, points, t):
        pts = np.asarray(points, float).reshape(-1, 3)
        return sum((getattr(w, what)(pts, t) for w in self.waves), np.zeros((len(pts), 3)))

    def u(self, points, t):
        """The free-field displacement at ``points`` (n, 3) at time t (scalar) [m]."""
        return self._sum("displacement", points, t)

    def acceleration(self, points, t):
        """The free-field acceleration at ``points`` at time t [m/s^2]."""
        return self._sum("acceleration", points, t)

    def velocity(self, points, t):
        """The free-field velocity at ``points`` (n, 3) at time t [m/s]."""
        return self._sum("velocity", points, t)

    def stress(self, points, t):
        """The free-field Cauchy stress at ``points`` (n, 3) at time t (scalar): (n, 3, 3) [Pa],
        tension positive (zero traction on the free surface z = 0)."""
        pts = np.asarray(points, float).reshape(-1, 3)
        return sum((w.stress(pts, t) for w in self.waves), np.zeros((len(pts), 3, 3)))

    def traction(self, points, normals, t):
        """The free field's traction t_ff = sigma_ff n on faces through ``points`` (n, 3) with unit
        normals ``normals`` (n, 3) (any orientation: a basement's walls and bottom) at time t [Pa].
        On a face of the soil's boundary the scattered field's traction is -t_ff (the total
        traction there is zero, or the structure's)."""
        n = np.asarray(normals, float).reshape(-1, 3)
        return np.einsum("pij,pj->pi", self.stress(points, t), n)

    def traction_integral(self, points, normals, t):
        """int_{-inf}^t sigma_ff n dt' at ``points`` (n, 3) for the (not necessarily unit) ``normals`` (n, 3)
        [Pa s]: the difference of two values over a step is the step's exact mean traction times dt
        (``sources.free_field.FreeFieldTraction``)."""
        pts = np.asarray(points, float).reshape(-1, 3)
        S = sum((w.stress_integral(pts, t) for w in self.waves), np.zeros((len(pts), 3, 3)))
        return np.einsum("pij,pj->pi", S, np.asarray(normals, float).reshape(-1, 3))

    def rotation(self, points, t):
        """The rotation of the free surface at surface ``points`` (n, 3) at time t (scalar or 1-D):
        1/2 curl u_ff = (du_z/dy, -du_z/dx, (du_y/dx - du_x/dy)/2) [rad], (n, 3) or (nt, n, 3). Each
        plane wave is a function of t - p e_h.(x - x0) along the surface, so du/dx_j = -p e_h[j]
        du/dt; traction-free (sigma_xz = sigma_yz = 0) makes 1/2 curl's horizontal components the
        surface's tilts."""
        pts = np.asarray(points, float).reshape(-1, 3)
        out = 0.0
        for w in self.waves:
            if w.p == 0.0:
                continue
            v = w.velocity(pts, t)
            gx, gy = -w.p * w.e_h[0], -w.p * w.e_h[1]         # d/dx = gx d/dt, d/dy = gy d/dt
            out = out + np.stack([gy * v[..., 2], -gx * v[..., 2],
                                  0.5 * (gx * v[..., 1] - gy * v[..., 0])], axis=-1)
        if np.isscalar(out):
            shape = (len(pts), 3) if np.ndim(t) == 0 else (len(np.atleast_1d(t)), len(pts), 3)
            return np.zeros(shape)
        return out

    def uniform(self):
        """Whether the free field is the same at every point (vertical incidence)."""
        return self.kind == "vertical"

    def direction(self):
        """The components the free field moves (for the symmetry check): (3,) of 0/1."""
        v = np.zeros(3)
        for w in self.waves:
            amp = np.abs(np.asarray(w.surface_coefficients(), complex))
            v += (amp[0] > 0) * np.abs(w.e_h) + (amp[1] > 0) * np.array([0.0, 0.0, 1.0]) + \
                (amp[2] > 0) * np.abs(w.e_t)
        return (v > 1e-12).astype(float)

    def summary_lines(self):
        c = self.cfg
        head = (f"[ssi] seismic input: {self.kind}" +
                (f", angle {c.seismic_angle:g} deg, azimuth {c.seismic_azimuth:g} deg" if self.kind in ("sh", "sv", "p")
                 else "") + f", control {c.seismic_control}, start t0 = {self.t0:.6g} s, free field until "
                f"{self.duration:.6g} s")
        lines = [head]
        if self.precursor is not None:
            tb, w, tail = self.precursor
            lines.append(f"[ssi]   the field holds H[g], the record's Hilbert transform, which starts before the record: "
                         f"tapered to zero over {w:.4g} s before {tb:.4g} s of the record (where |H[g]| stays within "
                         f"{c.seismic_hilbert_tol:g} of its peak: -ssi_seismic_hilbert_tol; largest value tapered "
                         f"{tail:.3g} m); the wave starts {-(tb - w):.4g} s before the record")
        return lines + record_lines(self.motions, "[ssi]")

    def arrays(self):
        """{name: (array, unit)} of the output group 'seismic': the processed motions (per component)
        and the wave's parameters."""
        out = motion_arrays(self.motions, self.t0)
        out["angle"] = (np.array(float(self.cfg.seismic_angle)), "deg")
        out["azimuth"] = (np.array(float(self.cfg.seismic_azimuth)), "deg")
        out["control"] = (np.bytes_(self.cfg.seismic_control), "-ssi_seismic_control: surface (the record is the "
                          "free-field surface motion at the control point) or incident")
        return out
