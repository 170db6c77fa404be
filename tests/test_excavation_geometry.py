"""A soil surface with an excavation, as the half-space takes it or refuses it (issue 42, items 1 and the
bad-geometry line of 'How it is shown'; ``mesh.surface.check_excavation``, ``bem.receivers.locate_3d``):
the grid generator's pit and the .geo's pass; a surface that does not close (a missing bottom, a hole in
the ground), walls that meet the mesh's edge (a step across the mesh), normals into the soil (one element
or all of them), an edge of three elements and a hill above z = 0 are each refused in one line naming
what is wrong; receivers are found on the ground, on the walls and on the bottom (a point off the
surface is refused)."""
import numpy as np
import pytest

from petsc_ssi.mesh.surface import SurfaceMesh, pit, check_excavation, FLIP
from petsc_ssi.petsc import SSIError

pytestmark = pytest.mark.unit

WHAT = "-ssi_mesh test"


def _pit():
    return pit(6.0, 6.0, 1.0, 1.0, 1.5, 1.0)


def _without(m, drop):
    keep = np.setdiff1d(np.arange(m.n_cells), drop)
    used, cells = np.unique(m.cells[keep], return_inverse=True)
    return SurfaceMesh(m.nodes[used], cells.reshape(-1, 9))


def test_the_generators_pit_passes():
    check_excavation(_pit(), WHAT)
    check_excavation(pit(8.0, 5.0, 0.5, 2.0, 1.0, 0.25), WHAT)


def test_a_surface_that_does_not_close_is_refused():
    m = _pit()
    with pytest.raises(SSIError, match=r"^-ssi_mesh test: the surface does not close: element \d+ has a free edge at "
                                       r"\(.*\) m below the ground \(a wall or bottom missing\)$"):
        check_excavation(_without(m, m.groups["bottom"]), WHAT)
    ground = m.groups["ground"]
    inner = ground[np.argmin(np.linalg.norm(m.centres()[ground] - [2.0, 0.0, 0.0], axis=1))]
    with pytest.raises(SSIError, match=r"^-ssi_mesh test: the surface does not close: its free element edges form 2 "
                                       r"loops"):
        check_excavation(_without(m, [inner]), WHAT)


def test_walls_meeting_the_mesh_edge_are_refused():
    """A step across the whole mesh: the ground z = 0 for x < 0, a wall x = 0 and a lower ground z = -1 for
    x > 0 (a trench's side reaching the truncation): its free edges at y = +-1 run below the ground."""
    from petsc_ssi.mesh.surface import _quad9
    X = []
    for x0 in (-2.0, -1.0):
        for y0 in (-1.0, 0.0):
            X.append(_quad9([x0, y0, 0.0], [1, 0, 0], [0, 1, 0]))
    for y0 in (-1.0, 0.0):
        X.append(_quad9([0.0, y0, -1.0], [0, 1, 0], [0, 0, 1]))       # normal +x: out of the soil (x < 0)
        for x0 in (0.0, 1.0):
            X.append(_quad9([x0, y0, -1.0], [1, 0, 0], [0, 1, 0]))
    X = np.array(X)
    nodes, inv = np.unique(np.round(X.reshape(-1, 3), 9), axis=0, return_inverse=True)
    step = SurfaceMesh(nodes, inv.reshape(-1, 9))
    with pytest.raises(SSIError, match=r"^-ssi_mesh test: the excavation meets the mesh's edge: element \d+ has a "
                                       r"free edge at \(.*\) m below the ground; keep the walls inside the ground"):
        check_excavation(step, WHAT)


def test_normals_into_the_soil_are_refused():
    m = _pit()
    one = _pit()
    k = one.groups["walls"][3]
    one.cells[k] = one.cells[k][FLIP]
    with pytest.raises(SSIError, match=r"^-ssi_mesh test: the normals of elements \d+ and \d+ disagree across their "
                                       r"shared edge \(one points into the soil\)"):
        check_excavation(one, WHAT)
    m.cells[:] = m.cells[:, FLIP]
    with pytest.raises(SSIError, match=r"^-ssi_mesh test: the normals point into the soil \(\d+ ground elements face "
                                       r"-z, element \d+ at"):
        check_excavation(m, WHAT)


def test_an_edge_of_three_elements_and_a_hill_are_refused():
    m = _pit()
    ground = m.groups["ground"]
    e = ground[np.argmin(np.linalg.norm(m.centres()[ground] - [2.0, 0.0, 0.0], axis=1))]     # inside the ground
    extra = m.cells[e].copy()
    extra[[2, 3, 6, 7, 5, 8]] = m.n_nodes + np.arange(6)            # a fin on the element's first edge
    X = m.nodes[m.cells[e]].copy()
    X[[2, 3, 6, 7, 5, 8], 2] -= 1.0
    bad = SurfaceMesh(np.vstack([m.nodes, X[[2, 3, 6, 7, 5, 8]]]), np.vstack([m.cells, extra]))
    with pytest.raises(SSIError, match=r"is shared by 3 elements: not a surface"):
        check_excavation(bad, WHAT)
    hill = _pit()
    hill.nodes[:, 2] = -hill.nodes[:, 2]
    with pytest.raises(SSIError, match=r"^-ssi_mesh test: node \d+ at \(.*\) m lies above the ground z = 0"):
        check_excavation(hill, WHAT)


def test_receivers_on_the_ground_walls_and_bottom():
    """locate_3d: the element and natural coordinates whose point is the receiver, to 1e-12, on the
    ground, on a wall (x = a), on the bottom and on the rim; a point in the pit's air is refused."""
    from petsc_ssi.bem.receivers import locate
    from petsc_ssi.mesh import quad9
    m = _pit()
    for p, group in (([2.3, 0.4, 0.0], "ground"), ([1.0, 0.7, -0.3], "walls"), ([-0.2, 1.5, -0.6], "walls"),
                     ([0.3, -0.4, -1.0], "bottom"), ([1.0, 0.2, 0.0], None)):
        e, xi, eta = locate(m, np.array(p))
        assert np.abs(quad9.shape(xi, eta) @ m.cell_coords()[e] - p).max() < 1e-12
        if group:
            assert e in m.groups[group]
    with pytest.raises(SSIError, match=r"receiver \(0, 0, -0.5\) lies off the surface mesh"):
        locate(m, np.array([0.0, 0.0, -0.5]))
