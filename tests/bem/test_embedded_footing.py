"""An embedded rigid square footing's static stiffness against Pais & Kausel's embedment factors (issue 42,
item 2; NIST GCR 12-917-21 Table 2-2b; ``runs/embedment/static_stiffness.py``, whose functions these tests
run). The footing is the pit's walls and bottom moved rigidly (B = 1 m, D/B = 0.5 and 1), on an 8 m x 8 m
ground; the factor eta = K_embedded / K_surface is taken on meshes of the same element size.

Measured (runs/embedment/README.md, quarter models), eta_BEM / eta_PK - 1 at D/B = 0.5 and 1 on h = 1, 0.5
and 0.25 m elements:
    vertical   -7.5 %, -7.4 %  ->  -4.3 %, -4.4 %  ->  -2.8 %, -2.7 %
    horizontal -5.5 %, -6.1 %  ->  -1.9 %, -2.7 %  ->  -0.3 %, -0.9 %
    torsion   -18.2 %, -20.1 % ->  -9.2 %, -11.5 % ->  -4.5 %, -6.5 %
    rocking   -10.5 %, -15.8 % ->  -1.8 %, -8.1 %  ->  +2.4 %, -3.3 %   (about the base's centre)
the successive differences of every factor shrinking (observed orders 0.7-1.1)."""

import pytest

from helpers import run_script

pytestmark = pytest.mark.run


def script():
    return run_script("runs", "embedment", "static_stiffness.py")


def test_embedment_factors_on_one_metre_elements(tmp_path):
    """h = B = 1 m, D/B = 1, the quarter models of the four modes: vertical and horizontal within 10 % of the
    table (measured -7.4 %, -6.1 %), torsion and rocking within 25 % (-20.1 %, -15.8 %), every factor above
    1.3 (the embedment stiffens); the vertical quarter model equals the whole one (the symmetry's images)."""
    s = script()
    rows = s.embedment_factors(1.0, (1.0,), out=str(tmp_path / "k.h5"), quarter=True)
    err = {r[2]: r[7] for r in rows}
    assert all(r[3] > 0 and r[4] > 0 and r[5] > 1.3 for r in rows), rows
    assert abs(err["vertical"]) < 0.10 and abs(err["horizontal"]) < 0.10, err
    assert abs(err["torsion"]) < 0.25 and abs(err["rocking"]) < 0.25, err
    whole = s.embedment_factors(1.0, (1.0,), modes=("vertical",), out=str(tmp_path / "w.h5"))
    assert whole[0][3] == pytest.approx(rows[0][3], rel=1e-9) and whole[0][4] == pytest.approx(rows[0][4], rel=1e-9)


# slow tier: the three meshes h = 1, 0.5, 0.25 m, both embedments (3 minutes; h = 1 m, D/B = 1 stays)
@pytest.mark.slow
def test_embedment_factors_converge_towards_pais_and_kausel(tmp_path):
    """On 0.25 m elements every factor is within 10 % of the table (the largest measured: torsion at D/B = 1,
    -6.5 %); over h = 1, 0.5, 0.25 m every factor's successive differences shrink (monotone convergence) and
    the Richardson extrapolation lands within 8 % of the table (measured: within 1.5 % but rocking, +4.8 % and
    +6.4 %)."""
    s = script()
    rows = [r for h in (1.0, 0.5, 0.25) for r in s.embedment_factors(h, (0.5, 1.0), out=str(tmp_path / "k.h5"),
                                                                     quarter=True)]
    fine = [r for r in rows if r[0] == 0.25]
    assert len(fine) == 8 and all(abs(r[7]) < 0.10 for r in fine), fine
    conv = s.convergence(rows)
    assert len(conv) == 8, conv             # (a factor whose differences grow or change sign is left out)
    for D, m, etas, p, ex, ref in conv:
        assert 0.5 < p < 1.5 and abs(ex / ref - 1) < 0.08, (D, m, etas, p, ex, ref)
