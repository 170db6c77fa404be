"""petsc_ssi.seismic.response_spectrum against closed forms: piecewise-linear input (exact at
the samples, independent of dt), steady harmonic response, impulse response, the short- and
long-period limits, RotD identities, and every refusal."""
import csv

import numpy as np
import pytest
import scipy.linalg as sl

from petsc_ssi.seismic import response_spectrum as rs
from petsc_ssi.seismic.response_spectrum import SpectrumInputError

pytestmark = pytest.mark.unit

# a piecewise-linear ground acceleration [m/s^2]: triangle pulses then ramp-hold at 0.8;
# every knot is a multiple of 0.05 s
KNOTS_T = np.array([0.0, 0.1, 0.3, 0.45, 0.8, 1.2])
KNOTS_A = np.array([0.0, 2.0, -1.5, 0.0, 0.8, 0.8])
T_END = 3.0


def _pl(t):
    return np.interp(t, KNOTS_T, KNOTS_A)


def _ramp_response(t, c, w, z):
    """u, u' of u'' + 2 z w u' + w^2 u = -c t from rest at t = 0 (0 for t < 0): particular
    solution -c (t / w^2 - 2 z / w^3) plus the free vibration matching u(0) = u'(0) = 0."""
    wd = w * np.sqrt(1 - z * z)
    tp = np.maximum(t, 0.0)
    e, co, si = np.exp(-z * w * tp), np.cos(wd * tp), np.sin(wd * tp)
    C, S = 2 * z / w ** 3, -(1 - 2 * z * z) / (w * w * wd)
    u = -c * (tp / w ** 2 - C + e * (C * co + S * si))
    v = -c * (1 / w ** 2 + e * ((-z * w * C + wd * S) * co + (-z * w * S - wd * C) * si))
    on = t >= 0
    return u * on, v * on


def _closed_form(t, period, zeta):
    """Duhamel for the PL signal: a superposition of ramps c_j (t - t_j)_+, c_j the slope
    changes at the knots (the signal starts at 0, so no step term)."""
    slopes = np.diff(KNOTS_A) / np.diff(KNOTS_T)
    dc = np.diff(np.concatenate([[0.0], slopes, [0.0]]))
    w = 2 * np.pi / period
    u, v = np.zeros_like(t), np.zeros_like(t)
    for tj, cj in zip(KNOTS_T, dc):
        du, dv = _ramp_response(t - tj, cj, w, zeta)
        u, v = u + du, v + dv
    return u, v, -2 * zeta * w * v - w * w * u


def _grid(kind):
    if kind == "uniform":
        return np.arange(301) * 0.01
    rng = np.random.default_rng(3)
    return np.unique(np.concatenate([KNOTS_T, rng.uniform(0, T_END, 250), [T_END]]))


def _relerr(x, ref):
    return np.abs(x - ref).max() / np.abs(ref).max()


def _record(n=4000, dt=0.005, seed=0, fmax=8.0):
    """A synthetic horizontal pair: band-limited noise (f < fmax) under a sin^2 envelope."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) * dt
    f = np.fft.rfftfreq(n, dt)
    pair = []
    for _ in range(2):
        spec = (rng.standard_normal(f.size) + 1j * rng.standard_normal(f.size)) * (f < fmax)
        x = np.fft.irfft(spec, n) * np.sin(np.pi * t / t[-1]) ** 2
        pair.append(3.0 * x / np.abs(x).max())
    return t, pair[0], pair[1]


# ----------------------------------------------------------------------------- exactness
def test_step_matrices_equal_matrix_exponential():
    """A, B against scipy's expm of the augmented system (y, a, a') over omega h from 1e-7
    (where explicit Nigam-Jennings formulas cancel) to 50: relative 1e-11 of the largest entry
    (observed 1.1e-13, at zeta 0.99 and omega h 50; the former 1e-12 left a margin of 9x; the
    cancellation it guards against is ~eps / (omega h)^2)."""
    h = 0.01
    for zeta in (0.0, 0.05, 0.7, 0.99):
        for wh in (1e-7, 1e-4, 1e-2, 0.3, 0.49, 0.51, 2.0, 50.0):
            w = wh / h
            A, B = rs._step_matrices(h, np.array([w]), np.array([zeta]))
            W = np.zeros((4, 4))
            W[:2, :2] = w * np.array([[0, 1], [-1, -2 * zeta]])
            W[1, 2], W[2, 3] = -1.0, 1.0
            E = sl.expm(W * h)
            Bref = np.stack([E[:2, 2] - E[:2, 3] / h, E[:2, 3] / h], axis=1)
            assert _relerr(A[..., 0], E[:2, :2]) < 1e-11, (zeta, wh)
            assert _relerr(B[..., 0], Bref) < 1e-11, (zeta, wh)


@pytest.mark.parametrize("kind", ["uniform", "nonuniform"])
@pytest.mark.parametrize("period", [0.02, 0.1, 0.5, 2.0])
@pytest.mark.parametrize("zeta", [0.0, 0.05, 0.3])
def test_piecewise_linear_input_is_exact(kind, period, zeta):
    """u, u', absolute acceleration at the samples against the closed-form Duhamel solution:
    relative 1e-9 of each history's peak (also for T = 2 dt and random steps)."""
    t = _grid(kind)
    h = rs.sdof_history(t, _pl(t), period, zeta)
    u, v, a = _closed_form(t, period, zeta)
    assert _relerr(h.u, u) < 1e-9
    assert _relerr(h.v, v) < 1e-9
    assert _relerr(h.a_abs, a) < 1e-9


@pytest.mark.parametrize("period, zeta", [(0.05, 0.0), (0.3, 0.05), (1.7, 0.2)])
def test_response_at_samples_does_not_depend_on_dt(period, zeta):
    """The PL signal on dt = 1 ms and on every 50th of those samples (dt = 50 ms, still PL:
    the knots are on it) or a non-uniform subset holding the knots: identical responses at
    the common samples, within 1e-10 of the history's peak (at T = 0.05 s the 50 ms grid
    samples the undamped response once per period, where u' is 0 to rounding)."""
    t = np.arange(3001) * 0.001
    fine = rs.sdof_history(t, _pl(t), period, zeta)
    coarse_idx = np.arange(0, t.size, 50)
    rng = np.random.default_rng(5)
    knots = np.rint(KNOTS_T / 0.001).astype(int)
    odd_idx = np.unique(np.concatenate([knots, coarse_idx[::3], rng.choice(t.size, 40),
                                        [t.size - 1]]))
    for idx in (coarse_idx, odd_idx):
        c = rs.sdof_history(t[idx], _pl(t[idx]), period, zeta)
        assert np.abs(c.u - fine.u[idx]).max() < 1e-10 * np.abs(fine.u).max()
        assert np.abs(c.v - fine.v[idx]).max() < 1e-10 * np.abs(fine.v).max()


def test_history_blocks_do_not_change_results(monkeypatch):
    """Histories are integrated and reduced in blocks; with 7-row blocks (many block
    boundaries, also inside oversampled steps) spectra, RotD and histories are bit for bit the
    single-block run's: a block holds rows of the same element-wise recursion, and the reductions
    over the blocks are maxima (observed equal; the former tolerance was relative 1e-14)."""
    t, ax, ay = _record(n=400)
    args = (PERIODS, DAMPING)
    ref = (rs.response_spectrum(t, ax, *args, oversample=3), rs.rotd(t, ax, ay, *args),
           rs.sdof_history(t, ax, 0.3, 0.05, 3))
    monkeypatch.setattr(rs, "_BLOCK_VALUES", 7 * 2 * 8)
    new = (rs.response_spectrum(t, ax, *args, oversample=3), rs.rotd(t, ax, ay, *args),
           rs.sdof_history(t, ax, 0.3, 0.05, 3))
    for q in rs.QUANTITIES:
        assert np.array_equal(new[0][q], ref[0][q], equal_nan=True), q
    assert np.array_equal(new[1][50]["PSA"], ref[1][50]["PSA"])
    assert np.array_equal(new[2].u, ref[2].u)


# ----------------------------------------------------------------------------- closed forms
@pytest.mark.parametrize("r, zeta",
                         [(0.5, 0.05), (1.0, 0.05), (2.0, 0.05), (1.0, 0.2), (0.8, 0.02)])
def test_harmonic_steady_state_amplitude(r, zeta):
    """a_g = A0 sin(r omega t), 200 samples per forcing period, fitted (least squares) over the
    last 10 periods after exp(-zeta omega t) < 1e-6: amplitude = A0 / omega^2 |H(r)|,
    |H| = 1 / sqrt((1 - r^2)^2 + (2 zeta r)^2), relative 2e-4 (PL interpolation of the sine
    lowers it by 1 - sinc^2(pi / 200) = 8e-5; the transient left is below 3e-5)."""
    T, A0 = 1.0, 1.5
    w = 2 * np.pi / T
    Om = r * w
    dt = 2 * np.pi / Om / 200
    t_start = np.log(1e6) / (zeta * w)
    t = np.arange(int((t_start + 20 * np.pi / Om) / dt) + 1) * dt
    h = rs.sdof_history(t, A0 * np.sin(Om * t), T, zeta)
    tail = t >= t_start
    basis = np.stack([np.cos(Om * t[tail]), np.sin(Om * t[tail])], axis=1)
    coef = np.linalg.lstsq(basis, h.u[tail], rcond=None)[0]
    H = 1 / np.sqrt((1 - r * r) ** 2 + (2 * zeta * r) ** 2)
    assert abs(np.hypot(*coef) / (A0 / w ** 2 * H) - 1) < 2e-4


def _rect_pulse(area, width, dt, t_end, edge=1e-7):
    """A rectangular acceleration pulse of the given area on [0, width] (edges: the start
    is the record's first sample, the end a ramp over `edge` s centred on `width`), then zero
    sampled every dt: a non-uniform grid."""
    after = width + edge / 2 + np.arange(1, int(t_end / dt)) * dt
    t = np.concatenate([[0.0, width - edge / 2, width + edge / 2], after])
    a = np.zeros(t.size)
    a[:2] = area / width
    return t, a


@pytest.mark.parametrize("period", [0.5, 1.0, 2.0])
@pytest.mark.parametrize("zeta", [0.0, 0.05, 0.2])
def test_impulse_peak_displacement(period, zeta):
    """Pulse of area I = 0.2 m/s and width w = 5 ms ~ an impulse: u = -(I / omega_d)
    exp(-zeta omega t) sin(omega_d t), peak at omega_d t_p = arccos(zeta):
    SD = (I / omega) exp(-zeta arccos(zeta) / sqrt(1 - zeta^2)).  Tolerance
    2 [(omega w)^2 / 24 (box average of the impulse response) + (omega dt)^2 / 8 (peak
    between samples)], dt = 1 ms: 3.5e-4 at T = 0.5 s."""
    I, width, dt = 0.2, 0.005, 0.001
    t, a = _rect_pulse(I, width, dt, 1.5 * period)
    s = rs.response_spectrum(t, a, [period], [zeta], quantity="SD")
    w = 2 * np.pi / period
    sd = I / w * np.exp(-zeta * np.arccos(zeta) / np.sqrt(1 - zeta ** 2))
    tol = 2 * ((w * width) ** 2 / 24 + (w * dt) ** 2 / 8)
    assert abs(s["SD"][0, 0] / sd - 1) < tol


def test_oversample_recovers_peak_between_samples():
    """Same impulse, T = 0.5 s, but 50 ms steps after the pulse (omega dt = 0.63): at the
    samples the peak may be missed by up to (omega dt)^2 / 8 = 5 %; 20 sub-steps bring it
    within 2 [(omega w)^2 / 24 + (omega dt / 20)^2 / 8] = 3.6e-4, and leave the response at
    the samples unchanged (relative 1e-12)."""
    I, width, dt, period, zeta = 0.2, 0.005, 0.05, 0.5, 0.05
    t, a = _rect_pulse(I, width, dt, 1.5)
    w = 2 * np.pi / period
    sd = I / w * np.exp(-zeta * np.arccos(zeta) / np.sqrt(1 - zeta ** 2))
    sub = rs.response_spectrum(t, a, [period], [zeta], oversample=20)["SD"][0, 0]
    assert abs(sub / sd - 1) < 2 * ((w * width) ** 2 / 24 + (w * dt / 20) ** 2 / 8)
    h1, h20 = rs.sdof_history(t, a, period, zeta), rs.sdof_history(t, a, period, zeta, 20)
    assert np.array_equal(h20.t[::20], t)
    assert _relerr(h20.u[::20], h1.u) < 1e-12


# ----------------------------------------------------------------------------- limits
def test_short_period_limit_is_pga():
    """Record band-limited below 3 Hz: SA at T = 5 and 10 ms equals PGA within 1 % (the
    expected deviation is ~ (f T)^2 < 0.1 %); T = 0 gives SA = PSA = PGA exactly and
    SD = SV = PSV = 0."""
    t, ax, _ = _record(fmax=3.0)
    s = rs.response_spectrum(t, ax, [0.0, 0.005, 0.01], [0.02, 0.05])
    pga = np.abs(ax).max()
    assert np.all(np.abs(s["SA"][:, 1:] / pga - 1) < 0.01)
    assert np.all(s["SA"][:, 0] == pga) and np.all(s["PSA"][:, 0] == pga)
    assert np.all(s["SD"][:, 0] == 0) and np.all(s["SV"][:, 0] == 0) and np.all(s["PSV"][:, 0] == 0)


def test_long_period_limit_is_pgd():
    """Ground displacement pulse D sin^2(pi t / Td), D = 0.1 m, Td = 2 s (a_g piecewise
    linear at dt = 10 ms, PGD from its exact double integral): at T = 50 and 100 s the mass
    stays nearly still, SD = PGD and PSA = PGD omega^2 within 3 % (the damping force
    2 zeta omega u_g' makes the deviation first order in Td / T: 0.9 % and 0.4 %)."""
    D, Td, dt = 0.1, 2.0, 0.01
    t = np.arange(int(10 / dt) + 1) * dt
    a = np.where(t <= Td, D * 2 * np.pi ** 2 / Td ** 2 * np.cos(2 * np.pi * t / Td), 0.0)
    h = np.diff(t)
    vel = np.concatenate([[0.0], np.cumsum(h * (a[:-1] + a[1:]) / 2)])
    disp = np.concatenate([[0.0], np.cumsum(h * vel[:-1] + h * h * (2 * a[:-1] + a[1:]) / 6)])
    pgd = np.abs(disp).max()
    periods = np.array([50.0, 100.0])
    s = rs.response_spectrum(t, a, periods, [0.05])
    assert np.all(np.abs(s["SD"][0] / pgd - 1) < 0.03)
    assert np.all(np.abs(s["PSA"][0] / (pgd * (2 * np.pi / periods) ** 2) - 1) < 0.03)


# ----------------------------------------------------------------------------- two components
PERIODS = np.array([0.0, 0.05, 0.2, 1.0, 3.0])
DAMPING = (0.02, 0.05)


def test_rotd_single_component():
    """ay = 0: RotD100 = the spectrum of ax (1e-10); RotD50 = median_j |cos theta_j| times it
    (1e-10), so strictly below."""
    t, ax, _ = _record()
    single = rs.response_spectrum(t, ax, PERIODS, DAMPING)
    r = rs.rotd(t, ax, np.zeros_like(ax), PERIODS, DAMPING)
    assert _relerr(r[100]["PSA"], single["PSA"]) < 1e-10
    assert _relerr(r[100]["SD"], single["SD"]) < 1e-10
    med = np.percentile(np.abs(np.cos(np.arange(180) * np.pi / 180)), 50)
    assert _relerr(r[50]["PSA"], med * single["PSA"]) < 1e-10
    assert np.all(r[50]["PSA"] < r[100]["PSA"])


def test_rotd_equal_components():
    """ax = ay: u_theta = sqrt(2) u sin(theta + 45 deg), 45 deg on the grid: RotD100 =
    sqrt(2) x the single spectrum, relative 1e-10."""
    t, ax, _ = _record()
    single = rs.response_spectrum(t, ax, PERIODS, DAMPING)
    r = rs.rotd(t, ax, ax, PERIODS, DAMPING, percentiles=(100,))
    assert _relerr(r[100]["PSA"], np.sqrt(2) * single["PSA"]) < 1e-10


def test_rotd_is_percentile_of_rotated_spectra():
    """Definition, brute force: the spectra of the 12 rotated components ax cos + ay sin,
    percentiles 0 / 50 / 100 over them, against rotd(n_angles=12): relative 1e-10."""
    t, ax, ay = _record()
    th = np.arange(12) * np.pi / 12
    psa = np.stack([rs.response_spectrum(t, ax * np.cos(a) + ay * np.sin(a), PERIODS, DAMPING,
                                         quantity="PSA")["PSA"] for a in th])
    r = rs.rotd(t, ax, ay, PERIODS, DAMPING, percentiles=(0, 50, 100), n_angles=12)
    for q in (0, 50, 100):
        assert _relerr(r[q]["PSA"], np.percentile(psa, q, axis=0)) < 1e-10


def test_rotd_rotation_invariance():
    """Rotating the input pair by 30 deg (a multiple of the 1 deg grid) leaves RotD50 and
    RotD100 unchanged (1e-10).  By 17.3 deg (0.3 deg off the grid): RotD100 within
    1 - cos(0.5 deg) = 3.8e-5 relative, RotD50 within 0.3 deg (rad) x RotD100 absolute
    (peak(theta) is Lipschitz with constant max_t |(u_x, u_y)| <= RotD100 / cos(0.5 deg))."""
    t, ax, ay = _record()
    ref = rs.rotd(t, ax, ay, PERIODS, DAMPING)
    for deg in (30.0, 17.3):
        c, s = np.cos(np.radians(deg)), np.sin(np.radians(deg))
        rot = rs.rotd(t, c * ax - s * ay, s * ax + c * ay, PERIODS, DAMPING)
        if deg == 30.0:
            for q in (50, 100):
                assert _relerr(rot[q]["PSA"], ref[q]["PSA"]) < 1e-10
            continue
        assert np.all(np.abs(rot[100]["PSA"] / ref[100]["PSA"] - 1) < 1 - np.cos(np.radians(0.5)))
        lip = np.radians(0.3) * ref[100]["PSA"] / np.cos(np.radians(0.5))
        assert np.all(np.abs(rot[50]["PSA"] - ref[50]["PSA"]) <= lip)


def test_geometric_mean_and_ratio():
    """Linearity: spectra of 4 ax and ax give geometric mean = 2 x spectrum(ax) and ratio 4
    (relative 1e-12) for every quantity; the ratio is nan where the divisor is 0 (SD at
    T = 0); mismatched grids are refused."""
    t, ax, _ = _record()
    s1 = rs.response_spectrum(t, ax, PERIODS, DAMPING)
    s4 = rs.response_spectrum(t, 4 * ax, PERIODS, DAMPING)
    gm, ratio = rs.geometric_mean(s1, s4), rs.spectral_ratio(s4, s1)
    for q in rs.QUANTITIES:
        assert _relerr(gm[q], 2 * s1[q]) < 1e-12
        finite = s1[q] != 0
        assert np.all(np.abs(ratio[q][finite] - 4) < 4e-12) and np.all(np.isnan(ratio[q][~finite]))
        assert ratio.units[q] == "-"
    other = rs.response_spectrum(t, ax, PERIODS[1:], DAMPING)
    with pytest.raises(SpectrumInputError):
        rs.spectral_ratio(s1, other)
    with pytest.raises(SpectrumInputError):
        rs.geometric_mean(s1, rs.response_spectrum(t, ax, PERIODS, (0.05, 0.1)))


# ----------------------------------------------------------------------------- periods, output
def test_standard_periods():
    """Sorted, unique, 0.01 ... 10 s, holds every NGA-West2 period exactly; pga=True puts 0
    first."""
    p = rs.standard_periods()
    assert np.all(np.diff(p) > 0) and p[0] == 0.01 and p[-1] == 10.0
    assert set(rs.NGA_PERIODS) <= set(p.tolist())
    assert rs.standard_periods(pga=True)[0] == 0.0


def test_write_csv_and_plot(tmp_path):
    """CSV header names every column with its unit; one row per (damping, period); values
    read back exactly.  The plot is a PNG file."""
    t, ax, _ = _record()
    s = rs.response_spectrum(t, ax, PERIODS, DAMPING)
    path = tmp_path / "spec.csv"
    rs.write_csv(path, s)
    with open(path) as fh:
        rows = list(csv.reader(fh))
    assert rows[0] == ["period [s]", "damping [-]", "SA [m/s^2]", "PSA [m/s^2]", "PSV [m/s]",
                       "SD [m]", "SV [m/s]"]
    data = np.array(rows[1:], dtype=float)
    assert data.shape == (len(DAMPING) * PERIODS.size, 7)
    assert np.array_equal(data[:, 4].reshape(len(DAMPING), -1), s["PSV"])
    png = tmp_path / "spec.png"
    rs.plot(png, [s, rs.rotd(t, ax, ax, PERIODS, DAMPING)[50]], ["ax", "RotD50"])
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


# ----------------------------------------------------------------------------- refusals
T3, A3 = np.array([0.0, 0.01, 0.02]), np.array([0.0, 1.0, 0.5])
REFUSALS = {
    "non-increasing t": lambda: rs.response_spectrum([0.0, 0.01, 0.01], A3, [1.0]),
    "decreasing t": lambda: rs.response_spectrum([0.0, 0.02, 0.01], A3, [1.0]),
    "nan acceleration": lambda: rs.response_spectrum(T3, [0.0, np.nan, 1.0], [1.0]),
    "inf time": lambda: rs.response_spectrum([0.0, 0.01, np.inf], A3, [1.0]),
    "negative period": lambda: rs.response_spectrum(T3, A3, [1.0, -0.1]),
    "nan period": lambda: rs.response_spectrum(T3, A3, [np.nan]),
    "damping 1": lambda: rs.response_spectrum(T3, A3, [1.0], [1.0]),
    "negative damping": lambda: rs.response_spectrum(T3, A3, [1.0], [-0.01]),
    "empty series": lambda: rs.response_spectrum([], [], [1.0]),
    "one sample": lambda: rs.response_spectrum([0.0], [1.0], [1.0]),
    "mismatched lengths": lambda: rs.response_spectrum(T3, A3[:2], [1.0]),
    "2-d series": lambda: rs.response_spectrum(T3, np.ones((3, 2)), [1.0]),
    "empty periods": lambda: rs.response_spectrum(T3, A3, []),
    "unknown quantity": lambda: rs.response_spectrum(T3, A3, [1.0], quantity="PGV"),
    "oversample 0": lambda: rs.response_spectrum(T3, A3, [1.0], oversample=0),
    "rotd mismatched pair": lambda: rs.rotd(T3, A3, A3[:2], [1.0]),
    "rotd percentile 101": lambda: rs.rotd(T3, A3, A3, [1.0], percentiles=(50, 101)),
    "rotd n_angles 0": lambda: rs.rotd(T3, A3, A3, [1.0], n_angles=0),
    "history nan": lambda: rs.sdof_history(T3, [0.0, 1.0, np.nan], 1.0),
}


@pytest.mark.parametrize("case", sorted(REFUSALS))
def test_refusals_are_one_line(case):
    """Every bad input raises SpectrumInputError (a ValueError) with a one-line message."""
    with pytest.raises(SpectrumInputError) as err:
        REFUSALS[case]()
    msg = str(err.value)
    assert isinstance(err.value, ValueError) and msg and "\n" not in msg
