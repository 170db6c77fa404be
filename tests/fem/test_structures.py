"""Structures of frames, shells and bricks through the application: dof map, parts, reader,
loads with moments, fixed dof names, static / modes / dynamics, output, parallel.

Each test compares with an independent reference: a scipy assembly written in the test
(np_assembly.py, obstacle.solve), closed forms, the pre-dof-map release's output
(tests/fem/data/hex8_before_dofmap.npz, written by commit 8e2fe32 on the same cases), or the
1-rank run.
"""
import os
import sys

import h5py
import numpy as np
import pytest

from fem_helpers import ROOT, run_cli

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "elements"))
from np_assembly import assemble as np_assemble, solve_static  # noqa: E402

pytestmark = pytest.mark.mpi

SLAB = os.path.join("runs", "structures", "slab-on-columns.opts")
REF = os.path.join(os.path.dirname(__file__), "data", "hex8_before_dofmap.npz")


def ok(r):
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    return r


def receivers(path):
    with h5py.File(path, "r") as f:
        return {k: f["receivers/" + k][:] for k in f["receivers"]}


def relmax(a, b):
    a, b = np.asarray(a), np.asarray(b)
    return float(np.abs(a - b).max() / max(np.abs(b).max(), 1e-300))


# ------------------------------------------------------------------ dof map
def test_dofmap_offsets_ownership_and_rigid_modes(PETSc):
    from petsc_ssi.fem.dofmap import DofMap
    rot = np.array([0, 1, 1, 0, 1, 0, 0, 1], bool)
    dm = DofMap(rot, PETSc.COMM_SELF)
    assert dm.size == 3 * 8 + 3 * 4
    assert list(dm.offset) == list(np.r_[0, np.cumsum(np.where(rot, 6, 3))[:-1]])
    assert dm.section.getFieldDof(1, 1) == 3 and dm.section.getFieldDof(0, 1) == 0
    assert list(dm.dofs([1, 3], ("uy", "rz"))) == [dm.offset[1] + 1, dm.offset[3] + 1, dm.offset[1] + 5]
    with pytest.raises(Exception, match="did you mean rx"):
        dm.dofs([1], ("rxx",))
    fixed = dm.set_fixed(dm.dofs([1], ("ux", "rz")))
    assert dm.section.getConstraintDof(1) == 2 and list(dm.section.getConstraintIndices(1)) == [0, 5]
    assert list(fixed) == [dm.offset[1], dm.offset[1] + 5] == list(dm.fixed)     # read back from the Section
    # rigid-body modes: a rotation about z moves node (x, y) by (-y, x) and turns rz by 1
    x = np.random.default_rng(0).standard_normal((8, 3))
    R = dm.rigid_body_modes(x, centre=np.zeros(3))
    assert np.allclose(R[dm.offset[2]:dm.offset[2] + 6, 5], [-x[2, 1], x[2, 0], 0, 0, 0, 1])
    assert np.linalg.matrix_rank(R) == 6
    # the balanced split never cuts a node and balances dofs
    from petsc_ssi.fem.dofmap import _balanced_split, _uniform_split
    b = _balanced_split(np.where(rot, 6, 3), 3)
    assert b[0] == 0 and b[-1] == 8 and np.all(np.diff(b) >= 0)
    assert list(_uniform_split(10, 3)) == [0, 4, 7, 10]


def test_hex8_K_and_M_equal_the_node_blocked_assembly(PETSc):
    """A hex8 mesh through the dof map: K and M equal, bit for bit, a plain scatter of the hex8
    kernels into dof 3 * node + c (the layout before the dof map)."""
    from petsc_ssi.fem.mesh import read_gmsh
    from petsc_ssi.fem.assembly import Material, assemble
    from petsc_ssi.fem.dofmap import BrickDofMap as Layout
    from petsc_ssi.fem.elements.hex8 import hex8_stiffness, hex8_lumped_mass
    from fem_helpers import dense
    mesh = read_gmsh(os.path.join(ROOT, "meshes", "foundation.geo"))
    lay = Layout(mesh.n_nodes, PETSc.COMM_SELF)
    K, m = assemble(mesh, Material(300e6, 0.2, 2000.0), lay)
    Ke = hex8_stiffness(mesh.coords[mesh.cells], 300e6, 0.2)
    dofs = (3 * mesh.cells[:, :, None] + np.arange(3)).reshape(-1, 24)
    Kr = np.zeros((3 * mesh.n_nodes,) * 2)
    for e in range(len(dofs)):
        Kr[np.ix_(dofs[e], dofs[e])] += Ke[e]
    assert np.abs(dense(K) - Kr).max() <= 1e-12 * np.abs(Kr).max()
    mr = np.repeat(np.bincount(mesh.cells.ravel(), hex8_lumped_mass(mesh.coords[mesh.cells], 2000.0).ravel()), 3)
    assert np.array_equal(m.getArray(), mr)


@pytest.fixture(scope="module")
def before(tmp_path_factory):
    return dict(np.load(REF))


def test_hex8_fem_run_equals_the_release_before_the_dof_map(before, tmp_path):
    """runs/foundation/block-fixed.opts (8 steps): receivers and the last snapshot equal the
    output of the code before the dof map (same command, commit 8e2fe32) to round-off."""
    out = str(tmp_path / "b.h5")
    ok(run_cli(["-options_file", "runs/foundation/block-fixed.opts", "-ssi_t_end", "0.05",
                "-ssi_output", out, "-ssi_output_stride", "4"]))
    rec = receivers(out)
    assert np.array_equal(rec["t"], before["fem_t"])
    assert relmax(rec["u"], before["fem_u"]) < 1e-12
    with h5py.File(out) as f:
        snaps = sorted(k for k in f if k.startswith("displacement_"))
        assert len(snaps) == int(before["fem_nsnap"])
        assert relmax(f[snaps[-1]][:], before["fem_last"]) < 1e-12
        assert np.array_equal(f["coordinates"][:], before["fem_coords"])
        assert "rotation_000000" not in f          # no rotation field for bricks


def test_hex8_coupled_run_equals_the_release_before_the_dof_map(before, tmp_path):
    """runs/foundation/sym-bonded.opts (4 steps, coupled): soil and structure receivers and the
    interface tractions equal the code before the dof map to round-off. (The reference was made by
    commit 8e2fe32 with one change in the BEM, the node-order-independent element size of
    bem/windows.py:bounding_spheres, so that it isolates the structure's side.)"""
    out = str(tmp_path / "c.h5")
    ok(run_cli(["-options_file", "runs/foundation/sym-bonded.opts", "-ssi_t_end", "0.03", "-ssi_output", out,
                "-ssi_structure_receivers", "0,0,0.5;0.5,0.5,0.5", "-ssi_output_stride", "0"], timeout=600))
    with h5py.File(out) as f:
        assert relmax(f["interface/p"][:], before["ssi_p"]) < 1e-10
        assert relmax(f["interface/uf"][:], before["ssi_uf"]) < 1e-10
        assert relmax(f["receivers/u"][:], before["ssi_soil_u"]) < 1e-10
    st = receivers(out.replace(".h5", "_structure.h5"))
    assert relmax(st["u"], before["ssi_struct_u"]) < 1e-10


# ------------------------------------------------------------------ frames through the CLI
def _cantilever_msh(path, n=6, L=3.0, direction=(1.0, 2.0, 2.0)):
    from petsc_ssi.mesh.gmsh import write_msh
    d = np.asarray(direction, float) / np.linalg.norm(direction)
    X = np.outer(np.linspace(0, L, n + 1), d) + np.array([0.5, -0.2, 1.0])
    cells = np.column_stack([np.arange(n), np.arange(1, n + 1)])
    write_msh(path, X, {"beam": ("line2", cells), "root": ("point", [[0]]), "tip": ("point", [[n]])})
    return X, d


def test_frame_cantilever_static_cli_against_closed_form(tmp_path):
    """A skew cantilever (6 frames, Timoshenko, b x h = 0.2 x 0.4) under a tip force normal to it
    and a tip torque: `petsc-ssi static` gives w = P L^3/(3 E I) + P L/(k G A) and the torsion
    angle T L/(G J) (exact for the Timoshenko element) to 1e-9."""
    msh = str(tmp_path / "cant.msh")
    X, d = _cantilever_msh(msh)
    E, nu, b, h, L = 30e9, 0.25, 0.2, 0.4, 3.0
    G = E / (2 * (1 + nu))
    z = np.array([0.0, 0.0, 1.0]) - d[2] * d          # depth direction: orientation z projected
    z /= np.linalg.norm(z)
    P, T = 1e4, 2e3
    tip = X[-1]
    f = P * z
    load = ",".join(repr(v) for v in np.r_[tip, f, T * d])
    out = str(tmp_path / "cant.h5")
    r = ok(run_cli(["static", "-ssi_problem", "fem", "-ssi_fem_mesh", msh, "-ssi_fem_parts", "beam",
                    "-ssi_fem_part_beam_element", "frame", "-ssi_fem_part_beam_E", str(E),
                    "-ssi_fem_part_beam_nu", str(nu), "-ssi_fem_part_beam_rho", "2500",
                    "-ssi_fem_part_beam_section", f"{b},{h}", "-ssi_fem_part_beam_orientation", "0,0,1",
                    "-ssi_fem_fixed", "root", "-ssi_fem_point_load", load,
                    "-ssi_receivers", ",".join(repr(v) for v in tip), "-ssi_output", out]))
    assert "[static] solved K u = F" in r.stdout
    rec = receivers(out)
    from petsc_ssi.fem.parts import rect_section
    s = rect_section(b, h)
    w = P * L ** 3 / (3 * E * s["Iy"]) + P * L / (5 / 6 * G * s["area"])
    assert rec["t"].tolist() == [1.0]
    assert abs(rec["u"][0, 0] @ z - w) < 1e-9 * w
    assert np.linalg.norm(rec["u"][0, 0] - (rec["u"][0, 0] @ z) * z) < 1e-9 * w
    theta = T * L / (G * s["J"])
    assert abs(rec["rotation"][0, 0] @ d - theta) < 1e-9 * theta
    assert bool(rec["has_rotation"][0])


# ------------------------------------------------------------------ shells through the CLI
@pytest.mark.parametrize("name, n, tol", [("pinched_cylinder", 32, 0.05), ("scordelis_lo", 16, 0.02)])
def test_obstacle_course_through_the_application(name, n, tol, tmp_path):
    """The obstacle-course problem written as a .msh and solved by `petsc-ssi static` (reader,
    parts, dof map, fixed dof names such as fix_ux_ry_rz:ux+ry+rz, point forces) equals the
    element-level solve (obstacle.solve, its own scipy assembler) to 1e-8, and the published
    value within the issue's tolerance."""
    from petsc_ssi.fem import obstacle
    prob = obstacle.PROBLEMS[name](n)
    path, opts = obstacle.write_case(prob, str(tmp_path))
    out = str(tmp_path / "o.h5")
    ok(run_cli(["static", "-ssi_problem", "fem"] + opts + ["-ssi_output", out], timeout=300))
    rec = receivers(out)
    val = sum(w * (rec["u"][0, i, k] if k < 3 else rec["rotation"][0, i, k - 3])
              for i, (_, k, w) in enumerate(prob.probe))
    ref = obstacle.solve(prob)
    assert abs(val - ref) < 1e-8 * abs(ref)
    assert abs(val - prob.reference) < tol * abs(prob.reference)


def test_fv16_modes_through_the_application(tmp_path):
    """NAFEMS FV16 (24 x 24) by `petsc-ssi modes` (SLEPc, lumped M with rotary inertia): the six
    frequencies equal the element-level eigenvalues to 1e-7 and NAFEMS's within 2%."""
    from petsc_ssi.fem import obstacle
    prob = obstacle.fv16(24)
    path, opts = obstacle.write_case(prob, str(tmp_path))
    r = ok(run_cli(["modes", "-ssi_problem", "fem"] + opts + ["-ssi_modes_n", "6",
                                                             "-ssi_output", str(tmp_path / "m.h5")], timeout=300))
    lines = r.stdout[r.stdout.index("mode,frequency_hz"):].splitlines()[1:7]
    f = np.array([float(s.split(",")[1]) for s in lines])
    assert np.allclose(f, obstacle.solve(prob), rtol=1e-7)
    assert np.all(np.abs(f / prob.reference - 1) < 0.02), f


# ------------------------------------------------------------------ a mixed model
@pytest.fixture(scope="module")
def slab_model(PETSc):
    """The slab on columns read through the application's reader and parts, and its K, M."""
    from types import SimpleNamespace
    from petsc_ssi.fem.mesh import read_gmsh
    from petsc_ssi.fem.parts import parse_parts
    from petsc_ssi.fem.dofmap import DofMap
    from petsc_ssi.fem.assembly import assemble
    raw = {}
    for line in open(os.path.join(ROOT, SLAB)):
        if line.startswith("-ssi_fem_part_"):
            k, v = line.split()[:2]
            raw[k[len("-ssi_fem_part_"):]] = v
    specs = parse_parts(SimpleNamespace(get=lambda *a: "slab,columns"), raw=raw)
    mesh = read_gmsh(os.path.join(ROOT, "meshes", "slab_on_columns.geo"), specs)
    dm = DofMap(mesh.has_rotation(), PETSc.COMM_SELF)
    K, m = assemble(mesh, None, dm)
    return mesh, dm, K, m


def test_mixed_model_K_M_against_independent_assembly(slab_model):
    """Slab on four columns: K and M equal the independent scipy assembly (6 dofs per node) to
    round-off; the 6 rigid-body modes span K's null space; M > 0 on every dof; the part masses
    are exact (slab 4 x 3 x (2500 x 0.2 + 100), columns 4 x 3 x 0.09 x 2500)."""
    from fem_helpers import dense
    mesh, dm, K, m = slab_model
    assert dm.has_rotation.all()
    blocks = [(b.element, b.cells, mesh.coords, b.props) for b in mesh.blocks]
    Kr, mr = np_assemble(mesh.n_nodes, blocks, ndof=6)
    perm = (dm.offset[:, None] + np.arange(6)).ravel()            # dof map order -> 6 node + k
    Kd = dense(K)
    assert np.abs(Kd[np.ix_(perm, perm)] - Kr.toarray()).max() < 1e-12 * np.abs(Kd).max()
    assert np.allclose(m.getArray()[perm], mr, rtol=1e-14) and np.all(mr > 0)
    R = dm.rigid_body_modes(mesh.coords)
    assert np.abs(Kd @ R).max() < 1e-9 * np.abs(Kd).max()
    from petsc_ssi.fem.assembly import mass_report
    parts, total = mass_report(mesh)
    assert parts["slab"]["mass"] == pytest.approx(12 * 600.0, rel=1e-12)
    assert parts["columns"]["mass"] == pytest.approx(4 * 3 * 0.09 * 2500.0, rel=1e-12)
    assert np.all(parts["slab"]["rotary"] > 0) and np.all(parts["columns"]["rotary"] > 0)
    assert total == pytest.approx(7200.0 + 2700.0, rel=1e-12)


# slow tier: the mixed model's statics, modes, dynamics and two ranks (67 s; siblings in make test: the
# building's fixed-base modes at two ranks and the element tests of tests/fem/elements)
@pytest.mark.slow
def test_mixed_model_static_modes_dynamics_and_two_ranks(slab_model, tmp_path):
    """runs/structures/slab-on-columns.opts as static, modes and dynamics:
    static receivers equal the independent assembly's solution (1e-9); `-n 2` equals `-n 1`
    (static 1e-10, modes 1e-8, dynamics 1e-9); the dynamic run's late static part is bounded
    and its XDMF has a Mixed topology with displacement, rotation and velocity."""
    mesh, dm, K, m = slab_model
    res = {}
    for n in (1, 2):
        s = str(tmp_path / f"s{n}.h5")
        ok(run_cli(["static", "-options_file", SLAB, "-ssi_output", s], n=n))
        res[("static", n)] = receivers(s)
        mo = ok(run_cli(["modes", "-options_file", SLAB, "-ssi_modes_n", "6", "-ssi_output",
                         str(tmp_path / f"m{n}.h5")], n=n))
        lines = mo.stdout[mo.stdout.index("mode,frequency_hz"):].splitlines()[1:7]
        res[("modes", n)] = np.array([float(x.split(",")[1]) for x in lines])
        d = str(tmp_path / f"d{n}.h5")
        ok(run_cli(["-options_file", SLAB, "-ssi_t_end", "0.1", "-ssi_output", d], n=n))
        res[("dyn", n)] = receivers(d)
    # static against the independent assembly
    from petsc_ssi.fem.loads import nodal_load, fixed_dofs
    from types import SimpleNamespace
    cfg = SimpleNamespace(fem_load_p0=1000.0, fem_load_group="slab", fem_point_load="4,3,3,1e4,0,0")
    blocks = [(b.element, b.cells, mesh.coords, b.props) for b in mesh.blocks]
    Kr, _ = np_assemble(mesh.n_nodes, blocks, ndof=6)
    F = nodal_load(mesh, cfg, dm)[0]
    perm = (dm.offset[:, None] + np.arange(6)).ravel()
    fixed = fixed_dofs(mesh, "base", dm)
    inv = np.empty_like(perm)
    inv[perm] = np.arange(perm.size)
    u = solve_static(Kr, F[perm], inv[fixed])
    nodes = [int(np.argmin(np.linalg.norm(mesh.coords - p, axis=1))) for p in ([2, 1.5, 3], [4, 3, 3])]
    st = res[("static", 1)]
    for i, node in enumerate(nodes):
        assert np.allclose(st["u"][0, i], u[6 * node:6 * node + 3], rtol=0, atol=1e-9 * np.abs(u).max())
        assert np.allclose(st["rotation"][0, i], u[6 * node + 3:6 * node + 6], rtol=0, atol=1e-9 * np.abs(u).max())
    # the slab pressure pushes the slab down (cells oriented up)
    assert st["u"][0, 0, 2] < 0
    assert relmax(res[("static", 2)]["u"], st["u"]) < 1e-10
    assert relmax(res[("static", 2)]["rotation"], st["rotation"]) < 1e-10
    assert np.allclose(res[("modes", 2)], res[("modes", 1)], rtol=1e-8)
    for k in ("u", "rotation", "velocity", "acceleration"):
        assert relmax(res[("dyn", 2)][k], res[("dyn", 1)][k]) < 1e-9, k
    dyn = res[("dyn", 1)]
    assert dyn["t"].size == 51 and np.all(np.isfinite(dyn["acceleration"]))
    # the recorded acceleration is the mean over each step, (v^n - v^{n-1}) / dt
    t, v, a = dyn["t"], dyn["velocity"], dyn["acceleration"]
    assert np.allclose(a[1:], (v[1:] - v[:-1]) / (t[1:] - t[:-1])[:, None, None], rtol=1e-12, atol=0)
    assert np.all(a[0] == 0)
    xmf = open(str(tmp_path / "d1.xmf")).read()
    assert 'TopologyType="Mixed"' in xmf and 'Name="rotation"' in xmf and 'Name="velocity"' in xmf
    assert 'Precision="8"' in xmf
    with h5py.File(str(tmp_path / "d1.h5")) as f:
        topo = f["topology"][:]
        assert topo.size == 48 * 5 + 24 * 4                        # 48 quads (id 5 + 4), 24 lines (2, 2 + 2)
        assert f["rotation_000001"].shape == (mesh.n_nodes, 3)


def test_iterative_solver_with_rotation_near_null_space(tmp_path):
    """CG + BoomerAMG with the dof map's six rigid-body modes (rotations included) as the
    near-null space gives the direct solution of the mixed model (static, 1e-8)."""
    a, b = str(tmp_path / "a.h5"), str(tmp_path / "b.h5")
    ok(run_cli(["static", "-options_file", SLAB, "-ssi_output", a]))
    ok(run_cli(["static", "-options_file", SLAB, "-ssi_output", b, "-ssi_fem_solver", "iterative"]))
    assert relmax(receivers(b)["u"], receivers(a)["u"]) < 1e-8


@pytest.mark.parametrize("name", ["s.h5", "r&d <1>.h5"])
def test_xdmf_of_a_mixed_model_opens_in_paraview(name, tmp_path):
    """ParaView reads the Mixed-topology XDMF: every cell (48 shells + 24 frames), and the
    displacement equals the HDF5 data in double precision; also when the file name has XML's
    special characters (escaped in the .xmf)."""
    from helpers import pv_or_skip, pvpython
    pv_or_skip()
    s = str(tmp_path / name)
    ok(run_cli(["static", "-options_file", SLAB, "-ssi_output", s]))
    got = pvpython("r.UpdatePipeline()\nd = dsa.WrapDataObject(sm.Fetch(r))\n"
                   "u = np.asarray(d.PointData['displacement'])\n"
                   "print(json.dumps({'cells': int(d.GetNumberOfCells()), 'points': int(d.GetNumberOfPoints()),"
                   " 'u': u.tolist(), 'dtype': str(u.dtype)}))\n", s.replace(".h5", ".xmf"), tmp_path)
    assert got["cells"] == 72
    with h5py.File(s) as f:
        u = f["displacement_000000"][:]
    assert got["points"] == u.shape[0]
    assert got["dtype"] == "float64"
    assert np.array_equal(np.array(got["u"]), u)


def test_group_receivers_and_group_point_loads(tmp_path):
    """'group:NAME' receivers and 'GROUP,fx,fy,fz' point loads act on the group's nodes: the same
    answer as the coordinates of that node (top_corner is the point 4,3,3)."""
    a, b = str(tmp_path / "a.h5"), str(tmp_path / "b.h5")
    ok(run_cli(["static", "-options_file", SLAB, "-ssi_output", a, "-ssi_receivers", "4,3,3"]))
    ok(run_cli(["static", "-options_file", SLAB, "-ssi_output", b, "-ssi_receivers", "group:top_corner",
                "-ssi_fem_point_load", "top_corner,1e4,0,0"]))
    ra, rb = receivers(a), receivers(b)
    assert rb["u"].shape == (1, 1, 3)
    assert relmax(rb["u"], ra["u"]) < 1e-12 and relmax(rb["rotation"], ra["rotation"]) < 1e-12


def test_point_masses_add_to_M_and_lower_the_frequencies(tmp_path):
    """-ssi_fem_point_mass: a 1000 kg mass at each slab corner adds exactly 4000 kg to the
    lumped M (the printed total) and lowers every frequency of the slab on columns."""
    a = ok(run_cli(["modes", "-options_file", SLAB, "-ssi_modes_n", "3", "-ssi_output", str(tmp_path / "a.h5")]))
    b = ok(run_cli(["modes", "-options_file", SLAB, "-ssi_modes_n", "3", "-ssi_output", str(tmp_path / "b.h5"),
                    "-ssi_fem_point_mass", "0,0,3,1000;4,0,3,1000;4,3,3,1000,50;0,3,3,1000"]))
    assert "[fem] point masses: 4000 kg in all" in b.stdout

    def freqs(r):
        lines = r.stdout[r.stdout.index("mode,frequency_hz"):].splitlines()[1:4]
        return np.array([float(x.split(",")[1]) for x in lines])
    assert np.all(freqs(b) < freqs(a))


def test_one_time_grid_for_fem_runs(tmp_path):
    """t_end / dt not a whole number: the FEM takes ceil(t_end / dt) steps like the BEM
    (t_end 0.04, dt 7.5e-4: 54 steps, the last at 0.0405 s); a whole number up to round-off
    takes exactly that number (0.03 / 7.5e-4 = 40)."""
    from petsc_ssi.timegrid import n_steps
    assert n_steps(0.04, 7.5e-4) == 54 and n_steps(0.03, 7.5e-4) == 40 and n_steps(0.1, 0.01) == 10
    out = str(tmp_path / "g.h5")
    ok(run_cli(["-ssi_problem", "fem", "-ssi_fem_box_cells", "2,2,2", "-ssi_fem_fixed", "base",
                "-ssi_fem_load_group", "top", "-ssi_fem_load_p0", "1000", "-ssi_t_end", "0.04", "-ssi_dt", "7.5e-4",
                "-ssi_receivers", "0,0,0.5", "-ssi_output", out, "-ssi_output_stride", "0"]))
    t = receivers(out)["t"]
    assert t.size == 55 and t[-1] == pytest.approx(0.0405, rel=1e-12)


def test_building_fixed_base_modes_two_ranks(tmp_path):
    """The paper's three-storey building on a fixed base (runs/building/fixed-base.opts, 14640
    dofs): `-n 2` finds the 1-rank frequencies to 1e-9 (on 2 ranks some parts own no cells on a
    rank: the case that once failed in the lumped mass), and the printed total mass is the hand
    calculation's 879764.4 kg (runs/building/README.md)."""
    f = {}
    for n in (1, 2):
        r = ok(run_cli(["modes", "-options_file", "runs/building/fixed-base.opts", "-ssi_modes_n", "4",
                        "-ssi_output", str(tmp_path / f"m{n}.h5")], n=n, timeout=300))
        lines = r.stdout[r.stdout.index("mode,frequency_hz"):].splitlines()[1:5]
        f[n] = np.array([float(x.split(",")[1]) for x in lines])
        assert "[fem] structure: total mass 879764 kg" in r.stdout
    assert np.allclose(f[2], f[1], rtol=1e-9)


def _cylinder(nth=16, nz=4, seed=0):
    th = np.linspace(0, 2 * np.pi, nth, endpoint=False)
    z = np.linspace(0, 3, nz + 1)
    T, Z = np.meshgrid(th, z, indexing="ij")
    X = np.column_stack([np.cos(T).ravel(), np.sin(T).ravel(), Z.ravel()])
    idx = np.arange(X.shape[0]).reshape(nth, nz + 1)
    c = np.stack([idx[:, :-1], np.roll(idx, -1, 0)[:, :-1], np.roll(idx, -1, 0)[:, 1:], idx[:, 1:]],
                 -1).reshape(-1, 4)
    f = np.random.default_rng(seed).random(len(c)) < 0.5
    c[f] = c[f][:, [0, 3, 2, 1]]
    return X, c


def test_shell_orientation_is_consistent_over_a_surface():
    """Shell cells in random orders: a flat slab comes out facing up, a vertical tube (a silo wall)
    outward on every cell, so a uniform pressure has zero net force and pushes every node inward;
    a Moebius strip is refused."""
    from petsc_ssi.fem.mesh import orient_shells
    from petsc_ssi.fem.loads import quad_pressure_forces
    from petsc_ssi.petsc import SSIError
    X, c = _cylinder()
    o = orient_shells(c, X)
    Y = X[o]
    n = np.cross(Y[:, 2] - Y[:, 0], Y[:, 3] - Y[:, 1])
    assert np.all(np.einsum("ij,ij->i", n[:, :2], Y.mean(axis=1)[:, :2]) > 0)
    f = quad_pressure_forces(Y, 1000.0)
    F = np.zeros((X.shape[0], 3))
    np.add.at(F, o.ravel(), f.reshape(-1, 3))
    assert np.abs(F.sum(axis=0)).max() < 1e-9 * np.abs(F).max()
    assert np.all(np.einsum("ij,ij->i", F[:, :2], X[:, :2]) < 0)      # pushes inward
    x = np.linspace(0, 1, 5)
    A, B = np.meshgrid(x, x, indexing="ij")
    P = np.column_stack([A.ravel(), B.ravel(), 0 * A.ravel()])
    idx = np.arange(25).reshape(5, 5)
    c2 = np.stack([idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]], -1).reshape(-1, 4)
    c2[::3] = c2[::3][:, [0, 3, 2, 1]]
    Y = P[orient_shells(c2, P)]
    assert np.all(np.cross(Y[:, 2] - Y[:, 0], Y[:, 3] - Y[:, 1])[:, 2] > 0)
    # Moebius strip: a band of 12 cells closed with a half twist
    m = 12
    t = np.linspace(0, 2 * np.pi, m, endpoint=False)
    inner = np.column_stack([np.cos(t) * (1 - 0.2 * np.cos(t / 2)), np.sin(t) * (1 - 0.2 * np.cos(t / 2)),
                             -0.2 * np.sin(t / 2)])
    outer = np.column_stack([np.cos(t) * (1 + 0.2 * np.cos(t / 2)), np.sin(t) * (1 + 0.2 * np.cos(t / 2)),
                             0.2 * np.sin(t / 2)])
    Pm = np.vstack([inner, outer])
    cm = [[k, k + 1, m + k + 1, m + k] for k in range(m - 1)] + [[m - 1, m, 0, 2 * m - 1]]
    with pytest.raises(SSIError, match="not orientable"):
        orient_shells(np.array(cm), Pm)
