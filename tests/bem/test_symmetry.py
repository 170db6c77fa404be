"""Symmetry planes: a quarter model reproduces the full model to round-off."""
import numpy as np

from helpers import run_bem, relmax

COMMON = dict(mesh_size="6,6", mesh_h=1.0, mesh_patch="1,1", dt=7.5e-4, t_end=0.006,
              receivers="2,1,0;-2,-1.5,0;0.5,-2.5,0;0,0,0", output_stride=0)


def test_quarter_vertical_load_equals_full(tmp_path):
    """Vertical pressure (symmetric about x=0 and y=0): quarter == full to 1e-10."""
    full = run_bem(**COMMON, load_group="load", load_p0=1000, output=tmp_path / "full.h5")
    quart = run_bem(**COMMON, load_group="load", load_p0=1000, symmetry="x=sym,y=sym",
                    output=tmp_path / "quarter.h5")
    assert np.abs(full["u"]).max() > 0
    assert relmax(quart["u"], full["u"]) <= 1e-10


def test_antisymmetric_plane_with_prescribed_displacement(tmp_path):
    """A horizontal (x) prescribed displacement of the central patch is
    antisymmetric about x = 0 and symmetric about y = 0: the model
    'x=anti,y=sym' equals the full model to 1e-10 (this also exercises the
    mixed conditions: traction unknown under the patch)."""
    kw = dict(COMMON, disp_group="load", disp_value="1e-6,0,0")
    full = run_bem(**kw, output=tmp_path / "full.h5")
    part = run_bem(**kw, symmetry="x=anti,y=sym", output=tmp_path / "part.h5")
    assert np.abs(full["u"][:, :, 0]).max() > 0
    assert relmax(part["u"], full["u"]) <= 1e-10
