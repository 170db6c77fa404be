"""The integrators' steady response to a harmonic load and their free vibration against the closed
forms of fem/integrator_response.py (issue 46): the classes themselves, run on one dof."""
import numpy as np
import pytest

from fem_helpers import sdof_mats
from petsc_ssi.fem import integrator_response as ir
from petsc_ssi.fem.integrators import make_integrator

pytestmark = pytest.mark.run

DT, MASS = 5e-3, 2.0


def _run(kind, W, zeta, load, u0=0.0, v0=0.0, steps=80, ad=(0.25, 0.5)):
    """u^0..u^N of the class ``kind`` on one dof (omega dt = W, mass-proportional zeta at omega);
    ``load(n)`` is the load sample g^n [N] (None: free)."""
    from petsc_ssi.petsc import init
    PETSc = init()
    omega = W / DT
    K, m = sdof_mats(MASS * omega ** 2, MASS)
    integ = make_integrator(kind, K, m, DT, 2 * zeta * omega, (), *ad)

    def vec(x):
        v = m.duplicate()
        v.set(x)
        return v
    g = (lambda n: None) if load is None else (lambda n: vec(load(n)))
    integ.start(vec(u0), vec(v0), g(0))
    us = [integ.u.getArray()[0]]
    for n in range(1, steps + 1):
        integ.step(g(n))
        us.append(integ.u.getArray()[0])
    integ.destroy()
    K.destroy()
    assert PETSc is not None
    return np.array(us)


def measured_ratio(kind, W, x, zeta=0.0, F=3.0, ad=(0.25, 0.5)):
    """The steady amplitude of the class under F cos(Omega t) (its samples: the cell mean for green and
    newmark, the interval mean for midpoint) over the exact one, as a complex number: least squares of
    u^n on cos(theta n), sin(theta n) and the class's own free responses from u0 = 1 and from v0 = 1
    (the transient is a combination of them), so the fit is exact to round-off."""
    th = 2 * np.pi * x
    S = np.sinc(x)
    shift = 0.5 * th if ir.SAMPLING[kind] == "interval" else 0.0

    def load(n):
        return 0.0 if (kind == "midpoint" and n == 0) else F * S * np.cos(th * n - shift)
    u = _run(kind, W, zeta, load, ad=ad)
    n = np.arange(len(u))
    basis = np.column_stack([np.cos(th * n), np.sin(th * n), _run(kind, W, zeta, None, u0=1.0, ad=ad),
                             _run(kind, W, zeta, None, v0=1.0, ad=ad)])
    coef, *_ = np.linalg.lstsq(basis, u, rcond=None)
    assert np.abs(basis @ coef - u).max() < 1e-8 * np.abs(u).max()
    omega, Om = W / DT, th / DT
    exact = F / (MASS * (omega ** 2 - Om ** 2 + 2j * zeta * omega * Om))
    return (coef[0] - 1j * coef[1]) / exact


CASES = [(W, x) for W in (50.0, 2.0, 0.3) for x in (0.05, 0.17, 0.3, 0.39, 0.45)]


@pytest.mark.parametrize("kind", ir.SCHEMES)
def test_steady_amplitude_of_the_classes_is_the_closed_form(kind):
    """Undamped: the measured ratio equals the closed form to 1 % (in fact to round-off) at stiff
    (omega dt = 50), moderate and soft oscillators and f dt from 0.05 to 0.45; the phase too (the
    closed form is real)."""
    for W, x in CASES:
        meas, cf = measured_ratio(kind, W, x), ir.closed_form_ratio(kind, W, x)
        assert abs(meas / cf - 1.0) < 0.01, (kind, W, x, meas, cf)
        assert abs(meas / cf - 1.0) < 1e-6, (kind, W, x, meas, cf)


@pytest.mark.parametrize("kind", ir.SCHEMES)
def test_damped_steady_amplitude_is_the_transfer_function(kind):
    for W, x in ((50.0, 0.39), (1.0, 0.1), (0.3, 0.25)):
        meas, tf = measured_ratio(kind, W, x, zeta=0.05), ir.steady_ratio(kind, W, x, zeta=0.05)
        assert abs(meas / tf - 1.0) < 1e-6, (kind, W, x, meas, tf)


@pytest.mark.parametrize("kind", ["green", "newmark"])
def test_dissipative_constants_match_the_transfer_function(kind):
    """alpha = 0.36, delta = 0.6 (delta^2 = alpha: the Green scheme's other family): the classes against
    step_matrices' transfer function; green still amplifies a stiff mode (x1.73 at f dt 1/4, x5.1 at 0.39)."""
    for W, x in ((50.0, 0.25), (50.0, 0.39), (1.0, 0.1)):
        meas = measured_ratio(kind, W, x, ad=(0.36, 0.6))
        assert meas == pytest.approx(ir.steady_ratio(kind, W, x, alpha=0.36, delta=0.6), rel=1e-6)
    if kind == "green":
        assert abs(ir.steady_ratio("green", 50.0, 0.39, alpha=0.36, delta=0.6)) == pytest.approx(5.127, rel=1e-3)


def test_green_is_newmark_times_one_over_cos2():
    """The cause: U_green = 4z/(1+z)^2 U_newmark for every oscillator and damping."""
    for W in (0.3, 1.5, 50.0):                      # (not 2.0: newmark's discrete resonance at f dt 1/4)
        for zeta in (0.0, 0.05):
            for x in (0.05, 0.25, 0.39, 0.45):
                g, n = ir.steady_ratio("green", W, x, zeta), ir.steady_ratio("newmark", W, x, zeta)
                if abs(n) > 1e-6:
                    assert g / n == pytest.approx(1.0 / np.cos(np.pi * x) ** 2, rel=1e-6)
    # the stiff limit: x1.80 at f dt 1/4, x6.69 at 0.39, x28.5 at 0.45 (green); newmark below 1
    amp = [float(ir.stiff_amplification("green", x)) for x in (0.25, 0.39, 0.45)]
    assert amp == pytest.approx([1.8006, 6.6926, 28.549], rel=1e-3)
    assert np.all(ir.stiff_amplification("newmark", np.linspace(0.01, 0.49, 49)) < 1.0)
    assert measured_ratio("green", 50.0, 0.39) == pytest.approx(6.69, rel=0.02)


def test_a_three_point_load_average_would_make_green_newmark():
    """The impulse h (g^{n-1} + 2 g^n + g^{n+1})/4 (module docstring): the class fed that sample answers
    like newmark (measured), where the plain sample gives x1/cos^2."""
    th, x, W, F = 2 * np.pi * 0.39, 0.39, 50.0, 3.0
    g = lambda n: F * np.sinc(x) * np.cos(th * n)                     # noqa: E731
    u = _run("green", W, 0.0, lambda n: (g(n - 1) + 2 * g(n) + g(n + 1)) / 4)
    n = np.arange(len(u))
    basis = np.column_stack([np.cos(th * n), np.sin(th * n), _run("green", W, 0.0, None, u0=1.0),
                             _run("green", W, 0.0, None, v0=1.0)])
    c = np.linalg.lstsq(basis, u, rcond=None)[0]
    omega = W / DT
    meas = (c[0] - 1j * c[1]) * MASS * (omega ** 2 - (th / DT) ** 2) / F
    assert meas == pytest.approx(ir.closed_form_ratio("newmark", W, x), rel=1e-6)
    assert ir.steady_ratio("green", W, x, smoothed=True) == pytest.approx(ir.steady_ratio("newmark", W, x), rel=1e-6)


@pytest.mark.parametrize("kind", ir.SCHEMES)
def test_free_vibration_radius_and_period(kind):
    """The class's free run u^{n+1} = p u^n + q u^{n-1} (fitted) has the eigenvalues of ``free_vibration``:
    radius 1 and T_h/T = (W/2)/arctan(W/2) undamped (trapezoidal), and the damped radius."""
    for W, zeta in ((0.5, 0.0), (2.0, 0.0), (1.0, 0.05)):
        u = _run(kind, W, zeta, None, u0=1.0, steps=40)[2:]
        A = np.column_stack([u[1:-1], u[:-2]])
        p, q = np.linalg.lstsq(A, u[2:], rcond=None)[0]
        lam = np.roots([1.0, -p, -q])
        rho, period = ir.free_vibration(kind, W, zeta)
        assert np.abs(lam).max() == pytest.approx(rho, rel=1e-6)
        assert W / abs(np.angle(lam[0])) == pytest.approx(period, rel=1e-6)
        if zeta == 0.0:
            assert rho == pytest.approx(1.0, abs=1e-12)
            assert period == pytest.approx(0.5 * W / np.arctan(0.5 * W), rel=1e-12)


def test_safe_band_and_record_note():
    """green keeps a stiff mode within 5 % up to f dt 0.0766, midpoint 0.120, newmark everywhere; the
    note fires for a record with energy above the band and names a dt that puts it inside."""
    assert ir.safe_band("green") == pytest.approx(0.0766, abs=2e-4)
    assert ir.safe_band("midpoint") == pytest.approx(0.1197, abs=2e-4)
    assert ir.safe_band("newmark") == 0.5
    t = np.arange(0.0, 2.0, 0.001)
    env = np.sin(np.pi * t / 2.0) ** 2                         # (a record is tapered)
    low = np.sin(2 * np.pi * 5 * t) * env
    hf = low + 0.5 * np.sin(2 * np.pi * 70 * t) * env
    assert ir.record_note("green", 5e-3, t, low, "low") is None
    assert ir.record_note("newmark", 5e-3, t, hf, "hf") is None
    note = ir.record_note("green", 5e-3, t, hf, "hf", advice="use newmark")
    assert note is not None and "the 20 % of its acceleration's energy above 15.32 Hz" in note, note
    # 70 Hz at 5 ms: x4.2 (S/cos^2 at f dt 0.35) on a third of the peak: the record's peak x1.98
    assert ir.stiff_peak_ratio("green", 5e-3, t, hf) == pytest.approx(1.98, abs=0.01)
    assert "a peak x1.98 the record's" in note and "-ssi_dt 0.0017 keeps that within 5 %" in note, note
    assert note.endswith("; use newmark"), note
    assert ir.stiff_peak_ratio("green", 1.7e-3, t, hf) <= 1.05 < ir.stiff_peak_ratio("green", 1.9e-3, t, hf)
    assert ir.record_note("green", 1.7e-3, t, hf, "hf") is None


BOX = ["-ssi_problem", "fem", "-ssi_fem_box_cells", "1,1,2", "-ssi_fem_box_size", "1,1,1", "-ssi_fem_box_origin",
       "-0.5,-0.5,0", "-ssi_fem_E", "30e9", "-ssi_fem_fixed", "base", "-ssi_seismic", "vertical",
       "-ssi_seismic_taper", "0", "-ssi_seismic_baseline", "none", "-ssi_receivers", "0.5,0.5,1"]


# slow tier: the 70 Hz record under a stiff structure run twice (20 s; siblings in make test:
# test_safe_band_and_record_note and test_which_runs_check_their_record)
@pytest.mark.slow
def test_a_stiff_structure_under_a_record_at_70_hz_is_warned_and_the_named_dt_resolves_it(tmp_path):
    """A stiff block (first mode ~ 600 Hz) on a fixed base under 5 Hz + 70 Hz (a third of the peak):
    at dt = 5 ms green's roof peak absolute acceleration exceeds newmark's by over 30 % and the run
    warns, naming -ssi_dt 0.0017; newmark does not warn; at dt = 1.7 ms green does not warn and its roof
    peak is within 5 % of newmark's."""
    import h5py
    from helpers import cli
    t = np.arange(0.0, 0.6, 0.001)
    env = np.sin(np.pi * t / 0.6) ** 2
    rec = tmp_path / "hf.txt"
    np.savetxt(rec, np.c_[t, (np.sin(2 * np.pi * 5 * t) + 0.5 * np.sin(2 * np.pi * 70 * t)) * env],
               header="units: m/s2")
    peak, warned = {}, {}
    for kind, dt in (("green", "0.005"), ("newmark", "0.005"), ("green", "0.0017"), ("newmark", "0.0017")):
        out = tmp_path / f"{kind}-{dt}.h5"
        p = cli(BOX + ["-ssi_dt", dt, "-ssi_fem_integrator", kind, "-ssi_seismic_record", str(rec),
                       "-ssi_output", str(out)])
        warned[kind, dt] = [ln for ln in p.stdout.splitlines()
                            if ln.startswith("petsc-ssi: warning:") and "static response" in ln]
        with h5py.File(out, "r") as f:
            peak[kind, dt] = float(np.abs(f["receivers/absolute_acceleration"][:, 0, 0]).max())
    assert len(warned["green", "0.005"]) == 1, warned
    w = warned["green", "0.005"][0]
    assert "above 15.32 Hz" in w and "-ssi_dt 0.0017 keeps that within 5 %" in w and "newmark" in w, w
    assert not warned["newmark", "0.005"] and not warned["green", "0.0017"] and not warned["newmark", "0.0017"]
    assert peak["green", "0.005"] / peak["newmark", "0.005"] > 1.3, peak
    assert peak["green", "0.0017"] / peak["newmark", "0.0017"] == pytest.approx(1.0, abs=0.05), peak


def test_which_runs_check_their_record():
    """The fixed base checks its -ssi_fem_integrator, the staggered coupling its Green scheme; the implicit
    coupling (interface force solved with the soil; runs/integrators/coupled.csv) and the soil alone none."""
    import inspect
    from petsc_ssi.coupling.step import STRATEGIES
    from petsc_ssi.bem.halfspace import HalfSpace
    assert STRATEGIES["staggered"].record_scheme == "green" and STRATEGIES["implicit"].record_scheme is None
    assert inspect.signature(HalfSpace).parameters["record_scheme"].default is None      # the soil alone

