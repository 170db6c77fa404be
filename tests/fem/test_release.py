"""Released joints (``-ssi_fem_part_NAME_release rotations``): translations tied, rotations free.

Each case is solved by `petsc-ssi static` on a mesh written here and compared with a closed
form: a frame with an internal hinge (the released part), and a square plate on stiff edge
beams, which is clamped when monolithic and simply supported when released (Timoshenko and
Woinowsky-Krieger, Theory of plates and shells, tables 8 and 35). The dof map's released
triple is checked directly (rigid-body modes in K's null space, fixed rotations on both
triples) and `-n 2` equals `-n 1`.
"""
import numpy as np
import pytest

from fem_helpers import run_cli
from test_structures import ok, receivers, relmax

pytestmark = pytest.mark.mpi

E, NU = 30e9, 0.3


def _beam_msh(path, La=2.0, Lb=3.0, n=4):
    """Two collinear frame parts along x: 'a' on [0, La], 'b' on [La, La + Lb] (shared node)."""
    from petsc_ssi.mesh.gmsh import write_msh
    x = np.r_[np.linspace(0, La, n + 1), np.linspace(La, La + Lb, n + 1)[1:]]
    X = np.column_stack([x, np.zeros_like(x), np.zeros_like(x)])
    ca = np.column_stack([np.arange(n), np.arange(1, n + 1)])
    cb = np.column_stack([np.arange(n, 2 * n), np.arange(n + 1, 2 * n + 1)])
    write_msh(path, X, {"a": ("line2", ca), "b": ("line2", cb), "root": ("point", [[0]]),
                        "hinge": ("point", [[n]]), "end": ("point", [[2 * n]])})


def _beam_opts(msh, release, out, P):
    o = ["static", "-ssi_problem", "fem", "-ssi_fem_mesh", msh, "-ssi_fem_parts", "a,b",
         "-ssi_fem_fixed", "root,end:ux+uy+uz+rx", "-ssi_fem_point_load", f"2,0,0,0,0,{-P}",
         "-ssi_receivers", "2,0,0;5,0,0", "-ssi_output", out]
    for p in ("a", "b"):
        o += [f"-ssi_fem_part_{p}_element", "frame", f"-ssi_fem_part_{p}_E", str(E), f"-ssi_fem_part_{p}_nu",
              str(NU), f"-ssi_fem_part_{p}_rho", "2500", f"-ssi_fem_part_{p}_section", "0.3,0.5",
              f"-ssi_fem_part_{p}_shear_factor", "0"]
    return o + (["-ssi_fem_part_b_release", "rotations"] if release else [])


def test_frame_hinge_against_closed_forms(tmp_path):
    """Clamped at x = 0, pinned at x = 5, load P at x = 2 (Euler-Bernoulli, exact at nodes):
    monolithic: the propped cantilever, w = P a^3 b^2 (3 L + b) / (12 E I L^3);
    part b released: a hinge at the load, so a carries P as a cantilever (w = P a^3 / (3 E I),
    tip rotation P a^2 / (2 E I)) and b turns rigidly by w / b (read at its pinned end).
    Both to 1e-9; the log names the released nodes."""
    from petsc_ssi.fem.parts import rect_section
    msh = str(tmp_path / "beam.msh")
    _beam_msh(msh)
    P, a, b = 1e4, 2.0, 3.0
    L = a + b
    I = rect_section(0.3, 0.5)["Iy"]
    res = {}
    for rel in (False, True):
        out = str(tmp_path / f"beam{int(rel)}.h5")
        r = ok(run_cli(_beam_opts(msh, rel, out, P)))
        assert ("released joints: 1 node(s)" in r.stdout) == rel
        res[rel] = receivers(out)
    w_mono = P * a ** 3 * b ** 2 * (3 * L + b) / (12 * E * I * L ** 3)
    u = res[False]["u"][0]
    assert abs(-u[0, 2] - w_mono) < 1e-9 * w_mono
    u, rot = res[True]["u"][0], res[True]["rotation"][0]
    w = P * a ** 3 / (3 * E * I)
    assert abs(-u[0, 2] - w) < 1e-9 * w
    assert abs(abs(u[1, 2])) < 1e-12 * w                                   # the pinned end
    # rotation about y: u_z = -theta_y x; a's tip slope -P a^2/(2EI) -> theta_y = +P a^2/(2EI)
    assert abs(rot[0, 1] - P * a ** 2 / (2 * E * I)) < 1e-9 * P * a ** 2 / (2 * E * I)
    # b (from the hinge, w down, to the pin) turns rigidly: theta_y = -w / b
    assert abs(rot[1, 1] + w / b) < 1e-9 * w / b


def _plate_msh(path, a=4.0, n=16):
    """Square plate [-a/2, a/2]^2 (quad4 'plate', n x n) with edge beams on its boundary nodes
    ('beams', line2) and the four corners ('corners')."""
    from petsc_ssi.mesh.gmsh import write_msh
    s = np.linspace(-a / 2, a / 2, n + 1)
    X, Y = np.meshgrid(s, s, indexing="ij")
    coords = np.column_stack([X.ravel(), Y.ravel(), np.zeros(X.size)])
    nid = lambda i, j: i * (n + 1) + j  # noqa: E731
    quads = [[nid(i, j), nid(i + 1, j), nid(i + 1, j + 1), nid(i, j + 1)] for i in range(n) for j in range(n)]
    ring = ([nid(i, 0) for i in range(n + 1)] + [nid(n, j) for j in range(1, n + 1)]
            + [nid(i, n) for i in range(n - 1, -1, -1)] + [nid(0, j) for j in range(n - 1, -1, -1)])
    lines = np.column_stack([ring[:-1], ring[1:]])
    corners = [[nid(0, 0)], [nid(n, 0)], [nid(n, n)], [nid(0, n)]]
    write_msh(path, coords, {"plate": ("quad4", quads), "beams": ("line2", lines), "corners": ("point", corners)})


def _plate_opts(msh, release, out, t, q, extra=()):
    o = ["static", "-ssi_problem", "fem", "-ssi_fem_mesh", msh, "-ssi_fem_parts", "plate,beams",
         "-ssi_fem_part_plate_element", "shell", "-ssi_fem_part_plate_E", str(E), "-ssi_fem_part_plate_nu", str(NU),
         "-ssi_fem_part_plate_rho", "2500", "-ssi_fem_part_plate_thickness", str(t),
         "-ssi_fem_part_beams_element", "frame", "-ssi_fem_part_beams_E", str(E * 1e4),
         "-ssi_fem_part_beams_nu", str(NU), "-ssi_fem_part_beams_rho", "2500",
         "-ssi_fem_part_beams_section", "0.5,0.5",
         "-ssi_fem_fixed", "corners", "-ssi_fem_load_group", "plate", "-ssi_fem_load_p0", str(q),
         "-ssi_receivers", "0,0,0;2,0,0", "-ssi_output", out] + list(extra)
    return o + (["-ssi_fem_part_plate_release", "rotations"] if release else [])


def test_plate_on_stiff_beams_clamped_or_simply_supported(tmp_path):
    """A 4 m square plate (t = 4 cm, a/t = 100, 16 x 16 MITC4) on edge beams 1e4 times stiffer,
    fixed at the corners, under q = 1 kPa. Monolithic, the beams' torsional stiffness clamps
    the edges: w_c = 0.00126 q a^4 / D (clamped plate, Timoshenko table 35); released, the
    edges are simply supported: w_c = 0.00406 q a^4 / D (Navier, table 8). Each within 1% (0.1% today);
    the released edge rotates (the slab's edge slope is not the beam's), the monolithic one
    does not. `-n 2` equals `-n 1` (1e-9) for the released model."""
    msh = str(tmp_path / "plate.msh")
    _plate_msh(msh)
    a, t, q = 4.0, 0.04, 1e3
    D = E * t ** 3 / (12 * (1 - NU ** 2))
    res = {}
    for rel in (False, True):
        out = str(tmp_path / f"plate{int(rel)}.h5")
        ok(run_cli(_plate_opts(msh, rel, out, t, q)))
        res[rel] = receivers(out)
    w_cl = -res[False]["u"][0, 0, 2]
    w_ss = -res[True]["u"][0, 0, 2]
    ref_cl, ref_ss = 0.00126532 * q * a ** 4 / D, 0.00406235 * q * a ** 4 / D
    print(f"clamped (monolithic) {w_cl:.6e} vs {ref_cl:.6e}: {w_cl / ref_cl - 1:+.3%}; "
          f"simply supported (released) {w_ss:.6e} vs {ref_ss:.6e}: {w_ss / ref_ss - 1:+.3%}")
    assert abs(w_cl / ref_cl - 1) < 0.01
    assert abs(w_ss / ref_ss - 1) < 0.01
    # the mid-edge node (2, 0, 0): its first rotation triple is the beam's; the beam barely twists
    assert abs(res[True]["rotation"][0, 1, 1]) < 1e-3 * w_ss / a
    out2 = str(tmp_path / "plate_n2.h5")
    ok(run_cli(_plate_opts(msh, True, out2, t, q), n=2))
    assert relmax(receivers(out2)["u"], res[True]["u"]) < 1e-9


def test_dofmap_released_triple(PETSc, tmp_path):
    """The dof map of the released plate: 64 edge nodes carry 9 dofs, the others 6 (plate) or
    none extra; K annihilates the rigid-body modes with the released triple turning too
    (1e-9 relative), and not when that triple is left out; a support fixing rotations by name
    fixes both triples, point moments and output use the first."""
    from types import SimpleNamespace
    from petsc_ssi.fem.mesh import read_gmsh
    from petsc_ssi.fem.parts import parse_parts
    from petsc_ssi.fem.dofmap import DofMap
    from petsc_ssi.fem.assembly import assemble
    from petsc_ssi.fem.loads import fixed_dofs
    from fem_helpers import dense
    msh = str(tmp_path / "plate.msh")
    _plate_msh(msh, n=4)
    o = _plate_opts(msh, True, "x.h5", 0.04, 1e3)
    raw = {o[i][len("-ssi_fem_part_"):]: o[i + 1] for i in range(len(o) - 1) if o[i].startswith("-ssi_fem_part_")}
    specs = parse_parts(SimpleNamespace(get=lambda *a: "plate,beams"), raw=raw)
    mesh = read_gmsh(msh, specs)
    rel = mesh.released_nodes()
    assert rel.sum() == 16 and np.all(mesh.has_rotation())
    dm = DofMap(mesh.has_rotation(), PETSc.COMM_SELF, rel)
    assert dm.size == 6 * mesh.n_nodes + 3 * 16
    assert set(np.diff(np.r_[dm.offset, dm.size])) == {6, 9}
    K, _ = assemble(mesh, None, dm)
    Kd = dense(K)
    R = dm.rigid_body_modes(mesh.coords)
    assert np.abs(Kd @ R).max() < 1e-9 * np.abs(Kd).max()
    R2 = R.copy()
    second = (dm.offset[rel][:, None] + np.arange(6, 9)).ravel()
    R2[second] = 0.0
    scale = np.abs(np.diag(Kd)[second]).max()                          # the slab's rotational stiffness
    assert np.abs(Kd @ R2[:, 3:]).max() > 0.1 * scale                  # the second triple is coupled
    corner = mesh.group_nodes("corners")
    fx = fixed_dofs(mesh, "corners:rx", dm)
    assert len(fx) == 4 * 2 and set(fx) == set(dm.offset[corner] + 3) | set(dm.offset[corner] + 6)
    assert np.all(dm.dofs(corner, ("rx",)) == dm.offset[corner] + 3)


def test_release_bad_input(tmp_path):
    """A misspelt release value is refused in one line, with a suggestion."""
    msh = str(tmp_path / "beam.msh")
    _beam_msh(msh)
    r = run_cli(_beam_opts(msh, False, str(tmp_path / "x.h5"), 1.0) + ["-ssi_fem_part_b_release", "rotation"])
    assert r.returncode != 0
    assert "-ssi_fem_part_b_release 'rotation': must be rotations or none (did you mean rotations?)" in r.stdout + r.stderr


def test_released_member_free_to_twist_is_refused(tmp_path):
    """Part b hinged at both ends (released at the joint, pinned at its end without rx) twists
    freely: the static solve refuses the mechanism in one line."""
    msh = str(tmp_path / "beam.msh")
    _beam_msh(msh)
    o = [x.replace("root,end:ux+uy+uz+rx", "root,end:ux+uy+uz") for x in _beam_opts(msh, True, str(tmp_path / "m.h5"), 1e4)]
    r = run_cli(o)
    errs = [ln for ln in r.stderr.splitlines() if ln.startswith("petsc-ssi: error: ")]
    assert r.returncode == 2 and len(errs) == 1 and "singular" in errs[0], r.stdout[-2000:]
