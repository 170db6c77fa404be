"""`petsc-ssi record FILE` (issue 43, item 7): the record processed as a run would, without a model.
The CSV's motion hits the target PGA (to the 12 printed digits), its velocity and displacement are the
exact integrals of the piecewise-linear acceleration (checked with the independent recurrences
v_i+1 = v_i + h (a_i + a_i+1)/2, d_i+1 = d_i + h v_i + h^2 (2 a_i + a_i+1)/6); implausible units and a
record given twice are refused in one line on every rank."""
import numpy as np
import pytest

from helpers import cli

pytestmark = pytest.mark.mpi

G0 = 9.80665


@pytest.fixture
def rec(tmp_path):
    t = np.arange(0.0, 5.0, 0.01)
    a = 1.5 * np.sin(2 * np.pi * 2 * t) * np.sin(np.pi * t / 5) ** 2
    p = tmp_path / "rec.txt"
    np.savetxt(p, np.c_[t, a], header="units: m/s2")
    g = tmp_path / "recg.txt"
    np.savetxt(g, np.c_[t, 100 * a], header="units: g")
    return p, g


def test_record_report_and_csv(rec, tmp_path):
    out = tmp_path / "m.csv"
    p = cli(["record", str(rec[0]), "-ssi_seismic_target", "pga:0.3g", "-ssi_seismic_baseline", "none",
             "-ssi_record_csv", str(out)])
    assert "PGA [m/s2]" in p.stdout and "target PGA: 2.94199 m/s^2 (0.3 g)" in p.stdout
    # the 'raw' column holds the record times the target's factor: its head says so
    head = [ln for ln in p.stdout.splitlines() if ln.rstrip().endswith("processed")]
    assert len(head) == 1 and " raw x " in head[0], p.stdout[-2000:]
    rows = [ln.split(",") for ln in out.read_text().splitlines() if not ln.startswith("#")]
    assert rows[0] == ["axis", "t [s]", "acceleration [m/s^2]", "velocity [m/s]", "displacement [m]"]
    data = np.array([[float(x) for x in r[1:]] for r in rows[1:]])
    t, a, v, d = data.T
    assert np.abs(a).max() == pytest.approx(0.3 * G0, rel=1e-11)
    h = np.diff(t)
    vi = np.concatenate([[0.0], np.cumsum(h * (a[:-1] + a[1:]) / 2)])
    assert np.allclose(v, vi, rtol=0, atol=1e-10 * np.abs(v).max())
    di = np.zeros_like(d)
    for i in range(len(t) - 1):
        di[i + 1] = di[i] + h[i] * vi[i] + h[i] ** 2 * (2 * a[i] + a[i + 1]) / 6
    assert np.allclose(d, di, rtol=0, atol=1e-9 * np.abs(d).max())


@pytest.mark.parametrize("which, extra, words", [
    (1, [], "PGA 148.9 g as read in g"),
    (0, ["-ssi_seismic_record", "x.txt"], "takes the record as its argument: drop -ssi_seismic_record"),
    (0, ["-ssi_seismic_target", "pga:-1"], "-ssi_seismic_target pga:-1"),
])
def test_refusals_one_line_every_rank(rec, which, extra, words):
    p = cli(["record", str(rec[which])] + extra, nranks=2, check=False, timeout=300)
    errors = [ln for ln in p.stderr.splitlines() if ln.startswith("petsc-ssi: error:")]
    assert p.returncode == 2 and len(errors) == 1 and words in errors[0], p.stdout + p.stderr


def test_a_plausible_record_scaled_to_an_implausible_run_is_refused(rec):
    """Issue 44's 'record scaled by 1e12': the units check reads the record before its scale, so the
    run's PGA (after -ssi_seismic_scale or -ssi_seismic_target) is checked too, naming the option
    that made it implausible; -ssi_seismic_units_check 0 runs it anyway."""
    for extra, opt in ((["-ssi_seismic_scale", "1e12"], "-ssi_seismic_scale"),
                       (["-ssi_seismic_target", "pga:1e12"], "-ssi_seismic_target"),
                       (["-ssi_seismic_scale", "1e-9"], "-ssi_seismic_scale")):
        p = cli(["record", str(rec[0]), "-ssi_seismic_baseline", "none"] + extra, check=False)
        lines = [ln for ln in p.stdout.splitlines() + p.stderr.splitlines() if "error" in ln]
        assert p.returncode == 2 and len(lines) == 1, p.stdout + p.stderr
        assert "the run's PGA" in lines[0] and f"check {opt}" in lines[0], lines[0]
    p = cli(["record", str(rec[0]), "-ssi_seismic_baseline", "none", "-ssi_seismic_scale", "1e12",
             "-ssi_seismic_units_check", "0"])
    assert "PGA [m/s2]" in p.stdout
