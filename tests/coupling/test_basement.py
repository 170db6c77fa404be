"""The demo's building on a 3 m basement (runs/basement, issue 42 item 5): meshes/building_basement.geo's block of
bricks under the foundation slab shares the slab's nodes and carries the nodes of the pit's nine-node soil
elements (-ssi_mesh pit, h = 1.2 m) on its walls and bottom; the coupled run under the earthquake (slow tier)."""
import os

import h5py
import numpy as np
import pytest

from helpers import ROOT, cli

pytestmark = pytest.mark.mpi

PARAMS = {"nbx": 2, "nby": 2, "sx": 3.6, "sy": 3.6, "ns": 2, "half": 0, "d": 3, "nzb": 4}


def test_the_basement_shares_the_slab_and_matches_the_pit():
    from petsc_ssi.mesh import gmsh as reader
    from petsc_ssi.mesh import surface
    m = reader.read(os.path.join(ROOT, "meshes", "building_basement.geo"), dim=3, params=PARAMS, user=tuple(PARAMS))
    x = m.coords
    slab = set(m.groups["foundation"].nodes)
    top = {i for i in m.groups["basement"].nodes if abs(x[i, 2]) < 1e-9}
    assert top == slab and len(slab) == 169
    soil = surface.pit(16.8, 16.8, 1.2, 3.6, 3.6, 3.0)
    on_pit = soil.nodes[np.unique(soil.cells[soil.groups["pit"]])]          # the pit's walls and bottom
    pit = x[m.groups["bpit"].nodes]
    key = lambda p: set(map(tuple, np.round(p, 6)))      # noqa: E731
    assert key(on_pit) <= key(pit) and len(on_pit) == 361 == len(pit)
