"""The soil boundary says what it is (issue 40, item 3; ``mesh.surface.SurfaceMesh``): whether it is the
plane z = 0, its unit normals out of the soil at the nodes, its edges and corners, and the one
refusal of a surface off the plane (with the reason), on a flat grid and on a made step (a pit's
edge: the ground z = 0 meeting a vertical wall)."""
import numpy as np
import pytest

from petsc_ssi.mesh.quad9 import NODE_XI
from petsc_ssi.mesh.surface import SurfaceMesh, grid
from petsc_ssi.petsc import SSIError

pytestmark = pytest.mark.unit


def _element(corner, du, dv):
    """Nine-node element x = corner + (1 + xi)/2 du + (1 + eta)/2 dv (normal du x dv)."""
    c, du, dv = (np.asarray(a, float) for a in (corner, du, dv))
    return c + 0.5 * (1 + NODE_XI[:, :1]) * du + 0.5 * (1 + NODE_XI[:, 1:]) * dv


def step_mesh():
    """The ground on x in [-1, 0], y in [0, 1] (z = 0, normal +z) and the pit's wall x = 0,
    z in [-1, 0] (the pit at x > 0: the wall's normal out of the soil is +x): 15 nodes."""
    ground = _element([-1, 0, 0], [1, 0, 0], [0, 1, 0])            # normal (1,0,0) x (0,1,0) = +z
    wall = _element([0, 0, 0], [0, 0, -1], [0, 1, 0])              # normal (0,0,-1) x (0,1,0) = +x
    X = np.vstack([ground, wall])
    nodes, inv = np.unique(np.round(X, 12), axis=0, return_inverse=True)
    return SurfaceMesh(nodes, inv.reshape(2, 9))


def test_a_flat_grid_is_the_plane_with_upward_normals_and_no_edges():
    m = grid(4.0, 2.0, 1.0)
    assert m.in_plane() and m.flat
    assert np.allclose(m.node_normals(), [0.0, 0.0, 1.0], atol=1e-15)
    assert len(m.edges_and_corners()[0]) == 0
    m.require_plane("-ssi_mesh test", "why")                        # nothing to refuse


def test_a_step_knows_its_normals_and_its_edge():
    m = step_mesh()
    assert m.n_nodes == 15 and not m.in_plane() and not m.flat
    n = m.node_normals()
    x = m.nodes
    on_edge = np.abs(x[:, 0]) + np.abs(x[:, 2]) < 1e-12           # x = 0, z = 0: where ground meets wall
    ground = (x[:, 0] < -1e-12)
    wall = (x[:, 2] < -1e-12)
    assert on_edge.sum() == 3 and ground.sum() == 6 and wall.sum() == 6
    assert np.allclose(n[ground], [0, 0, 1], atol=1e-14)
    assert np.allclose(n[wall], [1, 0, 0], atol=1e-14)
    assert np.allclose(n[on_edge], [2 ** -0.5, 0, 2 ** -0.5], atol=1e-14)
    nodes, ang = m.edges_and_corners()
    assert set(nodes) == set(np.nonzero(on_edge)[0]) and np.allclose(ang, 90.0)
    with pytest.raises(SSIError, match=r"-ssi_mesh pit: the surface mesh must lie in the plane z = 0 \(the free "
                                       r"surface of the half-space z < 0: a reason\); node \d+ is at z = -1 m"):
        m.require_plane("-ssi_mesh pit", "a reason")


def test_a_pit_is_a_closed_conforming_surface_with_normals_out_of_the_soil():
    """surface.pit: the ground with a rectangular excavation (issue 42's basement): every element edge
    inside the mesh is shared by exactly two elements and the free ones lie on the outer rectangle;
    the area is Lx Ly + 4 (a + b) d; normals point out of the soil (+z on the ground and the bottom,
    into the pit on the walls); the pit's rim, its bottom edges and its vertical corners are edges of
    90 degrees; the plane's refusal names the pit."""
    from petsc_ssi.mesh.surface import pit
    from petsc_ssi.mesh import quad9
    Lx, Ly, h, a, b, d = 8.0, 6.0, 1.0, 2.0, 1.5, 2.0
    m = pit(Lx, Ly, h, a, b, d)
    m.check()
    assert not m.in_plane()
    edges = {}
    for e, c in enumerate(m.cells):
        for tri in ((0, 4, 1), (1, 5, 2), (2, 6, 3), (3, 7, 0)):
            edges.setdefault(tuple(sorted(c[list(tri)])), []).append(e)
    free = [k for k, v in edges.items() if len(v) == 1]
    assert all(len(v) in (1, 2) for v in edges.values())
    xf = m.nodes[np.array(free).ravel()]
    assert np.all(xf[:, 2] == 0.0) and np.all((np.abs(np.abs(xf[:, 0]) - Lx / 2) < 1e-12) |
                                              (np.abs(np.abs(xf[:, 1]) - Ly / 2) < 1e-12))
    gq, gw = quad9.gauss_legendre(3)
    XI, ETA = np.meshgrid(gq, gq, indexing="ij")
    _, jn = quad9.geometry(m.cell_coords(), XI.ravel(), ETA.ravel())
    area = (np.linalg.norm(jn, axis=-1) * np.outer(gw, gw).ravel()).sum()
    assert area == pytest.approx(Lx * Ly + 4 * (a + b) * d, rel=1e-12)
    _, jc = quad9.geometry(m.cell_coords(), np.array([0.0]), np.array([0.0]))
    n = jc[:, 0] / np.linalg.norm(jc[:, 0], axis=1, keepdims=True)
    c = m.centres()
    for g in ("ground", "bottom"):
        assert np.allclose(n[m.groups[g]], [0, 0, 1], atol=1e-14)
    w = m.groups["walls"]
    into_pit = -c[w, :2] / np.linalg.norm(c[w, :2], axis=1, keepdims=True)
    assert np.all(np.abs(n[w, 2]) < 1e-14) and np.all(np.einsum("ij,ij->i", n[w, :2], into_pit) > 0.5)
    nodes, ang = m.edges_and_corners()
    x = m.nodes[nodes]
    rim_or_bottom = (x[:, 2] == 0.0) | (x[:, 2] == -d)
    on_pit = (np.abs(x[:, 0]) <= a + 1e-12) & (np.abs(x[:, 1]) <= b + 1e-12)
    on_wall_edge = (np.abs(np.abs(x[:, 0]) - a) < 1e-12) | (np.abs(np.abs(x[:, 1]) - b) < 1e-12)
    assert np.all(on_pit & on_wall_edge) and np.all(ang > 89.0)
    ring = 2 * (2 * a + 2 * b) / (h / 2)                   # nodes around the pit at h/2
    assert rim_or_bottom.sum() == 2 * ring                  # the rim and the bottom's edge
    assert len(nodes) == 2 * ring + 4 * (d / (h / 2) - 1)   # and the four vertical corners between
    with pytest.raises(SSIError, match="must lie in the plane z = 0"):
        m.require_plane("-ssi_mesh pit", "a reason")
    with pytest.raises(SSIError, match=r"pit: need a, b, d, h > 0 and the opening \[x - a, x \+ a\]"):
        pit(Lx, Ly, h, Lx, b, d)


def _normals_by_centre(m):
    from petsc_ssi.mesh import quad9
    _, jn = quad9.geometry(m.cell_coords(), np.array([0.0]), np.array([0.0]))
    n = jn[:, 0] / np.linalg.norm(jn[:, 0], axis=1, keepdims=True)
    order = np.lexsort(np.round(m.centres(), 9).T)
    return m.centres()[order], n[order]


def test_orientation_out_of_the_soil_is_restored_from_any_element_order():
    """orient_out_of_soil: a pit whose elements were flipped at random, or all of them, comes back
    with every normal out of the soil (the grid generator's)."""
    from petsc_ssi.mesh.surface import pit, orient_out_of_soil, FLIP
    ref = pit(6.0, 6.0, 1.0, 1.0, 1.5, 1.0)
    c0, n0 = _normals_by_centre(ref)
    rng = np.random.default_rng(5)
    for flip in (rng.random(ref.n_cells) < 0.5, np.ones(ref.n_cells, bool)):
        m = pit(6.0, 6.0, 1.0, 1.0, 1.5, 1.0)
        m.cells[flip] = m.cells[flip][:, FLIP]
        assert not np.allclose(_normals_by_centre(m)[1], n0)
        orient_out_of_soil(m)
        c, n = _normals_by_centre(m)
        assert np.allclose(c, c0) and np.allclose(n, n0, atol=1e-14)


def test_the_pit_geo_is_the_grid_generators_pit():
    """meshes/pit.geo read through gmsh (orientation out of the soil) against surface.pit: the same
    nodes, the same elements with the same normals, the same groups' sizes."""
    pytest.importorskip("gmsh")
    import os
    from petsc_ssi.mesh.surface import pit, read_gmsh
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    p = dict(Lx=8.0, Ly=6.0, a=2.0, b=1.5, d=2.0, h=1.0)
    g = read_gmsh(os.path.join(root, "meshes", "pit.geo"), p)
    ref = pit(p["Lx"], p["Ly"], p["h"], p["a"], p["b"], p["d"])
    assert (g.n_cells, g.n_nodes) == (ref.n_cells, ref.n_nodes)
    assert np.allclose(np.unique(np.round(g.nodes, 9), axis=0), np.unique(np.round(ref.nodes, 9), axis=0))
    cg, ng = _normals_by_centre(g)
    cr, nr = _normals_by_centre(ref)
    assert np.allclose(cg, cr, atol=1e-9) and np.allclose(ng, nr, atol=1e-9)
    assert {k: len(g.groups[k]) for k in ("ground", "walls", "bottom", "pit")} == \
        {k: len(ref.groups[k]) for k in ("ground", "walls", "bottom", "pit")}
