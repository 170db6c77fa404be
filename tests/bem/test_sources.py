"""Sources as objects (issue 40, item 1; ``petsc_ssi.sources``): a new kind of surface load is data
given to the soil, not code in it.

- A traction moving at constant speed along x, f(x) a(t - t0(x)) with t0 = (x - x_s)/v, made in this
  file as data and run on the small Lamb mesh through ``BEMTransient(cfg, sources=[...])``: it equals,
  bit for bit, the same load given as a sequence of patches (one per column of nodes, each switched
  on at its own time), and it moves (a receiver ahead of the load starts later, by about the load's
  travel time).
- The step mean of a delayed box against its closed form.
- Two sources on adjacent patches are refused (their shared nodes would carry the sum of both).
- A region's prescribed rigid motion is a source too (``sources.rigid``): given as data through
  ``sources=[...]``, it equals bit for bit the run of the options that describe it (-ssi_disp_*),
  its resultants included; a second motion source is refused.
"""

import h5py
import numpy as np
import pytest

from helpers import petsc

pytestmark = pytest.mark.run

V = 200.0                       # the load's speed [m/s] (below c_s = 316 m/s)
X_START, X_END = -3.0, 3.0      # where the load runs [m]
LENGTH = 1.0                    # the load's length along x [m]: a box of duration LENGTH / V
P0 = 1000.0                     # its pressure [Pa]

SMALL = {"problem": "bem", "cp": 548, "cs": 316, "rho": 2000, "dt": 7.5e-4, "t_end": 0.036, "mesh": "grid",
         "mesh_size": "10,6", "mesh_h": 1.0, "mesh_patch": "1,1", "symmetry": "y=sym", "scheme": "stabilized",
         "receivers": "-2.5,1.5,0;2.5,1.5,0", "output_stride": 8, "output_overwrite": 1, "warn_beta": 0}


def _cfg(out, **extra):
    PETSc = petsc()
    from petsc_ssi.app.kinds import resolve
    db = PETSc.Options()
    opts = dict(SMALL, output=out, **extra)
    for k, v in opts.items():
        db.setValue("ssi_" + k, str(v))
    try:
        return resolve("bem")
    finally:
        for k in opts:
            db.delValue("ssi_" + k)


def _strip(mesh):
    """The elements of the load's path: the strip of element centres |y| < 1 m (y >= 0 here)."""
    return mesh.select("box:-5,5,0,1")


def _on_path(x):
    return (x[:, 0] >= X_START - 1e-9) & (x[:, 0] <= X_END + 1e-9)


def moving_load(elements):
    """The new source kind, as data: p0 pushing down where the load is, t0(x) = (x - x_s)/V."""
    from petsc_ssi.sources import SurfaceTraction
    from petsc_ssi.histories import History
    return SurfaceTraction(elements, lambda x: np.where(_on_path(x)[:, None], [0.0, 0.0, -P0], 0.0),
                           History("box", LENGTH / V), delay=lambda x: (x[:, 0] - X_START) / V, name="moving load")


def patches(mesh, elements):
    """The same load as a sequence of patches: one per column of nodes x = x_k of the path, each
    uniform over its column and switched on at (x_k - x_s)/V."""
    from petsc_ssi.sources import SurfaceTraction
    from petsc_ssi.histories import History
    xs = np.unique(mesh.nodes[np.unique(mesh.cells[elements]), 0])
    out = []
    for xk in xs[(xs >= X_START - 1e-9) & (xs <= X_END + 1e-9)]:
        out.append(SurfaceTraction(elements, lambda x, xk=xk: np.where((x[:, 0] == xk)[:, None], [0.0, 0.0, -P0], 0.0),
                                   History("box", LENGTH / V), delay=(xk - X_START) / V, name=f"patch x = {xk:g} m"))
    return out


def _run(out, make_sources, **extra):
    PETSc = petsc()
    from petsc_ssi.bem.problem import BEMTransient
    from petsc_ssi.bem.halfspace import read_surface_mesh
    from petsc_ssi.bem import symmetry
    cfg = _cfg(out, **extra)
    mesh = read_surface_mesh(cfg, PETSc.COMM_WORLD, symmetry.parse(cfg.symmetry))
    BEMTransient(cfg, PETSc.COMM_WORLD, sources=make_sources(mesh) if make_sources else None).run()
    with h5py.File(out) as f:
        snaps = {k: f[k][...] for k in f if k.startswith("displacement_") or k.startswith("traction_")}
        return f["receivers/t"][...], f["receivers/u"][...], snaps


def test_a_moving_load_as_data_equals_the_same_load_as_patches(tmp_path):
    t, u_mov, s_mov = _run(str(tmp_path / "moving.h5"), lambda m: [moving_load(_strip(m))])
    t2, u_pat, s_pat = _run(str(tmp_path / "patches.h5"), lambda m: patches(m, _strip(m)))
    assert len(s_mov) >= 4 and set(s_mov) == set(s_pat)
    assert np.array_equal(t, t2) and np.array_equal(u_mov, u_pat)         # bit for bit
    for k in s_mov:
        assert np.array_equal(s_mov[k], s_pat[k]), k
    # the load moves: each receiver's largest vertical motion comes as the load passes beside it,
    # the one ahead (x = +2.5 m) later than the one behind (x = -2.5 m) by about the load's travel
    # time between them, 5 m / 200 m/s = 25 ms
    uz = np.abs(u_mov[:, :, 2])
    peak = [t[np.argmax(uz[:, r])] for r in range(2)]
    assert uz.max() > 0
    assert 0.7 * 5.0 / V < peak[1] - peak[0] < 1.3 * 5.0 / V, peak


def test_the_step_mean_of_a_delayed_box_is_exact():
    from petsc_ssi.sources import SurfaceTraction
    from petsc_ssi.histories import History
    from petsc_ssi.mesh.surface import grid
    mesh = grid(4.0, 4.0, 1.0, None, None, None)
    src = SurfaceTraction(np.arange(mesh.n_cells), lambda x: np.c_[x[:, 0], 0 * x[:, 0], -np.ones(len(x))],
                          History("box", 0.013), delay=lambda x: 0.01 * (x[:, 0] + 2.0))
    nodes = np.unique(mesh.cells)
    src.bind(mesh, nodes)
    dt = 0.004
    x = mesh.nodes[nodes]
    t0 = 0.01 * (x[:, 0] + 2.0)
    for m in range(1, 12):
        a, b = (m - 1) * dt, m * dt
        # the overlap of ((m-1) dt, m dt] with the box (t0, t0 + 0.013], over dt
        mean = np.clip(np.minimum(b, t0 + 0.013) - np.maximum(a, t0), 0.0, None) / dt
        got = src.step_mean(m, dt)
        assert np.allclose(got[:, 2], -mean, rtol=0, atol=1e-14)
        assert np.allclose(got[:, 0], x[:, 0] * mean, rtol=0, atol=1e-13)


def test_adjacent_sources_are_refused():
    from petsc_ssi.sources import SurfaceTraction
    from petsc_ssi.sources.traction import check_sources
    from petsc_ssi.histories import History
    from petsc_ssi.petsc import SSIError
    from petsc_ssi.mesh.surface import grid
    mesh = grid(4.0, 4.0, 1.0, None, None, None)
    c = mesh.centres()
    left, right = np.nonzero(c[:, 0] < 0)[0], np.nonzero(c[:, 0] > 0)[0]
    h = History("heaviside")
    a = SurfaceTraction(left, [0, 0, -1.0], h, name="left patch")
    b = SurfaceTraction(right, [0, 0, -1.0], h, name="right patch")
    with pytest.raises(SSIError, match="left patch and right patch load different elements that share 9 nodes"):
        check_sources(mesh, [a, b])
    check_sources(mesh, [a, SurfaceTraction(left, [0, 0, -2.0], h)])      # the same elements: summed


# the rigid motion of the 2 m x 2 m patch (group 'load' of the grid): a translation and a rocking about
# y (both even about the plane y = 0), about a reference point off the centre, switched on for 10 ms
U0, THETA, XREF, T0 = (1e-6, 0.0, -1e-6), (0.0, 1e-6, 0.0), (0.2, 0.0, 0.0), 0.01
DISP = {"disp_group": "load", "disp_value": "1e-6,0,-1e-6", "disp_rotation": "0,1e-6,0", "disp_ref": "0.2,0,0",
        "disp_history": "box", "disp_t0": T0}


def test_a_rigid_motion_as_data_equals_the_options_that_describe_it(tmp_path):
    from petsc_ssi.sources import PrescribedRigidMotion
    from petsc_ssi.histories import History
    motion = []

    def given(mesh):
        motion.append(PrescribedRigidMotion(mesh.select("load"), U0, THETA, History("box", T0), XREF,
                                            name="the patch's rigid motion"))
        return motion

    a, b = str(tmp_path / "data.h5"), str(tmp_path / "options.h5")
    t, u_data, s_data = _run(a, given)
    t2, u_opts, s_opts = _run(b, None, **DISP)
    assert np.array_equal(t, t2) and np.array_equal(u_data, u_opts) and np.abs(u_data).max() > 0
    assert len(s_data) >= 4 and set(s_data) == set(s_opts)
    for k in s_data:
        assert np.array_equal(s_data[k], s_opts[k]), k
    with h5py.File(a) as f, h5py.File(b) as g:
        assert set(f["resultants"]) == set(g["resultants"])
        for k in f["resultants"]:
            assert np.array_equal(f["resultants"][k][()], g["resultants"][k][()]), k
        assert np.array_equal(f["resultants/x_ref"][()], XREF)
        h = f["resultants/h"][()]
        assert h[0] == 1.0 and h[-1] == 0.0          # the box: on for 10 ms of the 36
        assert np.abs(f["resultants/force"][()][:, 2]).max() > 0
    assert motion[0].x is not None and len(motion[0].base) == 3 * len(motion[0].x)     # bound by the soil


def test_two_rigid_motions_are_refused(tmp_path):
    from petsc_ssi.sources import PrescribedRigidMotion
    from petsc_ssi.histories import History
    from petsc_ssi.petsc import SSIError

    def two(mesh):
        e = mesh.select("load")
        return [PrescribedRigidMotion(e[:1], U0, THETA, History("heaviside"), XREF, name="first"),
                PrescribedRigidMotion(e[1:], U0, THETA, History("heaviside"), XREF, name="second")]

    with pytest.raises(SSIError, match="2 prescribed motions of soil regions \\(first, second\\)"):
        _run(str(tmp_path / "two.h5"), two)


def test_a_source_of_the_older_protocol_is_checked_at_every_node(tmp_path):
    """Under x=anti a vertical load off the plane is mirrored into its opposite (tests/bem/test_symmetry.py); a
    source written before ``amplitudes(at)`` (``amplitudes()`` alone) cannot say which of its values lie on the
    plane, so it is checked at every node, as before: refused in one line, not a TypeError."""
    from petsc_ssi.sources import SurfaceTraction
    from petsc_ssi.histories import History
    from petsc_ssi.petsc import SSIError

    class Older(SurfaceTraction):
        def amplitudes(self):
            return super().amplitudes()

    def off_plane(kind):
        return lambda mesh: [kind(mesh.select("box:1.4,1.6,0.4,0.6"), [0, 0, -P0], History("heaviside"))]

    with pytest.raises(SSIError, match=r"x=anti: the load traction \(0.0, 0.0, -1000.0\) is not antisymmetric"):
        _run(str(tmp_path / "older.h5"), off_plane(Older), symmetry="x=anti", t_end=0.003)
    t, u, _ = _run(str(tmp_path / "newer.h5"), off_plane(SurfaceTraction), symmetry="x=anti", t_end=0.003)
    assert np.abs(u).max() > 0
