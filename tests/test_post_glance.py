"""petsc-ssi post SSI.h5 --glance FIXED.h5 (petsc_ssi/app/glance.py) on synthetic output files
written with h5py in the layout of a run's (dataset names and attributes copied from a coupled
run's soil output X.h5 and structure output X_structure.h5 and a fixed-base run's Y.h5 under
-ssi_seismic vertical), whose roof is a damped SDOF oscillator of known f0 and zeta:

  ground   a broadband record: white noise (seeded) low-passed (Butterworth 4 at 12 Hz),
           Hann-tapered, 20 s at 0.005 s, in m/s^2; the seismic group holds it as the
           processed motion (x_t, x_acceleration, x_velocity, x_displacement, t0) -- the
           coupled run's free field -- and the fixed-base file its step means.
  roof     the oscillator's absolute acceleration computed by scipy.signal.lsim (matrix
           exponential with the input linear between samples: exact for the piecewise-linear
           record; independent of the glance's own integrator, seismic.response_spectrum),
           stored as the structure files do: the mean over the step ending at t_n,
           (v_n - v_{n-1}) / dt of the absolute velocity, 0 at t = 0.
  runs     SSI-like: f0 2 Hz, zeta 0.15 on dt 0.005 s; fixed-base-like: f0 4 Hz,
           zeta 0.03 on dt 0.01 s (different steps: said, not refused).

The fit is the identification (app/glance.py's docstring); tolerances: f0 0.2 %, zeta 2 %
(measured: f0 1.3e-5 and 1.0e-5, zeta 0.9e-4 and 2.2e-4 relative; c0 -0.0003 and -0.005, c1
1.0004 and 1.005: the fit takes the step means as piecewise linear, an O((2 pi f0 dt)^2 / 12)
effect on the fitted amplitudes, 0.5 % at 4 Hz and dt 0.01 s)."""
import io
import math
import os

import numpy as np
import pytest

from petsc_ssi.app import glance as gl

pytestmark = pytest.mark.unit

REC_DT, REC_T = 0.005, 20.0
SSI = dict(f0=2.0, zeta=0.15, dt=0.005)
FIXED = dict(f0=4.0, zeta=0.03, dt=0.01)
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def _record():
    """(t, a, v, d) of the broadband record [s, m/s^2, m/s, m], exact integrals of the
    piecewise-linear a."""
    from scipy.signal import butter, sosfilt
    from petsc_ssi.seismic.records import integrate
    t = np.arange(0.0, REC_T + 1e-9, REC_DT)
    rng = np.random.default_rng(20261125)
    a = sosfilt(butter(4, 12.0, fs=1 / REC_DT, output="sos"), rng.standard_normal(t.size))
    w = np.ones_like(t)
    m = int(0.05 * t.size)
    w[:m] = 0.5 - 0.5 * np.cos(np.pi * np.arange(m) / m)
    w[-m:] = w[:m][::-1]
    a = a * w / np.abs(a * w).max()                          # PGA 1 m/s^2
    a[0] = a[-1] = 0.0
    v, d = integrate(t, a)
    return t, a, v, d


def _roof(f0, zeta, dt, t0):
    """(run times (n,), roof step means (n,), ground step means (n,)) [s, m/s^2, m/s^2] of the
    oscillator on the record shifted by t0 (run time = record time + t0), on the run grid dt
    (a multiple of the record's step)."""
    from scipy.signal import lsim
    tr, a, v, _ = _record()
    w = 2 * np.pi * f0
    A = [[0.0, 1.0], [-w * w, -2 * zeta * w]]
    _, _, x = lsim((A, [[0.0], [-1.0]], [[1.0, 0.0]], [[0.0]]), a, tr, interp=True)
    v_abs = x[:, 1] + v                                      # relative + ground velocity
    k = int(round(dt / REC_DT))
    n_shift = int(round(t0 / REC_DT))
    vs = np.concatenate([np.zeros(n_shift), v_abs])[::k]      # at run times t_n = n dt
    gs = np.concatenate([np.zeros(n_shift), v])[::k]
    t = dt * np.arange(vs.size)
    roof, ground = np.zeros_like(t), np.zeros_like(t)
    roof[1:], ground[1:] = np.diff(vs) / dt, np.diff(gs) / dt
    return t, roof, ground


def _receivers(g, t, acc, point=(0.0, 0.0, 6.0)):
    vel = np.concatenate([[0.0], np.cumsum(acc[1:]) * (t[1] - t[0])])
    zero = np.zeros((t.size, 1, 3))
    a3, v3 = zero.copy(), zero.copy()
    a3[:, 0, 0], v3[:, 0, 0] = acc, vel
    g["t"], g["acceleration"], g["velocity"], g["u"], g["rotation"] = t, a3, v3, zero, zero
    g["points"] = g["node_points"] = np.array([point])
    g["nodes"] = np.array([20])
    g["snap_distance"] = np.zeros(1)
    g["has_rotation"] = np.array([False])
    return a3


def _seismic(f, t0, control=None):
    tr, a, v, d = _record()
    s = f.create_group("seismic")
    for name, arr, unit in (("x_t", tr, "s"), ("x_acceleration", a, "m/s2"), ("x_velocity", v, "m/s"),
                            ("x_displacement", d, "m"), ("x_pga", np.abs(a).max(), "m/s2"),
                            ("t0", t0, "s (run time = record time + t0)")):
        s[name] = arr
        s[name].attrs["unit"] = unit
    if control is not None:
        s["control"] = np.bytes_(control)


def _demands(f, shear, drift):
    d = f.create_group("demands")
    d["peak_base_shear"] = np.array([shear, 0.1 * shear])
    d["peak_drift_ratio"] = np.array([[0.5 * drift, 0.0], [-drift, 0.0]])      # storey 2 governs


def write_ssi(tmp, name="ssi.h5", control="surface", demands=None, **kw):
    """A coupled run's soil output and its structure output name_structure.h5."""
    import h5py
    p = dict(SSI, **kw)
    t, roof, _ = _roof(p["f0"], p["zeta"], p["dt"], p["dt"])
    path = os.path.join(tmp, name)
    spath = path[:-3] + "_structure.h5"
    with h5py.File(path, "w") as f:
        f.attrs.update({"problem": "ssi", "dt": p["dt"], "cell_type": "quad9", "seismic": "vertical",
                        "cp": 208.0, "cs": 100.0, "rho": 1800.0, "run_status": "completed",
                        "structure_output": os.path.basename(spath)})
        _seismic(f, p["dt"], control)
        f["seismic/angle"], f["seismic/azimuth"] = 0.0, 0.0
    with h5py.File(spath, "w") as f:
        f.attrs.update({"problem": "ssi-structure", "dt": p["dt"], "cell_type": "mixed", "run_status": "completed"})
        _receivers(f.create_group("receivers"), t, roof)
        if demands:
            _demands(f, *demands)
    return path


def write_fixed(tmp, name="fixed.h5", demands=None, **kw):
    import h5py
    p = dict(FIXED, **kw)
    t, roof, ground = _roof(p["f0"], p["zeta"], p["dt"], p["dt"])
    path = os.path.join(tmp, name)
    with h5py.File(path, "w") as f:
        f.attrs.update({"problem": "fem", "dt": p["dt"], "cell_type": "mixed", "run_status": "completed",
                        "seismic": "support motion (relative-motion form: u, velocity, acceleration relative "
                                   "to the base)"})
        g = f.create_group("receivers")
        a3 = _receivers(g, t, roof - ground)                   # relative acceleration
        g["ground_acceleration"] = np.column_stack([ground, np.zeros_like(t), np.zeros_like(t)])
        g["absolute_acceleration"] = a3 + g["ground_acceleration"][()][:, None, :]
        _seismic(f, p["dt"])
        if demands:
            _demands(f, *demands)
    return path


def run(argv, capsys):
    out = io.StringIO()
    status = gl.main([str(a) for a in argv], out=out)
    return status, out.getvalue(), capsys.readouterr().err


def read_csv(path):
    import csv
    rows = [r for r in csv.reader(open(path)) if r and not r[0].startswith("#")]
    assert rows[0] == ["quantity", "unit", "with_ssi", "fixed_base", "ssi_over_fixed"]
    return {r[0]: (r[1], *map(float, r[2:])) for r in rows[1:]}


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = str(tmp_path_factory.mktemp("glance"))
    return write_ssi(d, demands=(2.0e5, 4e-3)), write_fixed(d, demands=(5.0e5, 1e-2))


def test_sdof_filter_equals_the_exact_march():
    """sdof_filter's recurrence as a digital filter equals sdof_history (Nigam & Jennings) on a
    random input starting at 0, to rounding."""
    from scipy.signal import lfilter
    from petsc_ssi.seismic import response_spectrum as rs
    rng = np.random.default_rng(3)
    t = 0.005 * np.arange(1000)
    a = rng.standard_normal(t.size)
    a[0] = 0.0
    for f0, z in ((2.0, 0.15), (4.0, 0.03), (0.05, 0.0), (40.0, 0.5)):
        h = rs.sdof_history(t, a, 1 / f0, z)
        y = lfilter(*rs.sdof_filter(f0, z, 0.005), a)
        assert np.abs(y - h.a_abs).max() < 1e-9 * np.abs(h.a_abs).max(), (f0, z)


@pytest.mark.parametrize("which", ["ssi", "fixed"])
def test_identifies_the_oscillator(files, which):
    """f0 within 0.2 %, zeta within 2 % of the oscillator's; c1 (participation) 1, c0 0 to 2 %; the
    smoothed ratio's peak within 5 % of |H|'s analytic peak f0 sqrt(sqrt(1 + 8 zeta^2) - 1) / (2 zeta)."""
    p = SSI if which == "ssi" else FIXED
    pair = gl.load_ssi(files[0], 0, "x") if which == "ssi" else gl.load_fixed(files[1], 0, "x")
    ratio, fit = gl.analyse(pair)
    assert abs(fit.f0 / p["f0"] - 1) < 2e-3, fit
    assert abs(fit.zeta / p["zeta"] - 1) < 0.02, fit
    assert abs(fit.c1 - 1) < 0.02 and abs(fit.c0) < 0.02, fit
    assert fit.r2 > 0.999
    z = p["zeta"]
    f_peak = p["f0"] * math.sqrt(math.sqrt(1 + 8 * z * z) - 1) / (2 * z)
    assert abs(ratio.f_peak / f_peak - 1) < 0.05, (ratio.f_peak, f_peak)


def test_report_csv_png(files, tmp_path, capsys):
    """The command: the table's rows (period lengthening = T_ssi / T_fixed = f_fixed / f_ssi,
    within 0.2 % of 4 / 2), the demands of both structure outputs, the note on the different
    steps, a PNG."""
    csv, png = tmp_path / "g.csv", tmp_path / "g.png"
    status, out, err = run([files[0], "--glance", files[1], "--csv", csv, "--png", png], capsys)
    assert status == 0, err
    assert "note: the time steps differ (SSI 0.005 s, fixed base 0.01 s)" in out
    rows = read_csv(csv)
    f = rows["first frequency f0 (SDOF fit)"]
    T = rows["period T0 = 1/f0 (ratio: period lengthening)"]
    assert f[0] == "Hz" and T[0] == "s"
    assert T[1] == pytest.approx(1 / f[1], rel=1e-12) and T[2] == pytest.approx(1 / f[2], rel=1e-12)
    assert T[3] == pytest.approx(T[1] / T[2], rel=1e-12) == pytest.approx(f[2] / f[1], rel=1e-12)
    assert abs(T[3] / (FIXED["f0"] / SSI["f0"]) - 1) < 2e-3
    z = rows["damping ratio zeta (SDOF fit)"]
    assert abs(z[1] / SSI["zeta"] - 1) < 0.02 and abs(z[2] / FIXED["zeta"] - 1) < 0.02
    assert rows["peak base shear"] == ("N", 2.0e5, 5.0e5, pytest.approx(0.4))
    assert rows["peak inter-storey drift ratio"] == ("-", 4e-3, 1e-2, pytest.approx(0.4))
    assert "(storey 2)" in out
    a = rows["peak roof absolute acceleration"]
    assert a[0] == "m/s^2"
    with open(png, "rb") as fh:
        assert fh.read(8) == PNG_MAGIC


def test_demands_not_recorded_and_incident_control(tmp_path, capsys):
    """Without the group demands the rows say 'not recorded' (CSV: nan); -ssi_seismic_control
    incident doubles the free field (the surface motion of a vertical wave), so the roof / free
    field ratio halves: c1 0.5, f0 unchanged."""
    s = write_ssi(str(tmp_path), control="incident")
    fx = write_fixed(str(tmp_path))
    status, out, err = run([s, "--glance", fx, "--csv", tmp_path / "g.csv"], capsys)
    assert status == 0, err
    assert "| peak base shear | N | not recorded | not recorded |  |" in out
    rows = read_csv(tmp_path / "g.csv")
    assert all(math.isnan(v) for v in rows["peak inter-storey drift ratio"][1:])
    assert "surface = 2 x incident" in out
    _, fit = gl.analyse(gl.load_ssi(s, 0, "x"))
    assert abs(fit.c1 - 0.5) < 0.005 and abs(fit.f0 / SSI["f0"] - 1) < 2e-3


def _refusals(d):
    s, fx, s2 = write_ssi(d), write_fixed(d), write_ssi(d, "other.h5")
    st = s[:-3] + "_structure.h5"
    return [
        ([s, "--glance", fx, "--csv", s], "is the input file"),
        ([s, "--glance", fx, "--png", st], "is the input file"),
        ([s, "--glance", fx, "--csv", fx], "is the input file"),
        ([fx, "--glance", fx], "the same file"),
        ([fx, "--glance", s], "not the soil output of a coupled run"),
        ([st, "--glance", fx], "a structure output"),
        ([s, "--glance", s2], "not a fixed-base run"),
        ([s, "--glance", fx, "--receiver", "3"], "--receiver 3: out of range"),
        ([s, "--glance", fx, "--component", "y"], "no free-field y motion"),
        ([s], "give the coupled run's soil output and its fixed-base twin"),
        ([s, "--glance", os.path.join(d, "none.h5")], "no such file"),
        ([s, "--glance", fx, "--band", "5,1"], "0 < F1 < F2"),
    ]


def test_refusals_one_line_status_2(tmp_path, capsys):
    for argv, words in _refusals(str(tmp_path)):
        status, out, err = run(argv, capsys)
        assert status == 2, (argv, out)
        lines = err.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("petsc-ssi post: error:"), (argv, err)
        assert words in lines[0], (argv, lines[0])


def test_refuses_an_oblique_wave_and_a_run_without_earthquake(tmp_path, capsys):
    import h5py
    s, fx = write_ssi(str(tmp_path)), write_fixed(str(tmp_path))
    with h5py.File(s, "r+") as f:
        f.attrs["seismic"] = "sv"
    status, _, err = run([s, "--glance", fx], capsys)
    assert status == 2 and "-ssi_seismic sv" in err and "vertical incidence only" in err
    with h5py.File(s, "r+") as f:
        del f["seismic"]
        del f.attrs["seismic"]
    status, _, err = run([s, "--glance", fx], capsys)
    assert status == 2 and "without an earthquake" in err


def test_an_undamped_fixed_base_has_no_damping_ratio(tmp_path, capsys):
    """An undamped fixed base (zeta 0: the fit's floor, about 1e-30 in an independent test's run) is
    shown as undamped with no SSI / fixed ratio (that test's glance printed 3.5e+26)."""
    s = write_ssi(str(tmp_path))
    fx = write_fixed(str(tmp_path), zeta=0.0)
    status, out, err = run([s, "--glance", fx, "--csv", tmp_path / "g.csv"], capsys)
    assert status == 0, err
    line = next(ln for ln in out.splitlines() if ln.startswith("| damping ratio zeta"))
    cells = [c.strip() for c in line.strip("|").split("|")]
    assert cells[3] == "< 1e-06 (undamped)" and cells[4] == "", line
    z = read_csv(tmp_path / "g.csv")["damping ratio zeta (SDOF fit)"]
    assert z[2] < 1e-6 and math.isnan(z[3])


def test_given_damping_beside_the_identified(tmp_path, capsys):
    """Issue 43: with the structure outputs' damping attributes (alpha_m, rayleigh_a1: what a run writes),
    the row 'damping ratio given ...' is alpha_m/(2 w) + a1 w/2 at each identified f0 (1e-12): Rayleigh
    damping of 3 % at 2 and 8 Hz is 3 % at the SSI's f0 (2 Hz) and 2.4 % at the fixed base's (4 Hz), within
    the fit's error on f0; without the attributes the row says 'not recorded'."""
    import h5py
    from petsc_ssi.fem.options import rayleigh_from_ratios
    s, fx = write_ssi(str(tmp_path)), write_fixed(str(tmp_path))
    status, out, err = run([s, "--glance", fx], capsys)
    assert status == 0, err
    q = "damping ratio given to the structure at that f0 (Rayleigh, + modal: the nearest damped mode's)"
    assert f"| {q} | - | not recorded | not recorded |  |" in out
    a0, a1 = rayleigh_from_ratios(2.0, 8.0, 0.03, 0.03)               # 3 % at 2 and 8 Hz: 2.4 % at 4 Hz
    for p in (s[:-3] + "_structure.h5", fx):
        with h5py.File(p, "r+") as f:
            f.attrs["alpha_m"], f.attrs["rayleigh_a1"] = a0, a1
    status, out, err = run([s, "--glance", fx, "--csv", tmp_path / "g.csv"], capsys)
    assert status == 0, err
    rows = read_csv(tmp_path / "g.csv")
    f0 = rows["first frequency f0 (SDOF fit)"]
    given = rows[q]
    for k in (1, 2):
        w = 2 * math.pi * f0[k]
        assert given[k] == pytest.approx(a0 / (2 * w) + a1 * w / 2, rel=1e-12)
    assert given[1] == pytest.approx(0.03, rel=0.02)                   # SSI f0 = 2 Hz: 3 %
    assert given[2] == pytest.approx(0.024, rel=0.02)                  # fixed f0 = 4 Hz: 2.4 %
    # modal damping (what a run with -ssi_fem_modal_damping writes): the ratio of the damped mode nearest
    # f0 is added (the SSI's 2 Hz is nearest the fixed-base mode of 4 Hz, not the one of 11 Hz)
    for p in (s[:-3] + "_structure.h5", fx):
        with h5py.File(p, "r+") as f:
            f.attrs["modal_damping_frequencies_hz"] = np.array([4.0, 11.0])
            f.attrs["modal_damping_ratios"] = np.array([0.02, 0.05])
    status, out, err = run([s, "--glance", fx, "--csv", tmp_path / "g2.csv"], capsys)
    assert status == 0, err
    given2 = read_csv(tmp_path / "g2.csv")[q]
    for k in (1, 2):
        assert given2[k] == pytest.approx(given[k] + 0.02, rel=1e-12)


def test_notes_base_shear_modelled_part_and_resolution(tmp_path, capsys, monkeypatch):
    """The header says what the base shear is (the foundation's inertia included, the same on both) and whose
    (the structure outputs' attribute symmetry: a half model's is the half's); on a series too short to
    resolve f0 (1/T above 5 % of f0) it says the spectral ratio's peak is uncertain. The 20 s record: no such
    warning (1/T = 0.05 Hz, 2.5 % and 1.25 % of f0); a 4 s one: both (0.25 Hz, 12.5 % and 6.2 %)."""
    import h5py
    import sys
    s = write_ssi(str(tmp_path), demands=(2.0e5, 4e-3))
    fx = write_fixed(str(tmp_path), demands=(5.0e5, 1e-2))
    with h5py.File(s[:-3] + "_structure.h5", "a") as f:
        f.attrs["symmetry"] = "y=sym"
    with h5py.File(fx, "a") as f:
        f.attrs["symmetry"] = ""
    status, out, err = run([s, "--glance", fx], capsys)
    assert status == 0, err
    notes = out.splitlines()
    assert sum(ln.startswith("base shear: ") and "foundation's own inertia included" in ln for ln in notes) == 1, out
    assert "with SSI: modelled part: the half of the structure on the planes -ssi_symmetry 'y=sym'" in out, out
    assert "fixed base: modelled part: the whole mesh (no -ssi_symmetry plane)" in out, out
    assert "resolve frequencies" not in out, out
    monkeypatch.setattr(sys.modules[__name__], "REC_T", 4.0)
    short = tmp_path / "short"
    short.mkdir()
    s, fx = write_ssi(str(short)), write_fixed(str(short))
    status, out, err = run([s, "--glance", fx], capsys)
    assert status == 0, err
    warn = [ln for ln in out.splitlines() if "so its spectra resolve frequencies 1/T" in ln]
    assert len(warn) == 2 and warn[0].startswith("with SSI: warning: the series is 4") and "12 % of f0" in warn[0] \
        and warn[1].startswith("fixed base: warning:"), warn
    assert "base shear: " not in out                          # no demands recorded: no note
