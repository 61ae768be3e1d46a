"""Phase noise of a clock or oscillator: L(f) and S_phi(f) from its time error, and the
power-law conversions between phase noise, S_y(f) and the Allan deviation.

With x(t) the time error (phase in seconds) of a carrier of frequency nu0 (Hz):

* S_x(f), the one-sided PSD of x (s**2/Hz);
* S_phi(f) = (2 pi nu0)**2 S_x(f), the one-sided PSD of the phase in radians (rad**2/Hz);
* L(f) = 10 log10(S_phi(f) / 2), the single-sideband phase noise (dBc/Hz, IEEE Std 1139's
  definition, valid where the phase excursions are small);
* S_y(f) = (2 pi f)**2 S_x(f) = (f / nu0)**2 S_phi(f), the PSD of the fractional frequency.
  For sampled data, y_i = (x_{i+1} - x_i) rate, the exact relation is
  S_y(f) = (2 rate sin(pi f / rate))**2 S_x(f), which :func:`phase_noise` uses (it tends to the
  one above where f << rate).

A power-law segment S_y(f) = h_alpha f**alpha is S_phi(f) = nu0**2 h_alpha f**(alpha - 2), and
its Allan variance (NIST SP 1065, Table 3; f_h the measurement's high cut-off, the Nyquist
frequency of sampled data):

======  =============  ==============================================================
alpha   noise          sigma_y**2(tau)
======  =============  ==============================================================
2       white PM       3 f_h h_2 / ((2 pi)**2 tau**2)
1       flicker PM     (1.038 + 3 ln(2 pi f_h tau)) h_1 / ((2 pi)**2 tau**2)
0       white FM       h_0 / (2 tau)
-1      flicker FM     2 ln 2 h_-1
-2      random-walk FM (2 pi)**2 tau h_-2 / 6
======  =============  ==============================================================

References
----------
IEEE Std 1139-2008, Standard definitions of physical quantities for fundamental frequency and
time metrology; W. J. Riley, NIST SP 1065 (2008), sections 7 and 8.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from avar._frozen import frozen_array
from avar._validation import check_freq, short_repr
from avar.stability.shared.inputs import finite_vector

__all__ = ["PhaseNoise", "phase_noise", "power_law_adev", "ssb_to_phase_psd", "phase_psd_to_ssb",
           "phase_psd_to_frequency_psd"]

#: Allan variance of each power law per unit h_alpha, as a function of (tau, f_h) (see the table above).
_AVAR_PER_H = {
    2: lambda tau, fh: 3.0 * fh / ((2 * np.pi) ** 2 * tau**2),
    1: lambda tau, fh: (1.038 + 3.0 * np.log(2 * np.pi * fh * tau)) / ((2 * np.pi) ** 2 * tau**2),
    0: lambda tau, fh: 1.0 / (2.0 * tau),
    -1: lambda tau, fh: 2.0 * np.log(2.0) + 0.0 * tau,
    -2: lambda tau, fh: (2 * np.pi) ** 2 * tau / 6.0,
}


def ssb_to_phase_psd(L: Any) -> np.ndarray:
    """S_phi(f) = 2 * 10**(L / 10) (rad**2/Hz) from L(f) (dBc/Hz).

    >>> ssb_to_phase_psd([-100.0]).tolist()
    [2e-10]
    """
    return 2.0 * 10.0 ** (np.asarray(L, dtype=np.float64) / 10.0)


def phase_psd_to_ssb(S_phi: Any) -> np.ndarray:
    """L(f) = 10 log10(S_phi(f) / 2) (dBc/Hz) from S_phi(f) (rad**2/Hz).

    >>> phase_psd_to_ssb([2e-10]).round(6).tolist()
    [-100.0]
    """
    with np.errstate(divide="ignore"):
        return 10.0 * np.log10(np.asarray(S_phi, dtype=np.float64) / 2.0)


def phase_psd_to_frequency_psd(frequencies: Any, S_phi: Any, carrier: float) -> np.ndarray:
    """S_y(f) = (f / nu0)**2 S_phi(f) (1/Hz) from S_phi(f) (rad**2/Hz) at Fourier ``frequencies`` (Hz).

    >>> phase_psd_to_frequency_psd([10.0], [1e-12], carrier=10e6).tolist()  # (10 / 1e7)**2 1e-12
    [1e-24]
    """
    carrier = check_freq(carrier, "carrier")
    f = np.asarray(frequencies, dtype=np.float64)
    return (f / carrier) ** 2 * np.asarray(S_phi, dtype=np.float64)


def power_law_adev(h: float, alpha: int, taus: Any, f_high: float | None = None) -> np.ndarray:
    """Allan deviation of one power-law segment S_y(f) = h f**alpha (see the module's table).

    Parameters
    ----------
    h : float
        The coefficient h_alpha (S_y in 1/Hz at f = 1 Hz), >= 0.
    alpha : {-2, -1, 0, 1, 2}
        The power-law exponent of S_y.
    taus : array_like
        Averaging times (s), > 0.
    f_high : float, optional
        The high cut-off f_h (Hz), needed for white and flicker PM (alpha 2, 1): the Nyquist
        frequency rate / 2 of sampled data.

    Returns
    -------
    ndarray, sigma_y(tau) (dimensionless).

    Examples
    --------
    >>> power_law_adev(2.0, 0, [1.0, 100.0]).tolist()   # white FM: sqrt(h0 / (2 tau))
    [1.0, 0.1]
    """
    if isinstance(alpha, bool) or alpha not in _AVAR_PER_H:
        raise ValueError(f"alpha must be a power-law exponent -2, -1, 0, 1 or 2, got {short_repr(alpha)}")
    h = float(h)
    if not (np.isfinite(h) and h >= 0):
        raise ValueError(f"h must be a finite coefficient >= 0, got {short_repr(h)}")
    tau = np.atleast_1d(np.asarray(taus, dtype=np.float64))
    if not (np.isfinite(tau).all() and (tau > 0).all()):
        raise ValueError(f"taus must be positive averaging times in seconds, got {short_repr(tau.tolist())}")
    if alpha in (1, 2):
        if f_high is None:
            raise ValueError("f_high is needed for white and flicker PM (alpha 2, 1): e.g. rate / 2 of sampled data")
        f_high = check_freq(f_high, "f_high")
    return np.sqrt(h * _AVAR_PER_H[alpha](tau, f_high))


@dataclass(frozen=True, eq=False)
class PhaseNoise:
    """The phase noise of a carrier, from its time error.

    Attributes
    ----------
    frequencies : ndarray
        Fourier (offset) frequencies f > 0 (Hz).
    L : ndarray
        Single-sideband phase noise L(f) = 10 log10(S_phi / 2) (dBc/Hz).
    S_phi : ndarray
        One-sided PSD of the phase in radians (rad**2/Hz).
    S_x : ndarray
        One-sided PSD of the time error (s**2/Hz).
    S_y : ndarray
        One-sided PSD of the fractional frequency y_i = (x_{i+1} - x_i) rate (1/Hz):
        (2 rate sin(pi f / rate))**2 S_x.
    carrier : float
        The carrier frequency nu0 (Hz).
    rate : float
        The sampling rate of the time error (Hz).
    segments : int
        Spectra averaged (Welch); each bin's estimate has about 2 * segments degrees of freedom.
    """

    frequencies: np.ndarray
    L: np.ndarray
    S_phi: np.ndarray
    S_x: np.ndarray
    S_y: np.ndarray
    carrier: float
    rate: float
    segments: int

    def __post_init__(self) -> None:
        for name in ("frequencies", "L", "S_phi", "S_x", "S_y"):
            object.__setattr__(self, name, frozen_array(getattr(self, name)))

    def deviation(self, taus: Any, kind: str = "adev") -> np.ndarray:
        """The deviation implied by the measured S_y (:func:`avar.psd_to_deviation`, sampled data)."""
        from avar.stability.spectral.spectrum import psd_to_deviation

        return psd_to_deviation(self.frequencies, self.S_y, taus, kind=kind, rate=self.rate)

    def summary(self):
        """A table: f (Hz), L (dBc/Hz), S_phi (rad^2/Hz), S_y (1/Hz)."""
        import pandas as pd

        return pd.DataFrame({"f (Hz)": self.frequencies, "L (dBc/Hz)": self.L, "S_phi (rad^2/Hz)": self.S_phi,
                             "S_y (1/Hz)": self.S_y})

    def __repr__(self) -> str:
        return (f"<PhaseNoise of a {self.carrier:g} Hz carrier: {self.frequencies.size} frequencies "
                f"{self.frequencies[0]:.3g} .. {self.frequencies[-1]:.3g} Hz, {self.segments} spectra averaged>")


def phase_noise(x: Any, rate: float = 1.0, carrier: float = 10e6, data_type: str = "phase",
                segments: int = 8) -> PhaseNoise:
    """Phase noise L(f) and S_phi(f) of a carrier from its time error (or fractional frequency).

    The PSD of the data is Welch's average of ``segments`` half-overlapping, Hann-windowed,
    linearly detrended spectra (``scipy.signal.welch``, one-sided density, so that white noise
    of variance sigma**2 per sample reads 2 sigma**2 / rate): of the time error x (s) for phase
    data, of y for frequency data. The other follows by the exact relation of sampled data,
    S_y = (2 rate sin(pi f / rate))**2 S_x; then S_phi = (2 pi nu0)**2 S_x and
    L = 10 log10(S_phi / 2) (see the module's formulas).

    Parameters
    ----------
    x : array_like
        Time error (s) with ``data_type="phase"``, or fractional frequency with ``"freq"``; 1-D, finite.
    rate : float
        Sampling rate in Hz.
    carrier : float
        The carrier frequency nu0 in Hz (e.g. 10e6 for a 10 MHz oscillator).
    data_type : {"phase", "freq"}
    segments : int
        Spectra averaged (>= 1): more gives a smoother L(f), fewer reaches lower frequencies.

    Returns
    -------
    PhaseNoise

    Examples
    --------
    >>> import numpy as np, avar
    >>> x = np.random.default_rng(1).standard_normal(2**16) * 1e-12   # 1 ps white PM at 1 Hz
    >>> pn = avar.phase_noise(x, rate=1.0, carrier=10e6)
    >>> theory = (2 * np.pi * 10e6) ** 2 * 2 * 1e-24          # S_phi = (2 pi nu0)**2 2 sigma**2 / rate
    >>> bool(abs(np.mean(pn.S_phi) / theory - 1) < 0.03), round(float(10 * np.log10(theory / 2)), 1)  # L (dBc/Hz)
    (True, -84.0)
    """
    from scipy import signal

    rate = check_freq(rate, "rate")
    carrier = check_freq(carrier, "carrier")
    if not isinstance(data_type, str) or data_type not in ("freq", "phase"):
        raise ValueError(f"data_type must be 'phase' (time error, s) or 'freq' (fractional frequency), "
                         f"got {short_repr(data_type)}")
    if isinstance(segments, bool) or not isinstance(segments, (int, np.integer)) or segments < 1:
        raise ValueError(f"segments must be a whole number >= 1, got {short_repr(segments)}")
    values = finite_vector(x, "x", 16)
    nperseg = int(2 * values.size // (segments + 1)) if segments > 1 else values.size
    if nperseg < 8:
        raise ValueError(f"x has {values.size} values: too few for {segments} spectra of 8 points or more")
    f, s = signal.welch(values, fs=rate, nperseg=nperseg, noverlap=nperseg // 2, detrend="linear")
    f, s = f[1:], s[1:]
    differencing = (2.0 * rate * np.sin(np.pi * f / rate)) ** 2  # |transfer|**2 of y_i = (x_{i+1} - x_i) rate
    s_x, s_y = (s, differencing * s) if data_type == "phase" else (s / differencing, s)
    s_phi = (2 * np.pi * carrier) ** 2 * s_x
    return PhaseNoise(frequencies=f, L=phase_psd_to_ssb(s_phi), S_phi=s_phi, S_x=s_x, S_y=s_y,
                      carrier=carrier, rate=rate, segments=int(segments))
