"""System identification of a structure from its base and roof motion (the numerics of
``petsc-ssi post --glance``, ``app/glance.py``, whose docstring states the method): the Konno-Ohmachi
smoothed spectral ratio (Konno & Ohmachi 1998, BSSA 88: 228-241) and the output-error fit of an
equivalent single-degree-of-freedom oscillator (Stewart & Fenves 1998, EESD 27: 869-885). Numpy and
scipy only; errors are ``IdentificationError`` (one line)."""
import math
from dataclasses import dataclass

import numpy as np

from . import response_spectrum as rs

KO_B = 40.0
N_FREQ = 200
BAND_FLOOR = 0.01          # the peak is looked for where the smoothed ground spectrum > 1 % of its max


class IdentificationError(ValueError):
    """A pair of series that cannot be identified (one-line message)."""


def _error(msg):
    return IdentificationError(" ".join(str(msg).split()))


# ---------------------------------------------------------------- spectra

def konno_ohmachi(f, amp, fc, b=KO_B):
    """Konno & Ohmachi (1998) smoothing of ``amp`` on the frequencies f (>= 0) at the centres
    fc (> 0): sum W amp / sum W, W = (sin(b log10(f/fc)) / (b log10(f/fc)))^4, W(fc) = 1."""
    f, amp, fc = np.asarray(f, float), np.asarray(amp, float), np.asarray(fc, float)
    pos = f > 0
    lf, a = np.log10(f[pos]), amp[pos]
    out = np.empty(fc.size)
    for i0 in range(0, fc.size, 32):
        w = np.sinc((b / np.pi) * (lf[None, :] - np.log10(fc[i0:i0 + 32])[:, None]))
        w *= w
        w *= w
        out[i0:i0 + 32] = (w @ a) / w.sum(axis=1)
    return out


@dataclass(eq=False)
class Ratio:
    f: np.ndarray            # [Hz] log-spaced
    smooth: np.ndarray       # smoothed |Y| / smoothed |X| [-]
    ground: np.ndarray       # smoothed |X| [m/s^2 s]
    f_raw: np.ndarray
    raw: np.ndarray          # |Y / X| on the FFT grid [-]
    band: tuple              # (f1, f2) [Hz] where the peak was looked for
    f_peak: float
    h_peak: float


def spectral_ratio(t, g, y, b=KO_B, band=None):
    n, dt = t.size, float(np.mean(np.diff(t)))
    nfft = 1 << int(math.ceil(math.log2(2 * n)))          # zero-padded: a grid fine enough to smooth on
    X, Y = np.fft.rfft(g, nfft), np.fft.rfft(y, nfft)
    fr = np.fft.rfftfreq(nfft, dt)
    f_lo, f_hi = 2.0 / (n * dt), 0.25 / dt
    if not f_lo < f_hi:
        raise _error(f"the record is too short to identify anything ({n} samples)")
    fc = np.geomspace(f_lo, f_hi, N_FREQ)
    sx, sy = konno_ohmachi(fr, np.abs(X), fc, b), konno_ohmachi(fr, np.abs(Y), fc, b)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(sx > 0, sy / sx, np.nan)
        raw = np.where(np.abs(X) > 0, np.abs(Y) / np.abs(X), np.nan)
    if band is None:
        ok = sx >= BAND_FLOOR * sx.max()
        if not ok.any():
            raise _error("the ground acceleration is zero")
        f1, f2 = fc[ok][0], fc[ok][-1]
    else:
        f1, f2 = max(band[0], f_lo), min(band[1], f_hi)
        if not f1 < f2:
            raise _error(f"--band {band[0]:g},{band[1]:g}: outside the identifiable range {f_lo:.4g} .. "
                         f"{f_hi:.4g} Hz (2 / record length .. 0.25 / dt)")
    sel = (fc >= f1) & (fc <= f2) & np.isfinite(ratio)
    if not sel.any():
        raise _error(f"no frequency of the grid in the band {f1:.4g} .. {f2:.4g} Hz")
    i = np.nonzero(sel)[0][np.argmax(ratio[sel])]
    return Ratio(fc, ratio, sx, fr, raw, (float(f1), float(f2)), float(fc[i]), float(ratio[i]))


# ---------------------------------------------------------------- SDOF fit

@dataclass(eq=False)
class Fit:
    f0: float                # [Hz]
    zeta: float              # [-]
    c0: float                # [-]
    c1: float                # [-]
    r2: float                # [-]
    band: tuple              # band-pass [Hz]

    def h(self, f):
        """The fitted |H(f)| [-]."""
        r = np.asarray(f, float) / self.f0
        return np.abs(self.c0 + self.c1 * (1 + 2j * self.zeta * r) / (1 - r ** 2 + 2j * self.zeta * r))


def _bandpass(dt, f1, f2):
    """Butterworth order 4 band-pass f1 .. f2 [Hz] (f2 capped at 0.9 x Nyquist) as sos, and the band."""
    from scipy.signal import butter
    fn = 0.5 / dt
    lo, hi = f1, min(f2, 0.9 * fn)
    if lo >= hi:
        raise _error(f"the band {f1:.4g} .. {f2:.4g} Hz is too close to the Nyquist frequency {fn:.4g} Hz to fit")
    return butter(4, [lo, hi], btype="bandpass", fs=1.0 / dt, output="sos"), (lo, hi)


ZETA_GRID = (0.005, 0.01, 0.02, 0.04, 0.08, 0.15, 0.3, 0.6)


def _fitter(t, g, y, f1, f2):
    """resid(p, full=False) of the fit in the band-pass f1 .. f2 [Hz], p = (ln f0, zeta)."""
    from scipy.signal import lfilter, sosfilt
    dt = float(np.mean(np.diff(t)))
    sos, band = _bandpass(dt, f1, f2)
    gf, yf = sosfilt(sos, g), sosfilt(sos, y)
    norm = float(np.sqrt(yf @ yf))
    if norm == 0:
        raise _error(f"the roof's acceleration is zero in the band {band[0]:.4g} .. {band[1]:.4g} Hz")

    def resid(p, full=False):
        s = lfilter(*rs.sdof_filter(math.exp(p[0]), p[1], dt), gf)
        M = np.column_stack([gf, s])
        c, *_ = np.linalg.lstsq(M, yf, rcond=None)
        r = (yf - M @ c) / norm
        return (r, c) if full else r
    return resid, band


def _grid(resid, f_lo, f_hi, n):
    best = None
    for f0 in np.geomspace(f_lo, f_hi, n):
        for z in ZETA_GRID:
            p = (math.log(f0), z)
            c = float(np.sum(resid(p) ** 2))
            if best is None or c < best[0]:
                best = (c, p)
    return best[1]


def fit_sdof(t, g, y, search):
    """The fit of the module docstring (step 2) of the pair (t, g, y): a grid search for f0 over
    ``search`` = (f1, f2) [Hz] in the band-pass f1 / 2 .. 2 f2, then the grid and the least
    squares in the band-pass f0 / 2 .. 2 f0 around its best."""
    from scipy.optimize import least_squares
    dt = float(np.mean(np.diff(t)))
    f_top = 0.45 / dt
    resid, _ = _fitter(t, g, y, 0.5 * search[0], 2.0 * search[1])
    f_start = math.exp(_grid(resid, search[0], min(search[1], f_top), 41)[0])
    resid, band = _fitter(t, g, y, 0.5 * f_start, 2.0 * f_start)
    f_lo, f_hi = 0.6 * f_start, min(1.6 * f_start, f_top)
    p0 = _grid(resid, f_lo, f_hi, 25)
    sol = least_squares(resid, p0, bounds=([math.log(f_lo), 0.0], [math.log(f_hi), 0.95]),
                        x_scale=[0.05, 0.05], xtol=1e-12, ftol=1e-12, gtol=1e-12)
    r, c = resid(sol.x, full=True)
    return Fit(math.exp(sol.x[0]), float(sol.x[1]), float(c[0]), float(c[1]), float(1 - r @ r), band)
