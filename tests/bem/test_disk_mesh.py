"""meshes/disk_soil.geo, the soil surface with a circular footing of radius a (impedances of a
rigid disk): read the way a run reads it (-ssi_mesh FILE.geo through HalfSpace: load_mesh with
the parameters from -ssi_mesh_size/_h/_patch/-ssi_symmetry, mesh.check, the symmetry-plane check,
kinks), full, quarter and half models; then one short quarter-model run of a prescribed rigid
translation of the disk."""
import os

import h5py
import numpy as np
import pytest

from helpers import ROOT, petsc, run_bem

pytestmark = pytest.mark.run

GEO = os.path.join(ROOT, "meshes", "disk_soil.geo")
A = 1.0
CASE = dict(mesh=GEO, mesh_size="6,6", mesh_h=0.25, mesh_patch=f"{A:g},{A:g}", dt=7.5e-4, t_end=0.003,
            warn_beta=0)


def problem(**opts):
    """The HalfSpace a run sets up (mesh read, checked, regions, rigid motion), no assembly."""
    PETSc = petsc()
    from petsc_ssi import options
    import petsc_ssi.app.kinds  # noqa: F401
    from petsc_ssi.bem.halfspace import HalfSpace
    db = PETSc.Options()
    for k, v in opts.items():
        db.setValue("ssi_" + k, str(v))
    try:
        return HalfSpace(options.resolve(("common", "bem")), PETSc.COMM_WORLD, log=lambda m: None)
    finally:
        for k in opts:
            db.delValue("ssi_" + k)


def setup_error(**opts):
    from petsc_ssi.petsc import SSIError
    try:
        problem(**opts)
    except SSIError as exc:
        return str(exc)
    return None


def area(mesh, cells, ng=6):
    """Area of the cells and the smallest Jacobian (z of J n) over ng x ng Gauss points each."""
    from petsc_ssi.mesh import quad9
    g, w = np.polynomial.legendre.leggauss(ng)
    xi, eta = (v.ravel() for v in np.meshgrid(g, g, indexing="ij"))
    ww = np.outer(w, w).ravel()
    _, jn = quad9.geometry(mesh.cell_coords()[cells], xi, eta)
    return float((jn[..., 2] * ww).sum()), float(jn[..., 2].min()), float(np.abs(jn[..., :2]).max())


def same_points(p, q, tol):
    """The rows of p and q are the same points (in any order), to tol."""
    from scipy.spatial import cKDTree
    if p.shape != q.shape:
        return False
    d, i = cKDTree(q).query(p)
    return d.max() <= tol and len(np.unique(i)) == len(i)


@pytest.fixture(scope="module")
def models():
    """The full and the quarter model of a = 1, h = 0.25 on a 6 m x 6 m surface, read and
    checked as a run reads them (a rigid translation of 'load' prescribed, so the rigid-motion
    set-up sees the mesh too)."""
    kw = dict(CASE, disp_group="load", disp_value="0,0,-1e-6")
    return problem(**kw).mesh, problem(**kw, symmetry="x=sym,y=sym").mesh


def test_full_and_quarter_disk_meshes(models):
    """Nine-node cells with Jacobians > 0 (normal +z) at every Gauss point; the load group has
    the disk's area (the quadratic rim: 32 cells around, area within 3.1e-6 of pi a^2) and all
    its nodes in the disk, the rim's nodes (mid-side ones included) on the circle; groups cover
    the mesh; the quarter model is the full model's part x, y >= 0, node for node and cell for
    cell; no kinks."""
    from petsc_ssi.mesh import surface
    full, quarter = models
    for mesh, frac in ((full, 1.0), (quarter, 0.25)):
        assert mesh.cells.shape[1] == 9
        load, free = mesh.groups["load"], mesh.groups["free"]
        assert len(load) and len(free) and not np.intersect1d(load, free).size
        assert len(load) + len(free) == mesh.n_cells
        aload, _, _ = area(mesh, load)
        assert abs(aload - frac * np.pi * A ** 2) <= 1e-5 * frac * np.pi * A ** 2, aload / (frac * np.pi)
        atot, jmin_all, jxy = area(mesh, np.arange(mesh.n_cells))
        assert jmin_all > 0 and jxy <= 1e-12
        assert abs(atot - frac * 36.0) <= 1e-9 * 36.0                # straight outer edges: exact
        r = np.hypot(*mesh.nodes[np.unique(mesh.cells[load])][:, :2].T)
        assert r.max() <= A * (1 + 1e-9)
        rim = np.intersect1d(mesh.cells[load], mesh.cells[free])     # nodes the two groups share
        assert np.abs(np.hypot(*mesh.nodes[rim][:, :2].T) - A).max() <= 1e-12 * A
        assert np.abs(mesh.nodes[:, 2]).max() == 0.0
        bad, _ = surface.kinks(mesh)
        assert len(bad) == 0
    # quarter = the full model's x, y >= 0 part: the same nodes, and the same cells in each group
    tol = 1e-12
    keep = np.all(full.nodes[:, :2] >= -tol, axis=1)
    assert keep.sum() == quarter.n_nodes
    assert same_points(full.nodes[keep], quarter.nodes, tol)
    for name in ("load", "free"):
        cf = full.nodes[full.cells[full.groups[name]]].reshape(-1, 27)      # every cell's nodes
        cq = quarter.nodes[quarter.cells[quarter.groups[name]]].reshape(-1, 27)
        inq = np.all(full.nodes[full.cells[full.groups[name]]][:, :, :2] >= -tol, axis=(1, 2))
        assert inq.sum() == len(cq) and 4 * len(cq) == len(cf), name
        assert same_points(cf[inq], cq, tol), name
    # the full model is its own mirror image in x and in y (each quadrant the same blocks)
    for ax in (0, 1):
        m = full.nodes.copy()
        m[:, ax] *= -1
        assert same_points(m, full.nodes, tol)


def test_element_quality(models):
    """Side lengths (corner to corner): under the disk between 0.45 h and h, at most 1.75 h in
    the free part; the longest over the shortest side of a cell at most 2.2; corner angles
    within 60..125 degrees (measured: 0.50 h..0.87 h, 1.66 h, 2.11, 64.7..121.9)."""
    h = CASE["mesh_h"]
    for mesh in models:
        X = mesh.cell_coords()[:, :4, :2]
        e = np.roll(X, -1, axis=1) - X
        le = np.linalg.norm(e, axis=2)
        cosang = np.einsum("eij,eij->ei", -np.roll(e, 1, axis=1), e) / (le * np.roll(le, 1, axis=1))
        ang = np.degrees(np.arccos(cosang))
        load = mesh.groups["load"]
        assert 0.45 * h <= le[load].min() and le[load].max() <= h
        assert le.max() <= 1.75 * h
        assert (le.max(1) / le.min(1)).max() <= 2.2
        assert 60 <= ang.min() and ang.max() <= 125


def test_half_models_orientation_and_refusals(models):
    """A half model (one symmetry plane, x or y) is the full model's half; gmsh itself makes
    every cell face +z (the reader flips none); an off-centre corner, a patch with b != a and a
    surface too small for the ring around the disk are refused in one line."""
    from petsc_ssi.mesh import gmsh as gmsh_reader, quad9
    full = models[0]
    for ax, sym in ((1, "y=sym"), (0, "x=sym")):
        half = problem(**CASE, symmetry=sym).mesh
        assert same_points(full.nodes[full.nodes[:, ax] >= -1e-12], half.nodes, 1e-12), sym
        a, _, _ = area(half, half.groups["load"])
        assert abs(a - np.pi * A ** 2 / 2) <= 1e-5 * np.pi * A ** 2 / 2, sym
    params = dict(Lx=6, Ly=6, xmin=-3, ymin=-3, h=0.25, a=A, b=A)
    raw = gmsh_reader.read(GEO, dim=2, order=2, params=params)
    _, jn = quad9.geometry(raw.coords[raw.blocks["quad9"]], np.array([0.0]), np.array([0.0]))
    assert jn[:, 0, 2].min() > 0
    for opts, expect in ((dict(mesh_patch="1,0.5"), "the patch must be a,a"),
                         (dict(mesh_size="2.2,2.2"), "must exceed 1.2 a"),
                         (dict(mesh_params="xmin=-1"), "xmin must be -Lx/2")):
        msg = setup_error(**{**CASE, **opts})
        assert msg is not None and expect in msg and "\n" not in msg, msg


def test_rigid_disk_quarter_model_runs(tmp_path):
    """-ssi_mesh meshes/disk_soil.geo, quarter model, h = 0.5 m, the disk pushed down by 1 um:
    four steps, a finite downward resultant (the images folded in: the whole disk's), no
    horizontal force or moment; the first step's force is near the plane P-wave limit
    rho c_p (pi a^2) u0 / dt of a suddenly moved footing (0.98 of it)."""
    out = tmp_path / "disk.h5"
    run_bem(mesh=GEO, mesh_size="4,4", mesh_h=0.5, mesh_patch="1,1", symmetry="x=sym,y=sym",
            disp_group="load", disp_value="0,0,-1e-6", dt=8e-4, t_end=0.0032, output_stride=0,
            warn_beta=0, output=out)
    with h5py.File(out) as f:
        F, M = f["resultants/force"][()], f["resultants/moment"][()]
    assert F.shape[0] == 4 and np.all(np.isfinite(F)) and np.all(np.isfinite(M))
    fz = F[:, 2]
    assert fz[-1] < 0
    assert abs(fz[0] / (-2000.0 * 548.0 * np.pi * 1e-6 / 8e-4) - 1) <= 0.1, fz[0]
    assert np.abs(F[:, :2]).max() <= 1e-12 * np.abs(fz).max()
    assert np.abs(M).max() <= 1e-12 * np.abs(fz).max()


def test_element_sizes_do_not_depend_on_node_order():
    """SurfaceMesh.element_sizes (the h of the beta check and the impedance band): the O-grid's
    distorted elements measured by their longest node-to-node segment, the same when every
    element's nodes are renumbered to start at another corner (a quarter turn: corners 1 2 3 0,
    midsides 5 6 7 4, centre 8); for a uniform grid it is the grid's node spacing h/2."""
    from petsc_ssi.mesh.surface import SurfaceMesh, grid
    m = problem(**CASE).mesh
    turned = SurfaceMesh(m.nodes, m.cells[:, [1, 2, 3, 0, 5, 6, 7, 4, 8]], getattr(m, "groups", {}))
    a, b = m.element_sizes(), turned.element_sizes()
    assert np.allclose(np.sort(a, axis=1), np.sort(b, axis=1), rtol=1e-12)
    assert a.max() == pytest.approx(b.max(), rel=1e-12)
    g = grid(4.0, 4.0, 0.5)
    assert np.allclose(g.element_sizes(), 0.25, rtol=1e-12)
