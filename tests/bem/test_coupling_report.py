"""petsc-ssi impedance's log of the static coupling terms (app/impedance.coupling_report): each
term in units of sqrt(K0_h K0_r), their reciprocity and their mean, the symmetric estimate; and the
mean's rows in the CSV (coupling_mean_rows)."""
import math

import pytest

import numpy as np

from petsc_ssi.app.impedance import coupling_mean_rows, coupling_report

pytestmark = pytest.mark.unit


def test_both_terms_give_reciprocity_and_the_mean():
    K0s = {"horizontal": 4.0, "rocking": 9.0}
    lines = coupling_report(K0s, {"horizontal-rocking": -0.9, "rocking-horizontal": -0.6})
    assert len(lines) == 4
    assert "K_hr / K_rh - 1 = 0.5" in lines[2]
    mean = lines[3]
    assert "(K_hr + K_rh) / 2 = -0.75" in mean
    assert f"{-0.75 / math.sqrt(36.0):.3g} of sqrt(K0_h K0_r)" in mean


def test_one_term_or_no_rocking():
    assert len(coupling_report({"horizontal": 4.0, "rocking": 9.0}, {"horizontal-rocking": -0.9})) == 1
    assert coupling_report({"horizontal": 4.0}, {"horizontal-rocking": -0.9}) == []


def _rows(name, K0, K, a0):
    return [(name, a, 10 * a, k.real, k.imag, k.real / K0, k.imag / (a * K0) if a > 0 else np.nan, K0, int(a > 0.5),
             np.nan, np.nan) for a, k in zip(a0, K)]


def test_the_csv_gets_the_mean_of_the_two_coupling_terms():
    a0 = np.array([0.0, 0.5, 1.0])
    hr = _rows("horizontal-rocking", -0.9, np.array([-0.9, -0.8 + 0.1j, -0.7 + 0.3j]), a0)
    rh = _rows("rocking-horizontal", -0.6, np.array([-0.6, -0.6 + 0.2j, -0.5 + 0.1j]), a0)
    rows = coupling_mean_rows(_rows("horizontal", 4.0, np.array([4.0, 4.0, 4.0]), a0) + hr + rh)
    assert [r[0] for r in rows] == ["coupling-mean"] * 3
    np.testing.assert_allclose([r[3] for r in rows], [-0.75, -0.7, -0.6])
    np.testing.assert_allclose([r[4] for r in rows], [0.0, 0.15, 0.2])
    assert all(r[7] == -0.75 for r in rows)
    np.testing.assert_allclose(rows[2][5:7], [-0.6 / -0.75, 0.2 / (1.0 * -0.75)])
    assert [r[8] for r in rows] == [0, 0, 1]


def test_no_mean_without_both_terms_on_one_grid():
    a0 = np.array([0.0, 0.5])
    hr = _rows("horizontal-rocking", -0.9, np.array([-0.9, -0.8]), a0)
    assert coupling_mean_rows(hr) == []
    assert coupling_mean_rows(hr + _rows("rocking-horizontal", -0.6, np.array([-0.6, -0.5]), a0 * 2)) == []
