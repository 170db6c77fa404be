"""``petsc-ssi post FILE.h5 [--receivers --csv] [--plot PNG] [--info] [--spectrum | --transfer A B]``.

Reads an output file with h5py (serial; no PETSc needed):
  --receivers --csv [OUT.csv]  one row per receiver and step (standard output without a
                      name) of the --quantity or --series: header ``receiver,x_m,y_m,z_m,t_s,ux_m,uy_m,uz_m``
                      (vx_m_s.., ax_m_s2.., rx_rad..: each column's unit in its name; SI)
  --plot PNG          receiver time histories (with the Pekeris patch solution
                      when the run was a Lamb problem)
  --info              what the file holds
  --series G/NAME --csv [OUT.csv]
                      (without --receivers, --spectrum, --transfer) any time series of the
                      file as columns: t [s], then one column per component, named
                      NAME_x [unit] (the unit from the dataset's attribute), e.g.
                      demands/base_shear, demands/drift_ratio (a column per storey),
                      interface/force_fe, resultants/force, input_motion/..., seismic/x_acceleration;
                      '#' lines first: file, series, unit, convention
  --demands --csv [OUT.csv]
                      the storey demands' summary of a structure output (group demands):
                      peak drift ratio per storey, peak base shear, V/W (W = m g of the
                      structure's mass attribute), peak overturning moment, each with its
                      time; columns quantity,storey,component,value,unit,time_s
  --forces [PART,...] --csv [OUT.csv]
                      the member forces of a structure output (-ssi_structure_forces) as
                      section resultants an engineer reads: frames at each end (N > 0
                      tension), shells at each element's centre; per element, end and
                      component the peak |E(t)| over every step and, with -ssi_fem_gravity,
                      G, G + E max and G + E min in the same convention; columns
                      part,element,end,node,x_m,y_m,z_m,component,unit,peak_abs,gravity,
                      gravity_plus_max,gravity_plus_min (every part without a name)

Frequency domain (petsc_ssi.spectrum; numpy FFT of the stored series):
  --spectrum          one-sided amplitude spectrum |X(f)| of a series, scaled so
                      that a sine of amplitude A gives a peak A (exact with
                      --window none and an integer number of periods; other
                      windows divide out their coherent gain): the series' unit.
                      Prints the highest peaks (component,rank,f_hz,amplitude_<unit>).
  --response-spectrum response spectra (SA, PSA, PSV, SD, SV; RotD50/RotD100, ratios of
                      two spectra) of a receiver's acceleration: ``petsc-ssi post FILE.h5
                      --response-spectrum --help`` (``app/response.py``)
  --glance FIXED.h5   SSI at a glance: FILE.h5 a coupled run with an earthquake, FIXED.h5
                      its fixed-base twin; first frequency and damping of each (transfer
                      function roof / ground), period lengthening, peak roof acceleration,
                      drift and base shear: ``petsc-ssi post FILE.h5 --glance FIXED.h5
                      --help`` (``app/glance.py``)
  --transfer A B      transfer function H = B / A of two series on the same time
                      grid, magnitude and phase.  A and B are each
                        K                  receiver K of the selected series of FILE
                        FILE2.h5:K         receiver K of the same series of FILE2
                        [FILE2.h5:]GROUP/NAME[@K]   any series, e.g. interface/force_be
                      H is a regularised single-record ratio (water level)
                      H = B conj(A) / (|A|^2 + (eps max|A|)^2), no averaging and
                      no coherence: rows with reliable=0 (|A| < 5% max|A|) are
                      not to be trusted.
 Series selection (both):
  --quantity Q        u (default) | velocity | acceleration | rotation: the
                      dataset receivers/Q (structure outputs hold all four)
  --series G/NAME     any time series dataset with a sibling G/t, shape (K,),
                      (K, 3) or (K, R, 3); e.g. interface/force_be,
                      interface/force_fe of coupled runs (overrides --quantity)
  --receiver K        receiver index for (K, R, 3) series (default 0)
  --component C       x | y | z | all (default all)
 Spectral options:
  --pad P             zero-pad to the next power of two >= P * N samples
                      (default: none, nfft = N).  Refines the grid df = 1/(nfft dt),
                      not the resolution 1/(N dt)
  --window W          none (default) | hann | tukey (--tukey-alpha, default 0.25)
  --detrend D         none (default) | mean | linear, before windowing
  --fmax F            output, peaks and plot limited to f <= F Hz
  --peaks N           the N highest peaks printed and marked (default 5), at
                      least --min-sep Hz apart (default: the resolution 1/(N dt)),
                      at f >= --fmin (default 1/(N dt): less than one period in
                      the record is not told apart from the mean; the first bins
                      also carry the one-sided 2x scaling step next to f = 0)
  --eps E             transfer regularisation (default 1e-3)
  --csv [OUT.csv]     write the spectrum (stdout without a name): '#' header lines
                      (file, series, window, padding, dt, df, resolution,
                      scaling), then columns f_hz and one per component
                      (transfer: f_hz, then |H|, phase_deg, reliable per component)
  --png OUT.png       plot (matplotlib Agg) with the peaks marked in Hz; the
                      title states window, padding and df
  --overwrite         replace an existing --csv/--png/--plot file of ours
Output files (--csv OUT.csv, --png, --plot) are checked before anything is read or
written: one naming an input file or its sidecars (.xmf, .json, .lock), or any
existing HDF5 file, is refused even with --overwrite; another existing file is
refused without --overwrite, as a run's -ssi_output is without -ssi_output_overwrite.
Errors (missing series, non-uniform time grid, different grids) end with one
line ``petsc-ssi post: error: ...`` on stderr and exit status 2.
"""
import argparse
import os
import sys

import numpy as np

COMPONENTS = ("x", "y", "z")
QUANTITIES = ("u", "velocity", "acceleration", "rotation")


class PostError(Exception):
    """A one-line error of the post command (exit status 2)."""


HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"


def is_hdf5(path):
    """Whether ``path`` is an HDF5 file (its signature at byte 0, 512, 1024, ... as HDF5 places it)."""
    try:
        with open(path, "rb") as fh:
            for off in (0, 512, 1024, 2048, 4096, 8192):
                fh.seek(off)
                if fh.read(8) == HDF5_SIGNATURE:
                    return True
    except OSError:
        return False
    return False


def _same_file(a, b):
    if os.path.realpath(a) == os.path.realpath(b):
        return True
    try:
        return os.path.samefile(a, b)
    except OSError:
        return False


def check_outputs(outputs, inputs, overwrite, flag="--overwrite"):
    """Before anything is read or written: PostError (one line) unless every output file of
    ``outputs`` [(option, path or None/True/'-' for none or standard output)] may be written: not
    an input of ``inputs`` nor one of its sidecars (.xmf, .json, .lock), never an existing HDF5
    file (a result), not a directory, not an existing file without ``overwrite``, in an existing
    directory, and no two outputs the same file."""
    named = [(opt, p) for opt, p in outputs if isinstance(p, str) and p and p != "-"]
    for opt, path in named:
        for src in inputs:
            stem = os.path.splitext(src)[0]
            for f in (src, stem + ".xmf", stem + ".json", src + ".lock"):
                if _same_file(path, f):
                    what = "the input file" if f == src else f"a sidecar of the input file {src}:"
                    raise PostError(f"{opt} {path}: is {what} {f}; refusing to overwrite it")
        if os.path.isdir(path):
            raise PostError(f"{opt} {path}: is a directory")
        if os.path.lexists(path) and is_hdf5(path):
            raise PostError(f"{opt} {path}: is an existing HDF5 file (a result); post never writes over one")
        if os.path.lexists(path) and not overwrite:
            raise PostError(f"{opt} {path}: exists (give {flag} to replace it)")
        d = os.path.dirname(os.path.abspath(path))
        if not os.path.isdir(d):
            raise PostError(f"{opt} {path}: no directory {d}")
    for i, (o1, p1) in enumerate(named):
        for o2, p2 in named[i + 1:]:
            if os.path.abspath(p1) == os.path.abspath(p2):
                raise PostError(f"{o2} {p2}: the same file as {o1}")


def open_h5(path):
    """h5py.File(path, "r"), or PostError naming ``path`` and why it cannot be read: missing,
    a directory, not HDF5, or an HDF5 file that does not open (truncated: a run killed without
    warning, a copy cut short)."""
    import h5py
    if not os.path.exists(path):
        raise PostError(f"{path}: no such file")
    if os.path.isdir(path):
        raise PostError(f"{path}: a directory, not an output file")
    if not h5py.is_hdf5(path):
        raise PostError(f"{path}: not an HDF5 file ({os.path.getsize(path)} bytes without HDF5's signature)")
    try:
        return h5py.File(path, "r")
    except OSError as exc:
        raise PostError(f"{path}: an HDF5 file that cannot be read, truncated or damaged (a run killed "
                        f"without warning, a copy cut short): {' '.join(str(exc).split())}") from None


def world_rank():
    """This process's rank under mpirun (0 outside it), from the launcher's environment: post is
    serial, so under ``mpirun -n 2`` only rank 0 writes and reports (the others check the file and
    exit with its status)."""
    for k in ("OMPI_COMM_WORLD_RANK", "PMIX_RANK", "PMI_RANK", "MV2_COMM_WORLD_RANK"):
        if os.environ.get(k, "").isdigit():
            return int(os.environ[k])
    return 0


def receivers(path):
    with open_h5(path) as f:
        if "receivers" not in f:
            raise SystemExit(f"petsc-ssi post: error: {path} holds no receiver series")
        g = f["receivers"]
        return g["points"][:], g["t"][:], g["u"][:]


CSV_COLUMNS = {"receivers/u": "u", "receivers/velocity": "v", "receivers/acceleration": "a",
               "receivers/rotation": "r"}


def unit_suffix(unit):
    """A column name's unit suffix, as the other CSVs write them (f_hz, time_s): '_m', '_m_s' for m/s, '_m_s2' for
    m/s^2, '_rad'; '' without a unit."""
    u = str(unit or "").strip()
    if not u:
        return ""
    return "_" + u.replace("^", "").replace("/", "_").replace(" ", "_").replace("*", "")


def series_unit(path, series):
    """The unit a series of an output file carries (its dataset's 'unit' attribute), '' without one."""
    with open_h5(path) as f:
        d = f.get(series.strip("/"))
        u = d.attrs.get("unit", "") if d is not None else ""
    return u.decode() if isinstance(u, bytes) else str(u)


def write_csv(path, out=None, series="receivers/u"):
    """One row per receiver and step of ``series`` (a (K, R, 3) receiver series, --quantity or
    --series): receiver,x_m,y_m,z_m,t_s then its three components with their unit in the name, ux_m,uy_m,uz_m,
    vx_m_s,vy_m_s,vz_m_s, ax_m_s2,ay_m_s2,az_m_s2, rx_rad,ry_rad,rz_rad (others: NAME_x,NAME_y,NAME_z with the
    dataset's 'unit' attribute as a suffix, ``unit_suffix``); SI units; a receiver without rotations (not at a frame
    or shell node) has empty rotation cells."""
    import h5py
    out = sys.stdout if out is None else out
    series = series.strip("/")
    grp, _, name = series.rpartition("/")
    if not os.path.exists(path):
        raise PostError(f"{path}: no such file")
    with h5py.File(path, "r") as f:
        if series not in f:
            have = [k for k in (f[grp].keys() if grp in f else []) if k not in ("t", "points")]
            raise PostError(f"{path} holds no series {series}" + (f" (the group {grp} holds: {', '.join(sorted(have))})"
                                                                   if have else ""))
        x = f[series][:]
        if x.ndim != 3 or x.shape[2] != 3 or grp + "/points" not in f:
            raise PostError(f"--receivers --csv: {series} is not a receiver series (K, R, 3) with {grp}/points; "
                            "--spectrum --csv writes any series")
        pts, t = f[grp + "/points"][:], f[grp + "/t"][:]
        units = [f[k].attrs.get("unit", "") for k in (grp + "/points", grp + "/t", series)]
        units = [u.decode() if isinstance(u, bytes) else str(u) for u in units]
        has = f[grp + "/has_rotation"][:].astype(bool) if name == "rotation" and grp + "/has_rotation" in f else None
    p = CSV_COLUMNS.get(series)
    up, ut, ux = (unit_suffix(u) for u in units)
    cols = [p + c + ux for c in "xyz"] if p else [f"{name}_{c}{ux}" for c in "xyz"]
    out.write(f"receiver,x{up},y{up},z{up},t{ut}," + ",".join(cols) + "\n")
    for k, q in enumerate(pts):
        for i, ti in enumerate(t):
            vals = ",," if has is not None and not has[k] else ",".join(f"{v:.9e}" for v in x[i, k])
            out.write(f"{k},{q[0]:.9g},{q[1]:.9g},{q[2]:.9g},{ti:.9g},{vals}\n")


def info(path, out=None):
    out = sys.stdout if out is None else out
    from ..io.output import missing_part
    gone = missing_part(path)
    if gone:                 # its snapshots there cannot be read: not reported as if they could
        raise PostError(f"{gone}; restore the part (the output of a running or stopped run links its snapshots "
                        "to the files of <stem>.parts/)")
    with open_h5(path) as f:
        for k, v in f.attrs.items():
            out.write(f"{k}: {v}\n")
        out.write("datasets: " + ", ".join(sorted(f.keys())[:12]) + (" ..." if len(f.keys()) > 12 else "") + "\n")


# ---------------------------------------------------------------- any series as CSV (issue 43)

G_STANDARD = 9.80665          # m/s^2: the weight W = m g of post --demands


def _time_key(f, grp, name):
    """The time grid of GROUP/NAME: the sibling GROUP/t, or GROUP/<c>_t for GROUP/<c>_<what> (the
    seismic group's per-component records)."""
    base = (grp + "/") if grp else ""
    for key in (base + "t", base + name.split("_")[0] + "_t"):
        if key in f and key != base + name:
            return key
    return None


def _unit(d):
    u = d.attrs.get("unit")
    return (u.decode() if isinstance(u, bytes) else str(u)) if u is not None else "unit not recorded"


def series_csv(path, series, out=None):
    """Any time series GROUP/NAME of an output file as CSV: '#' lines (file, series, unit, convention),
    then t [s] and a column per component (the dataset's trailing axes flattened: x, y, z for a last
    axis of 2 or 3; the middle axis of (K, S, C) as storey1.. for demands' drift ratios, r0.. otherwise),
    each named with the dataset's unit."""
    out = sys.stdout if out is None else out
    series = series.strip("/")
    grp, _, name = series.rpartition("/")
    with open_h5(path) as f:
        if series not in f or not hasattr(f[series], "shape"):
            have = [k for k in (f[grp].keys() if grp in f else []) if not k.endswith("t")]
            raise PostError(f"{path} holds no series {series}" + (f" (the group {grp} holds: {', '.join(sorted(have))})"
                                                                   if have else f" (no group {grp})" if grp else ""))
        tkey = _time_key(f, grp, name)
        d = f[series]
        if tkey is None:
            raise PostError(f"{path}: {series} has no time grid ({grp + '/' if grp else ''}t): not a time series")
        t = np.asarray(f[tkey][()], float)
        x = np.asarray(d[()], float)
        unit, tunit = _unit(d), _unit(f[tkey])
        conv = d.attrs.get("convention", "")
        conv = conv.decode() if isinstance(conv, bytes) else str(conv)
        attrs = {k: (v.decode() if isinstance(v, bytes) else v) for k, v in f.attrs.items()}
    if x.ndim == 0 or x.shape[0] != t.size:
        raise PostError(f"{path}: {series} has shape {x.shape}, its time grid {tkey} {t.size} samples: "
                        "not a time series")
    if x.ndim > 3:
        raise PostError(f"{path}: {series} has shape {x.shape}: more axes than a time series of points")
    comp = lambda n: list("xyz"[:n]) if n in (2, 3) else [str(j) for j in range(n)]   # noqa: E731
    if x.ndim == 1:
        names, cols = [name], [x]
    elif x.ndim == 2:
        names = [f"{name}_{c}" for c in comp(x.shape[1])]
        cols = [x[:, j] for j in range(x.shape[1])]
    else:
        tag = (lambda k: f"storey{k + 1}") if grp == "demands" else (lambda k: f"r{k}")
        names, cols = [], []
        for k in range(x.shape[1]):
            for j, c in enumerate(comp(x.shape[2])):
                names.append(f"{name}_{tag(k)}_{c}")
                cols.append(x[:, k, j])
    hdr = _header([f"petsc-ssi post --series {series} --csv: the time series as stored",
                   f"file: {os.path.abspath(path)} (problem {attrs.get('problem', '?')}, run_status "
                   f"{attrs.get('run_status', '?')})",
                   f"series: {series}, shape {tuple(x.shape)}, unit {unit}; time {tkey} [{tunit}]"]
                  + ([f"convention: {' '.join(conv.split())}"] if conv else []))
    _write_table(out, hdr, [f"t [{tunit}]"] + [f"{n} [{unit}]" for n in names], [t] + cols)
    return t, x


def demands_summary(path):
    """[(quantity, storey, component, value, unit, time_s)] of the group demands of a structure output."""
    rows = []
    with open_h5(path) as f:
        d = f.get("demands")
        if d is None or not hasattr(d, "keys"):
            what = f.attrs.get("problem", "?")
            raise PostError(f"{path}: no group demands (problem {what}: the storey demands are in a structure "
                            "output, FILE.h5 of -ssi_problem fem or FILE_structure.h5 of a coupled run)")
        mass = f.attrs.get("structure_mass")

        def get(k):
            return np.asarray(d[k][()], float) if k in d else None
        for name, label, unit in (("drift_ratio", "peak inter-storey drift ratio", "m/m"),
                                  ("drift_ratio_deformation", "peak drift ratio without the base's rocking", "m/m")):
            pk, pt = get("peak_" + name), get("peak_" + name + "_time")
            if pk is None:
                continue
            pk, pt = pk.reshape(-1, 2), pt.reshape(-1, 2)
            for s in range(pk.shape[0]):
                for j, c in enumerate("xy"):
                    rows.append((label, s + 1, c, pk[s, j], unit, pt[s, j]))
        V, Vt = get("peak_base_shear"), get("peak_base_shear_time")
        if V is not None:
            for j, c in enumerate("xy"):
                rows.append(("peak base shear", "", c, V[j], "N", Vt[j]))
            if mass is not None and float(mass) > 0:
                W = float(mass) * G_STANDARD
                for j, c in enumerate("xy"):
                    rows.append(("peak base shear / weight V/W", "", c, V[j] / W, "1", Vt[j]))
                rows.append((f"weight W = m g (m = {float(mass):.6g} kg, g = {G_STANDARD} m/s^2)", "", "", W, "N",
                             float("nan")))
        Mo, Mt = get("peak_overturning_moment"), get("peak_overturning_moment_time")
        if Mo is not None:
            for j, c in enumerate("xy"):
                rows.append((f"peak overturning moment (about {c})", "", c, Mo[j], "N m", Mt[j]))
    if not rows:
        raise PostError(f"{path}: the group demands holds no peaks (no base and no storeys recorded)")
    return rows, mass


BASE_SHEAR_NOTE = ("base shear: the horizontal force the structure exerts on the ground through its base, the "
                   "foundation's own inertia included (fixed base: the supports' reactions, the supported nodes' "
                   "m a_g with them; with SSI: the interface force), the same quantity with and without SSI; the "
                   "members' shear at the base is V plus the foundation's mass times its acceleration (V less its inertia "
                   "force -m a)")


def modelled_part_note(attrs):
    """One line: whose base shear, overturning moment and weight the file's values are (the structure output's
    attribute symmetry: the run's -ssi_symmetry planes)."""
    sym = attrs.get("symmetry")
    if sym is None:
        return ("modelled part: not recorded (a file written before its attribute symmetry); a half (quarter) "
                "model's base shear, overturning moment and weight are the half's (quarter's)")
    sym = str(sym).strip()
    if not sym:
        return ("modelled part: the whole mesh (no -ssi_symmetry plane); a structure meshed in half by hand (e.g. "
                "meshes/building.geo's half = 1) gives the half's base shear, overturning moment and weight")
    n = len([p for p in sym.split(",") if p.strip()])
    part, times = ("half", "twice") if n == 1 else ("quarter", "four times")
    return (f"modelled part: the {part} of the structure on the planes -ssi_symmetry '{sym}': base shear, "
            f"overturning moment and weight are the {part}'s; the whole structure's are {times} these, or zero for "
            "a component its symmetry cancels; drift ratios are the whole's")


FRAME_SECTION_NOTE = ("frames: section resultants at each end (i: node 0, j: node 1 of the element's nodes), local "
                      "axes x' from node 0 to node 1, z' the part's orientation made normal to x', y' = z' x x'; N > 0 "
                      "tension, V2 and V3 along y' and z', T about x', M2 > 0 stretches the +z' fibre, M3 > 0 "
                      "compresses the +y' fibre (the file's end forces f the nodes exert on the element: -f_i at end i, "
                      "+f_j at end j)")
SHELL_SECTION_NOTE = ("shells: stress resultants at the element's centre in its local frame (e1, e2 in the mean plane, e3 "
                      "the normal): N = int sigma dz [N/m] (N11 > 0 tension), M = int sigma z dz [N m/m] (M11 > 0 "
                      "stretches the +e3 fibre), Q = int sigma_a3 dz [N/m]")


FORCES_COLUMNS = ["part", "element", "end", "node", "x_m", "y_m", "z_m", "component", "unit", "peak_abs", "gravity",
                  "gravity_plus_max", "gravity_plus_min"]
STATIC_FORCES_COLUMNS = FORCES_COLUMNS[:9] + ["value"]


def forces_table(path, parts=None):
    """(header lines, columns, rows) of the member forces of a structure output as section resultants: per part,
    element, end (frames: i and j; shells: centre) and component (peak |E(t)|, and with gravity G, G + E max,
    G + E min: the file's G + max_t E(t) and G + min_t E(t) of the end forces, turned at end i, where the section's
    resultant is -f_i, into the section's min and max). A ``petsc-ssi static`` file (one solution, the
    self-weight already in it): the signed section resultant of that solution (STATIC_FORCES_COLUMNS)."""
    rows = []
    with open_h5(path) as f:
        attrs = dict(f.attrs)
        static = str(attrs.get("problem", "")) == "static"
        g = f.get("forces")
        if g is None or not hasattr(g, "keys"):
            raise PostError(f"{path}: no group forces (member forces are written with -ssi_structure_forces PARTS "
                            "into a structure output: FILE.h5 of -ssi_problem fem, FILE_structure.h5 of a coupled run)")
        have = [k[:-len("_envelope")] for k in g.keys() if k.endswith("_envelope")]
        want = have if not parts else parts
        for p in want:
            if p not in have:
                raise PostError(f"--forces {p}: {path} holds no member forces of a part '{p}' (it holds: "
                                f"{', '.join(sorted(have)) or 'none'})")
        X = np.asarray(f["coordinates"][()], float) if "coordinates" in f else None
        gravity = False
        for p in want:
            env = g[p + "_envelope"]
            comps = str(env.attrs["components"]).split(",")
            units = str(env.attrs["unit"]).split(",")
            element = str(env.attrs.get("element", ""))
            E = np.asarray(env[()], float)
            nodes = np.asarray(g[p + "_nodes"][()], np.int64) if p + "_nodes" in g else None
            grav = p + "_gravity" in g
            gravity |= grav
            G, Gmax, Gmin = ((np.asarray(g[p + s][()], float) if grav else None)
                             for s in ("_gravity", "_gravity_plus_max", "_gravity_plus_min"))
            S = None
            if static:                         # (the solution's end forces: its one snapshot)
                if p not in g or g[p].shape[0] < 1:
                    raise PostError(f"{path}: a static file without its member forces' snapshot forces/{p}")
                S = np.asarray(g[p][-1], float)
            if element == "frame":
                ends = [("i", 0, -1.0, [c for c in comps if c.endswith("_i")]),
                        ("j", 1, 1.0, [c for c in comps if c.endswith("_j")])]
            else:
                ends = [("centre", None, 1.0, comps)]
            for e in range(E.shape[0]):
                for end, which, sign, names in ends:
                    if nodes is None:
                        node, x = -1, (np.nan,) * 3
                    elif which is None:
                        node, x = -1, tuple(X[nodes[e]].mean(axis=0)) if X is not None else (np.nan,) * 3
                    else:
                        node = int(nodes[e, which])
                        x = tuple(X[node]) if X is not None else (np.nan,) * 3
                    for name in names:
                        c = comps.index(name)
                        row = [p, e, end, node, *x, name.rsplit("_", 1)[0] if which is not None else name, units[c],
                               E[e, c]]
                        if static:
                            row[-1] = sign * S[e, c]
                        elif grav:
                            a, b = sign * Gmax[e, c], sign * Gmin[e, c]
                            row += [sign * G[e, c], max(a, b), min(a, b)]
                        else:
                            row += [np.nan, np.nan, np.nan]
                        rows.append(row)
    if static:
        what = ("value: the static solution's section resultant, signed in the section's convention: the options' "
                "loads" + (f" plus the self-weight (-ssi_fem_gravity {float(attrs['gravity']):g} m/s^2)"
                           if "gravity" in attrs else " (no -ssi_fem_gravity)"))
    else:
        what = ("peak_abs: max over every time step of |E(t)|, E the run's response (the earthquake's or the loads'); "
                "gravity: the static self-weight case G; gravity_plus_max, gravity_plus_min: G + max_t E(t) and "
                "G + min_t E(t) of each component in the section's convention (linear superposition, factors 1)"
                + ("" if gravity else "; nan: the run had no -ssi_fem_gravity"))
    header = [f"petsc-ssi post --forces: member forces of {os.path.abspath(path)} (group forces) as section resultants",
              FRAME_SECTION_NOTE, SHELL_SECTION_NOTE, what, modelled_part_note(attrs),
              "x_m, y_m, z_m: the end's node (frames) or the element's centroid (shells) [m]"]
    return header, (STATIC_FORCES_COLUMNS if static else FORCES_COLUMNS), rows


def forces_csv(path, parts=None, out=None):
    out = sys.stdout if out is None else out
    header, columns, rows = forces_table(path, parts)
    out.write(_header(header))
    out.write(",".join(columns) + "\n")
    for r in rows:
        out.write(f"{r[0]},{r[1]},{r[2]},{r[3]},{r[4]:.9g},{r[5]:.9g},{r[6]:.9g},{r[7]},{r[8]},"
                  + ",".join(f"{v:.9g}" for v in r[9:]) + "\n")
    return rows


def demands_csv(path, out=None):
    out = sys.stdout if out is None else out
    rows, mass = demands_summary(path)
    with open_h5(path) as f:
        attrs = dict(f.attrs)
    out.write(_header([f"petsc-ssi post --demands: storey demands' peaks of {os.path.abspath(path)} (group demands)",
                       "value: max over the steps of |series| per component; time_s: the first time of that peak",
                       BASE_SHEAR_NOTE, modelled_part_note(attrs),
                       "V/W: " + ("base shear over the weight of the structure's mass attribute (the modelled part)"
                                  if mass is not None else "not given: the file records no structure_mass")]))
    out.write("quantity,storey,component,value,unit,time_s\n")
    for q, st, c, v, u, tt in rows:
        out.write(f'"{q}",{st},{c},{v:.9g},{u},{tt:.9g}\n')
    return rows


# ---------------------------------------------------------------- series selection

def read_series(path, series="receivers/u", receiver=0, component="all"):
    """(t, x (N, C), labels, description) of one series of an output file.

    series: 'GROUP/NAME' with a sibling 'GROUP/t'; a (K, R, 3) dataset is taken at
    ``receiver``, (K, 3) and (K,) as they are.  component: x|y|z|all (3-component series).
    """
    series = series.strip("/")
    grp, _, name = series.rpartition("/")
    with open_h5(path) as f:
        if series not in f:
            have = [k for k in (f[grp].keys() if grp in f else []) if k != "t"]
            hint = f" (the group {grp} holds: {', '.join(sorted(have))})" if have else \
                (f" ({path} has no group {grp})" if grp else "")
            raise PostError(f"{path} holds no series {series}{hint}")
        tkey = (grp + "/t") if grp else "t"
        if tkey not in f:
            raise PostError(f"{path}: the series {series} has no time grid {tkey}")
        t = np.asarray(f[tkey][:], dtype=float)
        d = f[series]
        shape = d.shape
        where = ""
        if len(shape) == 3:
            if not 0 <= receiver < shape[1]:
                raise PostError(f"{path}: receiver {receiver} out of range, {series} has {shape[1]} receivers")
            x = np.asarray(d[:, receiver, :], dtype=float)
            where = f" receiver {receiver}"
            if grp and grp + "/points" in f:
                p = f[grp + "/points"][receiver]
                where += f" at ({p[0]:g}, {p[1]:g}, {p[2]:g})"
            if series.endswith("/rotation") and grp + "/has_rotation" in f \
                    and not bool(f[grp + "/has_rotation"][receiver]):
                raise PostError(f"{path}: receiver {receiver} has no rotation (not at a frame or shell node)")
        elif len(shape) in (1, 2):
            x = np.asarray(d[:], dtype=float)
        else:
            raise PostError(f"{path}: {series} has shape {shape}, not a time series")
    if x.ndim == 1:
        x = x[:, None]
        labels = [name]
        if component not in ("all", None):
            raise PostError(f"{series} is a scalar series: no --component {component}")
    else:
        if x.shape[1] != 3:
            labels = [f"{name}_{j}" for j in range(x.shape[1])]
        else:
            labels = [f"{name}_{c}" for c in COMPONENTS]
        if component not in ("all", None):
            j = COMPONENTS.index(component)
            if j >= x.shape[1]:
                raise PostError(f"{series} has {x.shape[1]} components: no --component {component}")
            x, labels = x[:, [j]], [labels[j]]
    if x.shape[0] != t.size:
        raise PostError(f"{path}: {series} has {x.shape[0]} samples, its time grid {tkey} {t.size}")
    return t, x, labels, f"{path}:{series}{where}"


def _parse_ref(ref, path, series):
    """'K' | 'FILE:K' | '[FILE:]GROUP/NAME[@K]' -> (file, series, receiver)."""
    fpath, sel = path, ref
    head, sep, tail = ref.rpartition(":")
    if sep and (head.endswith((".h5", ".hdf5")) or os.path.exists(head)):
        fpath, sel = head, tail
    rec = 0
    if sel.lstrip("-").isdigit():
        return fpath, series, int(sel)
    if "@" in sel:
        sel, _, k = sel.partition("@")
        try:
            rec = int(k)
        except ValueError:
            raise PostError(f"--transfer {ref}: receiver index {k!r} is not an integer") from None
    if not sel:
        raise PostError(f"--transfer {ref}: give K, FILE.h5:K or [FILE.h5:]GROUP/NAME[@K]")
    return fpath, sel, rec


# ---------------------------------------------------------------- output

def _header(lines):
    return "".join(f"# {ln}\n" for ln in lines)


def _limit(f, arrays, fmax):
    if fmax is None:
        return f, arrays
    m = f <= fmax
    return f[m], [a[m] for a in arrays]


def _write_table(out, header, names, cols):
    out.write(header)
    out.write(",".join(names) + "\n")
    data = np.column_stack(cols)
    for row in data:
        out.write(",".join(f"{v:.9g}" for v in row) + "\n")


def _open_out(dest):
    if dest in (True, "-"):
        return sys.stdout, False
    return open(dest, "w"), True


def _mpl():
    import warnings
    import matplotlib
    matplotlib.use("Agg")
    with warnings.catch_warnings():  # "Unable to import Axes3D" of a mixed matplotlib install
        warnings.simplefilter("ignore", UserWarning)
        import matplotlib.pyplot as plt
    return plt


def spectrum_command(a, out=None):
    out = sys.stdout if out is None else out
    from ..spectrum import amplitude_spectrum, peaks
    t, x, labels, desc = read_series(a.file, a.series, a.receiver, a.component)
    f, A, inf = amplitude_spectrum(t, x, pad=a.pad, window=a.window, tukey_alpha=a.tukey_alpha,
                                   detrend=a.detrend)
    f, (A,) = _limit(f, [A], a.fmax)
    sep = inf["resolution"] if a.min_sep is None else a.min_sep
    fmin = inf["resolution"] if a.fmin is None else a.fmin
    found = [peaks(f, A[:, j], a.peaks, sep, fmin=fmin) for j in range(A.shape[1])]
    unit = series_unit(a.file, a.series)
    us = unit_suffix(unit)
    hdr = _header([
        "petsc-ssi post --spectrum: one-sided amplitude spectrum",
        f"file: {os.path.abspath(a.file)}",
        f"series: {desc}, components {', '.join(labels)}",
        f"window: {inf['window_text']}",
        f"padding: {inf['padding']}",
        f"dt: {inf['dt']:.9g} s, N: {inf['n']}, duration: {inf['duration']:.9g} s",
        f"df: {inf['df']:.9g} Hz (grid), resolution 1/(N dt): {inf['resolution']:.9g} Hz",
        f"detrend: {inf['detrend']}" + (f", fmax: {a.fmax:g} Hz" if a.fmax is not None else ""),
        f"scaling: {inf['scaling']}",
        "unit: the amplitudes in " + (f"{unit}, the series'" if unit else "the series' unit (none stored)"),
    ])
    out.write(f"# {desc}: {inf['summary']}\n")
    out.write(f"component,rank,f_hz,amplitude{us}\n")
    for lab, (fp, ap, _) in zip(labels, found):
        for r, (ff, aa) in enumerate(zip(fp, ap), 1):
            out.write(f"{lab},{r},{ff:.6g},{aa:.6g}\n")
    if a.csv is not None and a.csv is not False:
        fh, close = _open_out(a.csv)
        try:
            _write_table(fh, hdr, ["f_hz"] + [lab + us for lab in labels], [f] + [A[:, j] for j in range(A.shape[1])])
        finally:
            if close:
                fh.close()
    if a.png:
        plt = _mpl()
        fig, ax = plt.subplots(figsize=(9, 4.8))
        for j, lab in enumerate(labels):
            line, = ax.plot(f, A[:, j], lw=1.2, label=lab)
            fp, ap, _ = found[j]
            ax.plot(fp, ap, "v", color=line.get_color(), ms=6)
            for ff, aa in zip(fp, ap):
                ax.annotate(f"{ff:.3g} Hz", (ff, aa), textcoords="offset points", xytext=(3, 6),
                            fontsize=8, color=line.get_color())
        ax.set_xlabel("f [Hz]")
        ax.set_ylabel(f"amplitude |X(f)| [{unit}]" if unit else "amplitude |X(f)|")
        ax.set_xlim(0, f[-1] if f.size else 1)
        ax.set_title(f"{os.path.basename(a.file)}: {desc.split(':', 1)[1]}\n"
                     f"window {inf['window_text']}, {inf['padding']}, df {inf['df']:.4g} Hz",
                     fontsize=9)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(a.png, dpi=120)
        plt.close(fig)
    return f, A, inf, found


def transfer_command(a, out=None):
    out = sys.stdout if out is None else out
    from ..spectrum import transfer
    fa, sa, ra = _parse_ref(a.transfer[0], a.file, a.series)
    fb, sb, rb = _parse_ref(a.transfer[1], a.file, a.series)
    ta, xa, la, da = read_series(fa, sa, ra, a.component)
    tb, xb, lb, db = read_series(fb, sb, rb, a.component)
    if ta.size != tb.size or not np.allclose(ta, tb, rtol=0, atol=1e-9 * max(abs(ta[-1]), 1e-300)):
        raise PostError(f"--transfer: {da} and {db} are on different time grids "
                        f"({ta.size} samples to {ta[-1]:.6g} s, {tb.size} to {tb[-1]:.6g} s)")
    if xa.shape != xb.shape:
        raise PostError(f"--transfer: {da} and {db} have {xa.shape[1]} and {xb.shape[1]} components")
    f, H, inf = transfer(ta, xa, xb, pad=a.pad, window=a.window, tukey_alpha=a.tukey_alpha,
                         detrend=a.detrend, eps=a.eps)
    mag, ph, rel = inf["magnitude"], inf["phase"], inf["reliable"]
    f, (mag, ph, rel) = _limit(f, [mag, ph, rel], a.fmax)
    comps = [lab.rsplit("_", 1)[-1] for lab in lb]
    out.write(f"# H = B / A, A = {da}, B = {db}: {inf['summary']}\n")
    out.write(f"# {inf['method']}\n")
    if a.csv is not None and a.csv is not False:
        hdr = _header([
            "petsc-ssi post --transfer: H(f) = B(f) / A(f)",
            f"file: {os.path.abspath(a.file)}",
            f"series A: {da}", f"series B: {db}",
            f"method: {inf['method']}",
            f"window: {inf['window_text']}", f"padding: {inf['padding']}",
            f"dt: {inf['dt']:.9g} s, N: {inf['n']}",
            f"df: {inf['df']:.9g} Hz (grid), resolution 1/(N dt): {inf['resolution']:.9g} Hz",
            f"detrend: {inf['detrend']}; phase in degrees, (-180, 180]",
        ])
        names, cols = ["f_hz"], [f]
        for j, c in enumerate(comps):
            names += [f"mag_{c}", f"phase_deg_{c}", f"reliable_{c}"]
            cols += [mag[:, j], np.degrees(ph[:, j]), rel[:, j].astype(float)]
        fh, close = _open_out(a.csv)
        try:
            _write_table(fh, hdr, names, cols)
        finally:
            if close:
                fh.close()
    if a.png:
        plt = _mpl()
        fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(9, 6.5), sharex=True)
        for j, c in enumerate(comps):
            m = rel[:, j]
            line, = ax1.plot(f, mag[:, j], lw=0.8, alpha=0.4)
            ax1.plot(f, np.where(m, mag[:, j], np.nan), lw=1.4, color=line.get_color(), label=c)
            ax2.plot(f, np.where(m, np.degrees(ph[:, j]), np.nan), ".", ms=2, color=line.get_color(), label=c)
        ax1.set_yscale("log")
        ax1.set_ylabel("|H|")
        ax2.set_ylabel("phase [deg]")
        ax2.set_xlabel("f [Hz]")
        ax1.set_title(f"H = B/A, A = {da}\nB = {db}\nwindow {inf['window_text']}, {inf['padding']}, "
                      f"df {inf['df']:.4g} Hz, eps {inf['eps']:g} (faint: |A| < 5% max)", fontsize=8)
        for ax in (ax1, ax2):
            ax.grid(alpha=0.3)
            ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(a.png, dpi=120)
        plt.close(fig)
    return f, H, inf


# ---------------------------------------------------------------- command line

def _check_numbers(a):
    """PostError for a number option out of its range (argparse checks only the type): a negative
    --fmax kept no frequency, a negative --peaks printed none, without a word."""
    rules = [("fmax", a.fmax, lambda v: v > 0, "must be > 0 Hz"),
             ("peaks", a.peaks, lambda v: v >= 0, "must be >= 0"),
             ("pad", a.pad, lambda v: v >= 1, "must be >= 1 (a factor on the number of samples)"),
             ("min-sep", a.min_sep, lambda v: v >= 0, "must be >= 0 Hz"),
             ("fmin", a.fmin, lambda v: v >= 0, "must be >= 0 Hz"),
             ("eps", a.eps, lambda v: v > 0, "must be > 0"),
             ("tukey-alpha", a.tukey_alpha, lambda v: 0 <= v <= 1, "must lie in [0, 1]"),
             ("receiver", a.receiver, lambda v: v >= 0, "must be >= 0")]
    for name, value, ok, why in rules:
        if value is not None and not (np.isfinite(value) and ok(value)):
            raise PostError(f"--{name} {value:g}: {why}")


def main(argv=None):
    ap = argparse.ArgumentParser(prog="petsc-ssi post", description=__doc__.splitlines()[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog="\n".join(__doc__.splitlines()[2:]))
    ap.add_argument("file", nargs="?")
    ap.add_argument("--receivers", action="store_true", help="receiver series")
    ap.add_argument("--csv", nargs="?", const=True, default=None, metavar="OUT.csv",
                    help="CSV to OUT.csv, standard output without a name (receivers: the "
                         "--quantity or --series; spectrum, transfer)")
    ap.add_argument("--plot", metavar="PNG", help="plot receiver histories to PNG")
    ap.add_argument("--info", action="store_true")
    ap.add_argument("--demands", action="store_true", help="storey demands' summary (with --csv)")
    ap.add_argument("--forces", nargs="?", const="", default=None, metavar="PART,...",
                    help="member forces as section resultants, every part without a name (with --csv)")
    ap.add_argument("--spectrum", action="store_true", help="amplitude spectrum of a series")
    ap.add_argument("--transfer", nargs=2, metavar=("A", "B"), help="transfer function B/A")
    ap.add_argument("--quantity", choices=QUANTITIES, default="u")
    ap.add_argument("--series", metavar="GROUP/NAME", help="e.g. interface/force_be (overrides --quantity)")
    ap.add_argument("--receiver", type=int, default=0, metavar="K")
    ap.add_argument("--component", choices=COMPONENTS + ("all",), default="all")
    ap.add_argument("--pad", type=float, default=None, metavar="P")
    ap.add_argument("--window", choices=("none", "hann", "tukey"), default="none")
    ap.add_argument("--tukey-alpha", type=float, default=0.25)
    ap.add_argument("--detrend", choices=("none", "mean", "linear"), default="none")
    ap.add_argument("--fmax", type=float, default=None, metavar="F")
    ap.add_argument("--peaks", type=int, default=5, metavar="N")
    ap.add_argument("--min-sep", type=float, default=None, metavar="HZ")
    ap.add_argument("--fmin", type=float, default=None, metavar="HZ")
    ap.add_argument("--eps", type=float, default=1e-3)
    ap.add_argument("--png", metavar="OUT.png")
    ap.add_argument("--overwrite", action="store_true", help="replace an existing --csv/--png/--plot file "
                    "(never an input or an HDF5 file)")
    a = ap.parse_args(argv)
    # legacy order 'post --receivers --csv FILE.h5': the optional --csv value is the file
    if a.file is None and isinstance(a.csv, str) and a.csv.endswith((".h5", ".hdf5")) \
            and not (a.spectrum or a.transfer):
        a.file, a.csv = a.csv, True
    if a.file is None:
        ap.error("the following arguments are required: file")
    a.series_given = a.series is not None
    a.series = a.series or f"receivers/{a.quantity}"
    from ..spectrum import SpectrumError
    if world_rank() > 0:            # serial: rank 0 does the work and reports; the others agree on the status
        try:
            open_h5(a.file).close()
        except PostError:
            return 2
        return 0
    try:
        _check_numbers(a)
        inputs = [a.file] + [_parse_ref(r, a.file, a.series)[0] for r in (a.transfer or ())]
        plain_series = bool(a.series_given and a.csv and not (a.receivers or a.spectrum or a.transfer))
        # every file post writes, --receivers --csv's too (before: 'post X.h5 --receivers --csv X.h5' cut X.h5
        # to 0 bytes)
        check_outputs([("--csv", a.csv if (a.spectrum or a.transfer or plain_series or a.demands or a.receivers
                                           or a.forces is not None)
                        else None),
                       ("--png", a.png),
                       ("--plot", a.plot)], inputs, a.overwrite)
        if a.spectrum and a.transfer:
            raise PostError("give either --spectrum or --transfer, not both")
        if a.spectrum:
            spectrum_command(a)
            return 0
        if a.transfer:
            transfer_command(a)
            return 0
        open_h5(a.file).close()
        if a.info:
            info(a.file)
        forces = a.forces is not None
        if plain_series or ((a.demands or forces) and a.csv):
            fh, close = _open_out(a.csv)
            try:
                if plain_series:
                    series_csv(a.file, a.series, fh)
                elif forces:
                    forces_csv(a.file, [p.strip() for p in a.forces.split(",") if p.strip()], fh)
                else:
                    demands_csv(a.file, fh)
            except BaseException:
                if close:
                    fh.close()
                    os.remove(a.csv)                # no half-written file after an error
                raise
            if close:
                fh.close()
            return 0
        if a.demands:
            raise PostError("--demands writes a CSV: give --csv [OUT.csv]")
        if forces:
            raise PostError("--forces writes a CSV: give --csv [OUT.csv]")
        if a.receivers and a.csv:
            fh, close = _open_out(a.csv)            # --csv OUT.csv: that file; --csv alone: standard output
            try:
                write_csv(a.file, fh, a.series)
            finally:
                if close:
                    fh.close()
        if a.plot:
            from ..plot import receiver_plot
            read_series(a.file, a.series)          # a missing series: one line, not a traceback
            receiver_plot(a.file, png=a.plot, series=a.series)
        if not (a.info or (a.receivers and a.csv) or a.plot):
            ap.error("nothing to do: give --receivers --csv, --series G/NAME --csv, --demands --csv, --forces --csv, "
                     "--plot PNG, "
                     "--info, --spectrum or --transfer A B")
    except BrokenPipeError:             # the reader stopped ('post ... | head'): cli._post
        raise
    except (OSError, PostError, SpectrumError) as exc:
        msg = " ".join(str(exc).split())
        print(f"petsc-ssi post: error: {msg}", file=sys.stderr)
        return 2
    return 0
