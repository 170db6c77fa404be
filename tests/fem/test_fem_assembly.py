"""Hex8 kernels, mesh groups, pressure loads and the distributed assembly (serial tier)."""
import os

import numpy as np
import pytest

from fem_helpers import ROOT, small_system, dense
from petsc_ssi.petsc import SSIError
from petsc_ssi.fem import assembly as asm
from petsc_ssi.fem.mesh import structured_box, read_gmsh, renumber_rcm, boundary_faces
from petsc_ssi.fem.loads import quad_pressure_forces, fixed_dofs

pytestmark = pytest.mark.unit


def distorted_bricks(n=5, seed=1):
    rng = np.random.default_rng(seed)
    X = asm.XI_NODES[None] * np.array([0.7, 0.4, 0.3]) + 0.08 * rng.standard_normal((n, 8, 3))
    return X + rng.standard_normal((n, 1, 3))


def test_fast_kernel_matches_reference():
    """einsum kernel == textbook B^T D B loop on distorted bricks, to round-off (1e-12)."""
    X = distorted_bricks()
    Kf, Kr = asm.hex8_stiffness(X, 2.5e7, 0.3), asm.hex8_stiffness_reference(X, 2.5e7, 0.3)
    assert np.abs(Kf - Kr).max() <= 1e-12 * np.abs(Kr).max()


def test_element_rigid_modes_and_patch():
    """K_e r = 0 for the 6 rigid-body modes; a linear field gives the exact constant stress energy."""
    from petsc_ssi.fem.loads import rigid_body_modes
    X = distorted_bricks(3)
    E, nu = 1e7, 0.2
    Ke = asm.hex8_stiffness(X, E, nu)
    for e in range(3):
        R = rigid_body_modes(X[e])
        assert np.abs(Ke[e] @ R).max() <= 1e-10 * np.abs(Ke[e]).max()
        # uniform strain: u = G x with symmetric G -> energy = V * eps:C:eps / 2
        Gm = np.array([[1e-3, 2e-4, 0], [2e-4, -5e-4, 1e-4], [0, 1e-4, 3e-4]])
        u = (X[e] @ Gm.T).ravel()
        lam, mu = asm.lame(E, nu)
        w = 0.5 * (lam * np.trace(Gm) ** 2 + 2 * mu * np.sum(Gm * Gm))
        _, wd, _ = asm.hex8_geometry(X[e:e + 1])
        assert 0.5 * u @ Ke[e] @ u == pytest.approx(w * wd.sum(), rel=1e-12)


def test_lumped_mass_total():
    """sum of lumped masses = rho * volume (1e-12)."""
    mesh = structured_box((3, 2, 2), (1.0, 0.6, 0.4), (0, 0, 0))
    me = asm.hex8_lumped_mass(mesh.coords[mesh.cells], 2000.0)
    assert me.sum() == pytest.approx(2000.0 * 0.24, rel=1e-12)
    assert np.all(me > 0)


def test_inverted_brick_is_an_error():
    X = distorted_bricks(2)
    X[1] = X[1][[4, 5, 6, 7, 0, 1, 2, 3]]          # upside down: negative Jacobian
    with pytest.raises(SSIError, match="non-positive Jacobian"):
        asm.hex8_stiffness(X, 1e6, 0.2)


def test_global_K_equals_dense_assembly(PETSc):
    """Distributed assembly (one rank) == dense scatter-add of the reference kernel; RCM only permutes."""
    mesh = renumber_rcm(structured_box((3, 2, 2), (1.0, 0.5, 0.5), (0, 0, 0)))
    K, m, _ = small_system(mesh, E=3e7, nu=0.3)
    Kref = np.zeros((3 * mesh.n_nodes,) * 2)
    Ke = asm.hex8_stiffness_reference(mesh.coords[mesh.cells], 3e7, 0.3)
    for c, ke in zip(mesh.cells, Ke):
        d = (3 * c[:, None] + np.arange(3)).ravel()
        Kref[np.ix_(d, d)] += ke
    Kd = dense(K)
    assert np.abs(Kd - Kref).max() <= 1e-12 * np.abs(Kref).max()
    assert K.getBlockSize() == 3
    assert K.getInfo()["nz_unneeded"] == 0           # exact preallocation
    assert m.sum() == pytest.approx(3 * 1e3 * 0.25, rel=1e-12)


def test_pressure_forces_on_a_face():
    """Consistent forces of p on a 1 x 1 top face: total -p n A, corner:edge:interior = 1:2:4."""
    mesh = structured_box((2, 2, 1), (1.0, 1.0, 0.5), (-0.5, -0.5, 0))
    q = mesh.faces["top"]
    f = quad_pressure_forces(mesh.coords[q], 1000.0)
    F = np.zeros((mesh.n_nodes, 3))
    np.add.at(F, q, f)
    assert F.sum(axis=0) == pytest.approx([0, 0, -1000.0], abs=1e-9)
    top = np.unique(q)
    fz = np.sort(F[top, 2])
    assert fz == pytest.approx(sorted([-62.5] * 4 + [-125.0] * 4 + [-250.0]), rel=1e-12)


def test_box_groups_are_outward():
    mesh = structured_box((4, 3, 2))
    for name, n in (("top", [0, 0, 1]), ("base", [0, 0, -1]), ("xmin", [-1, 0, 0]), ("ymax", [0, 1, 0])):
        c = mesh.coords[mesh.faces[name]]
        nrm = np.cross(c[:, 1] - c[:, 0], c[:, 3] - c[:, 0])
        nrm /= np.linalg.norm(nrm, axis=1)[:, None]
        assert np.allclose(nrm, n, atol=1e-12), name
    assert len(boundary_faces(mesh.cells)) == 2 * (12 + 8 + 6)
    assert len(mesh.faces["top_left"]) == len(mesh.faces["top_right"]) == 6


def test_foundation_geo():
    """meshes/foundation.geo: 400 hex8, 605 nodes, groups top/base/top_left/top_right outward."""
    mesh = read_gmsh(os.path.join(ROOT, "meshes", "foundation.geo"))
    assert (mesh.n_cells, mesh.n_nodes) == (400, 605)
    assert np.allclose(mesh.coords.min(0), [-0.5, -0.5, 0]) and np.allclose(mesh.coords.max(0), [0.5, 0.5, 0.5])
    for name, nf, z, nz in (("top", 100, 0.5, 1), ("base", 100, 0.0, -1), ("top_left", 50, 0.5, 1),
                            ("top_right", 50, 0.5, 1)):
        c = mesh.coords[mesh.faces[name]]
        assert len(c) == nf and np.allclose(c[:, :, 2], z)
        assert np.all(np.sign(np.cross(c[:, 1] - c[:, 0], c[:, 3] - c[:, 0])[:, 2]) == nz)
    assert np.all(mesh.coords[mesh.faces["top_left"]][:, :, 0] <= 1e-12)
    assert np.all(mesh.coords[mesh.faces["top_right"]][:, :, 0] >= -1e-12)
    vol = asm.hex8_lumped_mass(mesh.coords[mesh.cells], 1.0).sum()
    assert vol == pytest.approx(0.5, rel=1e-12)


def test_msh_file_reads_like_the_geo(tmp_path):
    """A .msh written by gmsh from foundation.geo reads to the same mesh and groups."""
    import gmsh
    msh = str(tmp_path / "foundation.msh")
    gmsh.initialize(readConfigFiles=False, interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.open(os.path.join(ROOT, "meshes", "foundation.geo"))
        gmsh.model.mesh.generate(3)
        gmsh.write(msh)
    finally:
        gmsh.finalize()
    a, b = read_gmsh(os.path.join(ROOT, "meshes", "foundation.geo")), read_gmsh(msh)
    assert np.array_equal(a.cells, b.cells) and np.allclose(a.coords, b.coords, rtol=0, atol=1e-12)
    assert sorted(a.faces) == sorted(b.faces)
    for k in a.faces:
        assert np.array_equal(a.faces[k], b.faces[k])


def test_tet_mesh_is_rejected(tmp_path):
    geo = tmp_path / "tets.geo"
    geo.write_text('SetFactory("OpenCASCADE");\nBox(1) = {0,0,0,1,1,1};\nMesh.MeshSizeMax = 0.5;\n')
    with pytest.raises(SSIError, match="no hex8"):
        read_gmsh(str(geo))


def test_fixed_components():
    mesh = structured_box((2, 2, 2))
    d = fixed_dofs(mesh, "base, xmin:x")
    assert len(d) == 3 * 9 + 9 - 3
    with pytest.raises(SSIError, match="no group 'nope'"):
        fixed_dofs(mesh, "nope")
