"""Power spectral densities of phase or frequency data and their link to the deviations:
:func:`psd` and :func:`psd_to_deviation`.

S_y(f) is the one-sided PSD of the fractional frequency (1/Hz), S_x(f) =
S_y(f) / (2 pi f)**2 that of the phase (s**2/Hz); the power law is S_y(f) =
h_alpha f**alpha (NIST SP 1065 section 7).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from avar._frozen import frozen_array
from avar._validation import check_freq, short_repr
from avar.stability.shared.inputs import finite_vector

PSD_METHODS = ("welch", "periodogram")
DEVIATION_KINDS = ("adev", "mdev")


@dataclass(frozen=True, eq=False)
class PowerSpectrum:
    """One-sided PSD of the fractional frequency, with its power-law slopes.

    Attributes
    ----------
    frequencies : ndarray
        Fourier frequencies f > 0 (Hz).
    psd : ndarray
        S_y(f) (1/Hz).
    phase_psd : ndarray
        S_x(f) = S_y(f) / (2 pi f)**2 (s**2/Hz).
    slope, alpha : float, int
        Least-squares slope of log S_y against log f over all frequencies,
        and the nearest power-law exponent in -2 .. 2.
    slopes : pandas.DataFrame
        One row per decade of frequency (``f_low``, ``f_high``, ``slope``,
        ``alpha``): the power-law segments (slope fitted within the decade).
    """

    frequencies: np.ndarray
    psd: np.ndarray
    phase_psd: np.ndarray
    slope: float
    alpha: int
    slopes: pd.DataFrame

    def __post_init__(self) -> None:
        for name in ("frequencies", "psd", "phase_psd"):
            object.__setattr__(self, name, frozen_array(getattr(self, name)))


def _fitted_slope(f: np.ndarray, s: np.ndarray) -> float:
    keep = s > 0
    if keep.sum() < 2:
        return float("nan")
    return float(np.polyfit(np.log10(f[keep]), np.log10(s[keep]), 1)[0])


def _alpha_of(slope: float) -> int:
    return int(np.clip(np.round(slope), -2, 2)) if np.isfinite(slope) else 0


def psd(data: Any, rate: float = 1.0, data_type: str = "freq", method: str = "welch",
        nperseg: int | None = None) -> PowerSpectrum:
    """One-sided PSD S_y(f) of phase or frequency data, with its power-law slopes marked.

    Phase data are converted to frequency, y_i = (x_{i+1} - x_i) rate; the PSD
    of y is ``scipy.signal.welch`` (Hann window, segments of ``nperseg``
    samples, default min(N, 4096) ... N // 8 at least 256; linear detrending)
    or ``scipy.signal.periodogram``, scaled as a density so that
    sum S_y df = var(y). The zero frequency is dropped. Each decade's slope
    of log S_y against log f is rounded to the power-law alpha (2 white PM,
    1 flicker PM, 0 white FM, -1 flicker FM, -2 random-walk FM).

    Parameters
    ----------
    data : array_like
        Fractional frequency y or phase x (s), 1-D, finite.
    rate : float
        Sampling rate in Hz.
    data_type : {"freq", "phase"}
    method : {"welch", "periodogram"}
    nperseg : int, optional
        Welch segment length.

    Returns
    -------
    PowerSpectrum

    Examples
    --------
    >>> import numpy as np, avar
    >>> res = avar.psd(np.random.default_rng(0).standard_normal(2**14), rate=10.0)
    >>> res.alpha, bool(abs(np.median(res.psd) - 2 / 10.0) < 0.02)  # white FM: S_y = 2 sigma**2 / rate
    (0, True)
    """
    from scipy import signal

    rate = check_freq(rate, "rate")
    if not isinstance(data_type, str) or data_type not in ("freq", "phase"):
        raise ValueError(f"data_type must be 'freq' or 'phase', got {short_repr(data_type)}")
    if not isinstance(method, str) or method not in PSD_METHODS:
        raise ValueError(f"method must be one of {PSD_METHODS}, got {short_repr(method)}")
    values = finite_vector(data, "data", 9 if data_type == "phase" else 8)
    y = np.diff(values) * rate if data_type == "phase" else values
    if method == "welch":
        if nperseg is None:
            nperseg = int(min(y.size, max(256, min(4096, y.size // 8))))
        if isinstance(nperseg, bool) or not isinstance(nperseg, (int, np.integer)) or not 8 <= nperseg <= y.size:
            raise ValueError(f"nperseg must be an integer in 8 .. {y.size} (the number of frequency values), "
                             f"got {short_repr(nperseg)}")
        f, s = signal.welch(y, fs=rate, nperseg=int(nperseg), detrend="linear")
    else:
        f, s = signal.periodogram(y, fs=rate, detrend="linear")
    f, s = f[1:], s[1:]
    slope = _fitted_slope(f, s)
    rows = []
    for low in 10.0 ** np.arange(np.floor(np.log10(f[0])), np.ceil(np.log10(f[-1]))):
        inside = (f >= low) & (f < 10 * low)
        if inside.sum() >= 3:
            part = _fitted_slope(f[inside], s[inside])
            rows.append((float(f[inside][0]), float(f[inside][-1]), part, _alpha_of(part)))
    slopes = pd.DataFrame(rows, columns=["f_low", "f_high", "slope", "alpha"])
    return PowerSpectrum(frequencies=f, psd=s, phase_psd=s / (2 * np.pi * f) ** 2, slope=slope,
                         alpha=_alpha_of(slope), slopes=slopes)


def psd_to_deviation(frequencies: Any, psd: Any, taus: Any, kind: str = "adev", rate: float | None = None) -> np.ndarray:
    """Deviation implied by a one-sided frequency PSD: sigma**2(tau) = integral S_y(f) ``|H(f)|**2`` df.

    The transfer functions (NIST SP 1065 section 7.1, Barnes et al. 1971)::

        ADEV: |H(f)|**2 = 2 sin(pi tau f)**4 / (pi tau f)**2
        MDEV: |H(f)|**2 = 2 sin(pi tau f)**6 / ((pi tau f)**2 m**2 sin(pi tau0 f)**2),   m = tau / tau0

    With ``rate`` given, ADEV uses the exact transfer function of sampled data,
    2 sin(pi tau f)**4 / (m sin(pi tau0 f))**2 (equal to the one above where
    f << 1 / tau0), which the white and flicker PM of sampled data need; MDEV
    always needs ``rate``. The integral is the trapezoidal rule on the given
    frequencies (give a fine grid, logarithmic for steep spectra).

    Parameters
    ----------
    frequencies : array_like
        Increasing Fourier frequencies f > 0 (Hz).
    psd : array_like
        S_y(f) at those frequencies (1/Hz), >= 0.
    taus : array_like
        Averaging times (s); with ``rate``, whole multiples of tau0.
    kind : {"adev", "mdev"}
    rate : float, optional
        Sampling rate in Hz.

    Returns
    -------
    ndarray, the deviation at each tau.

    Examples
    --------
    >>> import numpy as np, avar
    >>> f = np.linspace(1e-6, 0.5, 200001)  # white FM, S_y = h0 = 2: ADEV = sqrt(h0 / (2 tau))
    >>> avar.psd_to_deviation(f, np.full(f.size, 2.0), [10.0, 100.0], rate=1.0).round(4).tolist()
    [0.3162, 0.1]
    """
    f = finite_vector(frequencies, "frequencies", 2)
    s = finite_vector(psd, "psd", 2)
    if f.size != s.size:
        raise ValueError(f"frequencies and psd must have one length, got {f.size} and {s.size}")
    if (f <= 0).any() or (np.diff(f) <= 0).any():
        raise ValueError("frequencies must be positive and increasing")
    if (s < 0).any():
        raise ValueError("psd must be >= 0")
    tau = finite_vector(np.atleast_1d(np.asarray(taus, dtype=np.float64)), "taus", 1)
    if (tau <= 0).any():
        raise ValueError(f"taus must be positive averaging times in seconds, got {short_repr(tau.tolist())}")
    if not isinstance(kind, str) or kind not in DEVIATION_KINDS:
        raise ValueError(f"kind must be one of {DEVIATION_KINDS}, got {short_repr(kind)}")
    if rate is None and kind == "mdev":
        raise ValueError("rate is needed for kind='mdev' (its transfer function depends on tau0 = 1 / rate)")
    if rate is not None:
        rate = check_freq(rate, "rate")
    from scipy.integrate import trapezoid

    out = np.empty(tau.size)
    for k, t in enumerate(tau):
        u = np.pi * t * f
        if rate is None:
            h = 2.0 * np.sin(u) ** 4 / u**2
        else:
            m = t * rate
            d = m * np.sin(np.pi * f / rate)
            h = 2.0 * np.sin(u) ** 4 / d**2 if kind == "adev" else 2.0 * np.sin(u) ** 6 / (u**2 * d**2)
        out[k] = np.sqrt(trapezoid(s * h, f))
    return out
