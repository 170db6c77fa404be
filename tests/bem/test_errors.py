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


@pytest.mark.skipif(shutil.which("mpirun") is None, reason="needs mpirun")
def test_error_under_mpirun_does_not_hang():
    """Two ranks, bad receiver: exit status 2 with the message, within the timeout."""
    p = cli(["-ssi_mesh_size", "4,4", "-ssi_receivers", "30,0,0", "-ssi_t_end", "0.003"], nranks=2,
            timeout=120, check=False)
    assert p.returncode != 0
    assert "petsc-ssi: error: receiver (30, 0, 0) lies off the surface mesh" in p.stdout


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
