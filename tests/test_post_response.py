"""petsc-ssi post --response-spectrum (petsc_ssi/app/response.py) on small synthetic output files
written with h5py in the layout of a run's (dataset names copied from a structure output
OUT_structure.h5 and a soil output OUT.h5), with accelerations known exactly:

  structure file: receivers/acceleration holds piecewise-linear pulses (t from 0, dt 0.01 s);
                  receiver 1 is receiver 0 times 2
  soil file:      receivers/u holds polynomials in t (t = dt, 2 dt, ...), whose second central
                  difference is exact (quadratic: constant, cubic: linear)

The command's CSV is compared with petsc_ssi.seismic.response_spectrum called directly on the
same series."""
import io
import math
import os

import numpy as np
import pytest

from petsc_ssi.app import response as rsp
from petsc_ssi.seismic import response_spectrum as rs

pytestmark = pytest.mark.unit

DT = 0.01
K = 101                                  # structure samples: t = 0 .. 1 s
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def _tri(t, t0, t1, t2, peak):
    """Piecewise-linear pulse: 0 before t0, peak at t1, 0 from t2 (nodes on the grid)."""
    return np.interp(t, [t0, t1, t2], [0.0, peak, 0.0], left=0.0, right=0.0)


def _structure_acc(t):
    """(K, 2, 3) [m/s^2]: receiver 0 pulses in x, y, z; receiver 1 = 2 x receiver 0."""
    a0 = np.stack([_tri(t, 0.0, 0.2, 0.4, 3.0), _tri(t, 0.1, 0.25, 0.5, -1.5),
                   _tri(t, 0.05, 0.3, 0.6, 0.8)], axis=1)
    return np.stack([a0, 2.0 * a0], axis=1)


def write_structure(path, scale=1.0):
    """A structure output: receivers/{t, u, velocity, acceleration, rotation, points,
    node_points, nodes, snap_distance, has_rotation}, t from 0."""
    import h5py
    t = np.arange(K) * DT
    a = scale * _structure_acc(t)
    v = np.concatenate([np.zeros((1, 2, 3)), np.cumsum(a[1:] * DT, axis=0)])
    u = np.concatenate([np.zeros((1, 2, 3)), np.cumsum(v[1:] * DT, axis=0)])
    with h5py.File(path, "w") as f:
        f.attrs.update({"problem": "ssi-structure", "dt": DT, "cell_type": "mixed",
                        "run_status": "completed"})
        g = f.create_group("receivers")
        g["t"], g["u"], g["velocity"], g["acceleration"] = t, u, v, a
        g["rotation"] = np.zeros_like(u)
        g["points"] = np.array([[0.0, 0.0, 6.0], [0.0, 0.0, 0.0]])
        g["node_points"] = g["points"][:]
        g["nodes"] = np.array([10, 3])
        g["snap_distance"] = np.zeros(2)
        g["has_rotation"] = np.array([True, False])
    return str(path)


def _soil_u(t, scale=1.0):
    """(n, 3, 3) [m]: receiver 0 quadratic per component (a = 2 c2), receiver 1 cubic
    (a = 6 c3 t + 2 c2), receiver 2 zero."""
    quad = np.stack([0.7 * t ** 2 + 0.01 * t + 1e-3, -0.25 * t ** 2, 0.4 * t ** 2 - 0.02 * t], axis=1)
    cub = np.stack([2.0 * t ** 3 - 0.5 * t ** 2, 0.3 * t ** 3, -t ** 3 + 0.1 * t], axis=1)
    return scale * np.stack([quad, cub, np.zeros_like(quad)], axis=1)


def _soil_t(n=80, dt=0.005):
    return dt * np.arange(1, n + 1)      # a soil output starts at t = dt


def write_soil(path, t=None, scale=1.0):
    """A soil output: receivers/{points, t, u} (displacement only)."""
    import h5py
    t = _soil_t() if t is None else t
    with h5py.File(path, "w") as f:
        f.attrs.update({"problem": "ssi", "dt": float(t[1] - t[0]), "cell_type": "quad9"})
        g = f.create_group("receivers")
        g["t"], g["u"] = t, _soil_u(t, scale)
        g["points"] = np.array([[4.0, 0.0, 0.0], [6.0, 0.0, 0.0], [-6.0, 0.0, 0.0]])
    return str(path)


def run(argv, capsys):
    """main in-process: (status, stdout, stderr)."""
    out = io.StringIO()
    status = rsp.main([str(a) for a in argv], out=out)
    err = capsys.readouterr().err
    return status, out.getvalue(), err


def read_csv(text_or_path):
    text = open(text_or_path).read() if os.path.exists(str(text_or_path)) else text_or_path
    lines = [ln for ln in text.splitlines() if ln and not ln.startswith("#")]
    names = lines[0].split(",")
    data = np.array([[float(v) for v in ln.split(",")] for ln in lines[1:]])
    return names, {n: data[:, j] for j, n in enumerate(names)}, data


def _flat(spec, q):
    return np.asarray(spec[q]).ravel()   # rows: damping outer, period inner (as the CSV)


def _ok(status, err):
    assert status == 0, err
    assert err == ""


@pytest.fixture
def structure(tmp_path):
    return write_structure(tmp_path / "A_structure.h5")


@pytest.fixture
def soil(tmp_path):
    return write_soil(tmp_path / "A.h5")


# ---------------------------------------------------------------- single component, structure file

def test_structure_csv_equals_response_spectrum(structure, tmp_path, capsys):
    csv = tmp_path / "rs.csv"
    st, out, err = run([structure, "--response-spectrum", "--receiver", 1, "--component", "y",
                        "--damping", "0.02,0.05", "--periods", "0.05:3:25", "--csv", csv], capsys)
    _ok(st, err)
    names, cols, data = read_csv(csv)
    assert names == ["period [s]", "damping [-]", "SA [m/s^2]", "PSA [m/s^2]", "PSV [m/s]",
                     "SD [m]", "SV [m/s]"]
    periods = np.geomspace(0.05, 3, 25)
    t = np.arange(K) * DT
    k = 1                                # auto sub-steps with exact peaks (issue 43): none needed
    ref = rs.response_spectrum(t, _structure_acc(t)[:, 1, 1], periods, [0.02, 0.05], oversample=k)
    assert data.shape == (2 * 25, 7)
    np.testing.assert_allclose(cols["period [s]"], np.tile(periods, 2), rtol=1e-12, atol=0)
    np.testing.assert_allclose(cols["damping [-]"], np.repeat([0.02, 0.05], 25), rtol=1e-12, atol=0)
    for q in rs.QUANTITIES:
        np.testing.assert_allclose(cols[f"{q} [{rs.UNITS[q]}]"], _flat(ref, q), rtol=1e-12, atol=0)
    # the summary states what was computed
    assert "receiver 1 at (0, 0, 0) m, component y" in out
    assert os.path.abspath(structure) in out
    assert "recorded acceleration receivers/acceleration" in out
    assert f"n {K}, dt 0.01 s (uniform)" in out
    assert "PGA: y 3 m/s^2" in out          # 2 x 1.5 m/s^2
    assert f"sub-steps per time step: {k}; peaks exact" in out
    assert f"wrote {csv}" in out
    # the '#' header of the CSV says the same
    head = [ln for ln in open(csv) if ln.startswith("#")]
    assert any("recorded acceleration" in ln for ln in head) and any("PGA" in ln for ln in head)


def test_defaults_standard_periods_damping_005(structure, tmp_path, capsys):
    csv = tmp_path / "rs.csv"
    st, out, err = run([structure, "--response-spectrum", "--csv", csv], capsys)
    _ok(st, err)
    _, cols, _ = read_csv(csv)
    p = rs.standard_periods()
    np.testing.assert_array_equal(cols["period [s]"], p)
    np.testing.assert_array_equal(cols["damping [-]"], np.full(p.size, 0.05))
    t = np.arange(K) * DT
    ref = rs.response_spectrum(t, _structure_acc(t)[:, 0, 0], p, [0.05],
                               oversample=math.ceil(10 * DT / p.min()))
    np.testing.assert_allclose(cols["PSA [m/s^2]"], _flat(ref, "PSA"), rtol=1e-12, atol=0)
    assert "component x" in out and "receiver 0 at (0, 0, 6) m" in out


def test_component_all_labels_every_column(structure, tmp_path, capsys):
    csv = tmp_path / "rs.csv"
    st, _, err = run([structure, "--component", "all", "--periods", "0.1,0.5,1", "--csv", csv], capsys)
    _ok(st, err)
    names, cols, _ = read_csv(csv)
    t = np.arange(K) * DT
    for j, c in enumerate("xyz"):
        ref = rs.response_spectrum(t, _structure_acc(t)[:, 0, j], [0.1, 0.5, 1.0], [0.05])
        np.testing.assert_allclose(cols[f"{c} SD [m]"], _flat(ref, "SD"), rtol=1e-12, atol=0)
    assert all(n.endswith("]") and " [" in n for n in names)     # every column has its unit


def test_csv_to_standard_output(structure, tmp_path, capsys):
    csv = tmp_path / "rs.csv"
    _ok(*run([structure, "--periods", "0.1,0.3", "--csv", csv], capsys)[::2])
    st, out, err = run([structure, "--periods", "0.1,0.3", "--csv"], capsys)
    _ok(st, err)
    assert read_csv(out)[0] == read_csv(csv)[0]
    np.testing.assert_array_equal(read_csv(out)[2], read_csv(csv)[2])
    assert "recorded acceleration" in out.splitlines()[2]          # as a '#' line


# ---------------------------------------------------------------- soil file: differentiated displacement

def test_second_difference_exact_for_quadratic_and_cubic():
    t = _soil_t()
    u = _soil_u(t)
    tm, a = rsp.second_difference(t, u[:, 0, :])
    np.testing.assert_array_equal(tm, t[1:-1])
    np.testing.assert_allclose(a, np.broadcast_to([1.4, -0.5, 0.8], a.shape), rtol=1e-9, atol=0)
    _, a3 = rsp.second_difference(t, u[:, 1, :])
    exact = np.stack([12.0 * tm - 1.0, 1.8 * tm, -6.0 * tm], axis=1)
    np.testing.assert_allclose(a3, exact, rtol=0, atol=1e-9 * np.abs(exact).max())


def test_soil_csv_equals_spectrum_of_differentiated_displacement(soil, tmp_path, capsys):
    csv = tmp_path / "rs.csv"
    st, out, err = run([soil, "--receiver", 1, "--component", "x", "--periods", "0.05:2:15",
                        "--damping", "0.05,0.1", "--oversample", 1, "--csv", csv], capsys)
    _ok(st, err)
    _, cols, _ = read_csv(csv)
    t = _soil_t()
    u = _soil_u(t)[:, 1, 0]
    dt = np.diff(t).mean()
    a = (u[2:] - 2 * u[1:-1] + u[:-2]) / dt ** 2
    periods = np.geomspace(0.05, 2, 15)
    ref = rs.response_spectrum(t[1:-1], a, periods, [0.05, 0.1])
    exact = rs.response_spectrum(t[1:-1], 12.0 * t[1:-1] - 1.0, periods, [0.05, 0.1])
    for q in rs.QUANTITIES:
        col = cols[f"{q} [{rs.UNITS[q]}]"]
        np.testing.assert_allclose(col, _flat(ref, q), rtol=1e-12, atol=0)
        np.testing.assert_allclose(col, _flat(exact, q), rtol=1e-9, atol=0)
    assert "differentiated displacement" in out and "first and last sample dropped" in out
    assert f"n {t.size - 2}, dt 0.005 s (uniform), t 0.01 .. {t[-2]:.9g} s" in out


def test_soil_quadratic_spectrum_of_constant_acceleration(soil, tmp_path, capsys):
    csv = tmp_path / "rs.csv"
    st, out, err = run([soil, "--component", "z", "--periods", "0,0.1,0.4", "--csv", csv], capsys)
    _ok(st, err)
    _, cols, _ = read_csv(csv)
    t = _soil_t()[1:-1]
    ref = rs.response_spectrum(t, np.full(t.size, 0.8), [0.0, 0.1, 0.4], [0.05],
                               oversample=math.ceil(10 * 0.005 / 0.1))
    np.testing.assert_allclose(cols["SA [m/s^2]"], _flat(ref, "SA"), rtol=1e-9, atol=0)
    assert cols["PSA [m/s^2]"][0] == pytest.approx(0.8, rel=1e-9)       # T = 0: PGA
    assert "PGA: z 0.8 m/s^2" in out


def test_structure_source_displacement(structure, tmp_path, capsys):
    csv = tmp_path / "rs.csv"
    st, out, err = run([structure, "--source", "displacement", "--periods", "0.2,1",
                        "--csv", csv], capsys)
    _ok(st, err)
    import h5py
    with h5py.File(structure, "r") as f:
        t, u = f["receivers/t"][:], f["receivers/u"][:, 0, 0]
    _, a = rsp.second_difference(t, u)
    ref = rs.response_spectrum(t[1:-1], a, [0.2, 1.0], [0.05])
    np.testing.assert_allclose(read_csv(csv)[1]["SA [m/s^2]"], _flat(ref, "SA"), rtol=1e-12, atol=0)
    assert "differentiated displacement" in out


# ---------------------------------------------------------------- two horizontal components

def test_rotd_equals_rotd(structure, tmp_path, capsys):
    csv = tmp_path / "rotd.csv"
    st, out, err = run([structure, "--response-spectrum", "--receiver", 0, "--rotd",
                        "--periods", "0.1,0.2,0.5,1,2", "--damping", "0.02,0.05", "--csv", csv], capsys)
    _ok(st, err)
    names, cols, _ = read_csv(csv)
    assert names[2:] == [f"RotD{p} {q} [{rs.UNITS[q]}]" for p in ("50", "100") for q in ("PSA", "PSV", "SD")]
    t = np.arange(K) * DT
    a = _structure_acc(t)[:, 0]
    ref = rs.rotd(t, a[:, 0], a[:, 1], [0.1, 0.2, 0.5, 1, 2], [0.02, 0.05])
    for p in (50, 100):
        for q in ("PSA", "PSV", "SD"):
            np.testing.assert_allclose(cols[f"RotD{p} {q} [{rs.UNITS[q]}]"], _flat(ref[p], q),
                                       rtol=1e-12, atol=0)
    assert "RotD50, RotD100 of x and y" in out and "component x, y" in out


def test_geomean_equals_geometric_mean(structure, tmp_path, capsys):
    csv = tmp_path / "gm.csv"
    st, _, err = run([structure, "--geomean", "--periods", "0.1,0.5", "--csv", csv], capsys)
    _ok(st, err)
    t = np.arange(K) * DT
    a = _structure_acc(t)[:, 0]
    gm = rs.geometric_mean(*(rs.response_spectrum(t, a[:, j], [0.1, 0.5]) for j in (0, 1)))
    np.testing.assert_allclose(read_csv(csv)[1]["PSA [m/s^2]"], _flat(gm, "PSA"), rtol=1e-12, atol=0)


# ---------------------------------------------------------------- spectral ratio

def test_ratio_of_a_file_with_itself_is_one(structure, tmp_path, capsys):
    csv = tmp_path / "ratio.csv"
    st, out, err = run([structure, "--component", "all", "--ratio", structure, "--csv", csv], capsys)
    _ok(st, err)
    names, cols, data = read_csv(csv)
    assert names[2] == "x SA ratio [-]" and len(names) == 2 + 3 * 5
    np.testing.assert_allclose(data[:, 2:], 1.0, rtol=1e-12, atol=0)
    assert "A input" in out and "B input" in out


@pytest.mark.parametrize("kind", ["structure", "soil"])
def test_ratio_with_scaled_copy_is_the_scale(kind, tmp_path, capsys):
    write = write_structure if kind == "structure" else write_soil
    a = write(tmp_path / "A.h5")
    b = write(tmp_path / "B.h5", scale=0.4)
    csv = tmp_path / "ratio.csv"
    st, _, err = run([a, "--ratio", b, "--periods", "0.05:5:20", "--damping", "0.02,0.05",
                      "--csv", csv], capsys)
    _ok(st, err)
    np.testing.assert_allclose(read_csv(csv)[2][:, 2:], 2.5, rtol=1e-12, atol=0)


def test_ratio_receiver_and_rotd(structure, tmp_path, capsys):
    csv = tmp_path / "ratio.csv"
    st, _, err = run([structure, "--receiver", 0, "--ratio", structure, "--ratio-receiver", 1,
                      "--rotd", "--periods", "0.1,0.3,1", "--csv", csv], capsys)
    _ok(st, err)
    names, _, data = read_csv(csv)
    assert names[2] == "RotD50 PSA ratio [-]"
    np.testing.assert_allclose(data[:, 2:], 0.5, rtol=1e-12, atol=0)     # receiver 1 = 2 x receiver 0


# ---------------------------------------------------------------- tables

def test_table_t_a_with_units_line(tmp_path, capsys):
    t = np.linspace(0, 2, 151) ** 1.2                      # non-uniform, allowed
    a = 250.0 * np.sin(7 * t) * np.exp(-t)                 # cm/s^2
    tab = tmp_path / "ff.txt"
    tab.write_text("# free field\n# units: cm/s2\n" + "".join(f"{x!r} {y!r}\n" for x, y in zip(t, a)))
    csv = tmp_path / "rs.csv"
    st, out, err = run(["--response-spectrum", "--table", tab, "--periods", "0.1,0.5,1,2",
                        "--oversample", 1, "--csv", csv], capsys)
    _ok(st, err)
    ref = rs.response_spectrum(t, a * 0.01, [0.1, 0.5, 1, 2], [0.05])
    np.testing.assert_allclose(read_csv(csv)[1]["SA [m/s^2]"], _flat(ref, "SA"), rtol=1e-12, atol=0)
    assert "cm/s2 (as the file states)" in out and "non-uniform dt" in out


def test_table_four_columns_rotd_and_ratio_over_table(structure, tmp_path, capsys):
    t = np.arange(K) * DT
    a = _structure_acc(t)[:, 0]
    tab = tmp_path / "ff.txt"
    np.savetxt(tab, np.column_stack([t, a]))
    csv = tmp_path / "rotd.csv"
    st, out, err = run(["--table", tab, "--rotd", "--periods", "0.2,0.6", "--csv", csv], capsys)
    _ok(st, err)
    ref = rs.rotd(t, a[:, 0], a[:, 1], [0.2, 0.6])
    np.testing.assert_allclose(read_csv(csv)[1]["RotD100 PSA [m/s^2]"], _flat(ref[100], "PSA"),
                               rtol=1e-12, atol=0)
    assert "m/s2 (assumed: the file states none)" in out
    # structure receiver 1 (2 x the table) over the table
    csv2 = tmp_path / "ratio.csv"
    st, _, err = run([structure, "--receiver", 1, "--ratio-table", tab, "--periods", "0.2,0.6",
                      "--csv", csv2], capsys)
    _ok(st, err)
    np.testing.assert_allclose(read_csv(csv2)[2][:, 2:], 2.0, rtol=1e-12, atol=0)


# ---------------------------------------------------------------- plot

def test_png_is_a_png(structure, soil, tmp_path, capsys):
    for argv in ([structure, "--damping", "0.02,0.05", "--periods", "0.05:3:20"],
                 [structure, "--rotd", "--periods", "0.05:3:20", "--ratio", soil, "--ratio-receiver", 1]):
        png = tmp_path / f"rs{len(argv)}.png"
        st, out, err = run(argv + ["--png", png], capsys)
        _ok(st, err)
        data = png.read_bytes()
        assert data[:8] == PNG_MAGIC and len(data) > 5000
        assert f"wrote {png}" in out


# ---------------------------------------------------------------- refusals: one line, status 2

REFUSALS = [
    # (argv with A = the structure file, S = the soil file, OUT = tmp/out.csv, words in the message)
    (["A", "--csv", "A"], ["--csv", "input file"]),
    (["A", "--csv", "A", "--overwrite"], ["--csv", "input file"]),
    (["A", "--png", "A"], ["--png", "input file"]),
    (["A", "--ratio", "S", "--png", "S", "--overwrite"], ["--png", "input file"]),
    (["A", "--csv", "EXISTING"], ["--csv", "exists", "--overwrite"]),
    (["A", "--csv", "S", "--overwrite"], ["--csv", "existing HDF5 file"]),        # a result, not an input
    (["A", "--png", "S", "--overwrite"], ["--png", "existing HDF5 file"]),
    (["A", "--png", "EXISTING"], ["--png", "exists"]),
    (["A", "--csv", "NODIR/out.csv"], ["--csv", "no directory"]),
    (["A", "--receiver", "2"], ["--receiver 2", "out of range", "2 receivers"]),
    (["A", "--receiver", "-1"], ["--receiver -1", "out of range"]),
    (["A", "--receiver", "one"], ["argument --receiver"]),
    (["A", "--ratio", "S", "--ratio-receiver", "3"], ["--ratio-receiver 3", "out of range"]),
    (["A", "--component", "q"], ["argument --component", "'q'"]),
    (["A", "--rotd", "--component", "x"], ["--component x", "--rotd"]),
    (["A", "--periods", "5:1:3"], ["argument --periods", "0 < T1 < T2"]),
    (["A", "--periods", "0.1:1:1"], ["argument --periods", "N >= 2"]),
    (["A", "--periods", "0.1:1"], ["argument --periods", "T1:T2:N"]),
    (["A", "--periods", "a,b"], ["argument --periods"]),
    (["A", "--periods=-1,2"], ["argument --periods", ">= 0"]),
    (["A", "--periods", "-1,2"], ["argument --periods"]),      # argparse: looks like an option
    (["A", "--damping", "5"], ["argument --damping", "[0, 1)", "0.05"]),
    (["A", "--damping", "-0.1"], ["argument --damping", "[0, 1)"]),
    (["A", "--damping", "abc"], ["argument --damping"]),
    (["A", "--oversample", "0"], ["argument --oversample"]),
    (["A", "--rotd", "--plot-quantity", "SA"], ["--plot-quantity SA"]),
    (["S", "--source", "acceleration"], ["--source acceleration", "displacement only"]),
    (["TEXT"], ["not an HDF5 file", "--table"]),
    (["MISSING"], ["no such file"]),
    ([], ["FILE.h5", "--table"]),
    (["A", "--bogus"], ["unrecognized arguments: --bogus"]),
    (["--table", "TABLE2", "--rotd"], ["--table", "one component"]),
    (["--table", "TEXT"], ["--table", "not a table of numbers"]),
    (["A", "--table", "TABLE2"], ["FILE.h5 or --table"]),
    (["NONUNIFORM"], ["non-uniform time grid"]),
]


@pytest.mark.parametrize("argv,words", REFUSALS, ids=[" ".join(a) or "no-input" for a, _ in REFUSALS])
def test_refusals_one_line_status_2(argv, words, structure, tmp_path, capsys):
    soil = write_soil(tmp_path / "S.h5")
    text = tmp_path / "notes.txt"
    text.write_text("this is not HDF5\nnor a table\n")
    table2 = tmp_path / "t_a.txt"
    table2.write_text("0 0\n0.01 1\n0.02 0\n")
    existing = tmp_path / "existing.out"
    existing.write_text("keep me\n")
    t = _soil_t()
    t[40:] += 0.001
    nonuniform = write_soil(tmp_path / "N.h5", t=t)
    names = {"A": structure, "S": soil, "TEXT": str(text), "TABLE2": str(table2),
             "EXISTING": str(existing), "MISSING": str(tmp_path / "missing.h5"),
             "NODIR/out.csv": str(tmp_path / "nodir" / "out.csv"), "NONUNIFORM": nonuniform}
    before = {p: open(p, "rb").read() for p in (structure, soil, str(existing))}
    st, out, err = run([names.get(a, a) for a in argv], capsys)
    assert st == 2
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("petsc-ssi post: error: "), err
    for w in words:
        assert w in lines[0], (w, lines[0])
    assert out == ""
    assert {p: open(p, "rb").read() for p in before} == before      # nothing overwritten
    assert not os.path.exists(tmp_path / "nodir")


def test_overwrite_replaces_an_existing_output(structure, tmp_path, capsys):
    csv = tmp_path / "rs.csv"
    csv.write_text("old\n")
    st, _, err = run([structure, "--periods", "0.1", "--csv", csv, "--overwrite"], capsys)
    _ok(st, err)
    assert read_csv(csv)[0][:3] == ["period [s]", "damping [-]", "SA [m/s^2]"]


def test_round_off_components_are_said_and_a_one_component_geomean_refused(tmp_path, capsys):
    """(An independent test, 2026-11-26.) A component peaking at 1e-12 of the largest is round-off:
    its spectra and ratios are said to be noise. The geometric mean of a pair with one silent
    component is 0 at every period: refused in one line."""
    t = np.arange(400) * 0.01
    ax = np.sin(2 * np.pi * 1.5 * t) * np.sin(np.pi * t / 4) ** 2
    tab = tmp_path / "t.txt"
    np.savetxt(tab, np.column_stack([t, ax, 0.5 * ax, 1e-12 * ax]))
    st, out, err = run(["--table", tab, "--component", "all", "--periods", "0.2,0.6"], capsys)
    _ok(st, err)
    notes = [ln for ln in out.splitlines() if "round-off, not motion" in ln]
    assert len(notes) == 1 and "z component" in notes[0], out
    one = tmp_path / "one.txt"
    np.savetxt(one, np.column_stack([t, ax, 0 * ax, 0 * ax]))
    st, out, err = run(["--table", one, "--geomean", "--periods", "0.2,0.6"], capsys)
    assert st == 2 and "--geomean: the y component" in err and len(err.strip().splitlines()) == 1, err
