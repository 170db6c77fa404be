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
max |F|; L the side of the meshed surface; runs/seismic/haskind_rocking.py):
    L = 2 m, 0.5 m elements, dt 6 ms:     F_y 0.0021,  M_z 0.0047, M_x 0.39
    L = 2 m, 0.25 m elements, dt 3 ms:    F_y 0.00045, M_z 0.0014, M_x 0.36
    L = 2 m, 0.125 m elements, dt 1.5 ms: F_y 0.0001,  M_z 0.0003, M_x 0.34   (3 GB)
    L = 3, 4, 6 m, 0.5 m elements:        M_x 0.21, 0.026, 0.033 (F_y, M_z as on 2 m)
    L = 4 m, 0.25 m elements:             M_x 0.019
and P at 30 degrees (y=sym), 0.5 m elements: F_x 0.0071, F_z 0.0015, M_y 0.43 on L = 2 m; M_y 0.13
on 4 m, 0.028 on 6 m (F_x 0.0008). The direct terms (the translation along the wave's motion,
torsion, the vertical force) hold to under 1 % on every surface and fall with the mesh (4.7x and
3.4x for F_y and M_z from 0.5 to 0.25 m).

Why the rocking moments missed by 36-43 % (issue 46; haskind_parts): not the relation (Betti's
theorem pairs the moment about x_ref with the rotation about the same x_ref, the test's rho_k; the
run's moment resultant and the prescribed rotation both use x_ref = the origin, the footing's
centre on the surface; the sign is the direct terms'), not the free field's rotation and not the
rocking impedance. Split u_ff on the footing into its rigid part (q_j: the mean translation and
rotations, M-orthogonal projection) and the rest: F - H is the asymmetry K_kj - K_jk of the
impedance runs' own rigid-mode block times q_j, plus the asymmetry of M Z acting on the free
field's deformation over the footing. K_kk cancels, so the rocking impedance cannot enter; the
horizontal-rocking coupling's asymmetry (K_{rx,uy} vs K_{uy,rx}, the transient K_hr vs K_rh)
carries the whole miss (0.400 of M_x's 0.395, 0.432 of M_y's 0.432 on L = 2 m); the rest is 0.15-0.5
%. M_x under SH is all coupling (the free surface does not turn about x: q_rx = 0), so its miss is
the coupling's relative asymmetry; M_y under P is the difference of its rotation's direct term
(1.21 max |M_y|) and the coupling (1.06), which magnifies the same asymmetry that costs F_x 0.7 %.
And that asymmetry is the meshed surface's truncation, not the element size: the surface ended
0.5 m beyond the footing (L = 2 m). The BEM drops the free surface beyond the mesh (Stokes kernels:
its displacement there is not represented), which is not a reciprocal approximation, and the
coupling terms, small against the direct ones, feel it most (K_hr, the moment under a horizontal
motion, most: max |F| of M_x is 553, 474, 422, 420 N m on L = 2, 3, 4, 6 m, H 376, 421, 420, 406).
On a 4 m surface the SH rocking moment holds to 2.6 % and falls with the mesh (1.9 % at 0.25 m);
on 2 m the element size hardly moves it (0.39, 0.36, 0.34 from 0.5 to 0.125 m).
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


def rigid_modes(x, modes):
    """{k: rho_k (n, 3)}: the unit rigid motions of ``modes`` (MODES' numbering) at the nodes x,
    rotations about the origin (the runs' x_ref and moment reference)."""
    rho = {}
    for k in modes:
        r = np.zeros_like(x)
        if k < 3:
            r[:, k] = 1.0
        else:
            r = np.cross(np.eye(3)[k - 3], x)
        rho[k] = r
    return rho


def haskind_parts(tmp_path, wave, angle, sym, modes, h, dt, T=0.1, t_end=0.3, L=2.0):
    """{mode: {"total", "coupling", "rest"}}: max |F - H| / max |F| of the blocked footing (module
    docstring) and its two parts. With u_ff^m = sum_j rho_j q_j^m + r^m (q: the M-orthogonal
    projection on the rigid modes run, r the footing's deformation) and K_kj^i = rho_k^T M Z_i rho_j
    the impulse response of resultant k to rigid mode j (from the same impedance runs),

        F_k - H_k = - sum_j sum_m (K_kj - K_jk)^{n-m} q_j^m  -  sum_m rho_k^T (M Z - Z^T M)_{n-m} r^m:

    "coupling" is the first sum, the asymmetry of the impedance matrix itself (the horizontal-rocking
    coupling K_hr vs K_rh; K_kk cancels), "rest" the second, F - H less the first; "direct" and
    "cross" the peaks of F's rigid parts K_kk * q_k and sum_{j != k} K_kj * q_j over max |F|,
    "rotation" the peak of q_k of a rotation. ``modes`` must be all the rigid modes the symmetry
    allows, for the projection to be complete. L: the meshed surface's side [m] around the 1 m footing."""
    rec = pulse(tmp_path / "p.txt", T)
    common = dict(cp=CP, cs=CS, rho=RHO, mesh_size=f"{L:g},{L:g}", mesh_h=h, mesh_patch="0.5,0.5",
                  disp_group="box:-0.5,0.5,-0.5,0.5", dt=dt, t_end=t_end, symmetry=sym, output_stride=0,
                  output=str(tmp_path / "h.h5"))
    pa, _, ra = run(dict(common, seismic=wave, seismic_angle=angle, seismic_record=rec, seismic_units="m/s2",
                         seismic_taper=0, seismic_baseline="none"))
    prob = pa.prob
    K = len(ra["t"])
    uff = np.array([prob.free_field_at(prob.regions.disp_nodes, prob.grid.time(n)).reshape(-1, 3)
                    for n in range(1, K + 1)])
    M = mass_matrix(prob)
    Mu = np.einsum("ij,mjc->mic", M, uff)                             # M u_ff^m, m = 1..K
    nimg = 2 ** len(prob.planes)
    F = np.c_[ra["resultants"]["force"], ra["resultants"]["moment"]]
    assert prob.regions.n_load == 0
    rho = rigid_modes(prob.mesh.nodes[prob.regions.disp_nodes], modes)
    Mrho = {k: M @ rho[k] for k in modes}
    Z = {}
    for k in modes:
        opt, val = MODES[k]
        _, ps, _ = run(dict(common, **{opt: val}))
        s = ps.reshape(K, -1, 3)                                       # s^n, n = 1..K [Pa per unit motion]
        Z[k] = np.diff(np.concatenate([np.zeros((1,) + s.shape[1:]), s]), axis=0)    # Z_j rho_k, j = 0..K-1
    # K_kj^i = n_img rho_k^T M Z_i rho_j; q_j^m from (rho^T M rho) q = rho^T M u_ff^m
    Kimp = {(k, j): nimg * np.einsum("nic,ic->n", Z[j], Mrho[k]) for k in modes for j in modes}
    gram = np.array([[np.sum(rho[a] * Mrho[b]) for b in modes] for a in modes])
    q = dict(zip(modes, np.linalg.solve(gram, np.array([np.einsum("mic,ic->m", uff, Mrho[a]) for a in modes]))))

    def conv(a, b):                                                    # (a * b)^n = sum_{m<=n} a^{n-m} b^m
        return np.array([np.dot(a[n::-1], b[:n + 1]) for n in range(K)])

    out = {}
    for k in modes:
        # H^n = -n_img sum_{m=1..n} (Z_{n-m} rho_k)^T M u_ff^m  (0-based: sum_{m<=n} Z[n - m] . Mu[m])
        H = -nimg * np.array([np.einsum("mic,mic->", Z[k][n::-1], Mu[:n + 1]) for n in range(K)])
        coupling = -sum(conv(Kimp[k, j] - Kimp[j, k], q[j]) for j in modes)
        peak = np.abs(F[:, k]).max()
        assert peak > 0
        d = F[:, k] - H
        out[k] = {"total": float(np.abs(d).max() / peak), "F": float(peak), "H": float(np.abs(H).max()),
                  "coupling": float(np.abs(coupling).max() / peak),
                  "rest": float(np.abs(d - coupling).max() / peak),
                  "rotation": float(np.abs(q[k]).max()) if k >= 3 else None,
                  # F's rigid part by source: the mode's own motion (K_kk q_k), the others (K_kj q_j)
                  "direct": float(np.abs(conv(Kimp[k, k], q[k])).max() / peak),
                  "cross": float(np.abs(sum(conv(Kimp[k, j], q[j]) for j in modes if j != k)).max() / peak)}
    return out


def haskind(tmp_path, wave, angle, sym, modes, h, dt, T=0.1, t_end=0.3, L=2.0):
    """{mode: max |F - H| / max |F|} of the blocked footing (module docstring)."""
    return {k: v["total"] for k, v in haskind_parts(tmp_path, wave, angle, sym, modes, h, dt, T, t_end, L).items()}


def test_haskind_blocked_footing_oblique_sh(tmp_path):
    """On a 4 m surface every resultant holds, the rocking moment M_x to 2.6 % (on the 2 m surface of
    the other tests 39 %: the truncation, module docstring)."""
    parts = haskind_parts(tmp_path, "sh", 60, "y=anti", (1, 3, 5), 0.5, 0.006, L=4.0)
    err = {k: v["total"] for k, v in parts.items()}
    assert err[1] < 0.005 and err[5] < 0.01, err       # F_y, M_z (measured 0.0021, 0.0047)
    assert err[3] < 0.05, err                          # M_x (measured 0.026)
    # M_x is all coupling (the SH free surface does not turn about x: q_rx = 0); the asymmetry of the
    # impedance runs' K_{rx,uy} vs K_{uy,rx} carries its miss (0.0259), the rest is 0.0033
    assert parts[3]["rotation"] == 0.0 and parts[3]["direct"] == 0.0, parts
    assert parts[3]["rest"] < 0.01, parts


def test_haskind_blocked_footing_oblique_p(tmp_path):
    """The 2 m surface (0.5 m around the footing): the direct terms hold, M_y misses by 0.43, all of it
    the asymmetry of the impedance's horizontal-rocking coupling (the truncated surface's, module
    docstring); on a 6 m surface M_y holds to 2.8 % (the slow test below)."""
    parts = haskind_parts(tmp_path, "p", 30, "y=sym", (0, 2, 4), 0.5, 0.006)
    err = {k: v["total"] for k, v in parts.items()}
    assert err[0] < 0.015 and err[2] < 0.005, err      # F_x, F_z (measured 0.0071, 0.0015)
    assert err[4] < 0.5, err                           # M_y: the coupling's asymmetry (0.43)
    # the coupling's asymmetry carries M_y's miss (0.432 of 0.432) and F_x's (0.0074 of 0.0071);
    # the rest: M_y 0.0015, F_x 0.0002, F_z 0.0015 (no coupling)
    assert parts[4]["coupling"] > 0.3, parts
    assert parts[4]["rest"] < 0.005 and parts[0]["rest"] < 0.002 and parts[2]["rest"] < 0.005, parts
    assert parts[2]["coupling"] < 1e-12, parts


# slow tier: the P wave on a 6 m surface (50 s); test_haskind_blocked_footing_oblique_p is its
# default-tier sibling (the same wave on the 2 m surface)
@pytest.mark.slow
def test_haskind_oblique_p_on_a_larger_surface(tmp_path):
    """P at 30 degrees on a 6 m surface: the rocking moment M_y within 5 % (measured 0.028; 0.129 on a
    4 m surface, 0.43 on the 2 m one), F_x and F_z within 0.5 % (0.0008, 0.0003)."""
    err = haskind(tmp_path, "p", 30, "y=sym", (0, 2, 4), 0.5, 0.006, L=6.0)
    assert err[4] < 0.05 and err[0] < 0.005 and err[2] < 0.005, err


def test_haskind_error_falls_with_the_mesh(tmp_path):
    """F_y and M_z of the SH case on 0.5 m and 0.25 m elements (dt halved with h, beta kept): the
    reciprocity error falls by more than 2 (measured 4.7 and 3.4)."""
    coarse = haskind(tmp_path, "sh", 60, "y=anti", (1, 5), 0.5, 0.006)
    fine = haskind(tmp_path, "sh", 60, "y=anti", (1, 5), 0.25, 0.003)
    for k in (1, 5):
        assert fine[k] < coarse[k] / 2, (coarse, fine)
    assert fine[1] < 0.001 and fine[5] < 0.003, fine
