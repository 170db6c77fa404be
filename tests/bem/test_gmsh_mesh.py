"""meshes/halfspace.geo through the gmsh API gives the same surface (and so the
same results) as the structured generator."""
import h5py
import numpy as np

from helpers import run_bem, relmax, ROOT
import pytest

pytestmark = pytest.mark.run


def test_geo_equals_grid(tmp_path):
    """The two meshes' nodes differ at round-off and are numbered in another order (the sums run in
    another order): 1e-10 of the surface's largest displacement, for the surface and for the
    receivers, whose displacements (44x smaller here) are sums over the surface's (observed: surface
    3.8e-13, receivers 2.5e-13 of the surface's largest displacement; the receivers differed by 1.1e-11
    of their own largest value, 9x under the former 1e-10 of it)."""
    kw = dict(mesh_size="8,8", mesh_h=1.0, mesh_patch="1,1", load_group="load", load_p0=1000,
              symmetry="x=sym,y=sym", t_end=0.006, receivers="3,0,0;2,1.5,0", output_stride=8)
    a = run_bem(**kw, output=tmp_path / "grid.h5")
    b = run_bem(**kw, mesh=f"{ROOT}/meshes/halfspace.geo", output=tmp_path / "geo.h5")
    assert np.abs(a["u"]).max() > 0
    last = []
    for name in ("grid", "geo"):                  # the last snapshot, nodes sorted by their coordinates
        with h5py.File(tmp_path / f"{name}.h5") as f:
            x = np.round(f["coordinates"][:], 9)
            last.append(f[sorted(k for k in f if k.startswith("displacement_"))[-1]][:][np.lexsort(x.T)])
    scale = np.abs(last[0]).max()
    assert relmax(last[1], last[0]) <= 1e-10
    assert np.abs(b["u"] - a["u"]).max() <= 1e-10 * scale
