"""An embedded rigid square footing's static stiffness against Pais & Kausel's embedment factors (issue 42,
item 2; NIST GCR 12-917-21 Table 2-2b; ``runs/embedment/static_stiffness.py``, whose functions these tests
run). The footing is the pit's walls and bottom moved rigidly (B = 1 m, D/B = 0.5 and 1), on an 8 m x 8 m
ground; the factor eta = K_embedded / K_surface is taken on meshes of the same element size.

Measured (runs/embedment/README.md), eta_BEM / eta_PK - 1 at h = 1 m and 0.5 m:
    vertical   -7.5 %, -7.4 %  ->  -4.3 %, -4.4 %
    horizontal -5.5 %, -6.1 %  ->  -1.9 %, -2.7 %
    torsion   -18.2 %, -20.1 % ->  -9.2 %, -11.5 %
    rocking    -10.5 %, -15.8 % ->  -1.8 %, -8.1 %   (about the base's centre)
every one closer to the table on the finer mesh (about halving)."""

import pytest

from helpers import run_script

pytestmark = pytest.mark.run


def script():
    return run_script("runs", "embedment", "static_stiffness.py")


def test_embedment_factors_on_one_metre_elements(tmp_path):
    """h = B = 1 m, D/B = 1: vertical and horizontal within 10 % of the table (measured -7.4 %, -6.1 %),
    both factors above 1.3 (the embedment stiffens). Torsion and rocking: the slow tier."""
    s = script()
    rows = s.embedment_factors(1.0, (1.0,), modes=("vertical", "horizontal"), out=str(tmp_path / "k.h5"))
    err = {r[2]: r[7] for r in rows}
    assert all(r[3] > 0 and r[4] > 0 and r[5] > 1.3 for r in rows), rows
    assert abs(err["vertical"]) < 0.10 and abs(err["horizontal"]) < 0.10, err


# slow tier: the convergence table at h = 1 and 0.5 m, both embedments (3 minutes; h = 1 m, D/B = 1 stays)
@pytest.mark.slow
def test_embedment_factors_converge_towards_pais_and_kausel(tmp_path):
    """On 0.5 m elements every factor is closer to the table than on 1 m elements, and within 10 % of it
    but torsion at D/B = 1 (12 %: -11.5 % measured)."""
    s = script()
    coarse = s.embedment_factors(1.0, (0.5, 1.0), out=str(tmp_path / "k.h5"))
    fine = s.embedment_factors(0.5, (0.5, 1.0), out=str(tmp_path / "k.h5"))
    for c, f in zip(coarse, fine):
        assert c[1:3] == f[1:3]
        assert abs(f[7]) < 0.8 * abs(c[7]), (c, f)
        assert abs(f[7]) < (0.12 if f[2] == "torsion" else 0.10), f
