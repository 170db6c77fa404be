"""petsc-ssi impedance's log of the static coupling terms (app/impedance.coupling_report): each
term in units of sqrt(K0_h K0_r), their reciprocity and their mean, the symmetric estimate."""
import math

import pytest

from petsc_ssi.app.impedance import coupling_report

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
