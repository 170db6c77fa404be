"""Half model == full model under an earthquake (issue 27): a vertically incident S wave polarised
along x is symmetric about the plane y = 0 (u_x, u_z even in y, u_y odd: -ssi_symmetry y=sym, which
bem/halfspace.py ``_seismic_symmetry`` allows for it).

Soil of the paper's example (c_p 42, c_s 20 m/s, rho 1800 kg/m^3), a 1 m x 1 m x 0.5 m block
(E 300 MPa, rho 2000 kg/m^3: it rocks and slides on the soil) on a 2 m x 2 m surface mesh; the
half model meshes y >= 0 of both. The wave's surface motion is a smooth acceleration pulse along x.

The half model must give the full model's soil receivers (total field, points with y >= 0), the
interface displacements and tractions of the matching nodes, and half the full interface's force
(x, z) and moment about y (the moment about x and the force along y vanish on the full interface
and are not halved quantities), bonded and with unilateral contact under the weight preload.
Tolerance 1e-10 relative to each series' largest value (both runs solve the same equations;
measured: displacements 3e-14, tractions 2.5e-12, resultants 2.3e-12, receivers 9e-15). The contact case runs at half the
amplitude (2.5 m/s^2): at 5 m/s^2 some steps cycle, and the cycling rule (change only the worst
node) then picks different nodes in the two models, so they part.
"""
import numpy as np
import pytest

from helpers import run_ssi

pytestmark = pytest.mark.run

CP, CS, RHO = 42.0, 20.0, 1800.0


@pytest.fixture(scope="module")
def record(tmp_path_factory):
    """sin^4 acceleration pulse up (0.3 s) then down, amplitude 1 m/s^2, every 5 ms."""
    t = np.arange(0.0, 0.9 + 1e-9, 0.005)
    a = np.where(t < 0.3, np.sin(np.pi * t / 0.3) ** 4, 0.0) - np.where((t >= 0.3) & (t < 0.6),
                                                                          np.sin(np.pi * (t - 0.3) / 0.3) ** 4, 0.0)
    p = tmp_path_factory.mktemp("rec") / "pulse.txt"
    np.savetxt(p, np.c_[t, a], header="units: m/s2")
    return str(p)


def run(tmp, record, half, name, **kw):
    o = dict(cp=CP, cs=CS, rho=RHO, mesh_size="2,2", mesh_h=0.5, mesh_patch="0.5,0.5",
             fem_box_cells="4,4,2", fem_box_size="1,1,0.5", fem_box_origin="-0.5,-0.5,0",
             fem_E=300e6, fem_rho=2000.0, dt=0.0125, t_end=0.5, output=str(tmp / name),
             output_stride=0, warn_beta=0, seismic="vertical", seismic_record=record,
             seismic_units="m/s2", seismic_taper=0.0, seismic_baseline="none", seismic_scale=5.0,
             receivers="1,0,0;0.75,0.5,0;0,0.75,0")
    if half:
        o.update(symmetry="y=sym", fem_box_cells="4,2,2", fem_box_size="1,0.5,0.5", fem_box_origin="-0.5,0,0")
    o.update(kw)
    return run_ssi(**o)


@pytest.mark.parametrize("contact", [dict(), dict(contact="unilateral", contact_preload="weight", seismic_scale=2.5)],
                         ids=["bonded", "unilateral-weight"])
def test_half_equals_full_under_a_vertical_s_wave(tmp_path, record, contact):
    full = run(tmp_path, record, False, "full.h5", **contact)
    half = run(tmp_path, record, True, "half.h5", **contact)
    fi, hi = full["interface"], half["interface"]
    # interface nodes of the half are those of the full with y >= 0, matched by position
    idx = [int(np.argmin(np.linalg.norm(fi["x"] - p, axis=1))) for p in hi["x"]]
    assert np.allclose(fi["x"][idx], hi["x"], atol=1e-12) and len(idx) == 15 and len(fi["x"]) == 25
    tol = 1e-10
    su = np.abs(fi["ub"]).max()
    assert su > 1e-2                                                  # the wave moves the block (cm)
    for k in ("ub", "uf"):
        assert np.abs(fi[k][:, idx] - hi[k]).max() <= tol * su, k
    sp = np.abs(fi["p"]).max()
    assert np.abs(fi["p"][:, idx] - hi["p"]).max() <= tol * sp
    # resultants: the half carries half the full force (x, z) and moment about y
    sf = np.abs(fi["force_be"]).max()
    for k in ("force_be", "force_fe"):
        assert np.abs(fi[k][:, [0, 2]] - 2 * hi[k][:, [0, 2]]).max() <= tol * sf, k
        assert np.abs(fi[k][:, 1]).max() <= tol * sf, k              # no y force on the full model
    sm = np.abs(fi["moment_be"]).max()
    assert np.abs(fi["moment_be"][:, 1]).max() > 1e-3 * sf            # it rocks (z tractions about y)
    assert np.abs(fi["moment_be"][:, 1] - 2 * hi["moment_be"][:, 1]).max() <= tol * sm
    # soil receivers (total field) at the same points
    su_r = np.abs(full["u"]).max()
    assert np.abs(full["u"] - half["u"]).max() <= tol * su_r
    if contact:
        assert np.array_equal(fi["closed"][:, idx], hi["closed"])
        assert fi["n_open"].max() > 0                                  # the contact law acts
