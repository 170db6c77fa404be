"""Issue 12: the impedance of a footing by two independent paths.

Path 1 prescribes a rigid motion of the soil region under the footing (``-ssi_disp_group``,
``bem/resultants.py``: the region's force and moment). Path 2 puts a very stiff hex8 block on the
soil (the coupled FEM-BEM problem, bonded), loads the block with a smooth step, fits a rigid
motion to the interface displacements (``impedance.rigid_fit``) and takes the soil-side
interface resultants the coupling records (``force_be``, ``moment_be``: its own quadrature). The
soil mesh and the time step are the same, so the two discrete systems relate the same interface
tractions and displacements: K must agree to the block's flexibility (E_block / G_soil = 4e5
here), at every frequency, not only within the band where K approximates the continuous soil.

Soil of the paper's foundation example (c_p 42, c_s 20 m/s, rho 1800 kg/m^3), a 1 m x 1 m block
(B = 0.5 m) on a 2 m x 2 m surface of 0.5 m elements, dt = 12.5 ms (beta = 0.5), 1 s."""
import numpy as np

from helpers import run_bem, run_ssi
from petsc_ssi.bem.impedance import rigid_fit, spectrum, step_spectrum
import pytest

pytestmark = pytest.mark.run

CP, CS, RHO, B = 42.0, 20.0, 1800.0, 0.5
DT, T_END, RISE, AMP = 0.0125, 1.0, 0.05, 1e-6
BASE = dict(cp=CP, cs=CS, rho=RHO, mesh_size="2,2", mesh_h=0.5, mesh_patch="0.5,0.5", dt=DT, t_end=T_END,
            output_stride=0, warn_beta=0, monitor=0)
BLOCK = dict(fem_box_cells="4,4,1", fem_box_size="1,1,0.25", fem_box_origin="-0.5,-0.5,0", fem_E=300e9,
             fem_rho=200, fem_load_history="smoothstep", fem_load_t0=RISE)
A0_MAX = 2.5          # omega dt = 1.56: well past the band the method trusts; both paths still agree


def prescribed(tmp, **motion):
    """Path 1: the resultants of a prescribed rigid motion of the region (AMP times the unit motion)."""
    return run_bem(**BASE, disp_group="load", disp_history="smoothstep", disp_t0=RISE,
                   output=str(tmp / "rigid.h5"), **motion)["resultants"]


def block(tmp, **load):
    """Path 2: the interface record of the stiff block under a smooth-step load."""
    res = run_ssi(**BASE, **BLOCK, output=str(tmp / "block.h5"), **load)["interface"]
    t, th, resid = rigid_fit(res["x"], res["uf"])
    return res, t, th, resid


def test_stiff_block_vertical_impedance_equals_prescribed_motion(tmp_path):
    r = prescribed(tmp_path, disp_value=f"0,0,{AMP}")
    om, K1 = spectrum(r["force"][:, 2] / AMP, r["h"], DT)
    res, t, th, resid = block(tmp_path, fem_load_group="top", fem_load_p0=1000)
    assert resid < 1e-4, resid                       # the block moves rigidly
    assert np.abs(th).max() < 1e-6 * np.abs(t[:, 2]).max()   # and only vertically (symmetric load)
    _, K2 = spectrum(res["force_be"][:, 2], t[:, 2], DT)
    a0 = om * B / CS
    m = a0 <= A0_MAX
    err = np.abs(K2[m] - K1[m]) / np.abs(K1[m])
    assert err.max() < 1e-4, err.max()
    # and it is a dynamic stiffness, not a constant: at a0 = 1.5 k has fallen and c is radiation
    i = int(np.argmin(np.abs(a0 - 1.5)))
    assert K1[i].real < 0.9 * K1[0].real and K1[i].imag > 0.5 * K1[0].real, K1[i] / K1[0]


def test_stiff_block_horizontal_and_rocking_obey_the_prescribed_impedance_matrix(tmp_path):
    """A horizontal load on the block's top moves it sideways and rocks it: its interface force
    F_x and moment M_y must be the 2 x 2 impedance matrix of path 1 (the horizontal and the
    rocking runs, each giving a direct and a coupling term) times the fitted u_x and theta_y."""
    rh = prescribed(tmp_path, disp_value=f"{AMP},0,0")
    rr = prescribed(tmp_path, disp_rotation=f"0,{AMP},0")
    om, Kxx = spectrum(rh["force"][:, 0] / AMP, rh["h"], DT)
    Kmx = spectrum(rh["moment"][:, 1] / AMP, rh["h"], DT)[1]
    Kxm = spectrum(rr["force"][:, 0] / AMP, rr["h"], DT)[1]
    Kmm = spectrum(rr["moment"][:, 1] / AMP, rr["h"], DT)[1]
    res, t, th, resid = block(tmp_path, fem_point_load="top,1000,0,0")
    assert resid < 1e-4, resid
    U, TH = step_spectrum(t[:, 0], DT)[1], step_spectrum(th[:, 1], DT)[1]
    F = step_spectrum(res["force_be"][:, 0], DT, traction=True)[1]
    M = step_spectrum(res["moment_be"][:, 1], DT, traction=True)[1]
    m = om * B / CS <= A0_MAX
    # the rocking is not negligible: the coupling terms carry a visible share of F and M
    assert np.abs(Kxm[m] * TH[m]).min() > 0.01 * np.abs(F[m]).max()
    assert np.abs(Kmm[m] * TH[m]).min() > 0.1 * np.abs(M[m]).max()
    eF = np.abs(F[m] - Kxx[m] * U[m] - Kxm[m] * TH[m]) / np.abs(F[m])
    eM = np.abs(M[m] - Kmx[m] * U[m] - Kmm[m] * TH[m]) / np.abs(M[m])
    assert eF.max() < 1e-4 and eM.max() < 1e-4, (eF.max(), eM.max())
    # without the coupling terms the prediction is visibly wrong: they matter
    assert (np.abs(F[m] - Kxx[m] * U[m]) / np.abs(F[m])).max() > 100 * eF.max()


def test_rigid_fit_recovers_a_rigid_motion():
    rng = np.random.default_rng(3)
    x = rng.uniform(-1, 1, (20, 3))
    tr, th = np.array([1e-3, -2e-3, 5e-4]), np.array([2e-4, -1e-4, 3e-4])
    xr = np.array([0.1, 0.2, -0.3])
    u = tr + np.cross(th, x - xr)
    t2, th2, resid = rigid_fit(x, np.stack([u, 2 * u]), x_ref=xr)
    assert np.allclose(t2[0], tr, rtol=0, atol=1e-15) and np.allclose(th2[1], 2 * th, rtol=0, atol=1e-15)
    assert resid < 1e-12
    u[3, 2] += 1e-4                                   # a non-rigid part shows in the residual
    assert rigid_fit(x, u, x_ref=xr)[2] > 1e-2
