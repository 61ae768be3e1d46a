"""Power-law noise of clocks and oscillators (Kasdin and Walter 1992): :func:`power_law`.

Reached as ``avar.noise`` (loaded on first use).
"""

from __future__ import annotations

import numbers
from typing import Any

import numpy as np

from avar._validation import check_count, check_freq, check_real, check_seed, short_repr

DATA_TYPES = ("freq", "phase")


def filter_coefficients(alpha: float, n: int) -> np.ndarray:
    """Kasdin and Walter's fractional-difference filter of S_y ~ f**alpha (impulse response, n terms).

    With beta = -alpha: h_0 = 1, h_k = h_{k-1} (beta / 2 + k - 1) / k.

    >>> filter_coefficients(-2, 4).tolist(), filter_coefficients(2, 4).tolist()
    ([1.0, 1.0, 1.0, 1.0], [1.0, -1.0, 0.0, 0.0])
    """
    k = np.arange(1, n, dtype=np.float64)
    return np.concatenate(([1.0], np.cumprod((-alpha / 2.0 + k - 1.0) / k)))


def discrete_psd(frequencies: Any, alpha: float, h: float = 1.0, rate: float = 1.0) -> np.ndarray:
    """The exact one-sided PSD of :func:`power_law`'s frequency series, S_y(f) (1/Hz).

    S_y(f) = 2 Q tau0 ``|2 sin(pi f tau0)|**alpha``, Q = h (2 pi)**(-alpha) / (2 tau0**(alpha + 1)),
    so that S_y(f) -> h f**alpha where f << 1 / tau0 (Kasdin and Walter 1992, eq. 14).

    >>> round(float(discrete_psd([1e-4], -1, h=3.0)[0] * 1e-4), 6)  # flicker FM: h_-1 / f
    3.0
    """
    tau0 = 1.0 / rate
    q = h * (2 * np.pi) ** (-alpha) / (2 * tau0 ** (alpha + 1))
    return 2 * q * tau0 * np.abs(2 * np.sin(np.pi * np.asarray(frequencies, dtype=np.float64) * tau0)) ** alpha


def power_law(alpha: float, n: int, h: float = 1.0, rate: float = 1.0, data_type: str = "freq",
              seed: Any = None) -> np.ndarray:
    """Power-law noise with S_y(f) = h f**alpha (exactly: :func:`discrete_psd`), by Kasdin and Walter's method.

    White Gaussian noise w of variance Q = h (2 pi)**(-alpha) / (2 tau0**(alpha + 1))
    is filtered by the fractional-difference filter h_k (:func:`filter_coefficients`):
    y_i = sum_{k=0}^{i} h_k w_{i-k}, a linear convolution computed by FFT
    (O(n log n)). alpha = 2 white PM, 1 flicker PM, 0 white FM, -1 flicker
    FM, -2 random-walk FM; any real alpha in -4 .. 2 is accepted. The series
    starts from rest (the filter sees no past), as Kasdin and Walter's; for
    alpha = -2 it is exactly the random walk of w, for alpha = 2 the first
    difference of w (w_{-1} = 0).

    Parameters
    ----------
    alpha : float
        Exponent of S_y(f) ~ f**alpha, -4 .. 2.
    n : int
        Number of values.
    h : float
        Level h_alpha of S_y(f) = h f**alpha (units 1/Hz**(alpha + 1)), > 0.
    rate : float
        Sampling rate in Hz (tau0 = 1 / rate).
    data_type : {"freq", "phase"}
        Return the fractional frequency y (n values) or the phase x =
        (0, cumsum(y)) tau0 (n + 1 points, seconds).
    seed : None, int or numpy.random.Generator
        Random seed, for reproducible series.

    Returns
    -------
    ndarray of float64

    References
    ----------
    N. J. Kasdin and T. Walter, "Discrete simulation of power law noise",
    Proc. IEEE Frequency Control Symposium, 1992, pp. 274-283.

    Examples
    --------
    >>> import avar
    >>> y = avar.noise.power_law(0, 100000, h=2.0, seed=1)  # white FM: ADEV = sqrt(h0 / (2 tau))
    >>> round(float(avar.oadev(y, taus=[10.0]).deviation[0]), 2)  # sqrt(2 / 20) = 0.316
    0.31
    """
    if isinstance(alpha, (bool, np.bool_)) or not isinstance(alpha, numbers.Real):
        raise TypeError(f"alpha must be a real power-law exponent in -4 .. 2, got {short_repr(alpha)}")
    alpha = float(alpha)
    if not -4.0 <= alpha <= 2.0:
        raise ValueError(f"alpha must be in -4 .. 2 (2 white PM ... -2 random-walk FM), got {alpha:g}")
    n = check_count(n, "n", minimum=1)
    h = check_real(h, "h", minimum=0.0)
    if h <= 0:
        raise ValueError(f"h must be positive, got {h:g}")
    rate = check_freq(rate, "rate")
    if not isinstance(data_type, str) or data_type not in DATA_TYPES:
        raise ValueError(f"data_type must be 'freq' or 'phase', got {short_repr(data_type)}")
    rng = np.random.default_rng(check_seed(seed))
    tau0 = 1.0 / rate
    q = h * (2 * np.pi) ** (-alpha) / (2 * tau0 ** (alpha + 1))
    w = rng.standard_normal(n) * np.sqrt(q)
    size = 1 << (2 * n - 1).bit_length()
    y = np.fft.irfft(np.fft.rfft(w, size) * np.fft.rfft(filter_coefficients(alpha, n), size), size)[:n]
    if data_type == "phase":
        return np.concatenate(([0.0], np.cumsum(y))) * tau0
    return y
