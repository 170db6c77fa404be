"""Foundation input motion of a massless rigid footing embedded in the half-space (issue 42, item 2;
``runs/embedment/input_motion.py``, whose functions these tests run): the pit's walls and bottom (B = 1 m)
as a massless rigid body under a vertically incident S wave, its base's translation and its rocking
against the free field's surface motion, beside NIST GCR 12-917-21's embedment transfer functions
H_u = cos(2 pi f D / V_s) (>= 0.453) and H_theta = 0.26 (1 - cos(2 pi f D / V_s)).

The footing's condition is a zero resultant of the TOTAL traction, scattered + free field
(``MasslessFooting.free_field_resultant``): with the term switched off (a trial edit, not kept) the base's
translation at 40 Hz was 1.11 of the free field at the base's depth, about 0.78 of the surface's against
NIST's 0.70, so the bounds below fail without it (with it: 0.70). Measured (runs/embedment/README.md)."""

import numpy as np
import pytest

from helpers import run_script

pytestmark = pytest.mark.run


def script():
    return run_script("runs", "embedment", "input_motion.py")


def test_embedded_footing_filters_the_translation_as_nist_says(tmp_path):
    """D/B = 1 on 1 m elements, dt = 0.94 ms (trusted f <= 50.8 Hz): from 2 to 45 Hz, H_u within 0.03 of
    cos(2 pi f D / V_s) (measured 0.024 at most) and H_theta within 0.01 of NIST's (measured 0.005); at
    40 Hz the translation is filtered to under 0.75 of the free field's (measured 0.70). The output holds the
    condition: the scattered traction's resultant ('resultants') plus the free field's
    ('input_motion/free_field_resultant') is zero to 1e-8 of the step stiffness's W q (measured 8e-16)."""
    s = script()
    f, hu, ht, _ = s.transfer(1.0, h=1.0, dt=9.4e-4, t_end=0.06, out=str(tmp_path / "fim.h5"))
    nu, nt = s.nist(f, 1.0)
    sel = (f >= 2.0) & (f <= 45.0)
    assert sel.sum() > 20 and f[-1] > 45.0
    assert np.abs(hu - nu)[sel].max() < 0.03, np.abs(hu - nu)[sel].max()
    assert np.abs(ht - nt)[sel].max() < 0.01, np.abs(ht - nt)[sel].max()
    assert np.interp(40.0, f, hu) < 0.75 and abs(hu[0] - 1) < 1e-3
    r = s.residual(str(tmp_path / "fim.h5"))
    assert r < 1e-8, r


# slow tier: the README's runs (D/B = 0.5 and 1 on 0.5 m elements, minutes); D/B = 1 on 1 m elements stays
@pytest.mark.slow
def test_input_motion_on_half_metre_elements(tmp_path):
    """h = 0.5 m, dt = 0.475 ms (trusted f <= 100 Hz): from 2 Hz to 0.7 f_c (f_c = V_s / 4 D: 79 Hz at
    D/B = 1, 158 Hz at 0.5, where NIST's floor 0.453 starts) or 100 Hz, H_u within 0.08 of NIST's (measured
    0.070 at D/B = 0.5, the BEM below NIST by up to 0.06 at 40 - 55 Hz; 0.076 at D/B = 1, where NIST's
    cosine meets its floor) and H_theta within 0.04 (measured 0.028 and 0.005)."""
    s = script()
    for D in (0.5, 1.0):
        f, hu, ht, _ = s.transfer(D, out=str(tmp_path / "fim.h5"))
        nu, nt = s.nist(f, D)
        sel = (f >= 2.0) & (f <= min(0.7 * 316.0 / (4 * D), 100.0))
        assert np.abs(hu - nu)[sel].max() < 0.08, (D, np.abs(hu - nu)[sel].max())
        assert np.abs(ht - nt)[sel].max() < 0.04, (D, np.abs(ht - nt)[sel].max())
