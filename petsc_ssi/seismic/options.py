"""Options of the earthquake input (group "seismic", prefix ``-ssi_seismic``): the plane wave, the
record and its processing. A problem that takes a seismic input (``bem``, ``ssi``; the ``fem``
structure alone takes the same record as a support motion) reads them. Units SI, angles degrees."""
from ..options import register, register_check
from .. import common_options  # noqa: F401

G = "seismic"


def _target_ok(text):
    from .scaling import target_validator
    return target_validator(text)
WAVES = ("none", "vertical", "sh", "sv", "p", "rayleigh")

register("seismic", "enum", "none", "", "plane-wave earthquake input in the scattered-field form: none, vertical "
         "(vertically incident S in x and y, P in z, from one record per component), sh, sv, p (oblique, "
         "-ssi_seismic_angle), rayleigh", G, choices=WAVES)
register("seismic_record", "str", "", "", "the record: PEER .AT2/.VT2/.DT2, a table 't a' (or 't ax ay az' for "
         "vertical), or a seismological format through ObsPy (miniSEED, SAC, K-NET, Kinemetrics EVT, ...)", G)
register("seismic_record_x", "str", "", "", "vertical: the record of the x component (any subset of x, y, z)", G)
register("seismic_record_y", "str", "", "", "vertical: the record of the y component", G)
register("seismic_record_z", "str", "", "", "vertical: the record of the z component (vertical P)", G)
register("seismic_format", "str", "auto", "", "record format: auto (by extension/header), peer, table, obspy or "
         "an ObsPy format name", G)
register("seismic_quantity", "enum", "auto", "", "what the record holds: auto (the file says; tables: "
         "acceleration), acceleration, velocity, displacement", G,
         choices=("auto", "acceleration", "velocity", "displacement"))
register("seismic_units", "str", "auto", "", "record units: auto (the file's), g, m/s2, cm/s2, gal, m/s, cm/s, m, "
         "cm, mm", G)
register("seismic_component", "str", "", "", "the trace of a multi-trace ObsPy file (channel code suffix or "
         "index) or the column of a 4-column table (x, y, z)", G)
register("seismic_traces", "str", "", "", "-ssi_seismic vertical with multi-trace files (miniSEED, SAC, ... "
         "through ObsPy): the traces that drive x, y and z, e.g. 'E,N,Z', 'HNE,HNN,HNZ' or '0,1,2' (a channel "
         "code, its suffix or the trace's index; '-' leaves an axis out); with one file in -ssi_seismic_record "
         "each listed trace drives its axis, with -ssi_seismic_record_x/_y/_z each file gives its axis's trace", G)
register("seismic_scale", "real", 1.0, "", "amplitude factor after unit conversion", G)
register("seismic_units_check", "bool", True, "", "refuse a record whose PGA as read (in its -ssi_seismic_units, "
         "before -ssi_seismic_scale) is above 5 g or below 1e-6 g, implausible for an earthquake: most likely wrong "
         "units; and a run whose PGA after -ssi_seismic_scale or -ssi_seismic_target is (0: run it anyway)", G)
register("seismic_target", "str", "none", "m/s^2, s", "scale the processed record(s) to a target: none, 'pga:A' "
         "(PGA A), 'psa:T:A' (pseudo-spectral acceleration at the period T [s] with -ssi_seismic_target_damping, "
         "ASCE 7 amplitude scaling) or 'sa:T:A' (spectral acceleration); A in m/s^2, or in g with a suffix g "
         "('pga:0.4g'); one factor for every component, set by the horizontal ones (larger PGA, RotD100 of x and "
         "y); seismic/scaling.py", G, validator=_target_ok)
register("seismic_target_damping", "real", 0.05, "1", "damping ratio of -ssi_seismic_target psa/sa", G,
         validator=lambda v: None if 0.0 <= v < 1.0 else "must lie in [0, 1)")
register("seismic_control", "enum", "surface", "", "surface: the record is the free-field surface (outcrop) "
         "motion at the control point; incident: the record is the incident wave (the surface motion is twice "
         "it at vertical incidence)", G, choices=("surface", "incident"))
register("seismic_direction", "enum", "auto", "", "the surface component the record controls: auto (SH "
         "transverse, SV horizontal, P vertical, Rayleigh vertical), horizontal, vertical, transverse", G,
         choices=("auto", "horizontal", "vertical", "transverse"))
register("seismic_angle", "real", 0.0, "deg", "incidence angle from the vertical, 0 <= angle < 90 (sh, sv, p)", G)
register("seismic_azimuth", "real", 0.0, "deg", "horizontal propagation direction, from +x toward +y", G)
register("seismic_postcritical", "bool", False, "", "allow SV beyond the critical angle (a Hilbert-transform "
         "field: its acausal precursor is tapered, -ssi_seismic_hilbert_tol)", G)
register("seismic_hilbert_tol", "real", 0.01, "", "rayleigh and post-critical SV: the free field holds the "
         "Hilbert transform H[g] of the record, which begins before the record does (a tail ~1/t where the "
         "displacement's integral is not zero). It is tapered to zero from where it stays below this fraction "
         "of its peak, and the automatic start begins the wave before that: smaller is more exact and starts "
         "earlier (more steps); the run's log gives the length", G,
         validator=lambda v: None if 0.0 < v < 1.0 else "must lie in (0, 1)")
register("seismic_ref", "str", "auto", "m", "control point 'x,y' on the surface (auto: the centroid of the "
         "interface, or of the prescribed region, else the origin)", G)
register("seismic_start", "str", "auto", "s", "time shift t0 of the wave: auto (the smallest that keeps the free "
         "field zero for t <= 0 at every soil node, plus one step) or seconds", G)
register("seismic_window", "str", "all", "", "part of the record: all, 't0,t1' (s of the record) or "
         "'arias:p0,p1' (fractions of the Arias intensity)", G)
register("seismic_taper", "real", 0.05, "", "Hann taper fraction at both ends (0: none)", G,
         validator=lambda v: None if 0.0 <= v <= 0.5 else "must lie in [0, 0.5]")
register("seismic_baseline", "enum", "auto", "", "baseline correction: auto (none when the tapered record ends at "
         "rest, |v_end| <= 1 % PGV and |d_end| <= 10 % PGD, else whichever of mean and poly6 leaves it nearest rest; "
         "the log says which and why), poly6 (sixth-order displacement fit, PEER/USGS), mean (pre-event mean), none", G,
         choices=("auto", "poly6", "mean", "none"))
register("seismic_highpass", "real", 0.0, "Hz", "corner frequency of an acausal (zero-phase) Butterworth "
         "high-pass of order 4 applied to the tapered, zero-padded acceleration (pads of 1.5 n / f_c in all, "
         "half at each end, kept: the motion lasts that much longer; PEER's processing; e.g. 0.1): removes the "
         "drift that the baseline leaves (0: none)", G,
         validator=lambda v: None if v >= 0 else "must be >= 0")
register("seismic_combine", "enum", "refuse", "", "a soil load (-ssi_load_group) with a seismic input: refuse, "
         "or superpose (the load acts on the scattered field, the wave is added)", G,
         choices=("refuse", "superpose"))


def _checks(cfg):
    if cfg.get("seismic", "none") == "none":
        used = [k for k in ("seismic_record", "seismic_record_x", "seismic_record_y", "seismic_record_z")
                if cfg.user_set(k)]
        return f"-ssi_{used[0]} is set but -ssi_seismic is none: say which wave (vertical, sh, sv, p, rayleigh)" \
            if used else None
    w = cfg.seismic
    comps = [cfg.get(f"seismic_record_{c}") for c in "xyz"]
    if w == "vertical":
        if not cfg.seismic_record and not any(comps):
            return "-ssi_seismic vertical: give -ssi_seismic_record (a table 't ax ay az' or one component) or " \
                   "-ssi_seismic_record_x/_y/_z"
        if cfg.seismic_record and any(comps):
            return "-ssi_seismic vertical: give either -ssi_seismic_record or -ssi_seismic_record_x/_y/_z, not both"
        if cfg.seismic_traces:
            tr = [x.strip() for x in cfg.seismic_traces.split(",")]
            if len(tr) != 3 or any(not x for x in tr) or all(x == "-" for x in tr):
                return f"-ssi_seismic_traces {cfg.seismic_traces}: give three traces x,y,z (a channel code, its " \
                       "suffix or an index; '-' leaves an axis out), e.g. E,N,Z"
            if cfg.seismic_record and cfg.user_set("seismic_component"):
                return "-ssi_seismic_traces and -ssi_seismic_component: give one (traces: x,y,z of a multi-trace file)"
    else:
        if any(comps):
            return f"-ssi_seismic_record_x/_y/_z are for -ssi_seismic vertical; -ssi_seismic {w} takes " \
                   "-ssi_seismic_record"
        if cfg.seismic_traces:
            return f"-ssi_seismic_traces is for -ssi_seismic vertical (three axes); -ssi_seismic {w} takes one " \
                   "trace: -ssi_seismic_component"
        if not cfg.seismic_record:
            return f"-ssi_seismic {w}: give the record (-ssi_seismic_record FILE)"
    if w in ("sh", "sv", "p") and not 0.0 <= cfg.seismic_angle < 90.0:
        return f"-ssi_seismic_angle {cfg.seismic_angle:g}: must lie in [0, 90) degrees"
    if w in ("vertical", "rayleigh") and cfg.user_set("seismic_angle") and cfg.seismic_angle != 0.0:
        return f"-ssi_seismic_angle {cfg.seismic_angle:g}: not used by -ssi_seismic {w}"
    if (cfg.get("load_group") or cfg.get("load_area")) and cfg.get("load_p0", 0.0) != 0.0 \
            and cfg.seismic_combine == "refuse":
        which = "-ssi_load_group" if cfg.get("load_group") else "-ssi_load_area"
        return (f"{which} with -ssi_seismic: say how the soil load and the wave combine "
                "(-ssi_seismic_combine superpose)")
    return None


register_check(("seismic",), _checks)
