"""Soil regions of finite elements take the soil's wave speeds (issue 42, item 4): a hex8 part given by
``cp``, ``cs`` and ``rho`` (or the box's ``-ssi_fem_cp/_cs/_rho``) is the isotropic solid of those speeds,
E = 2 rho cs^2 (1 + nu), nu = (cp^2 - 2 cs^2) / (2 (cp^2 - cs^2)); checked here against the speeds
recovered from the Lame constants, and the mixed or impossible inputs refused."""
from types import SimpleNamespace

import numpy as np
import pytest

from petsc_ssi.fem.parts import parse_parts
from petsc_ssi.petsc import SSIError

pytestmark = pytest.mark.unit


def speeds(p):
    lam = p.E * p.nu / ((1 + p.nu) * (1 - 2 * p.nu))
    mu = p.E / (2 * (1 + p.nu))
    return np.sqrt((lam + 2 * mu) / p.rho), np.sqrt(mu / p.rho)


def cfg(**kw):
    base = dict(fem_parts="", fem_E=1.0, fem_nu=0.2, fem_rho=2000.0, fem_cp=0.0, fem_cs=0.0)
    base.update(kw)
    ns = SimpleNamespace(**base)
    ns.get = lambda k, d=None: getattr(ns, k, d)
    ns.user_set = lambda k: k in kw
    return ns


@pytest.mark.parametrize("cp,cs", [(548.0, 316.0), (400.0, 150.0), (1500.0, 200.0)])
def test_a_part_by_its_wave_speeds_has_them(cp, cs):
    spec, = parse_parts(cfg(fem_parts="soil"), raw={"soil_element": "hex8", "soil_cp": str(cp),
                                                    "soil_cs": str(cs), "soil_rho": "1800"})
    assert np.allclose(speeds(spec.props), (cp, cs), rtol=1e-13)
    box, = parse_parts(cfg(fem_cp=cp, fem_cs=cs, fem_rho=1800.0), raw={})
    assert np.allclose(speeds(box.props), (cp, cs), rtol=1e-13)


@pytest.mark.parametrize("raw,msg", [
    ({"soil_element": "hex8", "soil_cp": "548", "soil_cs": "316", "soil_rho": "2000", "soil_E": "1e8"},
     "not E or nu"),
    ({"soil_element": "hex8", "soil_cp": "548", "soil_rho": "2000"}, "cp, cs and rho together"),
    ({"soil_element": "hex8", "soil_cp": "300", "soil_cs": "316", "soil_rho": "2000"}, "cp > 2 cs / sqrt(3)"),
    ({"soil_element": "shell", "soil_cp": "548", "soil_cs": "316", "soil_rho": "2000", "soil_thickness": "1"},
     "has no property 'cp'"),
])
def test_mixed_or_impossible_speeds_are_refused(raw, msg):
    with pytest.raises(SSIError, match=msg.replace("(", r"\(").replace(")", r"\)")):
        parse_parts(cfg(fem_parts="soil"), raw=raw)


def test_the_box_refuses_speeds_beside_E():
    with pytest.raises(SSIError, match="drop -ssi_fem_E"):
        parse_parts(cfg(fem_cp=548.0, fem_cs=316.0, fem_E=3e8), raw={})
