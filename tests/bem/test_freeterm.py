"""Free term c_lk at smooth points, edges and corners (Hartmann)."""
import numpy as np
import pytest

from petsc_ssi.bem.freeterm import cone_moments, free_term_from_cone, free_terms
from petsc_ssi.mesh.surface import grid

pytestmark = pytest.mark.run

NU = 0.25


def test_sphere_and_hemisphere():
    """Whole space: c = I; a half-space (smooth surface): c = I/2 (1e-13)."""
    eq = np.array([[np.cos(t), np.sin(t), 0.0] for t in np.linspace(0, 2 * np.pi, 9)[:-1]])
    area, M = cone_moments(eq, np.array([0, 0, -1.0]))
    area, M = abs(area), np.sign(area) * M
    assert abs(area - 2 * np.pi) < 1e-11
    assert np.abs(free_term_from_cone(area, M, NU) - 0.5 * np.eye(3)).max() < 1e-11
    assert np.abs(free_term_from_cone(4 * np.pi, 4 * np.pi / 3 * np.eye(3), NU) - np.eye(3)).max() < 1e-15


@pytest.mark.parametrize("theta", [np.pi / 2, 2 * np.pi / 3, 3 * np.pi / 2])
def test_wedge_edge_closed_form(theta):
    """Edge with interior wedge angle theta about z (directions with azimuth
    in [0, theta]): c_zz = theta / 2pi (antiplane), c_xx = theta/(2 pi) +
    [sin 2theta] / (8 pi (1-nu)), c_xy = (1 - cos 2theta) / (8 pi (1-nu)), from
    int d_x^2 = 4/3 (theta/2 + sin 2theta / 4) over the wedge (1e-10)."""
    # the wedge's boundary on the sphere: meridians at azimuth 0 and theta
    npts = 8
    mer = lambda ph: [np.array([np.sin(p) * np.cos(ph), np.sin(p) * np.sin(ph), np.cos(p)])
                      for p in np.linspace(0, np.pi, npts + 1)]
    m0, m1 = mer(0.0), mer(theta)
    loop = np.array(m0[:-1] + m1[::-1][:-1])
    # fan from several apexes inside the wedge (|D| < 2 pi needs any interior apex;
    # a reflex wedge is split into two convex halves)
    if theta <= np.pi:
        area, M = cone_moments(loop, np.array([np.cos(theta / 2), np.sin(theta / 2), 0.0]))
        area, M = abs(area), np.sign(area) * M
    else:
        h = theta / 2
        mh = mer(h)
        A1, M1 = cone_moments(np.array(m0[:-1] + mh[::-1][:-1]), np.array([np.cos(h / 2), np.sin(h / 2), 0]))
        A2, M2 = cone_moments(np.array(mh[:-1] + m1[::-1][:-1]), np.array([np.cos(1.5 * h), np.sin(1.5 * h), 0]))
        area, M = abs(A1) + abs(A2), np.sign(A1) * M1 + np.sign(A2) * M2
    c = free_term_from_cone(area, M, NU)
    k = 1 / (8 * np.pi * (1 - NU))
    assert abs(area - 2 * theta) < 1e-10
    assert abs(c[2, 2] - theta / (2 * np.pi)) < 1e-10
    assert abs(c[0, 0] - (theta / (2 * np.pi) + k * np.sin(2 * theta))) < 1e-10
    assert abs(c[0, 1] - k * (1 - np.cos(2 * theta))) < 1e-10


def test_flat_mesh_gives_half_identity():
    m = grid(4.0, 4.0, 1.0)
    c = free_terms(m.cell_coords(), m.cells, m.n_nodes, NU)
    assert np.abs(c - 0.5 * np.eye(3)).max() == 0.0


def test_edge_of_folded_mesh_matches_wedge_formula():
    """A ridge along x = 0 (surface z = -s |x|, soil below): at the ridge the
    soil fills a wedge of angle pi - 2 atan(s) about the y axis; a valley
    (z = +s |x|) gives pi + 2 atan(s)."""
    s = 0.5
    m = grid(4.0, 4.0, 1.0)
    m.nodes[:, 2] = -s * np.abs(m.nodes[:, 0])
    i = int(np.argmin(np.linalg.norm(m.nodes - [0, 0, 0], axis=1)))
    j = int(np.argmin(np.linalg.norm(m.nodes[:, :2] - [1.0, 1.0], axis=1)))
    c = free_terms(m.cell_coords(), m.cells, m.n_nodes, NU, nodes=[i, j])
    edge = int(np.argmin(np.linalg.norm(m.nodes[:, :2] - [0.0, -2.0], axis=1)))
    with pytest.raises(Exception, match="kink on the mesh boundary"):
        free_terms(m.cell_coords(), m.cells, m.n_nodes, NU, nodes=[edge])
    theta = np.pi - 2 * np.arctan(s)
    k = 1 / (8 * np.pi * (1 - NU))
    # wedge about y: the 'antiplane' component is yy; in-plane x,z with the
    # wedge symmetric about -z: c_xx - c_zz = -k sin(theta) ... check yy and trace
    assert abs(c[i, 1, 1] - theta / (2 * np.pi)) < 1e-10
    assert abs(np.trace(c[i]) - (3 * theta / (2 * np.pi) + 0.0)) < 1e-10 + 1e-9
    assert abs(c[i, 0, 2]) < 1e-10 and abs(c[i, 0, 1]) < 1e-10
    # smooth nodes away from the fold keep I/2 exactly
    assert np.abs(c[j] - 0.5 * np.eye(3)).max() == 0.0
    m.nodes[:, 2] *= -1.0                                   # the valley
    cv = free_terms(m.cell_coords(), m.cells, m.n_nodes, NU, nodes=[i])
    assert abs(cv[i, 1, 1] - (np.pi + 2 * np.arctan(s)) / (2 * np.pi)) < 1e-10
    # ridge + valley fill the whole space: c(ridge) + c(valley) = I
    assert np.abs(c[i] + cv[i] - np.eye(3)).max() < 1e-10


def _cube(n=2, side=1.0):
    """Closed surface of a cube [0,side]^3 of nine-node quads, outward normals."""
    from petsc_ssi.mesh.surface import SurfaceMesh, grid
    nodes, cells = [], []
    f = grid(side, side, side / n)               # face z = 0 in [-s/2, s/2]^2, normal +z
    P = f.nodes + [side / 2, side / 2, 0]
    faces = [lambda p: np.c_[p[:, 0], p[:, 1], np.full(len(p), side)],            # top, +z
             lambda p: np.c_[p[:, 1], p[:, 0], np.zeros(len(p))],                  # bottom, -z
             lambda p: np.c_[np.full(len(p), side), p[:, 0], p[:, 1]],             # +x
             lambda p: np.c_[np.zeros(len(p)), p[:, 1], p[:, 0]],                  # -x
             lambda p: np.c_[p[:, 1], np.full(len(p), side), p[:, 0]],             # +y
             lambda p: np.c_[p[:, 0], np.zeros(len(p)), p[:, 1]]]                  # -y
    for k, fmap in enumerate(faces):
        nodes.append(fmap(P))
        cells.append(f.cells + k * len(P))
    X = np.concatenate(nodes)
    key = np.round(X * 1e9).astype(np.int64)
    _, first, inv = np.unique(key, axis=0, return_index=True, return_inverse=True)
    return SurfaceMesh(X[first], inv.ravel()[np.concatenate(cells)])


def test_rigid_body_rows_vanish_on_a_closed_cube():
    """Interior problem inside a cube (normals outward): a rigid translation
    is traction-free, so every row of the static H (free term included) sums
    to zero: c_i + CPV int_Gamma P dGamma = 0 at face, edge and corner nodes.
    Checks the free term at edges (wedge pi/2) and corners (octant) together
    with the singular and near-singular integration on folded surfaces."""
    from helpers import petsc
    PETSc = petsc()
    from petsc_ssi.bem.lagset import Material, Regions, LagSet
    mesh = _cube()
    from petsc_ssi.mesh.quad9 import geometry
    _, jn = geometry(mesh.cell_coords(), np.array([0.0]), np.array([0.0]))
    cen = mesh.cell_coords()[:, 8] - 0.5
    assert np.all(np.einsum("ei,ei->e", jn[:, 0], cen) > 0)          # outward normals
    mat = Material(548.0, 316.0, 2000.0)
    opts = {"gauss": 2, "singular_order": 16, "subdivisions": 4, "near_factor": 4.0,
            "max_subdivisions": 32, "cache": True}
    x = mesh.nodes
    ids = [int(np.argmin(np.linalg.norm(x - p, axis=1)))
           for p in ([0, 0, 0], [0.5, 0, 0], [0.25, 0, 0], [0.5, 0.5, 0], [0.25, 0.25, 0])]
    ls = LagSet(PETSc.COMM_SELF, mesh, mat, 1e3, 1, Regions(mesh), [], opts)
    ls.rows = np.array(ids)
    corner, edge = ids[0], ids[1]
    assert abs(np.trace(ls.cfree[corner]) - 3 / 8) < 1e-10      # octant: solid angle pi/2
    assert np.abs(np.diag(ls.cfree[edge]) - 0.25).max() < 1e-10  # right-angle wedge: theta/2pi = 1/4
    ls.assemble()
    r, c, v = ls.H.peek(1)
    sums = [np.abs(v[r == i].sum(0)).max() for i in ids]
    # measured 2e-7 .. 8e-7 (1e-8 .. 5e-8 with subdivisions 8, near_factor 8)
    assert max(sums) < 2e-6, sums


def per_node_reference(VX, VN, n_nodes, nu, nodes, smooth_deg=1e-6, tol=1e-8):
    """The free terms node by node, the plain loop free_terms replaced (each node's (element, local
    node) pairs in that order, its first normal the reference): the independent reference."""
    from petsc_ssi.bem.freeterm import _sectors, _chain
    c = np.zeros((n_nodes, 3, 3))
    for i in nodes:
        arcs, normals = [], []
        for v in range(VN.shape[0]):
            for a in range(9):
                if VN[v, a] == i:
                    dirs, n = _sectors(VX[v], a)
                    normals.append(n)
                    if dirs is not None:
                        arcs.append(dirs)
        N = np.array(normals)
        if np.all(N @ N[0] >= min(np.cos(np.radians(smooth_deg)), 1 - 1e-12)):
            c[i] = 0.5 * np.eye(3)
            continue
        area, M = cone_moments(np.array(_chain(arcs, tol)), -N.mean(0))
        if area < 0:
            area, M = -area, -M
        c[i] = free_term_from_cone(area, M, nu)
    return c


def test_free_terms_equal_the_per_node_loop_bit_for_bit():
    """The vectorised smooth-point pass against the plain per-node loop, bit for bit: a cube (face,
    edge and corner nodes) and a ridge mesh (a fold inside), every node or a scattered selection
    given as a list and as an array; each node asked alone gives its value among all. On the cube:
    faces I/2 exactly, edges (a right-angle wedge) a diagonal of 1/4, corners (an octant) 1/8 and
    |c_ij| = 1 / (8 pi (1-nu))."""
    m = _cube(2)
    cases = [(m.cell_coords(), m.cells, m.n_nodes, None)]
    r = grid(4.0, 4.0, 1.0)
    r.nodes[:, 2] = -0.5 * np.abs(r.nodes[:, 0])
    inner = np.nonzero(np.abs(r.nodes[:, 1]) < 1.5)[0]              # off the kinked ends
    cases.append((r.cell_coords(), r.cells, r.n_nodes, inner))
    for VX, VN, n, nodes in cases:
        ask = np.arange(n) if nodes is None else nodes
        ref = per_node_reference(VX, VN, n, NU, ask)
        for sel in (nodes, list(ask[::3]), np.asarray(ask[1::2])):
            got = free_terms(VX, VN, n, NU, nodes=sel)
            want = ref if sel is None else np.where(np.isin(np.arange(n), sel)[:, None, None], ref, 0.0)
            assert np.array_equal(got, want)
        for i in ask[::5]:
            assert np.array_equal(free_terms(VX, VN, n, NU, nodes=[i])[i], ref[i])
    c_all = free_terms(m.cell_coords(), m.cells, m.n_nodes, NU)
    on_faces = np.sum(np.isclose(m.nodes, 0.0) | np.isclose(m.nodes, 1.0), axis=1)
    assert np.all(c_all[on_faces == 1] == 0.5 * np.eye(3))
    diag = np.diagonal(c_all, axis1=1, axis2=2)
    assert (on_faces == 2).sum() == 12 * 3 and np.abs(diag[on_faces == 2] - 0.25).max() < 1e-9
    corners = c_all[on_faces == 3]
    assert len(corners) == 8 and np.abs(diag[on_faces == 3] - 1 / 8).max() < 1e-9
    off = corners[:, ~np.eye(3, dtype=bool)]
    assert np.abs(np.abs(off) - 1 / (8 * np.pi * (1 - NU))).max() < 1e-9


@pytest.mark.parametrize("s,shift", [(0.5, 0.0), (-0.5, 0.0), (0.5, 4e-10)])
def test_a_symmetric_fold_equals_the_whole_mesh(s, shift):
    """Half of a ridge (s > 0; a valley, s < 0) meshed on x >= 0 with its image in the plane x = 0
    gives every node the free term of the whole mesh (1e-12): the fold on the plane closes with the
    image's elements, and a node off the plane takes no part of the image, whose elements list its
    number at its mirror image (a tilted plane there: I/2). Nodes ``shift`` off the plane, inside
    the tolerance by which symmetry.zero_dofs counts them on it, are on it here too (1e-8)."""
    from petsc_ssi.bem import symmetry
    whole = grid(4.0, 4.0, 1.0)
    whole.nodes[:, 2] = -s * np.abs(whole.nodes[:, 0])
    half = grid(4.0, 4.0, 1.0, xmin=0.0)
    half.nodes[:, 2] = -s * half.nodes[:, 0]
    plane = half.nodes[:, 0] == 0.0
    half.nodes[plane, 0] += shift
    h = float(half.element_sizes().max())
    assert set(symmetry.zero_dofs(half.nodes, [(0, 1)], h) // 3) == set(np.nonzero(plane)[0])
    VX, VN, _, _ = symmetry.virtual_elements(half.cell_coords(), half.cells, half.cells, [(0, 1)])
    inner = np.nonzero(np.abs(half.nodes[:, 1]) < 1.5)[0]
    inner = inner[half.nodes[inner, 0] < 1.5]                      # off the mesh's kinked ends
    ch = free_terms(VX, VN, half.n_nodes, NU, nodes=inner)
    match = [int(np.argmin(np.linalg.norm(whole.nodes - half.nodes[i], axis=1))) for i in inner]
    cw = free_terms(whole.cell_coords(), whole.cells, whole.n_nodes, NU, nodes=match)
    assert np.abs(ch[inner] - cw[match]).max() < (1e-12 if shift == 0 else 1e-8)
    on_plane = plane[inner]
    theta = np.pi - 2 * np.arctan(s)
    assert on_plane.sum() == 5
    assert np.abs(ch[inner[on_plane], 1, 1] - theta / (2 * np.pi)).max() < (1e-10 if shift == 0 else 1e-8)
    assert np.all(ch[inner[~on_plane]] == 0.5 * np.eye(3))


def test_a_node_in_no_element_is_refused():
    from petsc_ssi.petsc import SSIError
    m = grid(2.0, 2.0, 1.0)
    with pytest.raises(SSIError, match="belongs to no element"):
        free_terms(m.cell_coords(), m.cells, m.n_nodes + 1, NU, nodes=[m.n_nodes])


def test_element_nodes_outside_the_mesh_are_refused():
    m = grid(2.0, 2.0, 1.0)
    with pytest.raises(ValueError, match="outside"):
        free_terms(m.cell_coords(), m.cells, m.n_nodes - 1, NU)
