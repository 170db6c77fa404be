"""The time marching against a direct reference: the step equations
E_k = sum_{m<=k} (H_{k-m+1} u^m - G_{k-m+1} p^m) = 0 formed literally from
dense lag matrices, summed as E_{n+1} + 2E_n + E_{n-1} with the n+1 values
extrapolated (stabilised) or taken alone (plain), and solved for u^n. No
re-indexing by lag as in march.py: an independent path, agreement to 1e-10."""
import numpy as np
import pytest

from helpers import petsc, run_bem

pytestmark = pytest.mark.run


def _dense_lags(mesh_size, dt, L):
    PETSc = petsc()
    from petsc_ssi.mesh.surface import grid
    from petsc_ssi.bem.lagset import Material, Regions, LagSet
    mesh = grid(*mesh_size, 1.0, (1.0, 1.0))
    reg = Regions(mesh, load_elems=mesh.groups["load"])
    opts = {"gauss": 2, "singular_order": 12, "subdivisions": 4, "near_factor": 2.0,
            "max_subdivisions": 32, "cache": True}
    ls = LagSet(PETSc.COMM_SELF, mesh, Material(548.0, 316.0, 2000.0), dt, L, reg, [], opts)
    ls.assemble()
    N, nt = mesh.n_nodes, reg.n_t
    H = np.zeros((L + 1, 3 * N, 3 * N)); G = np.zeros((L + 1, 3 * N, 3 * nt))
    for l in range(1, L + 1):
        for B, M in ((ls.H, H), (ls.G, G)):
            r, c, v = B.peek(l)
            for rr, cc, vv in zip(r, c, v):
                M[l, 3 * rr:3 * rr + 3, 3 * cc:3 * cc + 3] += vv
    return mesh, reg, H, G


@pytest.mark.parametrize("scheme", ["plain", "stabilized"])
def test_marching_equals_literal_step_equations(tmp_path, scheme):
    dt, steps = 7.5e-4, 12
    L = steps + 1
    mesh, reg, H, G = _dense_lags((4.0, 4.0), dt, L)
    p0 = np.tile([0.0, 0.0, -1000.0], reg.n_t)       # Heaviside load: p^m = p0 for m >= 1
    Hl = lambda l: H[l] if 1 <= l <= L else 0.0 * H[1]
    Gl = lambda l: G[l] if 1 <= l <= L else 0.0 * G[1]
    u = {m: np.zeros(3 * mesh.n_nodes) for m in range(-1, 1)}
    p = lambda m: p0 if m >= 1 else 0.0 * p0

    def E(k, uu, pp):
        return sum(Hl(k - m + 1) @ uu(m) - Gl(k - m + 1) @ pp(m) for m in range(1, k + 1))

    for n in range(1, steps + 1):
        if scheme == "plain":
            A = H[1]
            uu = lambda m, x: u[m] if m < n else x
            b = E(n, lambda m: uu(m, 0 * p0[:1].repeat(3 * mesh.n_nodes)), p)
        else:
            A = 4 * H[1] + H[2]
            zero = np.zeros(3 * mesh.n_nodes)
            ext_u = lambda x: lambda m: (2 * x - u[n - 1]) if m == n + 1 else (x if m == n else u[m])
            ext_p = lambda m: (2 * p(n) - p(n - 1)) if m == n + 1 else p(m)
            b = E(n + 1, ext_u(zero), ext_p) + 2 * E(n, ext_u(zero), ext_p) + \
                (E(n - 1, ext_u(zero), ext_p) if n >= 2 else 0.0)
        u[n] = np.linalg.solve(A, -b)
    res = run_bem(mesh_size="4,4", mesh_h=1.0, mesh_patch="1,1", load_group="load", load_p0=1000,
                  dt=dt, t_end=steps * dt, scheme=scheme, receivers="0,0,0;1.5,0.5,0;-2,2,0",
                  output_stride=steps, output=tmp_path / "m.h5")
    import h5py
    with h5py.File(tmp_path / "m.h5") as f:
        assert not np.any(f["displacement_000000"][:])      # t = 0, at rest
        last = f["displacement_000001"][:].ravel()          # step 12
    assert np.abs(u[steps]).max() > 0
    assert np.abs(last - u[steps]).max() <= 1e-10 * np.abs(u[steps]).max()
