"""Storey demands of a coupled run (fem/demands.py, issue 28 item 2): base shear, overturning moment
and drift ratio in the group 'demands' of <output>_structure.h5.

The case: the block of tests/coupling/test_seismic.py (1 m x 1 m x 0.25 m bricks, 4 x 4 x 1 cells,
rho 2000 kg/m^3, E 1e8 Pa: deformable) on the paper's foundation soil under a vertically incident S
wave (x) of a smooth acceleration pulse, implicit coupling (the structure by the trapezoidal rule in
midpoint form, the soil's traction as the step's mean force), 24 steps.

Checks, every step:
- the base shear is minus the interface force (the soil's force on the structure, force_fe) and the
  overturning moment minus its moment about the interface's centroid at z = 0 (bitwise);
- Newton for the whole structure: the base shear equals minus the sum of the nodal inertia forces
  m (v^n - v^{n-1}) / dt (the midpoint rule's own acceleration; no fixed dof, no damping, so the
  stiffness forces sum to zero) and the moment minus their moment about the reference, to 1e-9 of
  the peak (round-off);
- the drift ratio of the one storey (levels 0, 0.25 m) is the mean x, y displacement of the top
  nodes minus that of the base nodes over 0.25 m, from the structure receivers (every node); the
  base's rotation is the least-squares plane through the base nodes' u_z, and the deformation drift
  the drift minus that rigid rotation;
- the peaks are max |series| and the time of it.
"""
import h5py
import numpy as np
import pytest

from helpers import petsc

pytestmark = pytest.mark.run


@pytest.fixture(scope="module")
def record(tmp_path_factory):
    t = np.arange(0.0, 0.4 + 1e-9, 0.005)
    a = np.where(t < 0.2, np.sin(np.pi * t / 0.2) ** 4, 0.0)
    p = tmp_path_factory.mktemp("rec") / "pulse.txt"
    np.savetxt(p, np.c_[t, a], header="units: m/s2")
    return str(p)


def run(opts):
    PETSc = petsc()
    import petsc_ssi.app.kinds  # noqa: F401  (every option declared)
    from petsc_ssi.app.kinds import resolve
    from petsc_ssi.coupling.problem import SSITransient
    db = PETSc.Options()
    for k, v in opts.items():
        db.setValue("ssi_" + k, str(v))
    try:
        prob = SSITransient(resolve("ssi"))
        return prob, prob.run()
    finally:
        for k in opts:
            db.delValue("ssi_" + k)


def test_coupled_base_shear_is_the_interface_force_and_the_inertia(tmp_path, record):
    out = tmp_path / "blk.h5"
    prob, res = run(dict(problem="ssi", cp=42, cs=20, rho=1800, mesh_size="2,2", mesh_h=0.5, mesh_patch="0.5,0.5",
                         fem_box_cells="4,4,1", fem_box_size="1,1,0.25", fem_box_origin="-0.5,-0.5,0", fem_E=1e8,
                         fem_rho=2000, dt=0.0125, t_end=0.3, output=str(out), output_overwrite=1, output_stride=0,
                         warn_beta=0, seismic="vertical", seismic_record=record, seismic_units="m/s2",
                         seismic_taper=0, seismic_baseline="none", structure_receivers="group:all",
                         structure_drift_levels="0,0.25"))
    dt = 0.0125
    it = res["interface"]
    with h5py.File(str(out).replace(".h5", "_structure.h5"), "r") as f:
        g = {k: f["demands/" + k][()] for k in f["demands"]}
        conv = f["demands/base_shear"].attrs["convention"]
        assert f["demands/base_shear"].attrs["source"].startswith("interface force")
        assert f["demands/overturning_moment"].attrs["unit"] == "N m"
    assert "exerts on the ground through its base" in conv
    t, V, M = g["t"], g["base_shear"], g["overturning_moment"]
    K = len(t)
    assert K == 25 and np.array_equal(t, np.r_[0.0, it["t"]])
    ref = g["reference_point"]
    assert np.allclose(ref, 0.0, atol=1e-12)                     # the block's interface is centred at x = y = 0
    # minus the interface force (steps 1..K-1; at rest at t = 0)
    assert np.array_equal(V[0], [0.0, 0.0]) and np.array_equal(V[1:], -it["force_fe"][:, :2])
    assert np.array_equal(M[1:], -(it["moment_fe"] - np.cross(ref, it["force_fe"]))[:, :2])
    # Newton: the sum of the inertia forces with the structure's own velocities (every node)
    s = res["structure"]
    nodes = prob.model.receiver_nodes
    assert len(nodes) == prob.model.mesh.n_nodes == 50
    m = prob.model.m.getArray(readonly=True)[prob.model.dofmap.translation_dofs(nodes)]     # (N, 3) [kg]
    assert m[:, 0].sum() == pytest.approx(2000 * 0.25, rel=1e-12)
    ma = m[None] * (s["velocity"][1:] - s["velocity"][:-1]) / dt                           # (K-1, N, 3) [N]
    peak = np.abs(V[:, 0]).max()
    assert peak > 10.0
    err = np.abs(V[1:] + ma.sum(axis=1)[:, :2]).max() / peak
    r = prob.model.mesh.coords[nodes] - ref
    errM = np.abs(M[1:] + np.cross(r[None], ma).sum(axis=1)[:, :2]).max() / np.abs(M[:, 1]).max()
    print(f"base shear + sum m a: {err:.2e}, moment: {errM:.2e} of the peaks {peak:.4g} N, "
          f"{np.abs(M[:, 1]).max():.4g} N m")
    assert err < 1e-9 and errM < 1e-9
    # the drift ratio from the receivers (every node): mean top minus mean base over 0.25 m
    z = prob.model.mesh.coords[nodes, 2]
    u = s["u"]
    ref_drift = (u[:, z > 0.2, :2].mean(axis=1) - u[:, z < 0.05, :2].mean(axis=1)) / 0.25
    assert g["drift_ratio"].shape == (K, 1, 2)
    # a difference of displacements (the block moves with the ground: the drift is 3e-3 of u / 0.25):
    # its round-off follows u / 0.25 (observed 3.7e-16 of it; 1.3e-13 of the drift's own largest value,
    # only 8x under the former 1e-12 of that)
    uscale = np.abs(u[..., :2]).max() / 0.25
    assert np.abs(g["drift_ratio"][:, 0] - ref_drift).max() <= 1e-12 * uscale
    assert np.abs(ref_drift[:, 0]).max() > 1e-6
    # the base's rocking: a least-squares plane u_z = c + theta_x y - theta_y x through the base nodes
    base = z < 0.05
    xb = prob.model.mesh.coords[nodes[base]]
    A = np.c_[np.ones(base.sum()), xb[:, 1], -xb[:, 0]]
    fit = np.linalg.lstsq(A, u[:, base, 2].T, rcond=None)[0][1:].T                    # (K, 2)
    rot = g["base_rotation"]
    assert np.abs(rot).max() > 1e-7
    assert np.abs(rot - fit).max() <= 1e-10 * np.abs(fit).max()
    rigid = np.stack([rot[:, 1], -rot[:, 0]], axis=-1)
    assert np.array_equal(g["drift_ratio_deformation"][:, 0], g["drift_ratio"][:, 0] - rigid)
    # the peak envelopes
    for name in ("base_shear", "overturning_moment", "drift_ratio", "base_rotation"):
        x = g[name]
        i = np.argmax(np.abs(x), axis=0)
        assert np.array_equal(g["peak_" + name], np.take_along_axis(np.abs(x), i[None], 0)[0])
        assert np.array_equal(g["peak_" + name + "_time"], t[i])
