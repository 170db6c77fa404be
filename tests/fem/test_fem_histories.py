"""petsc_ssi.histories, the one load-history convention of FEM and BEM, and its BEM layer."""
import numpy as np
import pytest
from scipy.integrate import quad

from petsc_ssi.petsc import SSIError
from petsc_ssi.histories import History
from petsc_ssi.bem import histories as bem_histories

pytestmark = pytest.mark.unit

TABLE = np.array([[0.01, 2.0], [0.02, -1.0], [0.035, 0.5], [0.05, 0.5]])   # jumps 0 -> 2 at t = 0.01


def test_point_values_follow_the_paper():
    """H(t) = 1 for t > 0; box = H(t) - H(t - t0) = 1 on (0, t0]; table 0 before its first time and for
    t <= 0, linear between rows, its last value after the last row."""
    H, box, tab = History("heaviside"), History("box", 0.025), History("table", table=TABLE)
    assert H([-1.0, 0.0, 1e-15, 5.0]).tolist() == [0, 0, 1, 1]
    assert box([0.0, 1e-15, 0.025, 0.025 + 1e-12, 1.0]).tolist() == [0, 1, 1, 0, 0]
    assert tab([-1.0, 0.0, 0.005, 0.0099, 0.01, 0.015, 0.02, 0.04, 9.0]) == pytest.approx(
        [0, 0, 0, 0, 2.0, 0.5, -1.0, 0.5, 0.5], abs=1e-14 * 2.0)      # of the table's largest |value|: observed 2.2e-16
    ramp = History("table", table=np.array([[-1.0, 0.0], [1.0, 1.0]]))       # starts before t = 0
    assert ramp([-0.5, 0.0, 1e-9, 0.5]) == pytest.approx([0, 0, 0.5, 0.75], abs=1e-9)


@pytest.mark.parametrize("hist", [History("heaviside"), History("box", 0.0237), History("table", table=TABLE),
                                  History("table", table=np.array([[-1.0, 1.0], [0.03, 3.0]]))],
                         ids=["heaviside", "box", "table-jump", "table-before-0"])
def test_interval_means_are_exact(hist):
    """mean(a, b) == the integral by adaptive quadrature (breakpoints given) / (b - a) to 1e-12, on
    intervals that straddle 0, t0, the jump and the kinks; step_mean and cell_mean are such means."""
    rng = np.random.default_rng(4)
    ab = np.sort(rng.uniform(-0.01, 0.07, (40, 2)), axis=1)
    ab = np.vstack([ab, [[0.0, 0.01], [0.005, 0.0105], [0.02, 0.035], [-1.0, 0.0]]])
    pts = [0.0, 0.01, 0.02, 0.0237, 0.03, 0.035, 0.05]
    for a, b in ab:
        ref = quad(lambda s: float(hist(s)), a, b, points=[p for p in pts if a < p < b], limit=200,
                   epsabs=1e-15, epsrel=1e-13)[0] / (b - a)
        assert hist.mean(a, b) == pytest.approx(ref, rel=1e-12, abs=1e-13), (a, b)
    dt = 0.004
    for n in range(1, 15):
        assert hist.step_mean(n, dt) == hist.mean((n - 1) * dt, n * dt)
        assert hist.cell_mean(n, dt) == hist.mean((n - 0.5) * dt, (n + 0.5) * dt)
    assert hist.cell_mean(0, dt) == hist.mean(0.0, 0.5 * dt)


def test_box_and_table_means_by_hand():
    """A few means worked by hand: the box end inside a step, a ramp across its kink."""
    h = History("box", 0.02)
    assert h.cell_mean(0, 0.01) == 1.0 and h.cell_mean(2, 0.01) == pytest.approx(0.5, rel=1e-14)
    assert h.cell_mean(3, 0.01) == 0.0 and h.step_mean(2, 0.015) == pytest.approx(1 / 3, rel=1e-14)
    ramp = History("table", table=np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 1.0]]))
    assert ramp.cell_mean(5, 0.1) == pytest.approx(0.5, rel=1e-14)        # linear part: midpoint value
    assert ramp.cell_mean(10, 0.1) == pytest.approx(0.9875, rel=1e-14)    # straddles the kink
    assert ramp.cell_mean(0, 0.1) == pytest.approx(0.025, rel=1e-14)


def test_bem_layer(tmp_path):
    """bem.histories.make returns the shared History; step_mean(f, m, dt, kind, t0) is the exact mean
    over ((m-1) dt, m dt] for every kind (tables from a file too), a midpoint rule for other callables."""
    path = tmp_path / "h.txt"
    np.savetxt(path, TABLE)
    dt = 0.004
    for kind, t0, table in (("heaviside", None, None), ("box", 0.0237, None), ("table", None, str(path))):
        f = bem_histories.make(kind, t0, table)
        ref = History(kind, t0, TABLE if kind == "table" else None)
        assert isinstance(f, History)
        for m in range(1, 16):
            assert bem_histories.step_mean(f, m, dt, kind, t0) == pytest.approx(ref.mean((m - 1) * dt, m * dt),
                                                                               rel=1e-14, abs=1e-15)
        assert f(np.array([0.0, 0.012])).tolist() == ref(np.array([0.0, 0.012])).tolist()
    assert bem_histories.step_mean(lambda t: t, 3, 0.5) == pytest.approx(1.25, rel=1e-14)


@pytest.mark.parametrize("text, message", [
    ("0 0\n0.01 one\n", "could not convert"), ("0 0\n0.02 1\n0.01 1\n", "t must increase strictly (data row 3"),
    ("0 0\n0 1\n", "t must increase strictly (data row 2"), ("0 0 1\n0.01 1 1\n", "need rows of two numbers"),
    ("0 0\n0.01 inf\n", "non-finite"), ("", "need rows of two numbers")])
def test_malformed_tables(tmp_path, text, message):
    path = tmp_path / "h.txt"
    path.write_text(text)
    with pytest.raises(SSIError, match=f"history table '{path}': .*" + message.replace("(", r"\(")):
        History("table", table=str(path))


def test_bad_kind_and_box():
    with pytest.raises(SSIError, match="unknown history 'ramp'"):
        History("ramp")
    with pytest.raises(SSIError, match="box history needs a duration t0 > 0"):
        History("box", 0.0)
    with pytest.raises(SSIError, match="needs a table file"):
        History("table", table="")
