"""Green's-function integrator (paper eqs. 13-24) against Newmark, identities at round-off."""
import numpy as np
import pytest

from fem_helpers import small_system, dense, newmark_dense, chain_mats, vec_from
from petsc_ssi.petsc import SSIError
from petsc_ssi.fem.integrators import GreenIntegrator, NewmarkIntegrator, green_constants
from petsc_ssi.fem.loads import fixed_dofs
from petsc_ssi.fem.mesh import structured_box
from petsc_ssi.fem.static import static_solve

pytestmark = pytest.mark.unit

RTOL = 1e-10    # "to round-off" for ~30-step recurrences on ~100 dofs


def block_model():
    """A 3 x 2 x 2 brick block (1 x 0.6 x 0.4 m) with its base fixed."""
    mesh = structured_box((3, 2, 2), (1.0, 0.6, 0.4), (0, 0, 0))
    K, m, layout = small_system(mesh, E=1e6, nu=0.25, rho=1e3)
    fixed = fixed_dofs(mesh, "base")
    free = np.setdiff1d(np.arange(3 * mesh.n_nodes), fixed)
    return mesh, K, m, fixed, free


def initial_state(mesh, free, seed=3):
    rng = np.random.default_rng(seed)
    u0 = np.zeros(3 * mesh.n_nodes)
    v0 = np.zeros(3 * mesh.n_nodes)
    u0[free] = 1e-3 * rng.standard_normal(free.size)
    v0[free] = 1e-2 * rng.standard_normal(free.size)
    return u0, v0


def test_trapezoidal_constants():
    """alpha = 1/4, delta = 1/2: b1 = 4/dt, b2 = -1, b6 = -4/dt, b7 = 2/dt (closed forms)."""
    dt, am = 1e-3, 7.0
    b = green_constants(dt, am)
    exact = dict(b0=am - 4 / dt, b1=4 / dt, b2=-1.0, b3=8 / dt ** 2, b4=4 * am / dt + 8 / dt ** 2,
                 b5=8 * am / dt ** 2 + 16 / dt ** 3, b6=-4 / dt, b7=2 / dt)
    for k, v in exact.items():
        assert b[k] == pytest.approx(v, rel=1e-13), k


@pytest.mark.parametrize("alpha_m", [0.0, 3.0])
def test_general_constants_are_superposed_newmark_green_functions(PETSc, alpha_m):
    """delta^2 = alpha = 0.36: one step of eqs. 13-14 == [dG M + G C] u + G M v with G, dG, ddG
    each computed by ONE textbook Newmark step from (0, M^{-1}) (the paper's definition), 1e-10."""
    alpha, delta, dt = 0.36, 0.6, 0.05
    rng = np.random.default_rng(0)
    B = rng.standard_normal((4, 4))
    Kd = B @ B.T + 4 * np.eye(4)
    md = np.array([1.0, 2.0, 0.5, 1.5])
    M, C = np.diag(md), alpha_m * np.diag(md)
    n = len(md)
    G, dG, ddG = np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n))
    for j in range(n):
        us, vs = newmark_dense(Kd, M, C, np.zeros(n), np.eye(n)[j] / md[j], dt, 1, alpha=alpha, delta=delta)
        G[:, j], dG[:, j] = us[1], vs[1]
        a0 = -alpha_m * np.eye(n)[j] / md[j]
        ddG[:, j] = (us[1] - dt * vs[0]) / (alpha * dt ** 2) - (1 / (2 * alpha) - 1) * a0
    u0, v0 = rng.standard_normal(n), rng.standard_normal(n)
    u1 = (dG @ M + G @ C) @ u0 + G @ M @ v0
    v1 = (ddG @ M + dG @ C) @ u0 + dG @ M @ v0
    K, m = chain_mats(Kd, md)
    integ = GreenIntegrator(K, m, dt, alpha_m, alpha=alpha, delta=delta, prefix="tgen_")
    integ.start(vec_from(u0, m), vec_from(v0, m))
    integ.step()
    assert np.abs(integ.u.getArray() - u1).max() <= RTOL * np.abs(u1).max()
    assert np.abs(integ.velocity().getArray() - v1).max() <= RTOL * np.abs(v1).max()


@pytest.mark.parametrize("alpha_m", [0.0, 40.0])
def test_free_vibration_reproduces_newmark(PETSc, alpha_m):
    """f = 0 from (u0, v0): Green (eqs. 13-14) == trapezoidal Newmark recurrence, 1e-10 relative,
    every step, displacement and velocity; PETSc Newmark integrator too."""
    mesh, K, m, fixed, free = block_model()
    u0, v0 = initial_state(mesh, free)
    dt, nsteps = 2e-3, 30
    Kd, md = dense(K), m.getArray().copy()
    F = np.ix_(free, free)
    us, vs = newmark_dense(Kd[F], np.diag(md[free]), alpha_m * np.diag(md[free]), u0[free], v0[free],
                           dt, nsteps)
    for cls in (GreenIntegrator, NewmarkIntegrator):
        integ = cls(K, m, dt, alpha_m, fixed, prefix="tfree_")
        integ.start(vec_from(u0, m), vec_from(v0, m))
        for n in range(1, nsteps + 1):
            integ.step()
            u, v = integ.u.getArray(), integ.velocity().getArray()
            assert np.abs(u[free] - us[n]).max() <= RTOL * np.abs(us).max(), (cls.__name__, n)
            assert np.abs(v[free] - vs[n]).max() <= RTOL * np.abs(vs).max(), (cls.__name__, n)
            assert np.all(u[fixed] == 0) and np.all(v[fixed] == 0)
        integ.destroy()


@pytest.mark.parametrize("alpha, delta", [(0.25, 0.5), (0.3025, 0.6)])
def test_forced_newmark_matches_textbook(PETSc, alpha, delta):
    """NewmarkIntegrator with loads == dense textbook Newmark with the same load samples (1e-10),
    trapezoidal and a dissipative (alpha, delta)."""
    mesh, K, m, fixed, free = block_model()
    dt, nsteps, am = 2e-3, 25, 10.0
    rng = np.random.default_rng(5)
    Fs = np.zeros(3 * mesh.n_nodes)
    Fs[free] = rng.standard_normal(free.size)
    h = lambda n: np.sin(0.3 * n) + 0.5          # noqa: E731
    Kd, md = dense(K), m.getArray().copy()
    F = np.ix_(free, free)
    us, _ = newmark_dense(Kd[F], np.diag(md[free]), am * np.diag(md[free]), np.zeros(free.size),
                          np.zeros(free.size), dt, nsteps, f=lambda n: h(n) * Fs[free], alpha=alpha, delta=delta)
    integ = NewmarkIntegrator(K, m, dt, am, fixed, alpha=alpha, delta=delta, prefix="tforced_")
    integ.start(f0=vec_from(h(0) * Fs, m))
    for n in range(1, nsteps + 1):
        integ.step(vec_from(h(n) * Fs, m))
        assert np.abs(integ.u.getArray()[free] - us[n]).max() <= RTOL * np.abs(us).max()


def free_load(mesh, free, seed, scale=1.0):
    f = np.zeros(3 * mesh.n_nodes)
    f[free] = scale * np.random.default_rng(seed).standard_normal(free.size)
    return f


def diff(a, b):
    return b.getArray() - a.getArray()


def test_load_is_an_impulse_at_tn(PETSc):
    """From a non-zero state under a background load g, two runs that differ only in the load f of
    step k: u^k is bitwise the same (predict() never sees f^k); v^k differs by M^{-1} f dt, velocity()
    by half of it (1e-12), and u^{k+1} by G(dt) f dt = b1 dt D^{-1} f (eq. 13; 1e-9 of its size,
    a difference of two ~1e3 times larger states)."""
    mesh, K, m, fixed, free = block_model()
    u0, v0 = initial_state(mesh, free)
    dt, am, k = 1e-3, 5.0, 3
    g = vec_from(free_load(mesh, free, 11), m)
    f = np.zeros(3 * mesh.n_nodes)
    f[free[-3:]] = [1.0, -2.0, 3.0]
    a, b = (GreenIntegrator(K, m, dt, am, fixed, prefix="timp_") for _ in range(2))
    for integ in (a, b):
        integ.start(vec_from(u0, m), vec_from(v0, m), f0=g)
        for n in range(1, k):
            integ.step(g)
        integ.predict()
    assert a.u.norm() > 0 and np.array_equal(a.u.getArray(), b.u.getArray())
    a.correct(g)
    b.correct(vec_from(g.getArray() + f, m))
    mf = m.getArray()
    jump = np.where(f != 0, f / np.where(mf > 0, mf, 1) * dt, 0)
    assert np.abs(diff(a.v, b.v) - jump).max() <= 1e-12 * np.abs(jump).max()
    assert np.abs(diff(a.velocity(), b.velocity()) - 0.5 * jump).max() <= 1e-12 * np.abs(jump).max()
    for integ in (a, b):
        integ.step(g)
    x = a.u.duplicate()
    a.ksp.solve(vec_from(f, m), x)
    ref = green_constants(dt, am)["b1"] * dt * x.getArray()
    assert np.abs(diff(a.u, b.u) - ref).max() <= 1e-9 * np.abs(ref).max()
    assert np.abs(ref).max() < 1e-2 * np.abs(a.u.getArray()).max()      # the states are much larger


def test_predict_ignores_the_load_of_step_n(PETSc):
    """Random loads through both arguments of correct(f, f_interface); a second run perturbs only the
    interface force of step k. Every predict() up to step k gives bitwise the same u^n, the first
    prediction after it differs; and correct(f, f_interface) == correct(f + f_interface) bit for bit
    (both round f + f_interface once into one Vec before M^{-1}, _masked_minv; observed equal, the
    former tolerance was 1e-13)."""
    mesh, K, m, fixed, free = block_model()
    u0, v0 = initial_state(mesh, free)
    nsteps, k = 8, 5
    fa = [vec_from(free_load(mesh, free, 20 + n), m) for n in range(nsteps + 1)]
    fb = [vec_from(free_load(mesh, free, 40 + n, 0.5), m) for n in range(nsteps + 1)]
    fb_pert = [v.copy() for v in fb]
    fb_pert[k].axpy(1.0, vec_from(free_load(mesh, free, 99), m))
    runs = {}
    for key, fint in (("ref", fb), ("pert", fb_pert)):
        integ = GreenIntegrator(K, m, 1e-3, 2.0, fixed, prefix="tsplit_")
        integ.start(vec_from(u0, m), vec_from(v0, m))
        us = []
        for n in range(1, nsteps + 1):
            us.append(integ.predict().getArray().copy())
            integ.correct(fa[n], f_interface=fint[n])
        runs[key] = (np.array(us), integ)
    (ua, a), (ub, b) = runs["ref"], runs["pert"]
    assert np.array_equal(ua[:k], ub[:k])                                  # u^1 .. u^k
    assert np.abs(ua[k] - ub[k]).max() > 1e-6 * np.abs(ua[k]).max()        # u^{k+1} sees it
    summed = GreenIntegrator(K, m, 1e-3, 2.0, fixed, prefix="tsplit_")
    summed.start(vec_from(u0, m), vec_from(v0, m))
    for n in range(1, nsteps + 1):
        summed.step(vec_from(fa[n].getArray() + fb[n].getArray(), m))
    for x, y in ((a.u, summed.u), (a.v, summed.v)):
        assert np.array_equal(x.getArray(), y.getArray())
    with pytest.raises(SSIError, match="without predict"):
        a.correct()
    a.predict()
    with pytest.raises(SSIError, match="predict\\(\\) called twice"):
        a.predict()


def test_velocity_between_predict_and_correct(PETSc):
    """velocity() raises while a prediction is pending (it would be off by M^{-1} f dt / 2);
    free_velocity() is v(t_n-) before and after correct(), and velocity() - free_velocity() is
    half the impulse after it (1e-14); at t = 0 both are v0 (before the initial half impulse)."""
    mesh, K, m, fixed, free = block_model()
    u0, v0 = initial_state(mesh, free)
    dt = 1e-3
    g = vec_from(free_load(mesh, free, 5), m)
    integ = GreenIntegrator(K, m, dt, 3.0, fixed, prefix="tvel_")
    integ.start(vec_from(u0, m), vec_from(v0, m), f0=g)
    for get in (integ.velocity, integ.free_velocity):
        assert np.abs(get().getArray() - v0).max() <= 1e-14 * np.abs(v0).max()
    integ.step(g)
    integ.predict()
    with pytest.raises(SSIError, match="velocity\\(\\) called between predict\\(\\) and correct\\(\\) "
                       "of step 2.*free_velocity"):
        integ.velocity()
    vfree = integ.free_velocity().getArray().copy()
    assert np.array_equal(vfree, integ.v.getArray())
    integ.correct(g)
    half = 0.5 * dt * np.where(np.isin(np.arange(len(v0)), fixed), 0, g.getArray() / m.getArray())
    assert np.abs(integ.free_velocity().getArray() - vfree).max() <= 1e-14 * np.abs(vfree).max()
    assert np.abs(integ.velocity().getArray() - vfree - half).max() <= 1e-14 * np.abs(vfree).max()


def test_load_on_fixed_dofs_warns_once(PETSc, capfd):
    """A load with entries on fixed dofs: rank 0 warns once (not every step), u = v = 0 stays exact
    there; the static solve warns too. Loads on free dofs only: no warning."""
    mesh, K, m, fixed, free = block_model()
    f = free_load(mesh, free, 8)
    f[fixed[:2]] = 5.0
    integ = GreenIntegrator(K, m, 1e-3, 0.0, fixed, prefix="tfixw_")
    integ.start()
    for _ in range(4):
        integ.step(vec_from(f, m))
    out = capfd.readouterr().out
    assert out.count("petsc-ssi: warning: a load acts on 2 fixed dof(s) at step 1") == 1, out
    assert out.count("a load acts on") == 1, out
    assert np.all(integ.u.getArray()[fixed] == 0) and np.all(integ.velocity().getArray()[fixed] == 0)
    static_solve(K, vec_from(f, m), fixed, mesh.coords, prefix="tstat_")
    assert "a load acts on 2 fixed dof(s) in the static solve" in capfd.readouterr().out
    quiet = NewmarkIntegrator(K, m, 1e-3, 0.0, fixed, prefix="tfixw_")
    quiet.start(f0=vec_from(free_load(mesh, free, 8), m))
    quiet.step(vec_from(free_load(mesh, free, 8), m))
    assert quiet.fixed_load_warning is None and "warning" not in capfd.readouterr().out


@pytest.mark.parametrize("value, word", [(0.0, r"\(0 negative\)"), (-1.0, r"\(3 negative\)")])
def test_singular_D_is_refused(PETSc, value, word):
    """Zero or negative lumped mass on an unconstrained structure: one-line SSIError before factorising."""
    mesh = structured_box((2, 1, 1))
    K, m, _ = small_system(mesh)
    m.getArray()[:3] = value
    with pytest.raises(SSIError, match="lumped mass is <= 0 at 3 free dof.*" + word):
        GreenIntegrator(K, m, 1e-3, prefix="tsing_")


def test_unconstrained_static_is_refused(PETSc):
    mesh = structured_box((2, 1, 1))
    K, m, _ = small_system(mesh)
    with pytest.raises(SSIError, match="K is singular"):
        static_solve(K, m.copy(), fixed_dofs(mesh, ""), mesh.coords, prefix="tstat_")
    with pytest.raises(SSIError, match="K is singular"):     # one line of nodes fixed: rotation remains
        line = np.nonzero((mesh.coords[:, 0] == 0) & (mesh.coords[:, 2] == 0))[0]
        static_solve(K, m.copy(), np.sort((3 * line[:, None] + np.arange(3)).ravel()), mesh.coords,
                     prefix="tstat_")


def test_alpha_m_from_damping_ratio():
    """-ssi_fem_damping_ratio 0.02 at 3.09 Hz gives alpha_m = 2 zeta omega = 0.7766 1/s (1e-12)."""
    from types import SimpleNamespace
    from petsc_ssi.fem.options import alpha_m
    am, note = alpha_m(SimpleNamespace(fem_damping_ratio=0.02, fem_damping_freq=3.09, fem_alpha_m=0.0))
    assert am == pytest.approx(2 * 0.02 * 2 * np.pi * 3.09, rel=1e-12) and "2 zeta omega" in note
    assert alpha_m(SimpleNamespace(fem_damping_ratio=0.0, fem_damping_freq=0.0, fem_alpha_m=0.68))[0] == 0.68


def test_receiver_snapping_distance():
    """A receiver between nodes snaps to the nearest node; the distance is reported exactly."""
    from petsc_ssi.fem.mesh import snap_points
    mesh = structured_box((2, 2, 1), (1.0, 1.0, 0.5), (0, 0, 0))
    nodes, dist = snap_points(mesh, [[0.3, 0.5, 0.5], [1.0, 1.0, 0.0]])
    assert np.allclose(mesh.coords[nodes], [[0.5, 0.5, 0.5], [1.0, 1.0, 0.0]])
    assert dist == pytest.approx([0.2, 0.0], abs=1e-15)


def test_newmark_with_loads_is_the_shifted_impulse_recurrence(PETSc):
    """Identity of the module docstring: for trapezoidal Newmark with loads, z^n = y^n - P J f^n obeys
    z^n = R z^{n-1} + dt (I - dt/2 A)^{-2} J f^{n-1} (P = (I - dt/2 A)^{-1} dt/2), to 1e-10."""
    Kd = np.array([[30.0, -20.0, 0.0], [-20.0, 35.0, -15.0], [0.0, -15.0, 15.0]])
    md, am, dt = np.array([1.0, 2.0, 1.5]), 0.3, 0.05
    n = 3
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Kd / md[:, None], -am * np.eye(n)]])
    L = np.eye(2 * n) - dt / 2 * A
    R = np.linalg.solve(L, np.eye(2 * n) + dt / 2 * A)
    P = np.linalg.solve(L, np.eye(2 * n)) * dt / 2
    Q = dt * np.linalg.matrix_power(np.linalg.inv(L), 2)
    K, m = chain_mats(Kd, md)
    f = np.random.default_rng(2).standard_normal((21, n))
    Jf = np.hstack([np.zeros_like(f), f / md])
    integ = NewmarkIntegrator(K, m, dt, am, prefix="tshift_")
    integ.start(f0=vec_from(f[0], m))
    y = [np.zeros(2 * n)]
    for k in range(1, 21):
        integ.step(vec_from(f[k], m))
        y.append(np.concatenate([integ.u.getArray(), integ.velocity().getArray()]))
    z = [yk - P @ jk for yk, jk in zip(y, Jf)]
    for k in range(1, 21):
        r = z[k] - R @ z[k - 1] - Q @ Jf[k - 1]
        assert np.abs(r).max() <= 1e-10 * np.abs(z[k]).max(), k
