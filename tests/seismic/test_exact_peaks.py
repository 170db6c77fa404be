"""Exact response-spectrum peaks (issue 43, item 5): each peak found within its step from the closed
form of the exactly integrated oscillator (response_spectrum._exact_peaks, _exact_rotd), the default.

References: (a) a closed form: the undamped oscillator under a ramp to A over t1 then held (a record of
three samples, so every peak lies between samples): SD = A/w^2 (1 + 2 |sin(w t1/2)|/(w t1)),
SV = A/(w^2 t1) max(2 |sin(w t1/2)|, 1 - cos(min(w t1, pi))) (after the ramp, or during a ramp longer
than half a period: u' = -A/(w^2 t1) (1 - cos w t)), SA = w^2 SD; (b) the sampled peaks with 200 sub-steps (a lower bound,
low by at most (w h / 200)^2 / 8, w the larger of the oscillator's and the record's frequencies); (c) the exact peaks do not depend
on the sub-steps. The records: a broadband one and the triangular pulses of test_post_response.py
(whose long-period velocity peak an over-eager bound once missed, 2.5e-4)."""
import numpy as np
import pytest

from petsc_ssi.seismic import response_spectrum as rs

pytestmark = pytest.mark.unit

PERIODS = np.array([0.02, 0.05, 0.11, 0.3, 0.46, 1.0, 2.0, 5.0])
DAMPING = (0.0, 0.02, 0.05)


def _broadband():
    from scipy.signal import butter, sosfilt
    rng = np.random.default_rng(5)
    t = np.arange(0.0, 4.0, 0.01)
    a = sosfilt(butter(4, 20.0, fs=100.0, output="sos"), rng.standard_normal(t.size)) * np.sin(np.pi * t / t[-1]) ** 2
    return t, a


def _pulses():
    t = np.arange(0.0, 3.0, 0.01)

    def tri(t0, tp, t1, amp):
        return amp * np.interp(t, [t0, tp, t1], [0.0, 1.0, 0.0], left=0.0, right=0.0)
    return t, 2.0 * tri(0.1, 0.25, 0.5, -1.5)


@pytest.mark.parametrize("T", [0.05, 0.3, 1.0, 3.7])
def test_ramp_and_hold_closed_form(T):
    A, t1 = 2.0, 0.137
    t = np.array([0.0, t1, t1 + 3 * T])
    w = 2 * np.pi / T
    s = rs.response_spectrum(t, [0.0, A, A], [T], [0.0])
    sd = A / w ** 2 * (1 + 2 * abs(np.sin(w * t1 / 2)) / (w * t1))
    assert s["SD"][0, 0] == pytest.approx(sd, rel=1e-12)
    sv = A / (w ** 2 * t1) * max(2 * abs(np.sin(w * t1 / 2)), 1 - np.cos(min(w * t1, np.pi)))   # after / in the ramp
    assert s["SV"][0, 0] == pytest.approx(sv, rel=1e-12)
    assert s["SA"][0, 0] == pytest.approx(w ** 2 * sd, rel=1e-12)
    nodes = rs.response_spectrum(t, [0.0, A, A], [T], [0.0], peaks="nodes")
    assert nodes["SD"][0, 0] < 0.999 * sd                      # the samples alone miss it


@pytest.mark.parametrize("record", [_broadband, _pulses])
def test_exact_against_dense_sampling_and_sub_steps(record):
    t, a = record()
    ex = rs.response_spectrum(t, a, PERIODS, DAMPING)
    ex3 = rs.response_spectrum(t, a, PERIODS, DAMPING, oversample=3)
    K = 200
    dense = rs.response_spectrum(t, a, PERIODS, DAMPING, peaks="nodes", oversample=K)
    nodes = rs.response_spectrum(t, a, PERIODS, DAMPING, peaks="nodes")
    # sampling misses a peak by at most (w h / K)^2 / 8 for the oscillator's own w; SA and SV follow the ground's
    # content too (the broadband record has little above 50 Hz): the larger of the two frequencies
    bound = (np.maximum(2 * np.pi / PERIODS, 2 * np.pi * 50) * 0.01 / K) ** 2 / 8
    for q in rs.QUANTITIES:
        r = ex[q] / dense[q] - 1
        assert r.min() > -1e-11, (q, r.min())                           # dense sampling is a lower bound
        assert np.all(r <= 1.05 * bound[None, :] + 1e-11), (q, r.max())
        assert np.allclose(ex[q], ex3[q], rtol=1e-11, atol=0), q
        print(f"{record.__name__} {q}: exact / dense - 1 in [{r.min():.1e}, {r.max():.1e}]; samples alone "
              f"{(nodes[q] / dense[q] - 1).min():+.1e}")


@pytest.mark.parametrize("record", [_broadband, _pulses])
def test_rotd_exact_against_dense(record):
    """Every angle's peak within its step (only the angles whose projected velocity turns in a piece are
    searched): RotD50 and RotD100 between 100-fold sampling (a lower bound) and its bound."""
    t, a = record()
    b = np.roll(a, 23) + 0.3 * a
    P = PERIODS[::2]
    ex = rs.rotd(t, a, b, P, [0.05])
    dense = rs.rotd(t, a, b, P, [0.05], peaks="nodes", oversample=100)
    bound = (np.maximum(2 * np.pi / P, 2 * np.pi * 50) * 0.01 / 100) ** 2 / 8      # as above
    for pct in (50, 100):
        r = ex[pct]["PSA"] / dense[pct]["PSA"] - 1
        assert r.min() > -1e-11 and np.all(r <= 1.05 * bound[None, :] + 1e-11), (pct, r)
    single = rs.response_spectrum(t, a, P, [0.05])
    r = rs.rotd(t, a, np.zeros_like(a), P, [0.05])[100]["PSA"]
    assert np.allclose(r, single["PSA"], rtol=1e-11)                      # one component: RotD100 = its PSA


def test_a_period_far_below_the_step_is_refused_not_allocated():
    """Exact peaks search each step in quarter-period pieces: 4 dt / T of them. A period of 1e-8 s under a
    5 ms record would take 2e6 pieces a step (a merged run of make test lost a worker to the kernel's OOM
    killer on --periods 1e-7): refused before anything is allocated, for the spectra and RotD."""
    from petsc_ssi.seismic import response_spectrum as rs
    t = np.arange(0.0, 10.0, 0.005)
    a = np.sin(2 * np.pi * t)
    with pytest.raises(rs.SpectrumInputError, match="pieces in each of 1999 steps"):
        rs.response_spectrum(t, a, [1e-8, 1.0])
    with pytest.raises(rs.SpectrumInputError, match="pieces"):
        rs.rotd(t, a, a, [1e-8, 1.0])
    assert rs.response_spectrum(t, a, [1e-8, 1.0], peaks="nodes").values["PSA"].shape == (1, 2)
