"""Bad input: a clear one-line error before heavy work, on every rank."""
import shutil

import numpy as np
import pytest

from helpers import resolve_error, cli, write_surface_msh

pytestmark = pytest.mark.mpi

SMALL = dict(mesh_size="4,4", mesh_h=1.0, t_end=0.003)


@pytest.mark.parametrize("opts,expect", [
    (dict(dt=0), "-ssi_dt 0.0: must be > 0"),
    (dict(dt=-1e-3), "must be > 0"),
    (dict(cs=600, cp=548), "must be smaller than -ssi_cp"),
    (dict(rho=0), "-ssi_rho 0.0: must be > 0"),
    (dict(mesh="/nonexistent/surface.msh"), "no such file"),
    (dict(receivers="30,0,0"), "lies off the surface mesh"),
    (dict(receivers="1,0,-2"), "not on the surface"),
    (dict(receivers="1,2"), "each point needs x,y,z"),
    (dict(load_group="nosuchgroup", load_p0=1), "element group 'nosuchgroup' is not in the mesh"),
    (dict(symmetry="z=sym"), "planes are x or y"),
    (dict(memory_limit=1e-6, t_end=0.01), "more than the"),
    (dict(scheme="explicit"), "is not one of"),
    (dict(dtt=1e-3), "did you mean -ssi_dt"),
    (dict(mesh_grade=0.5), "-ssi_mesh_grade: only the grid generator"),
    (dict(mesh_grade=1.5, mesh_patch="1,1"), "-ssi_mesh_grade 1.5: must be in [0, 1]"),
])
def test_bad_input_one_line_error(opts, expect):
    msg = resolve_error(**{**SMALL, **opts})
    assert msg is not None and expect in msg, msg
    assert "\n" not in msg


def _write_msh(path, order, xmin=-2.0):
    write_surface_msh(path, order, xmin)


def test_mesh_not_nine_node_quads(tmp_path):
    p = tmp_path / "quad4.msh"
    _write_msh(p, 1)
    msg = resolve_error(**{**SMALL, "mesh": str(p)})
    assert msg is not None and "nine-node quadrilaterals" in msg, msg


def test_symmetry_plane_not_respected(tmp_path):
    p = tmp_path / "full.msh"
    _write_msh(p, 2)
    assert resolve_error(**{**SMALL, "mesh": str(p)}) is None   # the mesh itself is fine
    msg = resolve_error(**{**SMALL, "mesh": str(p), "symmetry": "x=sym"})
    assert msg is not None and "crosses the plane x = 0" in msg, msg


def test_symmetry_plane_not_reached_is_warned(tmp_path):
    """A mesh 0.5 m off the plane x = 0 with -ssi_symmetry x=sym leaves the 1 m strip between it and its image
    out of the surface: one warning line says so (the run goes on: a surface may have holes)."""
    p = tmp_path / "off.msh"
    _write_msh(p, 2, xmin=0.5)
    r = cli(["-ssi_mesh", str(p), "-ssi_symmetry", "x=sym", "-ssi_t_end", "0.003", "-ssi_output", str(tmp_path / "o.h5")])
    w = [ln for ln in r.stdout.splitlines() if "does not reach the plane" in ln]
    assert len(w) == 1 and w[0].startswith("petsc-ssi: warning: -ssi_symmetry: the mesh does not reach the plane x = 0 "
                                           "(its nearest node at x = 0.5 m): the 1 m strip"), r.stdout[-3000:]
    r = cli(["-ssi_mesh", str(p), "-ssi_t_end", "0.003", "-ssi_output", str(tmp_path / "n.h5")])
    assert "does not reach the plane" not in r.stdout


@pytest.mark.parametrize("xmin", [1e-7, 2e-4])
def test_mesh_near_the_plane_but_not_on_it_is_refused(tmp_path, xmin):
    """A mesh that misses the plane x = 0 by less than 1e-3 of its element size (1e-7 m and 2e-4 m for 1 m
    cells) was meant to reach it: refused in one line naming the nearest node, where it used to run (quiet
    below 1e-6 h) with the plane's odd components free (test_mesh_near_the_plane_gives_a_wrong_answer)."""
    p = tmp_path / "near.msh"
    _write_msh(p, 2, xmin=xmin)
    assert resolve_error(**{**SMALL, "mesh": str(p)}) is None
    msg = resolve_error(**{**SMALL, "mesh": str(p), "symmetry": "x=sym"})
    assert msg is not None and "m off the plane x = 0" in msg and "put them on the plane" in msg, msg
    assert f"lies {xmin:.3g} m off" in msg, msg
    assert "\n" not in msg


@pytest.mark.slow                                   # (why the refusal above is there; it cannot fail if that breaks)
def test_mesh_near_the_plane_gives_a_wrong_answer(monkeypatch, tmp_path):
    """Why the refusal above: the 6 m grid's quarter model (vertical load on the central 1 m cell) with every
    node moved 1e-7 m (1e-7 h) off x = 0, the check bypassed, is far from the model on the plane at the
    receivers (a node and its image two free nodes 2e-7 m apart; the true change of the geometry is of
    order 1e-7), while 1e-10 m (on the plane within its 1e-9 m tolerance) is the same model to 1e-9.
    `pytest -s` prints both differences."""
    from helpers import run_bem, relmax
    import petsc_ssi.bem.halfspace as hs
    from petsc_ssi.bem import symmetry
    read, shift = hs.read_surface_mesh, [0.0]

    def shifted(cfg, comm, planes):
        m = read(cfg, comm, planes)
        m.nodes[:, 0] += shift[0]
        return m
    monkeypatch.setattr(hs, "read_surface_mesh", shifted)
    monkeypatch.setattr(symmetry, "check_mesh", lambda *a: None)
    kw = dict(mesh_size="6,6", mesh_h=1.0, mesh_patch="1,1", dt=7.5e-4, t_end=0.006, output_stride=0,
              receivers="2,1,0;-2,-1.5,0;0.5,-2.5,0;0.5,0.5,0", load_group="load", load_p0=1000,
              symmetry="x=sym,y=sym", warn_beta=0, output=tmp_path / "q.h5")
    ref = run_bem(**kw)["u"]
    out = {}
    for s in (1e-10, 1e-7):
        shift[0] = s
        out[s] = relmax(run_bem(**kw)["u"], ref)
    print(f"quarter model moved off x = 0: 1e-10 m {out[1e-10]:.3g}, 1e-7 m {out[1e-7]:.3g}")
    assert out[1e-10] <= 1e-9
    assert out[1e-7] >= 0.01


@pytest.mark.skipif(shutil.which("mpirun") is None, reason="needs mpirun")
def test_error_under_mpirun_does_not_hang():
    """Two ranks, bad receiver: exit status 2 with the message, within the timeout."""
    p = cli(["-ssi_mesh_size", "4,4", "-ssi_receivers", "30,0,0", "-ssi_t_end", "0.003"], nranks=2,
            timeout=120, check=False)
    assert p.returncode != 0
    assert "petsc-ssi: error: receiver (30, 0, 0) lies off the surface mesh" in p.stderr


@pytest.mark.parametrize("opts,expect", [
    (dict(symmetry="x=anti", mesh_patch="1,1", load_group="load", load_p0=1000), "is not antisymmetric"),
    (dict(symmetry="y=sym", mesh_patch="1,1", disp_group="load", disp_value="0,1e-6,0"), "is not symmetric"),
])
def test_load_contradicting_symmetry(opts, expect):
    msg = resolve_error(**{**SMALL, **opts})
    assert msg is not None and expect in msg, msg


def test_non_smooth_surface_detected():
    """Edges are found (the free term there comes from the interior cone)."""
    from petsc_ssi.mesh.surface import grid, kinks
    m = grid(4.0, 4.0, 1.0)
    assert len(kinks(m)[0]) == 0
    m.nodes[:, 2] = -0.5 * np.abs(m.nodes[:, 0])          # a ridge along x = 0
    bad, ang = kinks(m)
    assert len(bad) == 9 and np.allclose(m.nodes[bad, 0], 0.0) and np.allclose(ang, 2 * np.degrees(np.arctan(0.5)))
    # a surface tilted across a symmetry plane folds when mirrored
    q = grid(4.0, 4.0, 1.0, xmin=0.0)
    q.nodes[:, 2] = -0.3 * q.nodes[:, 0]
    assert len(kinks(q)[0]) == 0 and len(kinks(q, [(0, 1)])[0]) == 9


def test_near_the_plane_is_measured_by_the_node_s_own_elements():
    """The band is 1e-3 of the node's own elements' spacing, not of the mesh's largest: a graded mesh's
    interior node 4 mm from the plane (its cells 5 mm apart, the largest 5 m) is a node of the mesh, not a
    node that missed the plane; at 4 um from the plane it did miss it."""
    from petsc_ssi.bem import symmetry
    from petsc_ssi.petsc import SSIError
    planes = symmetry.parse("x=sym")
    nodes = np.array([[0.0, 0, 0], [0.004, 0, 0], [0.01, 0, 0], [10.0, 0, 0]])
    node_h = np.array([0.005, 0.005, 0.005, 5.0])
    symmetry.check_mesh(nodes, planes, 5.0, node_h)                       # passes: nothing said
    with pytest.raises(SSIError, match=r"node 1 at \(0.004, 0, 0\) m lies 0.004 m off the plane x = 0"):
        symmetry.check_mesh(nodes, planes, 5.0)                             # (the largest spacing: 5 mm band)
    nodes[1, 0] = 4e-6
    with pytest.raises(SSIError, match=r"node 1 at \(4e-06, 0, 0\) m lies 4e-06 m off the plane x = 0.*1 such node"):
        symmetry.check_mesh(nodes, planes, 5.0, node_h)


def test_an_odd_component_at_rounding_level_is_zero():
    """A direction computed by the API (a traction turned by cos(pi/2) = 6e-17) meets x=sym; an odd component
    of 1e-9 of the load does not."""
    from petsc_ssi.bem import symmetry
    from petsc_ssi.petsc import SSIError
    planes = symmetry.parse("x=sym")
    symmetry.check_compatible(planes, 1000.0 * np.array([np.cos(np.pi / 2), 0.0, -1.0]), None)
    with pytest.raises(SSIError, match=r"x=sym: the load traction \(1e-06, 0.0, -1000.0\) is not symmetric"):
        symmetry.check_compatible(planes, np.array([1e-6, 0.0, -1000.0]), None)
    with pytest.raises(SSIError, match="the prescribed displacement"):
        symmetry.check_compatible(symmetry.parse("y=sym"), None, np.array([0.0, 1e-6, 0.0]))


def test_node_spacing_of_a_graded_grid():
    """SurfaceMesh.node_spacing, what the near-the-plane band is measured by, against a plain loop over the
    elements: each node's smallest element size in the element's shorter direction (a graded grid: every size
    differs)."""
    from petsc_ssi.mesh.surface import grid
    m = grid(8.0, 6.0, 1.0, (1.0, 1.0), xmin=0.0, ymin=0.0, grade=1.0)
    sizes = m.element_sizes()
    assert np.ptp(sizes) > 0.1 * sizes.max()
    ref = np.full(m.n_nodes, np.inf)
    for e in range(m.n_cells):
        for n in m.cells[e]:
            ref[n] = min(ref[n], sizes[e].min())
    assert np.array_equal(m.node_spacing(), ref)


def test_area_load_and_non_finite_values_against_a_plane():
    """The area load's own check (sources/area.py, a rectangle across the plane) takes the same rule as the
    loads' (symmetry.has_odd): a direction turned by cos(pi/2) meets x=sym, 1e-9 of the load does not; a value
    that is not finite is refused."""
    from petsc_ssi.bem import symmetry
    from petsc_ssi.petsc import SSIError
    from petsc_ssi.sources.area import AreaTraction
    planes = symmetry.parse("x=sym")
    ok = AreaTraction((-1.0, 1.0, 0.5, 1.5), 1000.0 * np.array([np.cos(np.pi / 2), 0.0, -1.0]), None)
    assert len(ok.images(planes)) == 2
    with pytest.raises(SSIError, match="is not allowed by -ssi_symmetry x=sym"):
        AreaTraction((-1.0, 1.0, 0.5, 1.5), [1e-6, 0.0, -1000.0], None).images(planes)
    assert symmetry.has_odd([1e-6, 0.0, np.nan], 0, 1) and symmetry.has_odd([np.inf, 0.0, 1.0], 0, 1)
    assert not symmetry.has_odd([0.0, 0.0, 0.0], 0, 1)


def test_an_iterative_soil_solve_that_stops_short_stops_the_run(tmp_path):
    """An iterative soil solver (-ssi_bem_ksp_type gmres, Jacobi, 2 iterations) that stops short of convergence: the
    step's answer is not the step's, so the run stops at step 1 with one line and status 2 (before: it ran on and
    wrote results 1.3 % off, a sign changed, as 'completed'); the same solver converged gives the direct solve's
    receivers to 1e-8."""
    import os
    from helpers import ROOT, read_h5
    base = ["-options_file", os.path.join(ROOT, "runs", "pekeris", "small.opts"), "-ssi_t_end", "0.005"]
    it = ["-ssi_bem_ksp_type", "gmres", "-ssi_bem_pc_type", "jacobi"]
    r = cli(base + it + ["-ssi_bem_ksp_max_it", "2", "-ssi_output", str(tmp_path / "short.h5")], nranks=2, check=False)
    errs = [ln for ln in r.stderr.splitlines() if ln.startswith("petsc-ssi: error:")]
    assert r.returncode == 2 and len(errs) == 1, r.stdout[-3000:] + r.stderr[-3000:]
    assert "did not converge at step 1 (DIVERGED_MAX_IT after 2 iterations of -ssi_bem_ksp_type gmres" in errs[0], errs
    assert "Traceback" not in r.stdout + r.stderr
    ref, good = str(tmp_path / "direct.h5"), str(tmp_path / "gmres.h5")
    cli(base + ["-ssi_output", ref], nranks=2)
    cli(base + it + ["-ssi_bem_ksp_max_it", "500", "-ssi_bem_ksp_rtol", "1e-13", "-ssi_output", good], nranks=2)
    a, b = read_h5(good)["u"], read_h5(ref)["u"]
    assert np.abs(a - b).max() <= 1e-8 * np.abs(b).max(), np.abs(a - b).max() / np.abs(b).max()
