"""Frequency-domain post-processing of uniformly sampled series (numpy only).

``amplitude_spectrum(t, x, pad=None, window="none")``
    One-sided amplitude spectrum |X(f)|, scaled so that a sine of amplitude A
    gives a peak of height A: for ``window="none"`` exactly when the record holds
    an integer number of periods (the sine falls on a bin); for other windows
    the coherent gain ``sum(w)`` is divided out, so the same holds at a bin
    centre (off-bin the peak is lower: scalloping loss).
    Padding: ``pad=None`` -> no padding (nfft = N samples); ``pad=p`` -> the
    windowed record is zero-padded to the next power of two >= p * N.  Padding
    interpolates the spectrum on a finer grid df = 1 / (nfft dt); it does not
    improve the true resolution 1 / (N dt).
``peaks(f, a, n, min_separation)``
    The n highest interior local maxima, at least ``min_separation`` Hz apart.
``transfer(t, a, b, ...)``
    H(f) = B / A of two series on the same time grid, as a *regularised*
    single-record spectral ratio (water level):
    H = B conj(A) / (|A|^2 + (eps max|A|)^2).  No averaging over segments, so
    no coherence estimate: trust H only where |A| is well above eps max|A|
    (``info["reliable"]``).
"""
import numpy as np

WINDOWS = ("none", "hann", "tukey")
DETRENDS = ("none", "mean", "linear")


class SpectrumError(ValueError):
    """Invalid input for a spectrum (one-line message)."""


def check_uniform(t, rtol=1e-6):
    """The sampling interval dt of ``t``; SpectrumError unless uniform and increasing."""
    t = np.asarray(t, dtype=float).ravel()
    if t.size < 2:
        raise SpectrumError(f"a spectrum needs at least 2 samples, the series has {t.size}")
    d = np.diff(t)
    dt = (t[-1] - t[0]) / (t.size - 1)
    if not dt > 0 or not np.all(d > 0):
        raise SpectrumError("the time grid is not strictly increasing")
    dev = np.abs(d - dt).max()
    if dev > rtol * dt:
        k = int(np.argmax(np.abs(d - dt)))
        raise SpectrumError(f"the time grid is not uniform: step {k} is {d[k]:.6g} s, the mean step "
                            f"{dt:.6g} s (deviation {dev / dt:.2e} dt > {rtol:g} dt); resample first")
    return dt


def window_weights(n, window="none", tukey_alpha=0.25):
    """Window of n samples: 'none' (rectangular), 'hann' (symmetric), 'tukey' (cosine taper of
    the fraction ``tukey_alpha`` of the record, half at each end)."""
    if window == "none":
        return np.ones(n)
    if window == "hann":
        return np.hanning(n) if n > 1 else np.ones(n)
    if window == "tukey":
        if not 0.0 <= tukey_alpha <= 1.0:
            raise SpectrumError(f"tukey alpha must lie in [0, 1], got {tukey_alpha}")
        w = np.ones(n)
        if tukey_alpha == 0 or n < 2:
            return w
        x = np.arange(n) / (n - 1)
        lo = x < tukey_alpha / 2
        hi = x > 1 - tukey_alpha / 2
        w[lo] = 0.5 * (1 - np.cos(2 * np.pi * x[lo] / tukey_alpha))
        w[hi] = 0.5 * (1 - np.cos(2 * np.pi * (1 - x[hi]) / tukey_alpha))
        return w
    raise SpectrumError(f"unknown window {window!r}: use one of {', '.join(WINDOWS)}")


def _nfft(n, pad):
    if pad is None:
        return n
    pad = float(pad)
    if not pad >= 1:
        raise SpectrumError(f"pad must be >= 1 (a multiple of the record length), got {pad:g}")
    target = int(np.ceil(pad * n - 1e-9))
    nfft = 1 << max(0, int(target - 1).bit_length())
    from .sysmem import machine_memory
    need, room = 48.0 * nfft, 0.5 * machine_memory()     # the padded series and its complex FFT, a few copies
    if need > room:       # (issue 44: a pad of 1e12 asked for terabytes and ended in MemoryError)
        raise SpectrumError(f"--pad {pad:g}: {nfft:.3g} FFT points need about {need / 1e9:.3g} GB per component, "
                            f"more than half the memory ({room / 1e9:.3g} GB); give a pad below about "
                            f"{room / 48.0 / n:.3g}")
    return nfft


def _detrend(t, x, how):
    if how == "none":
        return x
    if how == "mean":
        return x - x.mean(axis=0)
    if how == "linear":
        A = np.stack([np.ones_like(t), t - t.mean()], 1)
        coef, *_ = np.linalg.lstsq(A, x, rcond=None)
        return x - A @ coef
    raise SpectrumError(f"unknown detrend {how!r}: use one of {', '.join(DETRENDS)}")


def _fft(t, x, pad, window, tukey_alpha, detrend):
    """Shared front end: (f, X scaled to amplitude, info); X has shape (nf, C) or (nf,)."""
    t = np.asarray(t, dtype=float).ravel()
    x = np.asarray(x, dtype=float)
    if x.shape[0] != t.size:
        raise SpectrumError(f"the series has {x.shape[0]} samples but the time grid {t.size}")
    if not np.all(np.isfinite(x)):
        raise SpectrumError("the series holds non-finite values")
    dt = check_uniform(t)
    n = t.size
    nfft = _nfft(n, pad)
    w = window_weights(n, window, tukey_alpha)
    xs = _detrend(t, x, detrend)
    wx = xs * (w if xs.ndim == 1 else w[:, None])
    X = np.fft.rfft(wx, n=nfft, axis=0)
    scale = np.full(X.shape[0], 2.0 / w.sum())
    scale[0] = 1.0 / w.sum()
    if nfft % 2 == 0:
        scale[-1] = 1.0 / w.sum()
    X = X * (scale if X.ndim == 1 else scale[:, None])
    f = np.fft.rfftfreq(nfft, dt)
    df = 1.0 / (nfft * dt)
    info = {
        "n": n, "dt": dt, "duration": n * dt, "nfft": nfft, "pad": pad, "df": df,
        "resolution": 1.0 / (n * dt), "nyquist": 0.5 / dt, "window": window,
        "tukey_alpha": tukey_alpha if window == "tukey" else None, "detrend": detrend,
        "coherent_gain": float(w.mean()),
    }
    info["padding"] = (f"no zero padding (nfft = N = {n})" if pad is None else
                       f"zero-padded from N = {n} to nfft = {nfft} (next power of two >= {float(pad):g} N)")
    info["window_text"] = window + (f" (alpha {tukey_alpha:g})" if window == "tukey" else "")
    info["scaling"] = ("one-sided amplitude: 2|X_k|/sum(w) (1/sum(w) at f = 0 and Nyquist); "
                       "a sine of amplitude A on a bin gives a peak A")
    info["summary"] = (f"window {info['window_text']}, {info['padding']}, dt {dt:.6g} s, "
                       f"df {df:.6g} Hz, resolution 1/(N dt) {info['resolution']:.6g} Hz, detrend {detrend}")
    return f, X, info


def amplitude_spectrum(t, x, pad=None, window="none", tukey_alpha=0.25, detrend="none"):
    """One-sided amplitude spectrum of ``x`` sampled at the uniform times ``t``.

    x: shape (N,) or (N, C) (one column per component).  Returns (f, |X|, info):
    f (nf,) in Hz from 0 to Nyquist with step info["df"]; |X| like x with N -> nf;
    info: n, dt, nfft, pad, df, resolution (1/(N dt)), nyquist, window, detrend,
    padding/summary (text).  See the module docstring for the scaling.
    """
    f, X, info = _fft(t, x, pad, window, tukey_alpha, detrend)
    return f, np.abs(X), info


def peaks(f, a, n=5, min_separation=0.0, fmin=None, fmax=None):
    """The ``n`` highest local maxima of the amplitude ``a(f)`` (1-D), highest first.

    A local maximum is an interior bin with a[i] >= both neighbours and > at least one
    (the end bins, f = 0 and Nyquist, are never peaks).  Peaks are taken greedily in
    decreasing amplitude, skipping any within ``min_separation`` Hz of one already
    taken (use about the resolution 1/(N dt) against side lobes of padded spectra).
    Returns (f_peaks, a_peaks, indices) as arrays.
    """
    f = np.asarray(f, dtype=float)
    a = np.asarray(a, dtype=float)
    if a.ndim != 1 or a.shape != f.shape:
        raise SpectrumError("peaks expects 1-D f and a of the same length")
    if a.size < 3 or n <= 0:
        e = np.array([], dtype=int)
        return f[e], a[e], e
    i = np.arange(1, a.size - 1)
    left, mid, right = a[:-2], a[1:-1], a[2:]
    cand = i[(mid >= left) & (mid >= right) & ((mid > left) | (mid > right))]
    if fmin is not None:
        cand = cand[f[cand] >= fmin]
    if fmax is not None:
        cand = cand[f[cand] <= fmax]
    cand = cand[np.argsort(-a[cand], kind="stable")]
    chosen = []
    for c in cand:
        if all(abs(f[c] - f[k]) >= min_separation for k in chosen):
            chosen.append(int(c))
            if len(chosen) == n:
                break
    idx = np.array(chosen, dtype=int)
    return f[idx], a[idx], idx


def transfer(t, a, b, pad=None, window="none", tukey_alpha=0.25, detrend="none", eps=1e-3,
             reliable_level=0.05):
    """Transfer function H = B / A of the output ``b`` over the input ``a`` (same grid t).

    a, b: shape (N,) or (N, C), with the same shape.  Regularised (water-level) ratio
    H = B conj(A) / (|A|^2 + (eps max_f |A|)^2), per component; exactly B/A where
    |A| >> eps max|A|, tending to 0 where A vanishes.  Single record, so no coherence.
    Returns (f, H complex, info) with info["magnitude"] = |H|, info["phase"] (rad,
    in (-pi, pi]), info["reliable"] (bool, |A| >= reliable_level max|A|), info["eps"],
    info["method"] (text), and the spectral info of amplitude_spectrum.
    """
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    if a.shape != b.shape:
        raise SpectrumError(f"transfer: the two series differ in shape, {a.shape} and {b.shape}")
    if not eps >= 0:
        raise SpectrumError(f"transfer: eps must be >= 0, got {eps}")
    f, A, info = _fft(t, a, pad, window, tukey_alpha, detrend)
    _, B, _ = _fft(t, b, pad, window, tukey_alpha, detrend)
    amax = np.abs(A).max(axis=0)
    lam2 = (eps * amax) ** 2
    den = np.abs(A) ** 2 + lam2
    with np.errstate(invalid="ignore", divide="ignore"):
        H = np.where(den > 0, B * np.conj(A) / np.where(den > 0, den, 1.0), 0.0)
    info = dict(info)
    info["magnitude"] = np.abs(H)
    info["phase"] = np.angle(H)
    info["reliable"] = np.abs(A) >= reliable_level * np.where(amax > 0, amax, np.inf)
    info["eps"] = eps
    info["method"] = (f"regularised single-record ratio H = B conj(A) / (|A|^2 + (eps max|A|)^2), "
                      f"eps {eps:g}; no segment averaging, no coherence; reliable where "
                      f"|A| >= {reliable_level:g} max|A|")
    return f, H, info
