"""`petsc-ssi post --series GROUP/NAME --csv` and `post --demands --csv` (issue 43, item 3) on a small
fixed-base run of the two-storey shear frame of test_demands.py under a record: every column equals the
stored dataset (to the 9 printed digits), the units come from the datasets' attributes, the summary's
peaks are the stored envelopes, V/W uses the structure's mass (the frame's, summed by hand: columns
4 x 6 m x 0.2^2 m^2 x 2500 kg/m^3 + beams 8 x 12 m x (0.3 x 0.6 x 2500 + 2000) kg/m = 237 600 kg)."""
import csv
import io

import h5py
import numpy as np
import pytest

from fem_helpers import run_cli
from test_demands import frame_msh, frame_opts

pytestmark = pytest.mark.run

MASS = 4 * 6 * 0.2 ** 2 * 2500 + 8 * 12 * (0.3 * 0.6 * 2500 + 2000)


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    d = tmp_path_factory.mktemp("series")
    msh = str(d / "frame.msh")
    frame_msh(msh)
    t = np.arange(0.0, 0.5 + 1e-9, 0.0037)
    np.savetxt(d / "rec.txt", np.c_[t, 2.0 * np.sin(2 * np.pi * 4.0 * t) * np.sin(np.pi * t / 0.5) ** 2],
               header="units: m/s2")
    o = frame_opts(msh)
    o.update(problem="fem", seismic="vertical", seismic_record=str(d / "rec.txt"), seismic_units="m/s2",
             seismic_taper=0, seismic_baseline="none", dt=0.005, t_end=0.4, output=str(d / "fb.h5"),
             output_stride=0, receivers="6,6,6")
    r = run_cli(sum([[f"-ssi_{k}", str(v)] for k, v in o.items()], []))
    assert r.returncode == 0, r.stdout + r.stderr
    return d


def _read(text):
    rows = [ln for ln in text.splitlines() if not ln.startswith("#")]
    head = rows[0].split(",")
    return head, np.array([[float(v) for v in ln.split(",")] for ln in rows[1:]]), \
        [ln for ln in text.splitlines() if ln.startswith("#")]


@pytest.mark.parametrize("series, names", [
    ("demands/base_shear", ["base_shear_x [N]", "base_shear_y [N]"]),
    ("demands/overturning_moment", ["overturning_moment_x [N m]", "overturning_moment_y [N m]"]),
    ("demands/drift_ratio", ["drift_ratio_storey1_x [m/m]", "drift_ratio_storey1_y [m/m]",
                             "drift_ratio_storey2_x [m/m]", "drift_ratio_storey2_y [m/m]"]),
    ("receivers/absolute_acceleration", ["absolute_acceleration_r0_x [m/s^2]", "absolute_acceleration_r0_y [m/s^2]",
                                         "absolute_acceleration_r0_z [m/s^2]"]),
    ("seismic/x_acceleration", ["x_acceleration [m/s2]"]),
])
def test_series_csv_equals_the_dataset(run, series, names):
    out = run / (series.replace("/", "_") + ".csv")
    r = run_cli(["post", str(run / "fb.h5"), "--series", series, "--csv", str(out)])
    assert r.returncode == 0, r.stdout + r.stderr
    head, data, comments = _read(out.read_text())
    assert head[0] == "t [s]" and head[1:] == names
    with h5py.File(run / "fb.h5", "r") as f:
        grp = series.split("/")[0]
        tkey = grp + "/t" if grp + "/t" in f else "seismic/x_t"
        x = f[series][()].reshape(f[series].shape[0], -1)
        t = f[tkey][()]
    assert data.shape == (t.size, 1 + x.shape[1])
    assert np.allclose(data[:, 0], t, rtol=1e-8, atol=0)
    assert np.allclose(data[:, 1:], x, rtol=1e-8, atol=1e-12 * np.abs(x).max())      # %.9g
    assert np.abs(x).max() > 0
    assert any(c.startswith("# series: " + series) for c in comments)


def test_series_csv_to_stdout_and_refusals(run):
    r = run_cli(["post", str(run / "fb.h5"), "--series", "demands/base_shear", "--csv"])
    assert r.returncode == 0 and "t [s],base_shear_x [N],base_shear_y [N]" in r.stdout
    for args, words in ((["--series", "demands/nothing", "--csv"], "holds no series demands/nothing (the group "
                         "demands holds:"),
                        (["--series", "demands/levels", "--csv"], "not a time series"),
                        (["--demands"], "--demands writes a CSV: give --csv")):
        r = run_cli(["post", str(run / "fb.h5")] + args)
        err = [ln for ln in r.stderr.splitlines() if ln.strip()]
        assert r.returncode == 2 and len(err) == 1 and words in err[0], r.stderr


def test_demands_summary(run):
    out = run / "dem.csv"
    r = run_cli(["post", str(run / "fb.h5"), "--demands", "--csv", str(out)])
    assert r.returncode == 0, r.stdout + r.stderr
    rows = [x for x in csv.reader(io.StringIO(out.read_text())) if x and not x[0].startswith("#")]
    assert rows[0] == ["quantity", "storey", "component", "value", "unit", "time_s"]
    by = {(q, s, c): (float(v), u, float(t)) for q, s, c, v, u, t in rows[1:]}
    with h5py.File(run / "fb.h5", "r") as f:
        g = f["demands"]
        V, t = g["base_shear"][()], g["t"][()]
        dr = g["drift_ratio"][()]
        mass = f.attrs["structure_mass"]
    assert mass == pytest.approx(MASS, rel=1e-12)
    for j, c in enumerate("xy"):
        k = int(np.argmax(np.abs(V[:, j])))
        assert by[("peak base shear", "", c)] == (pytest.approx(abs(V[k, j]), rel=1e-8), "N", pytest.approx(t[k]))
        assert by[("peak base shear / weight V/W", "", c)][0] == pytest.approx(abs(V[k, j]) / (MASS * 9.80665),
                                                                                rel=1e-8)
        for s in range(2):
            assert by[("peak inter-storey drift ratio", str(s + 1), c)][0] == \
                pytest.approx(np.abs(dr[:, s, j]).max(), rel=1e-8)
    assert by[("peak base shear / weight V/W", "", "x")][0] > 1e-3
    assert ("peak overturning moment (about y)", "", "y") in by
    # the header says what the base shear is and whose (a whole mesh here: the attribute symmetry is '')
    notes = [ln for ln in out.read_text().splitlines() if ln.startswith("#")]
    assert any(ln.startswith("# base shear: ") and "the foundation's own inertia included" in ln for ln in notes), notes
    assert any(ln.startswith("# modelled part: the whole mesh (no -ssi_symmetry plane)") for ln in notes), notes


def test_modelled_part_note():
    """Whose base shear and weight a structure output's are: the run's -ssi_symmetry planes (attribute symmetry)."""
    from petsc_ssi.app.post import modelled_part_note
    half = modelled_part_note({"symmetry": "y=sym"})
    assert "the half of the structure" in half and "whole structure's are twice these" in half, half
    quarter = modelled_part_note({"symmetry": "x=anti,y=sym"})
    assert "the quarter" in quarter and "four times" in quarter, quarter
    assert modelled_part_note({"symmetry": ""}).startswith("modelled part: the whole mesh")
    assert modelled_part_note({}).startswith("modelled part: not recorded")


def test_a_reader_that_stops_reading_ends_post_quietly(run):
    """`post X.h5 --series ... --csv | head -1`: the reader has gone before post writes (its end of the pipe
    closed at once), so the write fails with EPIPE; post ends with status 141 (128 + SIGPIPE, as a shell's own
    tools) and no error line or traceback (before: 'petsc-ssi post: error: [Errno 32] Broken pipe')."""
    import os
    import subprocess
    from fem_helpers import PY, ROOT
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
    p = subprocess.Popen([PY, "-m", "petsc_ssi", "post", str(run / "fb.h5"), "--series", "demands/base_shear",
                          "--csv"], cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    p.stdout.close()                        # (python starts in ~1 s: the pipe is closed before the first write)
    err = p.stderr.read()
    assert p.wait(timeout=120) == 141, err
    assert "error" not in err and "Traceback" not in err, err
    # the same command into a reader that reads: every row, status 0 (the handler changes nothing else)
    r = run_cli(["post", str(run / "fb.h5"), "--series", "demands/base_shear", "--csv"])
    assert r.returncode == 0 and r.stderr == "" and len(_read(r.stdout)[1]) == 81, (r.returncode, r.stderr)
