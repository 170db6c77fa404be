"""A part's properties in the wrong unit are named in one warning before the run (``fem/parts.py``
``plausibility``), and a structure that moves more than 1 % of its size under its own weight says so
(``fem/gravity.py``): an engineer's columns with E = 25 (GPa meant) ran without a word and sagged 1.5 km.

- E below 1e6 N/m^2 (GPa or MPa typed), rho below 10 kg/m^3 (t/m^3), a shell thicker than half the structure
  or a frame section (b,h) wider than all of it (mm or cm): each named with its option; a soil region's E with
  its c_s;
- nothing for the repo's building, for large areas and E (rigid links), a massless part (rho 0), a token rho
  where mass_per_area or added_mass carry the mass, a stocky pier (a 6 m x 2 m wall on a model 8 m across);
- the portal frame of test_gravity with its columns' E in GPa: both warnings, the run goes on (exit 0);
  with E in N/m^2 (and real areas): neither.
"""
import numpy as np
import pytest

from petsc_ssi.fem.elements.base import Props
from petsc_ssi.fem.parts import PartSpec, plausibility

from test_gravity import _portal

pytestmark = pytest.mark.run


def _spec(name, el, section=(), **kw):
    return PartSpec(name, el, Props(**kw), section=section)


def test_plausibility_names_each_slip():
    good = [_spec("floors", "shell", E=30e9, nu=0.2, rho=2500, thickness=0.3),
            _spec("columns", "frame", section=(0.5, 0.5), E=30e9, nu=0.2, rho=2500, area=0.25),
            _spec("links", "frame", E=1e15, nu=0.2, rho=0.0, area=1e3),        # a rigid link: large E and area
            _spec("contents", "shell", E=30e9, nu=0.2, rho=1e5, thickness=0.2)]  # lumped contents
    assert plausibility(good, 20.0) is None
    bad = good + [_spec("cols_gpa", "frame", section=(0.4, 0.4), E=25.0, nu=0.2, rho=2500, area=0.16),
                  _spec("slab_t", "shell", E=30e9, nu=0.2, rho=2.5, thickness=200.0),
                  _spec("cols_cm", "frame", section=(40.0, 40.0), E=30e9, nu=0.2, rho=2500, area=1600.0),
                  _spec("soil", "hex8", E=500.0, nu=0.25, rho=2000.0)]
    line = plausibility(bad, 20.0)
    assert line.startswith("unusual structure: ") and "check the units" in line, line
    for item in ("-ssi_fem_part_cols_gpa_E 25 N/m^2", "-ssi_fem_part_slab_t_rho 2.5 kg/m^3",
                 "-ssi_fem_part_slab_t_thickness 200 m on a structure 20 m across",
                 "-ssi_fem_part_cols_cm_section 40,40 m on a structure 20 m across"):
        assert item in line, (item, line)
    cs = np.sqrt(500.0 / (2 * 1.25) / 2000.0)
    assert f"-ssi_fem_part_soil_E 500 N/m^2 (c_s {cs:.3g} m/s)" in line, line
    for name in ("floors", "columns", "links", "contents"):
        assert f"part_{name}_" not in line, line
    # the part's mass elsewhere (a review found these named): a token rho beside mass_per_area (shell) or
    # added_mass (a light link frame); a pier wall deeper than half a single-pier model, within all of it
    assert plausibility([_spec("slab", "shell", E=30e9, nu=0.2, rho=1.0, thickness=0.3, mass_per_area=500.0),
                         _spec("link", "frame", E=2e11, nu=0.3, rho=1.0, area=0.01, added_mass=50.0),
                         _spec("pier", "frame", section=(6.0, 2.0), E=30e9, nu=0.2, rho=2500, area=12.0)],
                        8.0) is None
    assert "-ssi_fem_part_slab_rho 1 kg/m^3" in plausibility([_spec("slab", "shell", E=30e9, nu=0.2, rho=1.0,
                                                                    thickness=0.3)], 8.0)
    assert "section 6,2 m on a structure 5 m across" in plausibility(
        [_spec("pier", "frame", section=(6.0, 2.0), E=30e9, nu=0.2, rho=2500, area=12.0)], 5.0)
    # a region given by its wave speeds is named by them, as the user typed it (-ssi_fem_cs, a layer), with its E
    slow = Props(E=2 * 1.3 * 2000.0 * 0.3 ** 2, nu=0.3, rho=2000.0)             # c_s 0.3 m/s (cm/s typed as m/s)
    line = plausibility([PartSpec("structure", "hex8", slow, legacy=True, speeds=True)], 5.0)
    assert f"-ssi_fem_cs 0.3 m/s (E {slow.E:g} N/m^2)" in line and "-ssi_fem_E" not in line, line
    layered = PartSpec("soil", "hex8", Props(E=3e8, nu=0.3, rho=2000.0),
                       layers=((-2.0, Props(E=3e8, nu=0.3, rho=2000.0)), (-5.0, slow)))
    line = plausibility([layered], 5.0)
    assert f"-ssi_fem_part_soil_layers layer 2: c_s 0.3 m/s (E {slow.E:g} N/m^2)" in line and "layer 1" not in line
    legacy = PartSpec("structure", "hex8", Props(E=300.0, nu=0.3, rho=2000.0), legacy=True)
    assert "-ssi_fem_E 300 N/m^2" in plausibility([legacy], 5.0)


def warnings(r):
    return [ln for ln in r.stdout.splitlines() if ln.startswith("petsc-ssi: warning: ")]


def test_a_portal_in_gpa_is_named_and_runs(tmp_path):
    _, r = _portal(tmp_path, ["-ssi_fem_part_columns_E", "30"])          # GPa typed for N/m^2
    w = warnings(r)
    unusual = [ln for ln in w if "unusual structure" in ln]
    sag = [ln for ln in w if "under its own weight" in ln]
    assert len(unusual) == 1 and "-ssi_fem_part_columns_E 30 N/m^2" in unusual[0] and "beam" not in unusual[0], w
    assert len(sag) == 1 and "% of its size (6.71 m across)" in sag[0], w
    # (the test portal's 100 m^2 members weigh 2.5 t/m on a 4e-3 m^4 beam: it sags 2.4 % of its size, so
    # realistic areas here; still 1e9 times the E)
    _, r = _portal(tmp_path, ["-ssi_output_overwrite", "-ssi_fem_part_beam_area", "0.2", "-ssi_fem_part_columns_area",
                              "0.2"])
    assert not [ln for ln in warnings(r) if "unusual structure" in ln or "own weight" in ln], warnings(r)
