"""meshes/halfspace.geo through the gmsh API gives the same surface (and so the
same results) as the structured generator."""
import numpy as np

from helpers import run_bem, relmax, ROOT


def test_geo_equals_grid(tmp_path):
    kw = dict(mesh_size="8,8", mesh_h=1.0, mesh_patch="1,1", load_group="load", load_p0=1000,
              symmetry="x=sym,y=sym", t_end=0.006, receivers="3,0,0;2,1.5,0", output_stride=0)
    a = run_bem(**kw, output=tmp_path / "grid.h5")
    b = run_bem(**kw, mesh=f"{ROOT}/meshes/halfspace.geo", output=tmp_path / "geo.h5")
    assert np.abs(a["u"]).max() > 0
    assert relmax(b["u"], a["u"]) <= 1e-10
