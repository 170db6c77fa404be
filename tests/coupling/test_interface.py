"""Interface set-up (matching, normals, consistent forces) and the contact
algebra on small synthetic systems."""
import numpy as np
import pytest

from petsc_ssi.petsc import SSIError
from petsc_ssi.mesh import surface
from petsc_ssi.fem.mesh import structured_box
from petsc_ssi.coupling.interface import build_interface, fem_symmetry_dofs
from petsc_ssi.coupling.contact import ContactLaw, StaggeredSolve, ImplicitSolve, Capacitance

pytestmark = pytest.mark.mpi


def meshes(cells=4, h=0.5):
    be = surface.grid(2.0, 2.0, h, patch=(0.5, 0.5))
    fe = structured_box((cells, cells, 1), (1.0, 1.0, 0.25), (-0.5, -0.5, 0.0))
    return be, fe


def test_matching_normals_and_consistent_forces():
    be, fe = meshes()
    it = build_interface(be, fe, "auto", "base", 1e-6)
    assert it.n == 25 and len(it.be_elems) == 4
    assert np.allclose(be.nodes[it.be_nodes], fe.coords[it.fe_nodes], atol=1e-12)
    assert np.allclose(it.n_b, [0, 0, 1]) and np.allclose(it.n_f, [0, 0, -1])
    # sum_ij M_ij = area; M reproduces int x^2 dA for a quadratic field (nine-node exact)
    assert it.area() == pytest.approx(1.0, rel=1e-13)
    x = it.x[:, 0]
    assert x @ (it.M @ x) == pytest.approx(1.0 / 12.0, rel=1e-12)     # int_{-1/2}^{1/2} x^2 dx
    # the same interface named by a group (the grid's 'load' patch)
    it2 = build_interface(be, fe, "load", "base", 1e-6)
    assert np.array_equal(it2.be_nodes, it.be_nodes)


def test_unmatched_nodes_are_listed():
    be, _ = meshes()
    fe = structured_box((5, 5, 1), (1.0, 1.0, 0.25), (-0.5, -0.5, 0.0))     # 0.2 m spacing: no match
    with pytest.raises(SSIError, match="no soil element has all nine nodes") as exc:
        build_interface(be, fe, "auto", "base", 1e-6)
    # the line counts the soil nodes that do lie on the faces (an independent count), and the spacings
    base = fe.coords[np.abs(fe.coords[:, 2]) < 1e-12]
    d = np.linalg.norm(be.nodes[:, None, :] - base[None, :, :], axis=2)
    on = int((d.min(axis=1) <= 0.2e-6).sum())
    assert 0 < on < len(base)
    assert f": {on} soil node(s) lie on them (within 2e-07 m), at {on} of their {len(base)} nodes" in str(exc.value)
    assert "the faces' nodes 0.2 m" in str(exc.value), str(exc.value)
    # the soil's smallest element by its corners (nodes 0, 1, 3 of a nine-node cell), its nodes half that apart
    X = be.nodes[be.cells]
    side = min(np.linalg.norm(X[:, 1] - X[:, 0], axis=1).min(), np.linalg.norm(X[:, 3] - X[:, 0], axis=1).min())
    assert f"the soil's smallest element {side:.3g} m, its nodes {side / 2:.3g} m apart" in str(exc.value), \
        str(exc.value)
    with pytest.raises(SSIError, match=r"soil node\(s\) of -ssi_interface load match no node .*\(-0\.5, -0\.25, 0\).*\(21 in all\)"):
        build_interface(be, fe, "load", "base", 1e-6)
    with pytest.raises(SSIError, match="no face group 'bottom'"):
        build_interface(be, fe, "auto", "bottom", 1e-6)


def test_wrong_face_is_refused():
    be, fe = meshes()
    fe.coords[:, 2] -= 0.25            # the block's top now lies on the soil: normals agree
    with pytest.raises(SSIError, match="normals are not opposite"):
        build_interface(be, fe, "auto", "top", 1e-6)


def test_symmetry_dofs():
    fe = structured_box((2, 2, 1), (0.5, 0.5, 0.25), (0.0, 0.0, 0.0))
    d = fem_symmetry_dofs(fe, [(0, 1), (1, 1)])
    on_x = np.nonzero(np.abs(fe.coords[:, 0]) < 1e-12)[0]
    assert set(3 * on_x) <= set(d) and not set(3 * on_x + 2) & set(d)
    with pytest.raises(SSIError, match="extends to x"):
        fem_symmetry_dofs(structured_box((2, 2, 1), (1, 1, 0.25), (-0.5, -0.5, 0)), [(0, 1)])
    for off in (1e-8, -1e-8):           # a node that missed the plane (either side): refused, not left free
        fe = structured_box((2, 2, 1), (0.5, 0.5, 0.25), (0.0, 0.0, 0.0))
        fe.coords[np.argmin(fe.coords[:, 0] + fe.coords[:, 1]), 0] = off
        with pytest.raises(SSIError, match=f"the structure's node 0 at .* m lies {off:.3g} m off the plane x = 0"):
            fem_symmetry_dofs(fe, [(0, 1)])


def _toy(nI=3, seed=0):
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(3 * nI, 3 * nI))
    Z = -(A @ A.T + 3 * nI * np.eye(3 * nI))       # soil: p = q - Z u = q + K u, K SPD
    nb = np.tile([0.0, 0.0, 1.0], (nI, 1))
    return Z, nb


def test_capacitance_equals_direct_solution():
    """Staggered: open DOFs get p = 0 and u_b from the soil alone; the
    capacitance update equals solving the soil system with those columns."""
    Z, nb = _toy()
    law = ContactLaw(nb, np.zeros((3, 3), bool), "unilateral", 0.0)
    uf = np.array([0, 0, -1e-3, 0, 0, -1e-3, 0, 0, 1e-3])
    q = np.zeros(9)
    y = q - Z @ uf                                  # bonded traction
    solve = StaggeredSolve(law, Capacitance(Z))(y, uf)
    closed = np.array([True, True, False])
    O, ub, uf_, p = solve(closed)
    assert np.allclose(p[O], 0) and np.allclose(ub[:6], uf[:6])
    # direct: p = q - Z ub with ub_C = uf_C and p_O = 0
    C = np.arange(6)
    ubO = np.linalg.solve(Z[np.ix_(O, O)], q[O] - Z[np.ix_(O, C)] @ uf[C])
    assert np.allclose(ub[O], ubO, rtol=1e-12)


def test_implicit_interface_system():
    """Implicit: u_f = w + C f, f = -M3 p, p = q - Z u_b; closed u_b = u_f, open p = 0."""
    Z, nb = _toy()
    rng = np.random.default_rng(1)
    B = rng.normal(size=(9, 9))
    C = 1e-3 * (B @ B.T + 9 * np.eye(9))
    M3 = np.kron(np.diag([0.3, 0.5, 0.2]), np.eye(3))
    law = ContactLaw(nb, np.zeros((3, 3), bool), "unilateral", 0.0)
    w, q = rng.normal(size=9) * 1e-3, rng.normal(size=9)
    O, ub, uf, p = ImplicitSolve(law, Z, C, M3, 1.0)(q, w, np.zeros(9))(np.array([True, False, True]))
    assert np.allclose(uf, w - C @ M3 @ p, rtol=1e-12, atol=1e-15)
    assert np.allclose(p[O], 0.0) and np.allclose(ub[[0, 1, 2, 6, 7, 8]], uf[[0, 1, 2, 6, 7, 8]], atol=1e-15)
    pfull = q - Z @ ub
    assert np.allclose(pfull[O], 0.0, atol=1e-10) and np.allclose(p, pfull, atol=1e-10)


def test_active_set_opens_tension_and_closes_penetration():
    Z, nb = _toy()
    law = ContactLaw(nb, np.zeros((3, 3), bool), "unilateral", p_C=0.5)
    uf = np.zeros(9)
    y = np.array([0, 0, -2.0, 0, 0, 0.3, 0, 0, 5.0])   # node 2 in tension beyond p_C
    res = law.step(StaggeredSolve(law, Capacitance(Z))(y, uf), uf)
    assert not res["closed"][2] and res["closed"][0]
    assert np.all(res["pN"][res["closed"]] <= 0.5 + 1e-9)
    assert np.all(res["gap"][~res["closed"]] >= -1e-12)
    # compression everywhere: nothing opens, bonded answer
    law2 = ContactLaw(nb, np.zeros((3, 3), bool), "unilateral", p_C=0.0)
    y2 = -np.abs(y)
    r2 = law2.step(StaggeredSolve(law2, Capacitance(Z))(y2, uf), uf)
    assert r2["closed"].all() and np.array_equal(r2["p"], y2)


def test_open_nodes_carry_the_cohesion_when_asked():
    """open_traction 'cohesion' (eq. 25 literally): an open node carries p_N = p_C;
    'zero' (default): no traction. Both for the staggered and implicit algebra."""
    Z, nb = _toy()
    rng = np.random.default_rng(2)
    Cm = 1e-3 * np.eye(9)
    M3 = np.eye(9) * 0.3
    y = np.array([0, 0, -2.0, 0, 0, -0.3, 0, 0, 5.0])
    for mode, expect in (("zero", 0.0), ("cohesion", 0.5)):
        for kind in ("staggered", "implicit"):
            law = ContactLaw(nb, np.zeros((3, 3), bool), "unilateral", p_C=0.5, open_traction=mode)
            if kind == "staggered":
                solve = StaggeredSolve(law, Capacitance(Z))(y, np.zeros(9))
            else:
                solve = ImplicitSolve(law, Z, Cm, M3, 1.0)(y, np.zeros(9), np.zeros(9))
            res = law.step(solve, np.zeros(9))
            assert not res["closed"][2], (mode, kind)
            assert res["p"][8] == pytest.approx(expect) and res["p"][6] == 0.0 and res["p"][7] == 0.0
            assert res["gap"][2] >= 0


def test_open_node_closes_on_penetration():
    """An open node whose soil would rise above the structure (gap < 0) closes,
    both by the B.2 prediction (staggered: u_b^{n-1} vs u_f^n) and after a solve."""
    Z, nb = _toy()
    law = ContactLaw(nb, np.zeros((3, 3), bool), "unilateral", p_C=0.0)
    law.closed[:] = [True, True, False]
    uf = np.array([0, 0, -1e-3, 0, 0, -1e-3, 0, 0, -1e-3])      # the structure moves down
    law.ub_prev = np.zeros(9)                                     # the soil was at rest: gap -1e-3
    y = np.array([0, 0, -2.0, 0, 0, -2.0, 0, 0, -2.0])
    res = law.step(StaggeredSolve(law, Capacitance(Z))(y, uf), uf)
    assert res["closed"].all() and res["changes"] == 1
    # without a prediction (implicit step): the solve finds the penetration and closes it
    law2 = ContactLaw(nb, np.zeros((3, 3), bool), "unilateral", p_C=0.0)
    law2.closed[:] = [True, True, False]
    res2 = law2.step(StaggeredSolve(law2, Capacitance(Z))(y, uf), None)
    assert res2["closed"].all() and res2["iterations"] == 2 and res2["changes"] == 1


def test_contact_decisions_agree_across_ranks(tmp_path):
    """Under mpirun -n 2, a rank whose interface solve differs in the last digits (node 0's traction just
    over p_C on rank 1, just under on rank 0) still takes rank 0's active set: both ranks keep every node
    closed after one solve (the same iterations, so the collective calls that follow stay matched). The same
case without the communicator splits the ranks (checked, so the test case does provoke the hazard)."""
    import json
    import os
    import subprocess
    import sys
    here = os.path.dirname(os.path.abspath(__file__))
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OPENBLAS_NUM_THREADS="1")
    r = subprocess.run(["mpirun", "--allow-run-as-root", "--oversubscribe", "-n", "2", sys.executable,
                        os.path.join(here, "mpi_contact_agree.py"), str(tmp_path)], env=env, capture_output=True, text=True,
                       timeout=60)
    assert r.returncode == 0, r.stdout + r.stderr
    res = [json.loads((tmp_path / f"rank{k}.json").read_text()) for k in (0, 1)]
    assert [d["rank"] for d in res] == [0, 1]
    # without the agreement the case does split the ranks: rank 1 opens node 0 and solves twice
    assert res[0]["alone"]["closed"] == [True, True, True] and res[1]["alone"]["closed"] == [False, True, True]
    for d in res:
        a = d["agreed"]
        assert a["closed"] == [True, True, True] and a["iterations"] == 1 and len(a["calls"]) == 1, d


def test_interface_operator_of_a_shell_slab(tmp_path):
    """T from the dof map for a shell foundation slab: for every rigid-body motion of the
    structure (rotations included), T u is that motion at the soil side of the interface:
    the slab's nodes (translations only) or its underside x - (t/2) n (with the offset);
    T^T is its transpose (spread . gather is the adjoint pairing); the slab's faces are matched
    with normals opposite to the soil's."""
    from helpers import petsc
    PETSc = petsc()
    from petsc_ssi.mesh.gmsh import write_msh
    from petsc_ssi.fem.mesh import read_gmsh
    from petsc_ssi.fem.parts import PartSpec
    from petsc_ssi.fem.elements import Props
    from petsc_ssi.fem.dofmap import DofMap
    from petsc_ssi.coupling.interface import InterfaceOperator, interface_offsets
    x = np.linspace(-0.5, 0.5, 5)
    X, Y = np.meshgrid(x, x, indexing="ij")
    coords = np.column_stack([X.ravel(), Y.ravel(), np.zeros(X.size)])
    idx = np.arange(X.size).reshape(5, 5)
    cells = np.stack([idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]], -1).reshape(-1, 4)
    cells[::2] = cells[::2][:, [0, 3, 2, 1]]             # mixed orientations in the file: the reader fixes them
    path = str(tmp_path / "slab.msh")
    write_msh(path, coords, {"slab": ("quad4", cells)})
    t = 0.3
    fe = read_gmsh(path, [PartSpec("slab", "shell", Props(E=1e9, nu=0.2, rho=1.0, thickness=t))])
    be = surface.grid(2.0, 2.0, 0.5, patch=(0.5, 0.5))
    it = build_interface(be, fe, "auto", "slab", 1e-6)
    assert it.n == 25 and np.allclose(it.n_b, [0, 0, 1])
    dm = DofMap(fe.has_rotation(), PETSc.COMM_SELF)
    R = dm.rigid_body_modes(fe.coords, centre=np.zeros(3))
    for offset in (None, interface_offsets(fe, it, "slab")):
        T = InterfaceOperator(PETSc.COMM_SELF, it, dm, offset)
        pts = fe.coords[it.fe_nodes] + (0 if offset is None else offset)
        if offset is not None:
            assert np.allclose(offset, [0, 0, -t / 2])
        for k in range(6):
            u = dm.vec_from_global(R[:, k])
            got = T.gather(u).reshape(-1, 3)
            want = np.zeros_like(pts)
            if k < 3:
                want[:, k] = 1.0
            else:
                w = np.zeros(3)
                w[k - 3] = 1.0
                want = np.cross(w, pts)
            assert np.allclose(got, want, atol=1e-14), (k, offset is not None)
        f = np.random.default_rng(1).standard_normal(3 * it.n)
        out = dm.vec()
        T.spread(f, out)
        v = np.random.default_rng(2).standard_normal(dm.size)
        assert out.getArray() @ v == pytest.approx(f @ T.gather(dm.vec_from_global(v)), rel=1e-12)
        T.destroy()
