"""Lag-matrix interpolation (issue 3): exactness of the weights, fall-back,
and accuracy on a reduced Lamb case against the non-interpolated run.

Error definition: relative L2 error over the run of each displacement
component at each receiver, interpolated vs non-interpolated run."""
import numpy as np
import pytest

from helpers import run_bem
from petsc_ssi.bem import interp

pytestmark = pytest.mark.run


@pytest.mark.parametrize("k", [2, 3, 5, 8])
def test_chebyshev_reproduces_polynomials_of_degree_k_minus_1(k):
    """sum_j I(l, j) M(T_j) = M(tau_l) for a matrix history of degree k-1 (1e-12)."""
    rng = np.random.default_rng(k)
    TL, TN = 0.01, 0.05
    T = interp.nodes("chebyshev", TL, TN, k)
    assert np.all((T > TL) & (T < TN))
    tau = np.linspace(TL, TN, 37)
    A = rng.normal(size=(k, 3, 3))                       # M(t) = sum_d A_d ((t-TL)/(TN-TL))^d
    M = lambda t: np.einsum("d,dij->ij", ((t - TL) / (TN - TL)) ** np.arange(k), A)
    W = interp.weights("chebyshev", T, tau)
    approx = np.einsum("lj,jab->lab", W, np.array([M(t) for t in T]))
    exact = np.array([M(t) for t in tau])
    assert np.abs(approx - exact).max() <= 1e-12 * np.abs(exact).max()


@pytest.mark.parametrize("grading", [1.0, 2.0])
def test_multilinear_reproduces_linear_and_is_a_partition_of_unity(grading):
    TL, TN, k = 0.01, 0.05, 6
    T = interp.nodes("linear", TL, TN, k, grading)
    assert T[0] == TL and np.isclose(T[-1], TN) and np.all(np.diff(T) > 0)
    tau = np.linspace(TL, TN, 41)
    W = interp.weights("linear", T, tau)
    assert np.allclose(W.sum(1), 1.0, atol=1e-14) and W.min() >= 0
    assert np.abs(W @ (3.0 * T - 2.0) - (3.0 * tau - 2.0)).max() <= 1e-13
    assert np.count_nonzero(W, axis=1).max() <= 2


def test_plan_falls_back_to_exact_when_TL_beyond_TN():
    p = interp.Plan("chebyshev", 7.5e-4, 40, TL=1.0, k=5)
    assert not p.active and p.Lx == 40
    p = interp.Plan("chebyshev", 7.5e-4, 40, TL=0.01, k=5)
    assert p.active and p.Lx == 14 and p.W.shape == (26, 5)


CASE = dict(mesh_size="16,16", mesh_h=1.0, mesh_patch="1,1", load_group="load", load_p0=1000,
            symmetry="x=sym,y=sym", receivers="3,0,0;5,0,0", t_end=0.04, output_stride=0)


@pytest.fixture(scope="module")
def exact(tmp_path_factory):
    return run_bem(**CASE, output=tmp_path_factory.mktemp("i") / "exact.h5")


def _err(a, b):
    return max(np.linalg.norm(a["u"][:, k, c] - b["u"][:, k, c]) / np.linalg.norm(b["u"][:, k, c])
               for k in range(2) for c in (0, 2))


def test_none_equals_fallback_bit_for_bit(exact, tmp_path):
    """-ssi_interp none and an interpolation that falls back give the same bits."""
    fb = run_bem(**CASE, interp="chebyshev", interp_tl=1.0, interp_k=4, output=tmp_path / "fb.h5")
    assert np.array_equal(fb["u"], exact["u"])


def test_auto_above_rayleigh_accurate_and_early_threshold_worse(exact, tmp_path):
    """auto (tau_L = 1.5 at the farther receiver, Chebyshev, one exact matrix
    every 5 steps: k = 5 here): max error below 3% at both receivers (measured
    2.3%; paper Table 1: 0.2-1.3% on its case); more matrices over the same
    interval converge: k = 8 beats k = 5 and k = 12 is below 1% (measured
    1.1% and 0.2%); tau_L = 0.5 with k = 5 is at least 5x worse than auto
    (paper: 55-85%), and stores less."""
    a = run_bem(**CASE, interp="auto", output=tmp_path / "auto.h5")
    e_auto = _err(a, exact)
    assert a["stats"]["exact_lags"] < a["stats"]["lags"] and a["stats"]["interp_k"] == 5
    e_k = {k: _err(run_bem(**CASE, interp="chebyshev", interp_tl=1.5 * 5 / 316, interp_k=k,
                           output=tmp_path / f"k{k}.h5"), exact) for k in (8, 12)}
    early = run_bem(**CASE, interp="chebyshev", interp_tl=0.5 * 5 / 316, interp_k=5,
                    output=tmp_path / "early.h5")
    e_early = _err(early, exact)
    assert e_auto < 0.03, e_auto
    assert e_k[12] < 0.01 and e_k[12] < e_k[8] < e_auto, (e_auto, e_k)
    assert e_early > 5 * e_auto, (e_early, e_auto)
    assert early["stats"]["lag_bytes_exact"] + early["stats"]["lag_bytes_interp"] < \
        a["stats"]["lag_bytes_exact"] + a["stats"]["lag_bytes_interp"]
