r"""Reciprocity (Haskind) for a blocked footing under an oblique wave (issue 27, 'Reciprocity').

State A: the footing (the -ssi_disp_group region) blocked, total motion 0 under the wave: the BEM's
scattered displacement on the region is u_sc = -u_ff (-ssi_seismic with a prescribed rigid motion
0). State B_k: the footing given a unit rigid step in mode k (-ssi_disp_value / -ssi_disp_rotation,
-ssi_disp_history heaviside), no wave. Both radiate from rest and both have zero traction on the
free surface (t_ff = 0 there), so Betti's theorem on the soil gives, mode by mode,

    F_k^A(t) = - int_S t^(k) * u_ff dA        (* : convolution in time; t^(k): traction per unit
                                                 rigid impulse of mode k; F_k: force or moment)

Discrete statement. The march is linear and time-invariant in the step index: the region's traction
of step n is p^n = sum_{m=1..n} Z_{n-m} u^m for prescribed nodal displacements u^m (Z_j: 3n x 3n
matrices). The step response of B_k is s^n = sum_{m<=n} Z_{n-m} rho_k (rho_k: the mode's nodal
values), so Z_j rho_k = s^{j+1} - s^j (s^0 = 0). The resultant of A is F_k^n = rho_k^T M p_A^n with
M the region's consistent mass matrix int N_i N_j dA (the resultant operator of bem/resultants.py is
exactly M rho_k: x is interpolated exactly on flat elements). Hence

    F_k^n = - sum_m rho_k^T M Z_{n-m} u_ff^m,   and reciprocity's right-hand side is
    H_k^n = - sum_m (Z_{n-m} rho_k)^T M u_ff^m = - sum_m (s^{n-m+1} - s^{n-m})^T M u_ff^m,

equal exactly when M Z_j is symmetric. The continuous operator is (Betti); the collocation BEM's
is not, and F - H is exactly that asymmetry applied to u_ff. With a symmetry plane both sides are
the modelled half's times the number of images (the fields are symmetric, the product is even).

Measured (SH at 60 degrees along x, T = 0.1 s pulse, c_s 20 m/s, 1 m footing, y=anti; max |F - H| /
max |F|):
    0.5 m elements, dt 6 ms:   F_y 0.0021, M_z 0.0047, M_x 0.39
    0.25 m elements, dt 3 ms:  F_y 0.00045, M_z 0.0014, M_x 0.36
and P at 30 degrees (y=sym) on the 0.5 m mesh: F_x 0.0071, F_z 0.0015, M_y 0.43. The direct terms
(the translation along the wave's motion, torsion, the vertical force) hold to under 1 % and fall
with the mesh (4.7x and 3.4x for F_y and M_z from 0.5 to 0.25 m). The rocking moments M_x (SH)
and M_y (P) are small (M / (F B) ~ 0.05) and dominated by the horizontal-rocking coupling, whose
reciprocity the collocation BEM is known to miss by tens of percent at these meshes (K_hr / K_rh -
1 = 0.5 with one element per half-width, 0.16 with four: runs/impedance/README.md); they are held
to 0.5 here, which is that known defect, not a tolerance of the input-motion method.
"""
import numpy as np

from helpers import petsc
import pytest

pytestmark = pytest.mark.run

CP, CS, RHO = 42.0, 20.0, 1800.0


def pulse(path, T):
    t = np.arange(0.0, 2 * T + 1e-9, T / 80)
    a = np.where(t < T, np.sin(np.pi * t / T) ** 4, 0.0) - np.where(t >= T, np.sin(np.pi * (t - T) / T) ** 4, 0.0)
    np.savetxt(path, np.c_[t, a], header="units: m/s2")
    return str(path)


def run(opts):
    """(problem, p (K, 3 n_t) the traction of every step, results) of a BEM run in this process."""
    PETSc = petsc()
    import petsc_ssi.app.kinds  # noqa: F401
    from petsc_ssi.app.kinds import resolve
    from petsc_ssi.bem.problem import BEMTransient
    db = PETSc.Options()
    opts = dict(opts, output_overwrite=1)
    for k, v in opts.items():
        db.setValue("ssi_" + k, str(v))
    try:
        pr = BEMTransient(resolve("bem"))
        pr.setup()
        pr.start()
        ps = [pr.step(n)[1].getArray().copy() for n in range(1, pr.n_steps + 1)]
        return pr, np.array(ps), pr.finish()
    finally:
        for k in opts:
            db.delValue("ssi_" + k)


def mass_matrix(prob):
    """M_ij = int N_i N_j dA over the region's (modelled) elements, its nodes in the traction order."""
    from petsc_ssi.mesh import quad9
    mesh, reg = prob.mesh, prob.regions
    g, w = np.polynomial.legendre.leggauss(6)
    xi, eta = (a.ravel() for a in np.meshgrid(g, g, indexing="ij"))
    X = mesh.cell_coords()[reg.disp_elems]
    _, jn = quad9.geometry(X, xi, eta)
    J = np.linalg.norm(jn, axis=-1) * np.outer(w, w).ravel()
    N = quad9.shape(xi, eta)
    lut = -np.ones(mesh.n_nodes, np.int64)
    lut[reg.disp_nodes] = np.arange(reg.n_disp)
    M = np.zeros((reg.n_disp, reg.n_disp))
    for e, el in enumerate(reg.disp_elems):
        loc = lut[mesh.cells[el]]
        M[np.ix_(loc, loc)] += np.einsum("p,pa,pb->ab", J[e], N, N)
    return M


MODES = {0: ("disp_value", "1,0,0"), 1: ("disp_value", "0,1,0"), 2: ("disp_value", "0,0,1"),
         3: ("disp_rotation", "1,0,0"), 4: ("disp_rotation", "0,1,0"), 5: ("disp_rotation", "0,0,1")}


def haskind(tmp_path, wave, angle, sym, modes, h, dt, T=0.1, t_end=0.3):
    """{mode: max |F - H| / max |F|} of the blocked footing (module docstring)."""
    rec = pulse(tmp_path / "p.txt", T)
    common = dict(cp=CP, cs=CS, rho=RHO, mesh_size="2,2", mesh_h=h, mesh_patch="0.5,0.5",
                  disp_group="box:-0.5,0.5,-0.5,0.5", dt=dt, t_end=t_end, symmetry=sym, output_stride=0,
                  output=str(tmp_path / "h.h5"))
    pa, _, ra = run(dict(common, seismic=wave, seismic_angle=angle, seismic_record=rec, seismic_units="m/s2",
                         seismic_taper=0, seismic_baseline="none"))
    prob = pa.prob
    K = len(ra["t"])
    uff = np.array([prob.free_field_at(prob.regions.disp_nodes, prob.grid.time(n)).reshape(-1, 3)
                    for n in range(1, K + 1)])
    Mu = np.einsum("ij,mjc->mic", mass_matrix(prob), uff)            # M u_ff^m, m = 1..K
    nimg = 2 ** len(prob.planes)
    F = np.c_[ra["resultants"]["force"], ra["resultants"]["moment"]]
    assert prob.regions.n_load == 0
    out = {}
    for k in modes:
        opt, val = MODES[k]
        _, ps, _ = run(dict(common, **{opt: val}))
        s = ps.reshape(K, -1, 3)                                       # s^n, n = 1..K [Pa per unit motion]
        Z = np.diff(np.concatenate([np.zeros((1,) + s.shape[1:]), s]), axis=0)    # Z_j rho_k, j = 0..K-1
        # H^n = -n_img sum_{m=1..n} (Z_{n-m} rho_k)^T M u_ff^m  (0-based: sum_{m<=n} Z[n - m] . Mu[m])
        H = -nimg * np.array([np.einsum("mic,mic->", Z[n::-1], Mu[:n + 1]) for n in range(K)])
        assert np.abs(F[:, k]).max() > 0
        out[k] = float(np.abs(F[:, k] - H).max() / np.abs(F[:, k]).max())
    return out


def test_haskind_blocked_footing_oblique_sh(tmp_path):
    err = haskind(tmp_path, "sh", 60, "y=anti", (1, 3, 5), 0.5, 0.006)
    assert err[1] < 0.005 and err[5] < 0.01, err       # F_y, M_z (measured 0.0021, 0.0047)
    assert err[3] < 0.5, err                           # M_x: the coupling's asymmetry (0.39)


def test_haskind_blocked_footing_oblique_p(tmp_path):
    err = haskind(tmp_path, "p", 30, "y=sym", (0, 2, 4), 0.5, 0.006)
    assert err[0] < 0.015 and err[2] < 0.005, err      # F_x, F_z (measured 0.0071, 0.0015)
    assert err[4] < 0.5, err                           # M_y: the coupling's asymmetry (0.43)


def test_haskind_error_falls_with_the_mesh(tmp_path):
    """F_y and M_z of the SH case on 0.5 m and 0.25 m elements (dt halved with h, beta kept): the
    reciprocity error falls by more than 2 (measured 4.7 and 3.4)."""
    coarse = haskind(tmp_path, "sh", 60, "y=anti", (1, 5), 0.5, 0.006)
    fine = haskind(tmp_path, "sh", 60, "y=anti", (1, 5), 0.25, 0.003)
    for k in (1, 5):
        assert fine[k] < coarse[k] / 2, (coarse, fine)
    assert fine[1] < 0.001 and fine[5] < 0.003, fine
