"""Twins: two runs that saw the same earthquake (issue 44): the same -ssi_seismic_control, records of the
same SHA-256 driving the same axes, and the same processed accelerations (scale, units, window,
taper, baseline, high-pass). ``post --glance`` (app/glance.py) and ``post --response-spectrum
--ratio`` (app/response.py) refuse a pair that is not, in one line; ``error(msg)`` makes the
caller's exception. A file that says nothing of its input (an earlier petsc-ssi, a run without an
earthquake) is not judged on what it lacks.

The seismic input of a coupled run is in its soil output (OUT.h5); its structure's file
(OUT_structure.h5) is judged by that one (``seismic_file``)."""
import json
import os

import numpy as np


def seismic_file(path):
    """The file that holds the seismic input of the run whose output is ``path``: itself when it has a
    'seismic' group; for a coupled run's structure file (attribute problem 'ssi-structure', named
    STEM_structure.h5) its soil output STEM.h5 when that names it; else None."""
    import h5py
    with h5py.File(path, "r") as f:
        if "seismic" in f:
            return path
        prob = f.attrs.get("problem", "")
        prob = prob.decode() if isinstance(prob, bytes) else str(prob)
    stem, ext = os.path.splitext(path)
    if prob != "ssi-structure" or not stem.endswith("_structure"):
        return None
    soil = stem[:-len("_structure")] + ext
    if not os.path.isfile(soil) or not h5py.is_hdf5(soil):
        return None
    with h5py.File(soil, "r") as f:
        name = f.attrs.get("structure_output", "")
        name = name.decode() if isinstance(name, bytes) else str(name)
        return soil if name == os.path.basename(path) and "seismic" in f else None


def check(a, b, error, what="--ratio"):
    """Refuse (``error``) the pair of outputs a, b when both ran an earthquake and they are not twins
    (``same_control``, ``same_record``, judged on the files that hold their inputs); a pair where only
    one ran an earthquake is refused too (one moved by a record, the other not)."""
    sa, sb = seismic_file(a), seismic_file(b)
    if sa is None and sb is None:
        return
    if (sa is None) != (sb is None):
        has, hasnt = (a, b) if sb is None else (b, a)
        raise error(f"{what}: {has} ran an earthquake (its seismic group) and {hasnt} holds none: not twins; "
                    "compare runs of the same -ssi_seismic_record")
    same_control(sa, sb, error)
    same_record(sa, sb, error)


def control(path):
    """-ssi_seismic_control of the run of the soil output ``path``: its seismic/control, else its
    JSON record's options, else 'surface' (the default) and a note."""
    import h5py
    with h5py.File(path, "r") as f:
        if "seismic/control" in f:
            v = f["seismic/control"][()]
            return (v.decode() if isinstance(v, bytes) else str(v)), "seismic/control"
    js = os.path.splitext(path)[0] + ".json"
    try:
        with open(js) as fh:
            return str(json.load(fh)["options"]["seismic_control"]), os.path.basename(js)
    except (OSError, ValueError, KeyError, TypeError):
        return "surface", "assumed: the default (neither seismic/control nor the JSON record says)"


def same_control(ssi, fixed, error):
    """Refuse a pair of runs whose records drive different motions: -ssi_seismic_control differs, or
    the fixed base took 'incident' before its base moved as twice the record (its output has no
    seismic/control then: until 2026-11-26 a fixed base moved as the record itself). A file that says
    nothing of its control (neither seismic/control nor a JSON record) is not judged."""
    import h5py
    c_s, said_s = control(ssi)
    c_f, said = control(fixed)
    if c_s != c_f and not said.startswith("assumed") and not said_s.startswith("assumed"):
        raise error(f"the runs' -ssi_seismic_control differ: {c_s} in {ssi}, {c_f} in {fixed} ({said}): the "
                     f"bases would not move alike; rerun one of them")
    with h5py.File(fixed, "r") as f:
        old = "seismic" in f and "seismic/control" not in f
    if c_f == "incident" and old:
        raise error(f"{fixed}: a fixed base run with -ssi_seismic_control incident by an earlier petsc-ssi, whose "
                     f"base moved as the record instead of twice it (the free surface); rerun it")


def same_record(ssi, fixed, error):
    """Refuse a pair that did not run the same motion (not twins): the records' SHA-256 (``<axis>_sha256``
    of the seismic groups) differ, the axes the records drive differ, or the processed accelerations
    (``<axis>_acceleration``: the scale, units, window, taper, baseline and high-pass applied) differ.
    A file without them (an earlier petsc-ssi) is not judged on what it lacks."""
    import h5py

    def motions(path):
        out = {}
        with h5py.File(path, "r") as f:
            s = f.get("seismic")
            if not isinstance(s, h5py.Group):
                return out
            for k in s:
                if k.endswith("_acceleration") and not k.startswith("raw_"):
                    ax = k[:-len("_acceleration")]
                    sha = s[ax + "_sha256"][()] if ax + "_sha256" in s else None
                    sha = sha.decode() if isinstance(sha, bytes) else sha
                    out[ax] = (sha, np.asarray(s[k][()], float))
        return out
    ms, mf = motions(ssi), motions(fixed)
    if not ms or not mf:
        return
    if set(ms) != set(mf):
        raise error(f"the runs' records drive different axes: {', '.join(sorted(ms))} in {ssi}, "
                     f"{', '.join(sorted(mf))} in {fixed}: not twins; rerun one with the other's -ssi_seismic_record*")
    for ax in sorted(ms):
        (hs, a_s), (hf, a_f) = ms[ax], mf[ax]
        if hs and hf and hs != hf:
            raise error(f"the runs' records differ ({ax}: SHA-256 {hs[:12]}... in {ssi}, {hf[:12]}... in {fixed}): "
                         f"not twins; rerun one with the other's -ssi_seismic_record")
        if a_s.shape != a_f.shape or not np.allclose(a_s, a_f, rtol=1e-9, atol=1e-12 * max(np.abs(a_s).max(), 1e-300)):
            pk_s, pk_f = float(np.abs(a_s).max()), float(np.abs(a_f).max())
            raise error(f"the runs' processed {ax} records differ (peak {pk_s:.6g} m/s^2 in {ssi}, {pk_f:.6g} in "
                         f"{fixed}): another -ssi_seismic_scale, units, window, taper, baseline or high-pass; not "
                         f"twins: rerun one with the other's -ssi_seismic_* options")
